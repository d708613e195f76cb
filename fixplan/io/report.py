"""A plan's report: a self-contained folder with Markdown, HTML, JSON and PNG figures.

:func:`write_report` writes into a folder

- ``report.md`` and ``report.html``: the same content (the HTML opens in a browser with its
  figures): a header of versions, model choices and the problem file's SHA-256, the status and
  objective, active forces, safety factors per load case, the impending motions in words, the
  infeasibility certificate when there is one, the compliant analysis when one is given (the
  contacts' stiffnesses, per load case the first contact to slip, the contacts lifted off and
  the part's displacement, and every contact's friction use, rigid beside compliant), and the
  figures;
- ``plan.json``: :meth:`Plan.as_dict` with sorted keys;
- PNG figures (:mod:`fixplan.io.figures`): ``layout.png``, ``safety-factors.png``,
  ``contact-NN-NAME.png`` per loaded area contact, ``contact-set.png`` and, with a compliant
  analysis, ``compliant-utilisation.png``.

The report is built once as a list of blocks (headings, paragraphs, tables, lists, images) and
rendered to both formats from them. Nothing in it depends on the time or the machine's paths,
so two reports of the same problem file and plan are byte-identical and diff cleanly.
"""

from __future__ import annotations

import json
import os
import re
import warnings
from collections.abc import Sequence
from dataclasses import dataclass
from importlib.metadata import PackageNotFoundError, version
from pathlib import Path

import cvxpy
import numpy as np

import fixplan
from fixplan.errors import FixplanError, InvalidArgumentError
from fixplan.io import figures
from fixplan.io.compliant_report import compliant_summary, first_slip_text, millionths
from fixplan.io.problem_file import ProblemFile
from fixplan.io.report_document import (
    Block,
    Code,
    Heading,
    Image,
    List,
    Paragraph,
    ReportError,
    Table,
    Writer,
    inline,
    staged_folder,
)
from fixplan.motion.compliance import ComplianceResult
from fixplan.planner.contact_surface import COMPONENTS, ContactSetSurface
from fixplan.planner.plan import Plan
from fixplan.planner.planner import Planner
from fixplan.planner.problem import FIXED_FORCE_OBJECTIVES, PASSIVE_ROLES, Problem

#: A contact whose normal force is at most this fraction of the largest normal force of its load
#: case carries no load: its section figure is skipped (its friction set is a point).
UNLOADED_RTOL = 1e-9
#: Points per section of the contact-set surface (each is one conic solve).
CONTACT_SET_POINTS = 72
#: Printed contact forces and moments below this fraction of the largest normal force of their
#: load case (moments: times the planner's length scale) are solver rounding and printed as 0.
PRINT_RTOL = 1e-9
#: Longest part of a figure's file name taken from a contact name (the contact's index keeps
#: the names unique).
SLUG_LENGTH = 40
#: Equilibrium residuals below this are printed as ``below RESIDUAL_FLOOR`` (their digits are
#: rounding noise that differs between machines).
RESIDUAL_FLOOR = 1e-12
#: The figure of a compliant analysis (:func:`fixplan.io.figures.utilisation_figure`).
UTILISATION_FIGURE = "compliant-utilisation.png"

#: The package behind each solver name (the dual simplex is fixplan's own).
_SOLVER_PACKAGES = {"CLARABEL": "clarabel", "OSQP": "osqp", "SCS": "scs", "dual simplex": "fixplan"}


# -- numbers and names --------------------------------------------------------------------------


def _num(value: float | None, digits: int = 5) -> str:
    """One format for every number of the report (``∞`` for infinity, ``-0`` as ``0``)."""
    if value is None:
        return "n/a"
    value = float(value)
    if np.isnan(value):
        return "nan"
    if np.isinf(value):
        return "∞" if value > 0 else "-∞"
    return f"{value + 0.0:.{digits}g}"


