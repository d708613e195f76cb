"""How the planner scales with contacts x load cases: build, first solve, re-solve, peak memory.

Run: ``python benchmarks/bench_scaling.py`` (the whole table, a few minutes) or
``python benchmarks/bench_scaling.py CONTACTS CASES MODEL`` (one row). Each row runs in a fresh
process so that its peak resident memory is its own. The fixture is a 0.4 x 0.3 x 0.1 m plate
on a grid of support pads, with side locators, an end stop and top clamps (free clamp forces,
``min-total-clamp-force``), under random milling loads. The baseline of the same run is the
smallest problem; the fitted exponent ``p`` of ``time ~ (contacts x cases)^p`` shows the growth
(1 is linear).
"""

from __future__ import annotations

import json
import resource
import subprocess
import sys
import time

import numpy as np

from fixplan import pressure
from fixplan.planner.planner import Planner
from fixplan.planner.problem import Body, Contact, Load, Problem
from fixplan.planner.stacking import set_units

CONTACTS = (8, 50, 200)
CASES = (1, 20, 500)
MODELS = ("ellipsoid", "pyramid")


def plate_fixture(contacts: int, cases: int, model: str, seed: int = 0) -> Problem:
    """A plate held by ``contacts`` contacts: support pads underneath (three at the corners of a
    triangle, the rest random), side locators and an end stop, and clamps on top (two spread
    over the plate, the rest random); a quarter of the contacts each are locators and clamps."""
    pad, jaw = pressure.disk(0.008), pressure.rectangle(0.03, 0.01)
    clamps = max(2, contacts // 4)
    locators = max(2, contacts // 4)
    supports = contacts - clamps - locators - 1
    rng = np.random.default_rng(seed)
    items = []

    def add(role, position, normal, patch):
        name = f"{role}-{len(items)}"
        items.append(
            Contact(
                name=name,
                role=role,
                position=position,
                normal=normal,
                mu=0.3,
                model=model,
                patch=patch,
            )
        )

    corners = [[0.18, 0.0], [-0.18, 0.13], [-0.18, -0.13]]
    spread = rng.uniform([-0.2, -0.15], [0.2, 0.15], size=(supports, 2))
    for x, y in np.vstack([corners, spread])[:supports]:
        add("support", [x, y, 0.0], [0, 0, 1], pad)
    for x in np.linspace(-0.18, 0.18, locators):
        add("locator", [x, -0.15, 0.05], [0, 1, 0], jaw)
    add("locator", [-0.2, 0.0, 0.05], [1, 0, 0], jaw)
    spread = rng.uniform([-0.2, -0.15], [0.2, 0.15], size=(clamps, 2))
    for x, y in np.vstack([[[0.1, 0.0], [-0.1, 0.0]], spread])[:clamps]:
        add("clamp", [x, y, 0.1], [0, 0, -1], pad)
    return Problem(
        body=Body(mass=20.0, center_of_mass=[0.0, 0.0, 0.05]),
        contacts=items,
        loads=milling_loads(cases, seed),
        objective="min-total-clamp-force",
    )


def milling_loads(count: int, seed: int) -> list[Load]:
    rng = np.random.default_rng(seed + 1)
    return [
        Load(
            name=f"cut-{k}",
            force=rng.normal(size=3) * [150.0, 150.0, 60.0],
            point=[rng.uniform(-0.2, 0.2), rng.uniform(-0.15, 0.15), 0.1],
            torque=[0.0, 0.0, rng.normal() * 2.0],
        )
        for k in range(count)
    ]


def one_row(contacts: int, cases: int, model: str) -> dict:
    """Times [s] and peak memory [MB] of one size, measured in this process."""
    problem = plate_fixture(contacts, cases, model)
    start = time.perf_counter()
    planner = Planner(problem)
    plan = planner.solve(analyse=False)
    first = time.perf_counter() - start
    resolves = []
    for seed in range(1, 4):
        loads = milling_loads(cases, seed)
        start = time.perf_counter()
        again = planner.solve(loads, analyse=False)
        resolves.append(time.perf_counter() - start)
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0
    return {
        "contacts": contacts, "cases": cases, "model": model, "status": plan.status,
        "resolve_status": again.status, "build_and_first": first,
        "resolve": float(np.median(resolves)), "peak_mb": peak,
        "value": plan.objective_value,
    }  # fmt: skip


def dpp_table() -> None:
    """When cvxpy's DPP compilation pays: first solve and median re-solve with and without it."""
    import cvxpy as cp

    print("DPP: total time of a solve through cvxpy [s] (first / median of 2 re-solves)")
    for contacts, cases in ((8, 20), (50, 20), (200, 20), (50, 100), (200, 100)):
        problem = plate_fixture(contacts, cases, "ellipsoid")
        times = {}
        for dpp in (True, False):
            stacked = Planner(problem)._runner.stacked(problem.objective)
            set_units(stacked, problem.body.weight_wrench)
            runs = []
            for seed in range(3):
                stacked.task.value = np.column_stack([x.wrench for x in milling_loads(cases, seed)])
                start = time.perf_counter()
                stacked.problem.solve(solver=cp.CLARABEL, ignore_dpp=not dpp,
                                      iterative_refinement_enable=False)  # fmt: skip
                runs.append(time.perf_counter() - start)
            times[dpp] = (runs[0], float(np.median(runs[1:])))
        size = stacked.problem.size_metrics.num_scalar_variables
        print(
            f"  {contacts:4d} x {cases:4d} ({size:6d} variables): DPP {times[True][0]:.3f} / "
            f"{times[True][1]:.3f}, without {times[False][0]:.3f} / {times[False][1]:.3f}"
        )


def main() -> None:
    rows = []
    for model in MODELS:
        for contacts in CONTACTS:
            for cases in CASES:
                out = subprocess.run(
                    [sys.executable, __file__, str(contacts), str(cases), model],
                    capture_output=True, text=True, check=True,
                )  # fmt: skip
                rows.append(json.loads(out.stdout.strip().splitlines()[-1]))
    print("planner scaling, plate fixture, min-total-clamp-force (medians of 3 re-solves)")
    print("model      contacts cases  status   build+1st [s]  re-solve [s]  peak [MB]")
    for row in rows:
        print(
            f"{row['model']:10s} {row['contacts']:8d} {row['cases']:5d}  {row['status']:8s} "
            f"{row['build_and_first']:13.2f} {row['resolve']:13.3f} {row['peak_mb']:10.0f}"
        )
    for model in MODELS:
        # Sizes of at least 4,000 columns: below that fixed costs (imports aside) dominate.
        mine = [r for r in rows if r["model"] == model and r["contacts"] * r["cases"] >= 4000]
        size = np.log([r["contacts"] * r["cases"] for r in mine])
        for key in ("build_and_first", "resolve"):
            slope = np.polyfit(size, np.log([r[key] for r in mine]), 1)[0]
            print(f"{model}: {key} ~ (contacts x cases)^{slope:.2f} (sizes >= 4,000 columns)")
        base = next(r for r in rows if r["model"] == model and r["contacts"] * r["cases"] == 8)
        top = max(mine, key=lambda r: r["contacts"] * r["cases"])
        print(
            f"{model}: largest / smallest: {top['contacts'] * top['cases'] // 8}x the columns, "
            f"build+first x{top['build_and_first'] / base['build_and_first']:.0f}, "
            f"memory x{top['peak_mb'] / base['peak_mb']:.1f}"
        )
    dpp_table()


if __name__ == "__main__":
    if len(sys.argv) == 4:
        print(json.dumps(one_row(int(sys.argv[1]), int(sys.argv[2]), sys.argv[3])))
    else:
        main()
