"""Fixture design sweep: where along the plate should the side clamp of a 3-2-1 fixture push?

Run: ``python examples/fixture_sweep.py [--out DIR]`` (default ``examples/output/``).

The fixture of ``problems/fixture-321.toml`` (a 3.5 kg steel plate on three rest buttons, two
side pins and an end pin, held by a top clamp and a side clamp, twelve drilling and milling load
cases) is solved with the side clamp moved along the plate's +y face, x from -60 mm to +60 mm
in nine steps. For each position the planner finds the smallest total clamp force that holds
every load case, and the load case that sets it. The script prints a table and saves
``fixture_sweep.png``: total clamp force against clamp position, with the side pins' x
positions marked.

What it shows: from x = -15 mm to +30 mm the total is flat at the friction limit of the slot cut
that drags the plate away from its end pin (250 N along +x held by friction alone: about
250 N / (2 mu) of clamping, wherever the clamps are). Farther out the side clamp's push no
longer balances between the two side pins, and the chamfering pull at the far corner or the
slot cut needs 5-9 % more clamping.

Only the total is reported: the split between the two clamps is often not unique (many splits
reach the same smallest total), so it depends on the solver's path.
"""

from __future__ import annotations

import argparse
import dataclasses
from pathlib import Path

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from fixplan.io.problem_file import load_problem
from fixplan.planner.planner import Planner

ROOT = Path(__file__).resolve().parent.parent
PROBLEM_FILE = ROOT / "problems" / "fixture-321.toml"
CLAMP = "clamp-side"
POSITIONS = np.linspace(-0.06, 0.06, 9)  # clamp x positions along the plate [m]
#: Positions whose total is within this fraction of the least are all marked as least (the
#: optimum is often a flat range, equal up to the solver's accuracy).
BEST_RTOL = 1e-3


def sweep(positions: np.ndarray = POSITIONS) -> list[dict]:
    """Solve the fixture with the top clamp at each x position [m]; one row per position."""
    problem = load_problem(PROBLEM_FILE).problem
    rows = []
    for x in positions:
        contacts = tuple(
            dataclasses.replace(c, position=[x, c.position[1], c.position[2]])
            if c.name == CLAMP
            else c
            for c in problem.contacts
        )
        plan = Planner(dataclasses.replace(problem, contacts=contacts)).solve()
        rows.append(
            {
                "x": float(x),
                "status": plan.status,
                "total": plan.objective_value,
                "critical": plan.critical_load,
            }
        )
    return rows


def table(rows: list[dict]) -> str:
    """The sweep as a text table, the best position marked."""
    least = min(r["total"] for r in rows if r["status"] == "optimal")
    lines = [
        f"{CLAMP} position sweep on {PROBLEM_FILE.name} (min-total-clamp-force)",
        f"{'x [mm]':>8}  {'status':>10}  {'total clamp force [N]':>22}  critical load case",
    ]
    for row in rows:
        total = "-" if row["total"] is None else f"{row['total']:.1f}"
        best = row["total"] is not None and row["total"] <= least * (1.0 + BEST_RTOL)
        mark = "  <- least" if best else ""
        lines.append(
            f"{row['x'] * 1e3:8.1f}  {row['status']:>10}  {total:>22}  {row['critical']}{mark}"
        )
    return "\n".join(lines)


def figure(rows: list[dict]) -> Figure:
    """Total clamp force against the clamp position."""
    problem = load_problem(PROBLEM_FILE).problem
    pins = [c.position[0] for c in problem.contacts if c.name.startswith("side-pin")]
    solved = [r for r in rows if r["total"] is not None]
    x = np.array([r["x"] for r in solved]) * 1e3
    total = np.array([r["total"] for r in solved])
    best = total <= total.min() * (1.0 + BEST_RTOL)

    fig = Figure(figsize=(6.5, 4.2))
    ax = fig.subplots()
    ax.plot(x, total, "o-", color="C0", label="smallest total clamp force")
    ax.plot(x[best], total[best], "*", color="C3", markersize=14, label="least total")
    for k, pin in enumerate(sorted(set(pins))):
        ax.axvline(pin * 1e3, color="0.6", ls="--", label="side pins" if k == 0 else None)
    ax.set_xlabel(f"{CLAMP} position x [mm]")
    ax.set_ylabel("total clamp force [N]")
    ax.set_ylim(bottom=0.0)
    ax.set_title("3-2-1 fixture: side clamp position sweep (12 load cases)")
    ax.legend(loc="best")
    fig.tight_layout()
    return fig


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "--out",
        type=Path,
        default=Path(__file__).resolve().parent / "output",
        help="folder for fixture_sweep.png (default: examples/output/)",
    )
    args = parser.parse_args()
    rows = sweep()
    print(table(rows))
    args.out.mkdir(parents=True, exist_ok=True)
    fig = figure(rows)
    FigureCanvasAgg(fig)
    path = args.out / "fixture_sweep.png"
    fig.savefig(path, dpi=120, metadata={"Software": None})
    print(f"wrote {path}")


if __name__ == "__main__":
    main()
