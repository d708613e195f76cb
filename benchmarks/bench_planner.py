"""Speed of the planner on a realistic fixture, each figure next to a baseline of the same run.

Run: ``python benchmarks/bench_planner.py``. The fixture is a 120 x 80 x 40 mm block on three
support pads, pushed against two side locators and an end stop by two top clamps and one side
clamp (8 area contacts), under 20 milling load cases. Medians of repeated runs.
"""

from __future__ import annotations

import dataclasses
import os
import time
from pathlib import Path

import numpy as np
from performance_rows import emit

from fixplan import pressure
from fixplan.io.problem_file import load_problem
from fixplan.planner.planner import Planner
from fixplan.planner.problem import Body, Contact, Load, Problem


def fixture(model: str, objective: str, loads: list[Load], clamp_force: float | None = None):
    pad, jaw = pressure.disk(0.008), pressure.rectangle(0.03, 0.01)

    def contact(name, role, position, normal, patch):
        force = clamp_force if role == "clamp" else None
        return Contact(
            name=name, role=role, position=position, normal=normal, mu=0.3, model=model,
            patch=patch, force=force,
        )  # fmt: skip

    contacts = [
        contact("pad-1", "support", [0.04, 0.0, 0.0], [0, 0, 1], pad),
        contact("pad-2", "support", [-0.04, 0.03, 0.0], [0, 0, 1], pad),
        contact("pad-3", "support", [-0.04, -0.03, 0.0], [0, 0, 1], pad),
        contact("side-1", "locator", [0.03, -0.04, 0.02], [0, 1, 0], jaw),
        contact("side-2", "locator", [-0.03, -0.04, 0.02], [0, 1, 0], jaw),
        contact("end", "locator", [-0.06, 0.0, 0.02], [1, 0, 0], jaw),
        contact("clamp-top", "clamp", [0.0, 0.0, 0.04], [0, 0, -1], pad),
        contact("clamp-side", "clamp", [0.0, 0.04, 0.02], [0, -1, 0], jaw),
    ]
    body = Body(mass=3.0, center_of_mass=[0.0, 0.0, 0.02])
    return Problem(body=body, contacts=contacts, loads=loads, objective=objective)


def milling_loads(count: int, seed: int) -> list[Load]:
    rng = np.random.default_rng(seed)
    loads = []
    for k in range(count):
        force = rng.normal(size=3) * [80.0, 80.0, 40.0]
        point = [rng.uniform(-0.05, 0.05), rng.uniform(-0.03, 0.03), 0.04]
        torque = [0.0, 0.0, rng.normal() * 1.0]
        loads.append(Load(name=f"cut-{k}", force=force, point=point, torque=torque))
    return loads


def fixture_321_check(count: int, seed: int) -> Problem:
    """``problems/fixture-321.toml`` at its planned clamp forces (objective ``check``), its 12
    cuts scaled to ``count`` load cases by random convex combinations turned about z."""
    path = Path(__file__).resolve().parents[1] / "problems" / "fixture-321.toml"
    problem = load_problem(path).problem
    forces = Planner(problem).solve().forces
    contacts = tuple(
        dataclasses.replace(c, force=float(forces[c.name])) if c.name in forces else c
        for c in problem.contacts
    )
    rng = np.random.default_rng(seed)
    loads = []
    for k in range(count):
        a, b = rng.choice(len(problem.loads), 2, replace=False)
        w, angle = rng.uniform(), rng.uniform(-np.pi, np.pi)
        c, s = np.cos(angle), np.sin(angle)
        turn = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
        first, second = problem.loads[a], problem.loads[b]
        loads.append(Load(
            name=f"case-{k}", force=turn @ (w * first.force + (1 - w) * second.force),
            point=turn @ (w * first.point + (1 - w) * second.point),
            torque=w * first.torque + (1 - w) * second.torque,
        ))  # fmt: skip
    return dataclasses.replace(problem, contacts=contacts, loads=tuple(loads), objective="check")


def timed(function):
    start = time.perf_counter()
    result = function()
    return result, time.perf_counter() - start


