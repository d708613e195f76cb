"""Compliant analyses per second of the 3-2-1 fixture, against the rigid check in the same run.

Run: ``python benchmarks/bench_compliance.py``. The problem is ``problems/fixture-321.toml``
(six locators, two clamps, 12 milling load cases). Its least clamp forces are planned once;
then, timed (medians of repeated runs, wall clock):

- ``compliance.analyse`` of all 12 cases with steel spherical tips (``hertz_sphere``, 5 mm
  radius, linearised at each contact's share of the clamp force): contact wrenches, safety
  factors, displacement, first slip and collapse;
- the same with the clamp forces doubled, so that no contact slips below the task load (the
  sticking part of the analysis only, plus the increments up to collapse);
- the rigid check of the same forces (``Planner.solve`` with objective ``check``: safety factors,
  held intervals and motions of the 12 cases).

The load average is printed with the figures (other processes slow these single-threaded runs).
"""

from __future__ import annotations

import dataclasses
import os
import time
from pathlib import Path

import numpy as np

from fixplan.io.problem_file import load_problem
from fixplan.motion import compliance, hertz_sphere
from fixplan.planner.planner import Planner

ROOT = Path(__file__).resolve().parents[1]
RUNS = 5
STEEL = {"young": 210e9, "poisson": 0.29, "young_flat": 210e9, "poisson_flat": 0.29}


def fixture(multiple: float):
    """The fixture with its planned clamp forces times ``multiple``, as a ``check`` problem."""
    problem = load_problem(ROOT / "problems" / "fixture-321.toml").problem
    plan = Planner(problem).solve()
    contacts = tuple(
        dataclasses.replace(c, force=multiple * float(plan.forces[c.name]))
        if c.name in plan.forces
        else c
        for c in problem.contacts
    )
    return dataclasses.replace(problem, contacts=contacts, objective="check")


def stiffness(problem):
    """Hertz stiffness of a 5 mm steel sphere at each contact's clamp-force share [N/m]."""
    clamp = sum(c.force for c in problem.contacts if c.role == "clamp")
    return {
        c.name: hertz_sphere(radius=0.005, preload=clamp / 4, **STEEL) for c in problem.contacts
    }


def median_seconds(run) -> float:
    times = []
    for _ in range(RUNS):
        start = time.perf_counter()
        run()
        times.append(time.perf_counter() - start)
    return float(np.median(times))


def main() -> None:
    print(f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores; medians of {RUNS}")
    for multiple in (1.0, 2.0):
        problem = fixture(multiple)
        springs = stiffness(problem)
        result = compliance.analyse(problem, None, stiffness=springs)
        slips = sum(result.first_slip[c] < 1.0 for c in result.load_names)
        unbracketed = sum(np.isnan(result.collapse[c]) for c in result.load_names)
        seated = sum(result.seated.values())
        compliant = median_seconds(
            lambda p=problem, s=springs: compliance.analyse(p, None, stiffness=s)
        )
        rigid = median_seconds(lambda p=problem: Planner(p).solve())
        cases = len(problem.loads)
        print(
            f"clamp forces x{multiple:g}: compliant {1 / compliant:6.2f} analyses/s "
            f"({compliant / cases * 1e3:6.1f} ms per case; {slips} of {cases} cases slip below "
            f"the task load, {seated} seated, {unbracketed} collapse not bracketed), rigid check "
            f"{1 / rigid:6.2f}/s; compliant/rigid time {compliant / rigid:5.1f}x"
        )


if __name__ == "__main__":
    main()