def _residual(value: float | None) -> str:
    if value is not None and abs(value) < RESIDUAL_FLOOR:
        return f"below {RESIDUAL_FLOOR:g}"
    return _num(value, 3)


def _slug(name: str) -> str:
    """A file-name part made of ``name``: ASCII letters, digits, ``_`` and ``-``, at most
    :data:`SLUG_LENGTH` characters."""
    slug = re.sub(r"[^A-Za-z0-9_-]+", "-", name).strip("-")[:SLUG_LENGTH].strip("-")
    return slug or "contact"


def _package_version(package: str) -> str:
    try:
        return version(package)
    except PackageNotFoundError:
        return "not installed"


def _solver_text(solvers: str) -> str:
    names = [s for s in (part.strip() for part in solvers.split(",")) if s]
    return ", ".join(
        f"{name} {_package_version(_SOLVER_PACKAGES.get(base, base.lower()))}"
        for name, base in ((n, n.split(" (")[0]) for n in names)
    )


# -- defaults -----------------------------------------------------------------------------------


def default_sliding_subspace(problem: Problem) -> tuple[str, str, str]:
    """The wrench components in which a fixtured part slides on its supports.

    The world axis ``k`` most aligned with the supports' normals (``"support"`` contacts; all
    passive contacts if there are none; all contacts if none are passive) is the axis the part
    rests along; it slides in the plane across it: the two forces across ``k`` and the moment
    about ``k``. Supports along ``±z`` give ``("fx", "fy", "mz")``.
    """
    chosen = [c for c in problem.contacts if c.role == "support"]
    chosen = chosen or [c for c in problem.contacts if c.role in PASSIVE_ROLES]
    chosen = chosen or list(problem.contacts)
    k = int(np.argmax(np.abs([c.normal for c in chosen]).sum(axis=0)))
    forces = [f"f{axis}" for i, axis in enumerate("xyz") if i != k]
    return (forces[0], forces[1], f"m{'xyz'[k]}")


# -- figures ------------------------------------------------------------------------------------


@dataclass(frozen=True, slots=True)
class _Figure:
    file: str
    alt: str
    caption: str


def _state_text(plan: Plan) -> str:
    """When the plan's contact wrenches hold."""
    if plan.objective in FIXED_FORCE_OBJECTIVES:
        return "at impending slip (the task load times its safety factor)"
    return "at the task load"


def _contact_set_figure(problem, plan, j, subspace, writer, figures_out, notes) -> None:
    """The fixture's limit surface at the normal forces of load case ``j``, or a note why not."""
    select = np.array([np.eye(6)[COMPONENTS.index(c)] for c in subspace])
    friction = sum(
        select @ contact.wrench_basis()[:, 1:] @ plan.contact_wrenches[i, j, 1:]
        for i, contact in enumerate(problem.contacts)
    )
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            surface = ContactSetSurface(problem.contacts, plan.normal_forces[:, j], subspace)
            writer.figure(
                "contact-set.png",
                lambda: figures.contact_set_figure(surface, load=friction, n=CONTACT_SET_POINTS),
            )
        except (FixplanError, cvxpy.error.SolverError) as exc:
            notes.append(f"The contact-set limit surface was not drawn: {exc}.")
            return
    inaccurate = [w for w in caught if "inaccurate" in str(w.message)]
    for w in caught:
        if w not in inaccurate:
            warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
    caption = (
        f"Limit surface of all contacts together (Minkowski sum of their friction sets) in the "
        f"sliding subspace ({', '.join(subspace)}) at the normal forces of load case "
        f"'{plan.load_names[j]}'; the dot is the plan's friction resultant in that subspace."
    )
    if inaccurate:
        caption += f" The solver flagged {len(inaccurate)} section points as possibly inaccurate."
    figures_out.append(_Figure("contact-set.png", "contact-set limit surface", caption))


