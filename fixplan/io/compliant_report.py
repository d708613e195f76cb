"""The compliant analysis of a checked plan, in numbers and words (issue 12, paper §4.4).

With the objective ``check-compliant`` the command line and the plan report follow the rigid
check with :func:`fixplan.motion.compliance.analyse` at the problem file's stiffnesses and given
forces. :func:`compliant_analysis` runs it and names the file in its errors;
:func:`compliant_summary` condenses the result, beside the rigid analysis, into plain values
(the ``compliant`` object of ``--json``); :func:`describe_compliant` puts them in lines of text.

A contact's **utilisation** is the fraction of its friction set that its load uses (1 on the
limit). The rigid one is the plan's, at impending slip of the whole part (the task load times
its rigid safety factor, :attr:`Plan.utilisation <fixplan.planner.plan.Plan.utilisation>`); the
compliant one is ``1 / s``, with ``s`` the contact's own safety factor at the task load.
"""

from __future__ import annotations

import math

import numpy as np

from fixplan.errors import ConvergenceError
from fixplan.io.problem_file import ProblemFile
from fixplan.io.toml_schema import Issue, ProblemFileError
from fixplan.motion.compliance import ComplianceError, ComplianceResult, analyse
from fixplan.planner.plan import Plan

#: Micrometres per metre and microradians per radian (the printed displacement).
MICRO = 1e6
#: A displacement or rotation component below this fraction of the largest of its three is
#: rounding noise, printed as 0.
NOISE_RTOL = 1e-9


def compliant_analysis(problem_file: ProblemFile, plan: Plan) -> ComplianceResult:
    """The compliant analysis of ``plan`` (its active forces) with the file's stiffnesses.

    Raises
    ------
    ProblemFileError
        The analysis rejects its inputs or the springs cannot hold a load case (its
        :class:`~fixplan.motion.ComplianceError`), as an issue of the whole file.
    ConvergenceError
        The analysis did not converge; the message names the file.
    """
    try:
        return analyse(problem_file.problem, plan, stiffness=problem_file.stiffness)
    except ComplianceError as exc:
        issue = Issue(key_path="", message=f"the compliant analysis failed: {exc}")
        raise ProblemFileError(problem_file.path, [issue]) from exc
    except ConvergenceError as exc:
        raise ConvergenceError(
            f"{problem_file.path}: the compliant analysis failed: {exc}"
        ) from exc


def utilisation(plan: Plan, result: ComplianceResult) -> dict:
    """``{case: {contact: (rigid, compliant)}}``: each contact's utilisation in the rigid plan
    (``None`` where the plan has none) and in the compliant analysis (``inf`` for a load on a
    contact without friction capacity)."""
    table = {}
    for case in result.load_names:
        j = plan.load_names.index(case)
        row = {}
        for i, contact in enumerate(result.contact_names):
            rigid = None if plan.utilisation is None else float(plan.utilisation[i, j])
            with np.errstate(divide="ignore"):
                compliant = float(np.divide(1.0, result.safety_factors[case][contact]))
            row[contact] = (rigid, compliant)
        table[case] = row
    return table


def compliant_summary(plan: Plan, result: ComplianceResult) -> dict:
    """The compliant analysis beside the rigid one as plain values, per load case name (and
    contact name): SI units, the displacement ``(ux, uy, uz, θx, θy, θz)`` [m, rad] about the
    centre of mass; infinities and NaN stay floats."""
    cases = result.load_names
    return {
        "wrenches": {c: {k: list(w) for k, w in result.wrenches[c].items()} for c in cases},
        "safety_factors": {c: dict(result.safety_factors[c]) for c in cases},
        "slip_directions": {
            c: {k: v.tolist() for k, v in result.slip_directions[c].items()} for c in cases
        },
        "displacement": {c: result.displacement[c].tolist() for c in cases},
        "seated": dict(result.seated),
        "lifted": {c: list(result.lifted[c]) for c in cases},
        "sliding": {c: list(result.sliding[c]) for c in cases},
        "first_slip": dict(result.first_slip),
        "first_slip_contact": dict(result.first_slip_contact),
        "collapse": dict(result.collapse),
        "held": dict(result.held),
        "rigid_safety_factors": {c: plan.safety_factors.get(c) for c in cases},
        "utilisation": {
            c: {k: {"rigid": r, "compliant": u} for k, (r, u) in row.items()}
            for c, row in utilisation(plan, result).items()
        },
    }


def _value(value: float | None) -> str:
    if value is None:
        return "-"
    return "inf" if math.isinf(value) else f"{value:.4g}"


def millionths(values) -> list[float]:
    """Three components [m or rad] in millionths (µm, µrad), rounding noise as 0."""
    scaled = MICRO * np.asarray(values, dtype=float)
    noise = NOISE_RTOL * float(np.abs(scaled).max())
    return [float(v) if abs(v) > noise else 0.0 for v in scaled]


def _vector(values) -> str:
    return "(" + ", ".join(f"{v:.4g}" for v in millionths(values)) + ")"


def first_slip_text(summary: dict, case: str) -> str:
    """When the first contact slips in load case ``case``, in words."""
    multiple, contact = summary["first_slip"][case], summary["first_slip_contact"][case]
    if math.isinf(multiple):
        return "no contact slips (at any multiple searched)"
    if contact is None:
        return (
            f"the part moves at {_value(multiple)} × the task load (it leaves its contacts or "
            "turns where no spring holds it)"
        )
    return (
        f"{contact!r} slips first, at {_value(multiple)} × the task load; the part moves at "
        f"{_value(summary['collapse'][case])} ×"
    )


def describe_compliant(summary: dict) -> list[str]:
    """The summary in lines of text (the command line's compliant section)."""
    lines = [
        "compliant  contact springs; friction used per contact: rigid at impending slip of the "
        "part, compliant at the task load"
    ]
    for case, rows in summary["utilisation"].items():
        rigid = _value(summary["rigid_safety_factors"][case])
        displacement = summary["displacement"][case]
        lines += [
            f"  load case {case!r}: rigid safety factor {rigid}; {first_slip_text(summary, case)}",
            f"    displacement {_vector(displacement[:3])} µm, rotation "
            f"{_vector(displacement[3:])} µrad",
            "    clamping     "
            + (
                "seated (friction springs start unloaded)"
                if summary["seated"][case]
                else "stuck (no frictionless seating exists: friction springs take their share "
                "of the preloads)"
            ),
            f"    lifted off   {', '.join(summary['lifted'][case]) or 'none'}",
            f"    sliding      {', '.join(summary['sliding'][case]) or 'none'}"
            + (
                ""
                if summary["held"][case]
                else " (the part moves before the task load: state at the collapse multiple)"
            ),
            f"    {'contact':24s} {'rigid':>10s} {'compliant':>10s}",
        ]
        lines += [
            f"    {name:24s} {_value(use['rigid']):>10s} {_value(use['compliant']):>10s}"
            for name, use in rows.items()
        ]
    return lines


__all__ = [
    "compliant_analysis",
    "compliant_summary",
    "describe_compliant",
    "first_slip_text",
    "millionths",
    "utilisation",
]
