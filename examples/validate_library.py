"""Plan against simulation for the problem library: MuJoCo judges every least-force plan.

Run: ``python examples/validate_library.py [--quick] [--markdown TABLE.md]``. Every problem of
``problems/`` with an optimal plan is simulated with :func:`fixplan.sim.validate.validate` (all
load cases; ``--quick``: the critical case of each problem only). Printed per case: what the plan
says, held or slips at +10 % and -10 % of the planned forces, the simulated slip-onset multiple
over the plan's safety factor and the angle between the simulated and the planned motion. The
exit status is 1 when a case the plan calls held slips at +10 %.
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

from fixplan.io.problem_file import load_problem
from fixplan.planner.planner import Planner
from fixplan.sim.validate import validate

PROBLEMS = Path(__file__).resolve().parents[1] / "problems"


def rows(quick: bool) -> list[tuple[str, ...]]:
    """One row per simulated load case: problem, case, plan, +10 %, -10 %, onset, angle."""
    found = []
    for path in sorted(PROBLEMS.glob("*.toml")):
        if path.stem.startswith("push-"):
            continue
        problem = load_problem(path).problem
        plan = Planner(problem).solve()
        if plan.status != "optimal":
            found.append((path.stem, "-", plan.status, "-", "-", "-", "-", ""))
            continue
        loads = [plan.critical_load] if quick else None
        for case in validate(problem, plan, loads=loads):
            onset = "no slip up to 1.5 s" if case.onset_ratio is None else f"{case.onset_ratio:.3f}"
            if case.onset is None:
                onset = "- (s = inf)"
            angle = "-" if case.motion_angle is None else f"{math.degrees(case.motion_angle):.1f}°"
            found.append((
                path.stem, case.load, "held" if case.planned_held else "not held",
                "held" if case.above.held else "slips", "held" if case.below.held else "slips",
                onset, angle, "contradicts the plan" if case.contradicts else "",
            ))  # fmt: skip
    return found


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="the critical case of each problem")
    parser.add_argument("--markdown", type=Path, help="also write the table to this file")
    args = parser.parse_args()
    table = rows(args.quick)
    header = ("problem", "load case", "plan", "+10 %", "-10 %", "onset / s", "motion", "")
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    lines += ["| " + " | ".join(row) + " |" for row in table]
    text = "\n".join(lines)
    print(text)
    if args.markdown is not None:
        args.markdown.write_text(text + "\n", encoding="utf-8")
    return 1 if any(row[-1] for row in table) else 0


if __name__ == "__main__":
    sys.exit(main())