def _draw_figures(problem, plan, planner, load, subspace, writer) -> tuple[list, list]:
    """Write the figures; returns their descriptions and notes on those skipped."""
    out, notes = [], []
    j = plan.load_names.index(load)
    writer.figure("layout.png", lambda: figures.layout_figure(problem, plan, load))
    out.append(
        _Figure(
            "layout.png",
            "contact layout",
            f"Contacts, their normals and (black) the contact forces of load case '{load}' "
            f"{_state_text(plan)}; green: the task force."
            if plan.contact_wrenches is not None
            else f"Contacts and their normals; green: the task force of load case '{load}'. "
            "The plan has no contact forces.",
        )
    )
    if plan.safety_factors:
        writer.figure("safety-factors.png", lambda: figures.safety_figure(plan))
        out.append(
            _Figure("safety-factors.png", "safety factors", "Safety factor of every load case.")
        )
    if plan.contact_wrenches is None:
        notes.append("Force figures were skipped: the plan has no contact forces.")
        return out, notes
    wrenches = plan.contact_wrenches[:, j]
    largest = float(np.max(wrenches[:, 0]))
    for i, (contact, model) in enumerate(zip(problem.contacts, planner.models, strict=True)):
        if not model.torsion:
            continue
        if model.frictionless:
            notes.append(
                f"Contact '{contact.name}' is frictionless (mu = 0): its friction set is the "
                "single load 0, so it has no sections to draw."
            )
            continue
        if wrenches[i, 0] <= UNLOADED_RTOL * largest:
            notes.append(f"Contact '{contact.name}' carries no normal force in load case '{load}'.")
            continue
        name = f"contact-{i:02d}-{_slug(contact.name)}.png"
        writer.figure(
            name,
            lambda i=i, contact=contact, model=model: figures.contact_section_figure(
                contact, model, wrenches[i, 1:], wrenches[i, 0], load_name=load
            ),
        )
        out.append(
            _Figure(
                name,
                f"friction sections of contact {contact.name}",
                f"Load of contact '{contact.name}' in load case '{load}' inside the central "
                f"sections of its friction set ({type(model).__name__}) at its normal force, "
                "normalised as in the paper (forces by mu N, the moment by mu rho N); the cross "
                "is where the load's ray leaves the set.",
            )
        )
    _contact_set_figure(problem, plan, j, subspace, writer, out, notes)
    return out, notes


# -- the document -------------------------------------------------------------------------------


def _header(problem_file: ProblemFile, plan: Plan, planner: Planner, subspace) -> list[Block]:
    rows = [
        ("fixplan", inline(fixplan.__version__)),
        ("cvxpy", inline(cvxpy.__version__)),
        ("solver requested", inline(_solver_text(planner.solver))),
        ("solver used", inline(_solver_text(plan.solver) or "none")),
        ("problem", inline(problem_file.name)),
        ("kind", inline(problem_file.kind)),
        ("problem file", inline(Code(problem_file.path.name))),
        ("problem file SHA-256", inline(Code(problem_file.sha256))),
        ("model override", inline(problem_file.model_override or "none")),
        ("objective", inline(plan.objective)),
        ("sliding subspace", inline(", ".join(subspace))),
    ]
    models = [
        (inline(c.name), inline(c.role), inline(Code(repr(m))))
        for c, m in zip(planner.problem.contacts, planner.models, strict=True)
    ]
    return [
        Heading(1, inline(f"fixplan report: {problem_file.name}")),
        Table(("item", "value"), tuple((inline(k), v) for k, v in rows)),
        Heading(2, inline("Friction models")),
        Paragraph(inline("The model of every contact at unit normal force.")),
        Table(("contact", "role", "model"), tuple(models)),
    ]


