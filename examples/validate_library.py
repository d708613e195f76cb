"""Plan against simulation for the problem library: MuJoCo (or Drake) judges every plan.

Run: ``python examples/validate_library.py [--quick] [--engine mujoco|drake] [--markdown
TABLE.md]``. Every problem of ``problems/`` with an optimal plan is simulated with
:func:`fixplan.sim.validate.validate` or, with ``--engine drake``,
:func:`fixplan.sim.drake_validate.validate` (all load cases; ``--quick``: the critical case of
each problem only). Printed per case: what the plan says, held or slips at +10 % and -10 % of the
planned forces, the simulated slip-onset multiple over the plan's safety factor and the angle
between the simulated and the planned motion; with Drake also the safety factor of fixplan's
exact limit surface of the engine's pressure fields, the onset over it, and the range over the
area contacts of the fields' pressure deviation from the assumed profile and of their torsional
arm over the assumed one. The exit status is 1 when a case the plan calls held slips at +10 %.
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

from fixplan.io.problem_file import load_problem
from fixplan.planner.planner import Planner
from fixplan.sim import drake_validate, validate

PROBLEMS = Path(__file__).resolve().parents[1] / "problems"


def rows(quick: bool, engine: str = "mujoco") -> list[tuple[str, ...]]:
    """One row per simulated load case: problem, case, plan, +10 %, -10 %, onset, angle (and
    with Drake: exact s, onset over it, pressure deviations, torsion ratios)."""
    judge = drake_validate if engine == "drake" else validate
    blank = ("-",) * (4 if engine == "drake" else 0)
    found = []
    for path in sorted(PROBLEMS.glob("*.toml")):
        if path.stem.startswith("push-"):
            continue
        problem = load_problem(path).problem
        plan = Planner(problem).solve()
        if plan.status != "optimal":
            found.append((path.stem, "-", plan.status, "-", "-", "-", "-", *blank, ""))
            continue
        loads = [plan.critical_load] if quick else None
        for case in judge.validate(problem, plan, loads=loads):
            onset = "no slip up to 1.5 s" if case.onset_ratio is None else f"{case.onset_ratio:.3f}"
            if case.onset is None:
                onset = "- (s = inf)"
            angle = "-" if case.motion_angle is None else f"{math.degrees(case.motion_angle):.1f}°"
            found.append((
                path.stem, case.load, "held" if case.planned_held else "not held",
                "held" if case.above.held else "slips", "held" if case.below.held else "slips",
                onset, angle, *(_drake_columns(case) if engine == "drake" else ()),
                "contradicts the plan" if case.contradicts else "",
            ))  # fmt: skip
    return found


def _drake_columns(case) -> tuple[str, ...]:
    """Exact s of the engine's fields, onset over it, and the ranges over the area contacts of
    the pressure deviation and the torsion ratio."""
    ratio = "-" if case.exact_onset_ratio is None else f"{case.exact_onset_ratio:.3f}"

    def spread(values, form):
        values = [v for v in values if v is not None]
        if not values:
            return "-"
        low, high = form.format(min(values)), form.format(max(values))
        return low if low == high else f"{low}–{high}"

    deviation = spread([f.pressure_deviation for f in case.fields], "{:.0%}")
    torsion = spread([f.torsion_ratio for f in case.fields], "{:.3f}")
    exact = "none held" if case.exact_safety_factor is None else f"{case.exact_safety_factor:.4g}"
    return (exact, ratio, deviation, torsion)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="the critical case of each problem")
    parser.add_argument("--engine", choices=("mujoco", "drake"), default="mujoco")
    parser.add_argument("--markdown", type=Path, help="also write the table to this file")
    args = parser.parse_args()
    table = rows(args.quick, args.engine)
    header = ("problem", "load case", "plan", "+10 %", "-10 %", "onset / s", "motion")
    if args.engine == "drake":
        header += ("exact s", "onset / exact s", "pressure off assumed", "torsion / assumed")
    header += ("",)
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    lines += ["| " + " | ".join(row) + " |" for row in table]
    text = "\n".join(lines)
    print(text)
    if args.markdown is not None:
        args.markdown.write_text(text + "\n", encoding="utf-8")
    return 1 if any(row[-1] for row in table) else 0


if __name__ == "__main__":
    sys.exit(main())
