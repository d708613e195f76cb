"""A simulation check's report: ``report.md`` and ``report.html`` with the verdict of every load
case, and one PNG per case (``case-N.png``: the largest slip at a contact and the part's rotation
over time in the runs at +margin, -margin and at the planned forces with the load ramped past
the safety factor)."""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path

from fixplan.io.problem_file import ProblemFile
from fixplan.io.report_document import (
    Heading,
    Image,
    Paragraph,
    Table,
    Writer,
    inline,
    staged_folder,
)
from fixplan.sim.validate import HELD_DISPLACEMENT, SLIP_SPEED, CaseValidation

#: Resolution of the figures [dots per inch].
FIGURE_DPI = 110


def case_figure(case: CaseValidation, margin: float):
    """Slip [mm] and rotation [rad] over time of the three runs of ``case``."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=(9.0, 3.8), dpi=FIGURE_DPI, layout="constrained")
    FigureCanvasAgg(fig)
    slip_axes, turn_axes = fig.subplots(1, 2)
    runs = [(f"forces +{margin:.0%}", case.above, "tab:green"),
            (f"forces -{margin:.0%}", case.below, "tab:red")]  # fmt: skip
    if case.onset is not None:
        runs.append(("planned forces, load ramped past s", case.onset, "tab:blue"))
    for label, run, colour in runs:
        history = run.history
        slip_axes.plot(history[:, 0], history[:, 1] * 1e3, color=colour, label=label)
        turn_axes.plot(history[:, 0], history[:, 2], color=colour, label=label)
    slip_axes.axhline(HELD_DISPLACEMENT * 1e3, color="0.5", linestyle=":", label="held limit")
    for axes, unit in (
        (slip_axes, "largest slip at a contact [mm]"),
        (turn_axes, "rotation [rad]"),
    ):
        axes.set_yscale("symlog", linthresh=1e-3)
        axes.set_xlabel("time [s]")
        axes.set_ylabel(unit)
        axes.grid(alpha=0.3)
    slip_axes.legend(fontsize=7, loc="best")
    fig.suptitle(f"load case {case.load}: safety factor {case.safety_factor:.4g}")
    return fig


def _verdict(run) -> str:
    return (
        "held" if run.held else f"slips ({run.displacement * 1e3:.3g} mm, {run.rotation:.3g} rad)"
    )


def write_validation_report(
    directory: Path,
    problem_file: ProblemFile,
    plan,
    cases: Sequence[CaseValidation],
    margin: float,
    *,
    engine: str = "mujoco",
) -> list[Path]:
    """Write the report of a simulation check by ``engine`` (``"mujoco"`` or ``"drake"``) into
    ``directory``; returns the files written."""
    rows = []
    for case in cases:
        onset = "-" if case.onset_ratio is None else f"{case.onset_ratio:.4f}"
        angle = "-" if case.motion_angle is None else f"{math.degrees(case.motion_angle):.2f}°"
        rows.append((case.load, "held" if case.planned_held else "not held",
                     f"{case.safety_factor:.4g}", _verdict(case.above), _verdict(case.below),
                     onset, angle))  # fmt: skip
    contradicted = [case.load for case in cases if case.contradicts]
    blocks = [
        Heading(1, inline(f"Simulation check: {problem_file.name}")),
        Paragraph(
            inline(
                f"{_engine_version(engine)}, plan status {plan.status}, objective value "
                f"{plan.objective_value:.6g}; file SHA-256 {problem_file.sha256}. Held: no contact "
                f"slips more than {HELD_DISPLACEMENT * 1e3:g} mm (its tip against the part; area "
                "contacts: plus their turn about the normal times their radius) while the task "
                "load ramps to 1× and is held. Slip onset: a contact slips faster than "
                f"{SLIP_SPEED * 1e3:g} mm/s."
            )
        ),
        Paragraph(
            inline(
                "Every case the plan calls held is held in the simulation."
                if not contradicted
                else f"The simulation lets cases slip that the plan calls held: {', '.join(contradicted)}."
            )
        ),
        Table(
            (
                "load case",
                "plan",
                "safety factor",
                f"forces +{margin:.0%}",
                f"forces -{margin:.0%}",
                "slip onset / safety factor",
                "slip motion vs plan",
            ),
            tuple(rows),
        ),
    ]
    if engine == "drake":
        blocks += _field_blocks(cases)
    for index, case in enumerate(cases, start=1):
        blocks.append(Image(f"case-{index}.png", f"load case {case.load}",
                            inline(f"Load case {case.load}: slip and rotation over time.")))  # fmt: skip
    with staged_folder(directory) as staging:
        writer = Writer(staging)
        for index, case in enumerate(cases, start=1):
            writer.figure(f"case-{index}.png", lambda case=case: case_figure(case, margin))
        writer.document(blocks, f"fixplan simulation check: {problem_file.name}")
        names = [path.name for path in writer.written]
    return [directory / name for name in names]


def _field_blocks(cases) -> list:
    """Drake's pressure fields against the assumed profiles, and its onsets against fixplan's
    exact limit surface of those fields."""
    rows, fields = [], []
    for case in cases:
        ratio = "-" if case.exact_onset_ratio is None else f"{case.exact_onset_ratio:.4f}"
        exact = (
            "none held" if case.exact_safety_factor is None else f"{case.exact_safety_factor:.4g}"
        )
        rows.append((case.load, f"{case.safety_factor:.4g}", exact, ratio))
        for item in case.fields:
            deviation = "-" if item.pressure_deviation is None else f"{item.pressure_deviation:.1%}"
            fields.append((case.load, item.contact, f"{item.normal_force:.4g}",
                           str(item.polygons), f"{item.peak_pressure / 1e6:.3g}", deviation,
                           f"{item.torsion_ratio:.3f}",
                           "-" if item.onset_use is None else f"{item.onset_use:.3f}"))  # fmt: skip
    return [
        Heading(2, inline("Drake's pressure fields and fixplan's exact limit surface of them")),
        Paragraph(
            inline(
                "Per case, the safety factor at the planned forces with each area contact's "
                "model the exact limit surface of the field Drake produced, and Drake's slip "
                "onset over it. Per area contact, that field (read when the task load reaches "
                "1× at the planned forces, or at slip onset if sooner) against the profile the "
                "plan assumed at the same normal force: the largest pressure difference at the "
                "engine's polygons over its peak pressure, the largest friction moment per "
                "unit mu N over the assumed patch's, and the shear and torsion the engine "
                "applied there at slip onset as a fraction of the exact limit surface of its "
                "field then."
            )
        ),
        Table(
            (
                "load case",
                "plan's safety factor",
                "exact s of the engine's fields",
                "slip onset / exact s",
            ),
            tuple(rows),
        ),
        Table(
            (
                "load case",
                "contact",
                "normal force [N]",
                "polygons",
                "peak pressure [MPa]",
                "pressure off the assumed profile",
                "torsion / assumed",
            ),
            tuple(fields),
        ),
    ]


def _engine_version(engine: str) -> str:
    if engine == "drake":
        from importlib.metadata import version

        return f"Drake {version('drake')} (hydroelastic contact, lagged approximation)"
    import mujoco

    return f"MuJoCo {mujoco.__version__}"