def _result(plan: Plan, problem: Problem) -> list[Block]:
    unit = " (safety factor)" if plan.objective in FIXED_FORCE_OBJECTIVES else " N"
    value = "none" if plan.objective_value is None else _num(plan.objective_value) + unit
    blocks: list[Block] = [
        Heading(2, inline("Result")),
        Table(
            ("item", "value"),
            (
                (inline("status"), inline(plan.status)),
                (inline("objective value"), inline(value)),
                (inline("equilibrium residual (relative)"), inline(_residual(plan.residual))),
            ),
        ),
    ]
    if plan.warnings:
        blocks += [Paragraph(inline("Warnings:")), List(tuple(inline(w) for w in plan.warnings))]
    if plan.certificate is not None:
        blocks += [
            Heading(2, inline("Infeasibility certificate")),
            Paragraph(inline(plan.certificate)),
        ]
        if plan.infeasible_motions:
            blocks.append(
                Table(
                    ("load case", "unresisted motion"),
                    tuple(
                        (inline(name), inline(m.describe()))
                        for name, m in plan.infeasible_motions.items()
                    ),
                )
            )
    if plan.forces:
        roles = {c.name: c.role for c in problem.contacts}
        rows = []
        for name, force in plan.forces.items():
            if np.ndim(force) == 0:
                text = _num(force)
            else:
                text = ", ".join(
                    f"{case}: {_num(f)}" for case, f in zip(plan.load_names, force, strict=True)
                )
            rows.append((inline(name), inline(roles[name]), inline(text)))
        blocks += [
            Heading(2, inline("Active forces")),
            Table(("contact", "role", "normal force [N]"), tuple(rows)),
        ]
    if plan.safety_factors:
        rows = tuple(
            (
                inline(name),
                inline(_num(s)),
                inline("yes" if plan.held.get(name) else "no"),
                inline(plan.describe_held(name)),
            )
            for name, s in plan.safety_factors.items()
        )
        blocks += [
            Heading(2, inline("Safety factors")),
            Paragraph(
                inline(
                    "The largest factor by which each task load (not gravity) can be scaled "
                    "while the contacts hold it with these active forces, and the interval of "
                    "multiples held: it starts above 0 where the active forces and the weight "
                    "alone push the part out."
                )
            ),
            Table(("load case", "safety factor", "held", "multiples held"), rows),
            Paragraph(
                inline(
                    f"Critical load case: {plan.critical_load}; its most used contact: "
                    f"{plan.critical_contact}."
                )
            ),
        ]
    if plan.motions:
        rows = tuple(
            (inline(name), inline("no limit found" if m is None else m.describe()))
            for name, m in plan.motions.items()
        )
        blocks += [
            Heading(2, inline("Impending motion")),
            Paragraph(inline("How the body starts to slide when a task load exceeds its margin.")),
            Table(("load case", "motion"), rows),
        ]
    return blocks


def _wrench_table(plan: Plan, j: int, length_scale: float) -> list[Block]:
    wrenches = plan.contact_wrenches[:, j]
    noise = PRINT_RTOL * float(np.max(np.abs(wrenches[:, 0])))
    wrenches = np.where(
        np.abs(wrenches) < noise * np.array([1.0, 1.0, 1.0, length_scale]), 0.0, wrenches
    )
    rows = []
    for i, name in enumerate(plan.contact_names):
        fn, ft1, ft2, mn = wrenches[i]
        used = "n/a" if plan.utilisation is None else _num(plan.utilisation[i, j], 3)
        rows.append(
            tuple(inline(x) for x in (name, _num(fn), _num(ft1), _num(ft2), _num(mn), used))
        )
    load = plan.load_names[j]
    return [
        Heading(2, inline(f"Contact wrenches, load case {load}")),
        Paragraph(
            inline(
                f"Each contact's wrench on the body in its own frame (normal, tangents t1, t2, "
                f"moment about the normal), {_state_text(plan)}. Friction used: the fraction of "
                "the contact's friction set its load uses at impending slip."
                + (
                    ""
                    if plan.objective in FIXED_FORCE_OBJECTIVES
                    else " Friction in a fixture with more contacts than needed is statically "
                    "indeterminate: this is the distribution the planner found."
                )
            )
        ),
        Table(
            ("contact", "fn [N]", "ft1 [N]", "ft2 [N]", "mn [N m]", "friction used"), tuple(rows)
        ),
    ]


