"""The exact friction model in the planner against the ellipsoid, on the same problems.

Run: ``python benchmarks/bench_exact.py`` (``--cells 200`` is the default grid side). Two
problems, each model timed in a fresh process (peak resident memory of that process):

- a pinch: two fingers with ``cells × cells`` tactile grids (a Hertz-like pressure map over
  20 x 20 mm), holding a weight and a torque about the grasp axis, 4 load cases; build + first
  solve and the median of ``RESOLVES`` re-solves with new loads;
- the fixture of ``bench_planner.py`` (8 area contacts x 20 milling loads), the same figures
  and the number of rounds of the exact model (osculating ellipsoids, or cuts where those do
  not settle), with the time per round of a re-solve spent in Clarabel and in moving the
  ellipsoids or cutting (mostly the exact inverse map's queries).

The machine is shared and noisy: compare the ratios of the same run.
"""

from __future__ import annotations

import argparse
import json
import resource
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

from fixplan import Body, Contact, Load, Problem, pressure
from fixplan.planner.planner import Planner

sys.path.insert(0, str(Path(__file__).parent))
from bench_planner import fixture, milling_loads
from performance_rows import emit

#: Re-solves with new loads per problem and model (their median is reported).
RESOLVES = 20


def tactile_pinch(model: str, cells: int, loads: list[Load]) -> Problem:
    side = np.linspace(-0.01, 0.01, cells)
    x, y = np.meshgrid(side, side)
    values = np.sqrt(np.clip(1.0 - (x * x + y * y) / 0.009**2, 0.0, None))
    patch = pressure.grid(side, side, values)
    contacts = [
        Contact(name=name, role="finger", position=[0, s * 0.03, 0], normal=[0, -s, 0], mu=0.5,
                model=model, patch=patch)
        for name, s in (("left", -1), ("right", 1))
    ]  # fmt: skip
    return Problem(body=Body(mass=0.0, center_of_mass=[0, 0, 0]), contacts=contacts,
                   loads=loads, objective="min-max-normal-force")  # fmt: skip


def pinch_loads(seed: int) -> list[Load]:
    rng = np.random.default_rng(seed)
    return [
        Load(name=f"hold-{k}", force=[rng.normal(), 0, -rng.uniform(5, 20)],
             point=[rng.normal(0, 0.01), 0, 0], torque=[0, rng.uniform(-0.2, 0.2), 0])
        for k in range(4)
    ]  # fmt: skip


def measure(case: str, model: str, cells: int) -> dict:
    """Figures of one model on one problem (run in a fresh process)."""
    if case == "pinch":
        problem, new_loads = tactile_pinch(model, cells, pinch_loads(0)), pinch_loads
    else:
        problem = fixture(model, "min-total-clamp-force", milling_loads(20, 0))
        new_loads = lambda seed: milling_loads(20, seed)  # noqa: E731
    rounds, spent = [], {"cuts": 0.0, "solver": 0.0}
    if model == "exact":
        from fixplan.planner import cuts, direct_solve, osculating

        def timed(owner, name, key):
            method = getattr(owner, name)

            def wrapper(self, *args, **kwargs):
                start = time.perf_counter()
                try:
                    return method(self, *args, **kwargs)
                finally:
                    spent[key] += time.perf_counter() - start

            setattr(owner, name, wrapper)

        timed(cuts.CutPool, "add_cuts", "cuts")
        timed(osculating.OsculatingPool, "move", "cuts")
        timed(direct_solve.DirectSolver, "solve", "solver")
        add_cuts, move = cuts.CutPool.add_cuts, osculating.OsculatingPool.move
        cuts.CutPool.add_cuts = lambda pool: rounds.append(1) or add_cuts(pool)
        osculating.OsculatingPool.move = lambda pool: rounds.append(1) or move(pool)
    start = time.perf_counter()
    planner = Planner(problem)
    plan = planner.solve(analyse=False)
    first = time.perf_counter() - start
    assert plan.status == "optimal", plan.status
    first_rounds, times = len(rounds), []
    spent.update(cuts=0.0, solver=0.0)
    for seed in range(1, RESOLVES + 1):
        loads = new_loads(seed)
        start = time.perf_counter()
        again = planner.solve(loads, analyse=False)
        times.append(time.perf_counter() - start)
        assert again.status == "optimal", again.status
    return {
        "first": first,
        "resolve": float(np.median(times)),
        "peak_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024,
        "rounds": (first_rounds, (len(rounds) - first_rounds) / RESOLVES),
        "per_round": {
            key: value / max(len(rounds) - first_rounds, 1) for key, value in spent.items()
        },
        "objective": plan.objective_value,
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--cells", type=int, default=200, help="grid side of the pinch")
    parser.add_argument("--child", nargs=2, help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.child:
        print(json.dumps(measure(*args.child, args.cells)))
        return
    for case, title in (
        ("pinch", f"pinch, 2 tactile grids of {args.cells} x {args.cells} cells, 4 load cases"),
        ("fixture", "fixture, 8 area contacts x 20 milling loads (bench_planner.py)"),
    ):
        figures = {}
        for model in ("ellipsoid", "exact"):
            command = [sys.executable, __file__, "--cells", str(args.cells), "--child", case, model]
            output = subprocess.run(command, check=True, capture_output=True, text=True).stdout
            figures[model] = json.loads(output)
        print(title)
        for model, f in figures.items():
            cutting = ""
            if model == "exact":
                cutting = (
                    f", rounds {f['rounds'][0]} then {f['rounds'][1]:.1f} per re-solve "
                    f"(per round: Clarabel {f['per_round']['solver'] * 1e3:.1f} ms, ellipsoids or "
                    f"cuts with their inverse-map queries {f['per_round']['cuts'] * 1e3:.1f} ms)"
                )
            print(
                f"  {model:9s}: build + first solve {f['first']:7.3f} s, median re-solve "
                f"{f['resolve'] * 1e3:8.1f} ms, peak memory {f['peak_mb']:6.0f} MB, objective "
                f"{f['objective']:.6f} N{cutting}"
            )
        e, x = figures["ellipsoid"], figures["exact"]
        print(
            f"  exact / ellipsoid: build + first solve x{x['first'] / e['first']:.1f}, re-solve "
            f"x{x['resolve'] / e['resolve']:.1f}, memory x{x['peak_mb'] / e['peak_mb']:.2f}"
        )
        emit(
            f"exact model, {title}: build + first solve; re-solve ({x['rounds'][1]:.1f} rounds); "
            "peak memory",
            f"{x['first']:.2f} s; {x['resolve'] * 1e3:,.0f} ms; {x['peak_mb']:,.0f} MB",
            f"ellipsoid {e['first']:.2f} s; {e['resolve'] * 1e3:,.1f} ms; {e['peak_mb']:,.0f} MB",
            f"{x['first'] / e['first']:.1f}×; {x['resolve'] / e['resolve']:,.0f}×; "
            f"{x['peak_mb'] / e['peak_mb']:.2f}×",
        )


if __name__ == "__main__":
    main()