def build_and_resolve(model: str) -> tuple[float, float, float]:
    """(build + first solve [s], median re-solve [s], objective [N]) for a model."""
    problem = fixture(model, "min-total-clamp-force", milling_loads(20, 0))
    planner, build = timed(lambda: Planner(problem))
    plan, first = timed(lambda: planner.solve(analyse=False))
    assert plan.status == "optimal", plan.status
    times = []
    for seed in range(1, 21):
        loads = milling_loads(20, seed)
        times.append(timed(lambda loads=loads: planner.solve(loads, analyse=False))[1])
    return build + first, float(np.median(times)), plan.objective_value


def main() -> None:
    import cvxpy as cp

    print("planner, 8-contact x 20-load fixture, objective min-total-clamp-force")
    ellipsoid = build_and_resolve("ellipsoid")
    exact = build_and_resolve("exact")
    print(
        f"  ellipsoid: build + first solve {ellipsoid[0]:7.3f} s, median re-solve "
        f"{ellipsoid[1] * 1e3:7.2f} ms, total clamp force {ellipsoid[2]:8.2f} N"
    )
    print(
        f"  exact:     build + first solve {exact[0]:7.3f} s, median re-solve "
        f"{exact[1] * 1e3:7.2f} ms, total clamp force {exact[2]:8.2f} N"
    )
    print(
        f"  exact / ellipsoid cost: build x{exact[0] / ellipsoid[0]:.1f}, "
        f"re-solve x{exact[1] / ellipsoid[1]:.1f}"
    )

    problem = fixture("ellipsoid", "min-total-clamp-force", milling_loads(20, 0))
    planner = Planner(problem)
    planner.solve(analyse=False)
    compiled = planner._runner.stacked(problem.objective).problem
    raw = []
    for _ in range(20):
        raw.append(timed(lambda: compiled.solve(solver=cp.CLARABEL))[1])
    print(
        f"  baseline: cvxpy + Clarabel alone on the compiled problem {np.median(raw) * 1e3:.2f} ms"
        f" (fixplan's re-solve, direct Clarabel plus numpy verification, takes x{ellipsoid[1] / np.median(raw):.2f} of it)"
    )
    emit(
        "planner, 8 contacts × 20 loads, ellipsoid: build + first solve; median re-solve "
        "(verified)",
        f"{ellipsoid[0]:.2f} s; {ellipsoid[1] * 1e3:.2f} ms",
        f"cvxpy + Clarabel re-solve {np.median(raw) * 1e3:.2f} ms",
        f"re-solve {ellipsoid[1] / np.median(raw):.2f}×",
    )

    loads = milling_loads(1000, 7)
    check = fixture("ellipsoid", "check", loads, clamp_force=2000.0)
    check_planner = Planner(check)
    plan, first = timed(check_planner.solve)
    plan, again = timed(check_planner.solve)
    held = sum(plan.held.values())
    print(
        f"check of 1,000 load cases: {1000 / again:7.0f} cases/s ({again:.2f} s; first call "
        f"{first:.2f} s with compilation); {held} held, smallest safety factor "
        f"{plan.safety_factor:.3f}"
    )
    emit("`check` of 1,000 load cases, the ellipsoid fixture, plan included",
         f"{1000 / again:,.0f} cases/s", "", "")  # fmt: skip

    problem = fixture_321_check(1000, 11)
    planner = Planner(problem)
    planner.solve()
    wrenches = problem.task_wrenches()
    given = {i: c.force for i, c in enumerate(problem.contacts) if c.force is not None}

    def both_ends() -> None:  # the solves of the previous planner: k_max and k_min of every case
        for sense in (1.0, -1.0):
            planner._runner.run("check", wrenches, given, sense=sense)

    check = np.median([timed(planner.solve)[1] for _ in range(5)])
    solves = np.median([timed(both_ends)[1] for _ in range(5)])
    print(
        f"check of fixture-321 x 1,000 load cases (load average {os.getloadavg()[0]:.1f}): "
        f"{1000 / check:7.0f} cases/s, plan included; both ends of every case solved, without "
        f"the analysis: {1000 / solves:7.0f} cases/s"
    )
    emit(
        "`check` of 1,000 load cases of `problems/fixture-321.toml` (pyramids), plan included",
        f"{1000 / check:,.0f} cases/s",
        f"both ends of every held interval solved, no analysis: {1000 / solves:,.0f} cases/s",
        f"{solves / check:.2f}×",
    )


if __name__ == "__main__":
    main()