def _micro(values) -> str:
    """Three components [m or rad] in millionths (µm, µrad)."""
    return ", ".join(_num(v, 4) for v in millionths(values))


def _cells(*values: str) -> tuple:
    return tuple(inline(value) for value in values)


def _stiffness_rows(problem_file: ProblemFile) -> tuple:
    """Each contact's springs [N/m, N/m, N m/rad]."""
    return tuple(
        _cells(
            name,
            _num(k.normal),
            _num(k.tangential),
            "none" if k.torsional is None else _num(k.torsional),
        )
        for name, k in (problem_file.stiffness or {}).items()
    )


def _outcome_rows(summary: dict) -> tuple:
    """Each load case's rigid safety factor, first slip, lifted contacts and displacement."""
    return tuple(
        _cells(
            case, _num(summary["rigid_safety_factors"][case]), first_slip_text(summary, case),
            ", ".join(summary["lifted"][case]) or "none", _micro(moved[:3]), _micro(moved[3:]),
        )
        for case, moved in summary["displacement"].items()
    )  # fmt: skip


def _use_rows(summary: dict) -> tuple:
    """Each contact's compliant normal force and friction use, rigid and compliant, per case."""
    return tuple(
        _cells(
            case, contact, _num(summary["wrenches"][case][contact][0]), _num(use["rigid"], 3),
            _num(use["compliant"], 3),
        )
        for case, row in summary["utilisation"].items()
        for contact, use in row.items()
    )  # fmt: skip


_COMPLIANT_TEXT = (
    "The contacts as linear springs in their own frames (stiffnesses below) on the rigid part "
    "(fixplan.motion.compliance): the clamps and fingers press with the given forces, then "
    "gravity and the task load are applied; every contact's wrench, its own safety factor and "
    "the part's displacement follow. The first slip is the smallest multiple of the task load "
    "at which a contact reaches its friction set; the displacement (x, y, z) and rotation (about "
    "x, y, z) are the part's at the task load, about its centre of mass."
)
_USE_TEXT = (
    "Friction used: the fraction of a contact's friction set its load uses (1 on the limit). "
    "Rigid: the plan's, at impending slip of the whole part (the task load times its rigid "
    "safety factor). Compliant: 1 / the contact's own safety factor at the task load; fn is its "
    "compliant normal force."
)


def _compliant_section(problem_file, plan, result, writer) -> list[Block]:
    """The compliant analysis: the stiffnesses, each load case's outcome, every contact's
    friction use (rigid and compliant) and its figure."""
    summary = compliant_summary(plan, result)
    writer.figure(UTILISATION_FIGURE, lambda: figures.utilisation_figure(plan, result))
    springs = _stiffness_rows(problem_file)
    outcome = ("load case", "rigid safety factor", "first slip", "lifted off",
               "displacement [µm]", "rotation [µrad]")  # fmt: skip
    uses = ("load case", "contact", "fn [N]", "friction used, rigid", "friction used, compliant")
    caption = (
        "Friction used by every contact in every load case: rigid (blue) beside compliant "
        "(orange); the dashed line is where a contact slips."
    )
    stiffness = ("contact", "normal [N/m]", "tangential [N/m]", "torsional [N m/rad]")
    return [
        Heading(2, inline("Compliant analysis")),
        Paragraph(inline(_COMPLIANT_TEXT)),
        *([Table(stiffness, springs)] if springs else []),
        Table(outcome, _outcome_rows(summary)),
        Paragraph(inline(_USE_TEXT)),
        Table(uses, _use_rows(summary)),
        Image(
            UTILISATION_FIGURE, "friction used per contact, rigid and compliant", inline(caption)
        ),
    ]


