"""Grip forces at controller rate: re-solves of an 8-contact grasp with smoothly changing loads.

Run: ``python benchmarks/bench_realtime.py [--count N]``. The fixture of
``bench_planner.py`` (8 area contacts: three support pads, three locators, two clamps) with one
load case, objective ``min-total-clamp-force``, is solved ``N`` times (default 10,000) while its
load turns slowly (a cutting force of 80 N rotating in the plane and a torque varying with it,
as a controller would see it). For each friction model it prints the median and 99th percentile
of

- ``Planner.solve(load, analyse=False)``: the forces, verified in numpy;
- ``Planner.solve(load)``: the same plus the safety analysis (held interval, safety factor and
  impending motion of the forces found);
- the baseline: cvxpy + Clarabel re-solving the planner's compiled problem (parameters set,
  ``problem.solve``), with nothing else, in the same run.

The exact model (osculating ellipsoids, :mod:`fixplan.planner.osculating`) is timed on the first
twentieth of the path, against the ellipsoid's figures of the same run, with the mean number
of rounds per solve.

The machine's load average is printed with the figures (other processes slow these
single-threaded runs).
"""

from __future__ import annotations

import argparse
import os
import time

import cvxpy as cp
import numpy as np
from bench_planner import fixture
from performance_rows import emit

from fixplan.planner.planner import Planner
from fixplan.planner.problem import Load

MODELS = ("ellipsoid", "point-cone", "pyramid")


def loads(count: int) -> list[list[Load]]:
    """``count`` single-case load lists along a smooth path."""
    angles = np.linspace(0.0, 4.0 * np.pi, count)
    return [
        [
            Load(
                name="cut",
                force=[80.0 * np.cos(a), 80.0 * np.sin(a), -30.0],
                point=[0.02 * np.cos(a / 2), 0.01, 0.04],
                torque=[0.0, 0.0, 0.8 * np.sin(a)],
            )
        ]
        for a in angles
    ]


def timings(call, arguments) -> np.ndarray:
    out = np.empty(len(arguments))
    for k, argument in enumerate(arguments):
        start = time.perf_counter()
        call(argument)
        out[k] = time.perf_counter() - start
    return out


def figures(times: np.ndarray) -> str:
    return f"median {np.median(times) * 1e3:6.3f} ms, p99 {np.percentile(times, 99) * 1e3:6.3f} ms"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--count", type=int, default=10_000)
    count = parser.parse_args().count
    path = loads(count)
    print(f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores; {count} re-solves")
    medians = {}
    for model in MODELS:
        problem = fixture(model, "min-total-clamp-force", path[0])
        planner = Planner(problem)
        for warm in path[:3]:  # compile, then build the direct solvers
            planner.solve(warm)
        bare = timings(lambda x, planner=planner: planner.solve(x, analyse=False), path)
        analysed = timings(planner.solve, path[: max(count // 10, 10)])
        stacked = planner._runner.stacked(problem.objective)

        def baseline(x, stacked=stacked):
            stacked.task.value = np.column_stack([load.wrench for load in x])
            stacked.problem.solve(solver=cp.CLARABEL)

        raw = timings(baseline, path[: max(count // 10, 10)])
        plan = planner.solve(path[-1])
        print(f"{model:10s} solve {figures(bare)}; with analysis {figures(analysed)}")
        print(
            f"{'':10s} cvxpy + Clarabel {figures(raw)}; solve / baseline "
            f"{np.median(bare) / np.median(raw):.2f}, with analysis / solve "
            f"{np.median(analysed) / np.median(bare):.2f} (solver {plan.solver}, {plan.status})"
        )
        medians[model] = (np.median(bare), np.median(analysed))
        emit(
            f"grasp re-solve, 8 contacts × 1 case, {model}, {count:,} smoothly changing loads "
            "(median, p99): bare; with the safety analysis",
            f"{figures(bare)}; {figures(analysed)}",
            f"cvxpy + Clarabel re-solve {figures(raw)}",
            f"{np.median(bare) / np.median(raw):.2f}×; analysis / bare "
            f"{np.median(analysed) / np.median(bare):.2f}×",
        )

    exact_row(path[: max(count // 20, 10)], medians["ellipsoid"])


def exact_row(path: list, ellipsoid: tuple[float, float]) -> None:
    """The exact model on the same grasp, against the ellipsoid's medians (bare, analysed)."""
    from fixplan.planner import osculating

    rounds = []
    move = osculating.OsculatingPool.move
    osculating.OsculatingPool.move = lambda pool: rounds.append(1) or move(pool)
    planner = Planner(fixture("exact", "min-total-clamp-force", path[0]))
    for warm in path[:3]:
        planner.solve(warm)
    rounds.clear()
    bare = timings(lambda x: planner.solve(x, analyse=False), path)
    per_bare = len(rounds) / len(path)
    rounds.clear()
    analysed = timings(planner.solve, path)
    per_analysed = len(rounds) / len(path)
    osculating.OsculatingPool.move = move
    ratios = np.median(bare) / ellipsoid[0], np.median(analysed) / ellipsoid[1]
    print(f"{'exact':10s} solve {figures(bare)} ({per_bare:.1f} rounds); with analysis "
          f"{figures(analysed)} ({per_analysed:.1f} rounds); / ellipsoid {ratios[0]:.1f}, "
          f"{ratios[1]:.1f}")  # fmt: skip
    emit(
        f"grasp re-solve, 8 contacts × 1 case, exact, {len(path):,} smoothly changing loads "
        "(median, p99): bare; with the safety analysis (rounds of osculating ellipsoids)",
        f"{figures(bare)} ({per_bare:.1f}); {figures(analysed)} ({per_analysed:.1f})",
        f"ellipsoid of the same run: median {ellipsoid[0] * 1e3:.3f} ms; {ellipsoid[1] * 1e3:.3f} ms",
        f"{ratios[0]:.0f}×; {ratios[1]:.0f}×",
    )


if __name__ == "__main__":
    main()