def _figure_case(plan: Plan) -> tuple[str, str | None]:
    """The load case the figures show, and a note when it is not the critical one."""
    if plan.critical_load is not None:
        return plan.critical_load, None
    if plan.infeasible_motions:
        load = next(iter(plan.infeasible_motions))
        return load, f"The figures show load case '{load}', which cannot be held."
    load = plan.load_names[0]
    return load, f"No critical load case is known; the figures show load case '{load}'."


def write_report(
    directory: str | os.PathLike[str],
    problem_file: ProblemFile,
    plan: Plan,
    planner: Planner,
    *,
    sliding_subspace: Sequence[str] | None = None,
    compliant: ComplianceResult | None = None,
) -> list[Path]:
    """Write the report of ``plan`` into ``directory`` (see the module docstring).

    The folder is created if needed; the report's own files are overwritten and any other file
    in it is left alone. The files are written into a temporary folder beside it and moved into
    place only when all are written: a report that fails leaves nothing behind. Figures that
    need contact forces are skipped for a plan without them (infeasible, solver error), and the
    report says so.

    Parameters
    ----------
    directory : str or path-like
        The report folder.
    problem_file : ProblemFile
        The problem as read from its file (name, kind, SHA-256, model override).
    plan : Plan
        The plan of ``planner.problem``.
    planner : Planner
        The planner that produced ``plan`` (its friction models and solver).
    sliding_subspace : sequence of str, optional
        Wrench components of the contact-set surface figure; default
        :func:`default_sliding_subspace`.
    compliant : ComplianceResult, optional
        The compliant analysis of ``plan``'s forces (:func:`fixplan.motion.compliance.analyse`)
        with ``problem_file.stiffness``; adds the "Compliant analysis" section.

    Returns
    -------
    list of Path
        The files written, in the order written.

    Raises
    ------
    ReportError
        The folder cannot be created or a file cannot be written.
    InvalidArgumentError
        ``sliding_subspace`` names unknown components.
    """
    problem = planner.problem
    subspace = (
        default_sliding_subspace(problem) if sliding_subspace is None else tuple(sliding_subspace)
    )
    if len(subspace) < 2 or len(set(subspace)) != len(subspace) or set(subspace) - set(COMPONENTS):
        raise InvalidArgumentError(
            f"sliding_subspace must name at least two distinct components of "
            f"{', '.join(COMPONENTS)}; got {list(subspace)}"
        )
    directory = Path(directory)
    with staged_folder(directory) as staging:
        writer = Writer(staging)
        _write_files(writer, problem_file, plan, planner, subspace, compliant)
    return [directory / path.name for path in writer.written]


def _write_files(writer: Writer, problem_file: ProblemFile, plan: Plan, planner, subspace,
                 compliant):  # fmt: skip
    """Write every file of the report (see the module docstring) with ``writer``."""
    problem = planner.problem
    document = json.dumps(plan.as_dict(), indent=2, sort_keys=True)
    writer.write("plan.json", (document + "\n").encode("utf-8"))
    load, case_note = _figure_case(plan)
    drawn, notes = _draw_figures(problem, plan, planner, load, subspace, writer)
    blocks = _header(problem_file, plan, planner, subspace) + _result(plan, problem)
    if plan.contact_wrenches is not None:
        blocks += _wrench_table(plan, plan.load_names.index(load), planner.length_scale)
    if compliant is not None:
        blocks += _compliant_section(problem_file, plan, compliant, writer)
    blocks.append(Heading(2, inline("Figures")))
    if case_note:
        blocks.append(Paragraph(inline(case_note)))
    blocks += [Image(f.file, f.alt, inline(f.caption)) for f in drawn]
    if notes:
        blocks.append(List(tuple(inline(note) for note in notes)))
    title = f"fixplan report: {problem_file.name}"
    writer.document(blocks, title)


__all__ = ["ReportError", "default_sliding_subspace", "write_report"]
