r"""Figures of a plan (contact layout, friction use per contact, safety factors, fixture surface,
friction use in a compliant analysis) and of a pushed part's trajectory (a figure and an
animated GIF).

Every function computes its data first (plain numpy) and draws it second, on a
:class:`matplotlib.figure.Figure` with the Agg canvas (never ``pyplot``, so no global state and
no display is touched). Each accepts ``ax=`` (or ``axes=`` for the figures with several panels)
to draw into existing axes, and returns the figure drawn on. :func:`save_png` writes a figure
with a fixed resolution and without the software and date metadata, so equal figures give equal
bytes. matplotlib is imported inside the functions only: the rest of fixplan does not need it.

Axes of the contact sections are the paper's normalised loads (Table 2, step 3),

.. math:: \left(\frac{f_{t1}}{\mu N}, \frac{f_{t2}}{\mu N}, \frac{m_n}{\mu \rho N}\right),

with ``N`` the contact's normal force [N], ``mu`` its model's friction coefficient and ``rho``
[m] its characteristic length (maximum moment over maximum force).
"""

from __future__ import annotations

import itertools
import os
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from fixplan import validation
from fixplan.errors import FixplanError, InvalidArgumentError
from fixplan.io.compliant_report import utilisation
from fixplan.planner.plan import Plan
from fixplan.planner.problem import Contact, Problem

if TYPE_CHECKING:  # pragma: no cover - typing only; matplotlib is imported when drawing
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

    from fixplan.models.base import FrictionModel
    from fixplan.motion.compliance import ComplianceResult
    from fixplan.planner.contact_surface import ContactSetSurface
    from fixplan.surface.limit_surface import LimitSurface

#: Resolution of saved figures [dots per inch].
DPI = 100
#: Points per drawn section curve (contact sections; the fixture surface uses ``n``).
SECTION_POINTS = 181
#: Smallest side of the cube shown by :func:`layout_figure` [m] (a single contact at the centre
#: of mass would otherwise give an empty view).
MIN_VIEW_SIZE = 0.01
#: The longest force arrow of :func:`layout_figure` as a fraction of the view size.
FORCE_ARROW_FRACTION = 0.35
#: Contact normals of :func:`layout_figure` as a fraction of the view size.
NORMAL_ARROW_FRACTION = 0.15
#: Components of a normalised load below this are solver rounding and printed as 0.
PRINT_ATOL = 1e-9

_ROLE_COLORS = {
    "support": "tab:blue",
    "locator": "tab:purple",
    "clamp": "tab:red",
    "finger": "tab:orange",
}
_FORCE_COLOR = "black"
_LOAD_COLOR = "tab:green"
_SECTION_PLANES = (("fx-m", 0, 2), ("fy-m", 1, 2), ("fx-fy", 0, 1))
_SECTION_LABELS = (r"$f_{t1}/(\mu N)$", r"$f_{t2}/(\mu N)$", r"$m_n/(\mu \rho N)$")
_SECTION_NAMES = ("ft1", "ft2", "mn")
_BOX_EDGES = [(a, b) for a, b in itertools.combinations(range(8), 2) if bin(a ^ b).count("1") == 1]


class MissingDependencyError(FixplanError, ImportError):
    """An optional package that a feature needs is not installed; the message says which."""


def _matplotlib():
    """``(Figure, FigureCanvasAgg)``, or a :class:`MissingDependencyError` naming the fix."""
    try:
        from matplotlib.backends.backend_agg import FigureCanvasAgg
        from matplotlib.figure import Figure
    except ImportError as exc:
        raise MissingDependencyError(
            "figures and reports need matplotlib: pip install matplotlib"
        ) from exc
    return Figure, FigureCanvasAgg


def _new_figure(size: tuple[float, float]) -> Figure:
    Figure, FigureCanvasAgg = _matplotlib()
    fig = Figure(figsize=size, dpi=DPI, layout="constrained")
    FigureCanvasAgg(fig)
    return fig


def save_png(fig: Figure, path: str | os.PathLike[str]) -> None:
    """Write ``fig`` as a PNG at :data:`DPI` without software or date metadata.

    The same figure drawn twice gives the same bytes, so reports diff cleanly.
    """
    _, FigureCanvasAgg = _matplotlib()
    if not isinstance(fig.canvas, FigureCanvasAgg):
        FigureCanvasAgg(fig)
    fig.savefig(os.fspath(path), format="png", dpi=DPI, metadata={"Software": None})


def _load_index(plan: Plan, load_name: str) -> int:
    if load_name not in plan.load_names:
        raise InvalidArgumentError(
            f"load_name must be one of the plan's load cases {list(plan.load_names)}, "
            f"got {load_name!r}"
        )
    return plan.load_names.index(load_name)


def _fmt(value: float) -> str:
    return "∞" if np.isinf(value) else f"{value + 0.0:.4g}"


# -- contact layout --------------------------------------------------------------------------


@dataclass(frozen=True, slots=True)
class _Layout:
    names: tuple[str, ...]
    roles: tuple[str, ...]
    positions: np.ndarray  # (contacts, 3) [m]
    normals: np.ndarray  # (contacts, 3), arrow vectors [m]
    forces: np.ndarray | None  # (contacts, 3), arrow vectors [m]
    corners: np.ndarray  # (8, 3) body box [m]
    center_of_mass: np.ndarray
    load_point: np.ndarray
    load_arrow: np.ndarray  # [m]
    center: np.ndarray
    half: float  # half side of the view cube [m]
    title: str
    note: str


def _layout_data(problem: Problem, plan: Plan, load_name: str) -> _Layout:
    j = _load_index(plan, load_name)
    contacts = problem.contacts
    positions = np.array([c.position for c in contacts])
    com = problem.body.center_of_mass
    cloud = np.vstack([positions, com])
    low, high = cloud.min(axis=0), cloud.max(axis=0)
    corners = np.array(
        [[(low, high)[(k >> axis) & 1][axis] for axis in range(3)] for k in range(8)]
    )
    size = max(float(np.max(high - low)), MIN_VIEW_SIZE)
    load = next((x for x in problem.loads if x.name == load_name), None)
    task = np.zeros(3) if load is None else load.force
    vectors = [task]
    forces = None
    if plan.contact_wrenches is not None:
        wrenches = plan.contact_wrenches[:, j]  # (fn, ft1, ft2, mn) per contact
        forces = np.array(
            [c.frame.T @ w[[1, 2, 0]] for c, w in zip(contacts, wrenches, strict=True)]
        )
        vectors.extend(forces)
    largest = float(np.max(np.linalg.norm(vectors, axis=1)))
    scale = FORCE_ARROW_FRACTION * size / largest if largest > 0.0 else 0.0
    if plan.contact_wrenches is None:
        title = f"contact layout, load case {load_name!r} (no contact forces: {plan.status})"
    else:
        title = f"contact layout and contact forces, load case {load_name!r}"
    note = f"longest force arrow: {_fmt(largest)} N; box: extent of contacts and CoM"
    if load is not None and np.any(load.torque):
        note += f"; task torque ({', '.join(_fmt(x) for x in load.torque)}) N m (not drawn)"
    return _Layout(
        names=tuple(c.name for c in contacts),
        roles=tuple(c.role for c in contacts),
        positions=positions,
        normals=NORMAL_ARROW_FRACTION * size * np.array([c.normal for c in contacts]),
        forces=None if forces is None else scale * forces,
        corners=corners,
        center_of_mass=com,
        load_point=com if load is None else load.point,
        load_arrow=scale * task,
        center=(low + high) / 2.0,
        half=0.5 * size * (1.0 + 2.0 * FORCE_ARROW_FRACTION),
        title=title,
        note=note,
    )


def layout_figure(
    problem: Problem, plan: Plan, load_name: str, *, ax: Axes | None = None
) -> Figure:
    """The contacts in 3D with the body, their normals and their forces in one load case.

    The body is drawn as the bounding box of the contact positions and the centre of mass
    (marked). Thin coloured arrows are the contact normals (into the body, coloured by role),
    black arrows the force of each contact on the body, ``fn n + ft1 t1 + ft2 t2`` [N] from
    ``plan.contact_wrenches``, and the green arrow the task force of the load case at its point;
    forces share one scale, stated in the figure with any task torque (not drawn). The task
    force is that of the problem's load case named ``load_name`` (none if the plan was solved
    for loads of other names). Without contact forces (an infeasible plan) only the geometry and
    the task force are drawn.

    Parameters
    ----------
    problem : Problem
        The problem solved.
    plan : Plan
        Its plan.
    load_name : str
        The load case drawn.
    ax : Axes, optional
        3D axes to draw into (``projection="3d"``); default a new figure.

    Returns
    -------
    Figure
    """
    data = _layout_data(problem, plan, load_name)
    _matplotlib()
    from matplotlib.lines import Line2D
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    if ax is None:
        ax = _new_figure((8.0, 7.0)).add_subplot(projection="3d")
    faces = [[0, 1, 3, 2], [4, 5, 7, 6], [0, 1, 5, 4], [2, 3, 7, 6], [0, 2, 6, 4], [1, 3, 7, 5]]
    ax.add_collection3d(
        Poly3DCollection(
            [data.corners[f] for f in faces], facecolor="0.8", edgecolor="0.5", alpha=0.12
        )
    )
    for a, b in _BOX_EDGES:
        ax.plot(*data.corners[[a, b]].T, color="0.45", linewidth=0.8)
    ax.scatter(*data.center_of_mass, marker="X", s=80, color="0.2", depthshade=False)
    ax.text(*data.center_of_mass, "  CoM", color="0.2", fontsize=9)
    colors = [_ROLE_COLORS[role] for role in data.roles]
    ax.scatter(*data.positions.T, s=36, c=colors, depthshade=False)
    for k, name in enumerate(data.names):
        ax.quiver(*data.positions[k], *data.normals[k], color=colors[k], arrow_length_ratio=0.25)
        ax.text(*(data.positions[k] - 0.6 * data.normals[k]), f" {name}", fontsize=9)
        if data.forces is not None and np.any(data.forces[k]):
            ax.quiver(
                *data.positions[k],
                *data.forces[k],
                color=_FORCE_COLOR,
                linewidth=1.8,
                arrow_length_ratio=0.15,
            )
    if np.any(data.load_arrow):
        ax.quiver(
            *data.load_point,
            *data.load_arrow,
            color=_LOAD_COLOR,
            linewidth=2.2,
            arrow_length_ratio=0.15,
        )
    for axis, label in enumerate("xyz"):
        getattr(ax, f"set_{label}lim")(data.center[axis] - data.half, data.center[axis] + data.half)
        getattr(ax, f"set_{label}label")(f"{label} [m]")
    ax.set_box_aspect((1.0, 1.0, 1.0))
    ax.view_init(elev=24.0, azim=-58.0)
    ax.set_title(data.title, fontsize=11)
    handles = [
        Line2D([], [], color=_ROLE_COLORS[role], marker="o", label=f"{role} (normal)")
        for role in dict.fromkeys(data.roles)
    ]
    if data.forces is not None:
        handles.append(Line2D([], [], color=_FORCE_COLOR, linewidth=1.8, label="contact force"))
    handles.append(Line2D([], [], color=_LOAD_COLOR, linewidth=2.2, label="task force"))
    ax.legend(handles=handles, loc="upper left", fontsize=8)
    ax.figure.supxlabel(data.note, fontsize=9)
    return ax.figure


# -- one contact's friction use ---------------------------------------------------------------


@dataclass(frozen=True, slots=True)
class _Sections:
    curves: tuple[np.ndarray, ...]  # (n, 2) normalised section of each plane
    load: np.ndarray  # (3,) normalised load
    limit: np.ndarray  # (3,) normalised load scaled onto the set's boundary
    safety: float
    title: str
    note: str


def _section_data(
    contact: Contact, model: FrictionModel, load, normal_force: float, load_name: str | None
) -> _Sections:
    if not model.torsion:
        raise InvalidArgumentError(
            f"contact {contact.name!r} has a point model ({type(model).__name__}): its sections "
            "are drawn for area contacts only"
        )
    if model.frictionless:
        raise InvalidArgumentError(
            f"contact {contact.name!r} is frictionless (mu = 0): its friction set is the single "
            "load 0, which has no sections to draw"
        )
    load = validation.finite_array("load", load, shape=(3,))
    force = validation.positive_scalar("normal_force", normal_force)
    units = force * np.array([model.mu, model.mu, model.mu * model.rho])
    curves = tuple(
        model.curve(plane, SECTION_POINTS, normalized=True, normal_force=force)[:, [a, b]]
        for plane, a, b in _SECTION_PLANES
    )
    safety = float(model.safety_factor(load, normal_force=force))
    q = load / units
    shown = np.where(np.abs(q) < PRINT_ATOL, 0.0, q)
    case = "" if load_name is None else f", load case {load_name!r}"
    return _Sections(
        curves=curves,
        load=q,
        limit=q * safety if np.isfinite(safety) else np.full(3, np.nan),
        safety=safety,
        title=f"contact {contact.name!r}{case}: safety factor {_fmt(safety)}",
        note=(
            f"{type(model).__name__}, N = {_fmt(force)} N, $\\mu$ = {_fmt(model.mu)}, "
            f"$\\rho$ = {_fmt(model.rho * 1e3)} mm; normalised load = "
            f"({', '.join(_fmt(x) for x in shown)})"
        ),
    )


def contact_section_figure(
    contact: Contact,
    model: FrictionModel,
    load,
    normal_force: float,
    *,
    load_name: str | None = None,
    axes: Sequence[Axes] | None = None,
) -> Figure:
    """An area contact's load drawn inside the sections of its friction set (paper's figures).

    Three panels: the sections of the model's set at ``normal_force`` by the planes
    ``(ft1, mn)``, ``(ft2, mn)`` and ``(ft1, ft2)`` in normalised coordinates, the load's
    projection on each plane (dot), and where the ray from the origin through the load leaves the
    set (cross): their distances from the origin are in the ratio ``1 : safety factor``, so the
    gap shows how close the contact is to slipping. Sections are central (through the origin):
    a load with a component off a plane lies inside a smaller slice than the one drawn.

    Parameters
    ----------
    contact : Contact
        The contact (its name labels the figure).
    model : FrictionModel
        Its friction model at unit normal force (``Planner.models[i]``); an area model with
        friction (a frictionless model's set is a point).
    load : array_like (3,)
        Friction load ``(ft1, ft2, mn)`` [N, N, N m] the contact carries, in its frame
        (``plan.contact_wrenches[i, j, 1:]``).
    normal_force : float
        The contact's normal force [N], > 0.
    load_name : str, optional
        The load case, for the title.
    axes : sequence of 3 Axes, optional
        Where to draw the three panels; default a new figure.

    Returns
    -------
    Figure
    """
    data = _section_data(contact, model, load, normal_force, load_name)
    if axes is None:
        axes = _new_figure((11.0, 4.2)).subplots(1, 3)
    if len(axes) != 3:
        raise InvalidArgumentError(f"axes must hold 3 Axes, got {len(axes)}")
    for ax, curve, (_, a, b) in zip(axes, data.curves, _SECTION_PLANES, strict=True):
        ray = data.limit[[a, b]]
        _draw_section(
            ax, curve, "tab:blue", "friction set", data.load[[a, b]],
            ray if np.all(np.isfinite(ray)) else None,
        )  # fmt: skip
        reach = np.abs(np.concatenate([data.load, np.nan_to_num(data.limit)]))
        limit = 1.15 * max(1.0, float(reach.max()))
        ax.set_xlim(-limit, limit)
        ax.set_ylim(-limit, limit)
        ax.set_aspect("equal")
        ax.axhline(0.0, color="0.8", linewidth=0.6)
        ax.axvline(0.0, color="0.8", linewidth=0.6)
        ax.set_xlabel(_SECTION_LABELS[a])
        ax.set_ylabel(_SECTION_LABELS[b])
        ax.set_title(f"section ({_SECTION_NAMES[a]}, {_SECTION_NAMES[b]})", fontsize=10)
    axes[0].legend(loc="lower left", fontsize=8)
    fig = axes[0].figure
    fig.suptitle(data.title, fontsize=11)
    fig.supxlabel(data.note, fontsize=9)
    return fig


# -- safety factors ---------------------------------------------------------------------------


@dataclass(frozen=True, slots=True)
class _Safety:
    names: tuple[str, ...]
    values: np.ndarray  # safety factors, inf where unbounded
    top: float  # axis top; infinite bars reach it
    critical: str | None


def _safety_data(plan: Plan) -> _Safety:
    if not plan.safety_factors:
        raise InvalidArgumentError(
            f"the plan has no safety factors (status {plan.status!r}): nothing to draw"
        )
    names = tuple(plan.safety_factors)
    values = np.array([plan.safety_factors[name] for name in names], dtype=float)
    finite = values[np.isfinite(values)]
    top = 1.25 * max(1.2, float(finite.max())) if finite.size else 2.0
    return _Safety(names=names, values=values, top=top, critical=plan.critical_load)


def safety_figure(plan: Plan, *, ax: Axes | None = None) -> Figure:
    """Bar chart of the safety factor of every load case, with the line ``s = 1``.

    Green bars are held (``s >= 1``), red ones slip; a load case with an infinite safety factor
    (no scale of its task load breaks the hold) is a hatched bar up to the axis top labelled
    ``∞``.
    The critical load case's label is bold.

    Parameters
    ----------
    plan : Plan
        A plan with safety factors.
    ax : Axes, optional
        Where to draw; default a new figure.

    Returns
    -------
    Figure
    """
    data = _safety_data(plan)
    if ax is None:
        ax = _new_figure((max(5.0, 0.9 * len(data.names) + 2.5), 4.2)).add_subplot()
    x = np.arange(len(data.names))
    infinite = np.isinf(data.values)
    heights = np.where(infinite, data.top, data.values)
    colors = ["tab:green" if v >= 1.0 else "tab:red" for v in data.values]
    bars = ax.bar(x, heights, color=colors, edgecolor="black", linewidth=0.6)
    for bar, value in zip(bars, data.values, strict=True):
        if np.isinf(value):
            bar.set_hatch("//")
            bar.set_alpha(0.6)
    for k, value in enumerate(data.values):
        if np.isinf(value):
            ax.text(
                x[k],
                0.9 * data.top,
                "∞",
                ha="center",
                va="center",
                fontsize=16,
                bbox={"facecolor": "white", "edgecolor": "black", "boxstyle": "round"},
            )
        else:
            ax.annotate(
                _fmt(value),
                (x[k], value),
                xytext=(0, 3),
                textcoords="offset points",
                ha="center",
                va="bottom",
                fontsize=9,
            )
    ax.axhline(1.0, color="black", linestyle="--", linewidth=1.0, label="s = 1: slips below")
    ax.legend(loc="best", fontsize=8)
    ax.set_xlim(-0.6, len(x) - 0.4)
    ax.set_ylim(0.0, data.top)
    ax.set_xticks(
        x, data.names, rotation=20 if len(x) > 4 else 0, ha="right" if len(x) > 4 else "center"
    )
    for label, name in zip(ax.get_xticklabels(), data.names, strict=True):
        if name == data.critical:
            label.set_fontweight("bold")
    ax.set_ylabel("safety factor of the task load")
    ax.set_title("safety factor per load case (∞: not limited)", fontsize=11)
    return ax.figure


# -- contact utilisation, rigid and compliant ------------------------------------------------

#: Most panels per row of :func:`utilisation_figure` (one panel per load case).
UTILISATION_COLUMNS = 3
_RIGID_COLOR = "tab:blue"
_COMPLIANT_COLOR = "tab:orange"


@dataclass(frozen=True, slots=True)
class _Utilisation:
    cases: tuple[str, ...]
    contacts: tuple[str, ...]
    rigid: np.ndarray | None  # (cases, contacts); None: the plan has no utilisation
    compliant: np.ndarray  # (cases, contacts), inf for a load without friction capacity
    top: float  # axis top; infinite bars reach it
    first: tuple[str | None, ...]  # the contact that slips first, per case


def _utilisation_data(plan: Plan, result: ComplianceResult) -> _Utilisation:
    table = utilisation(plan, result)
    cases, contacts = result.load_names, result.contact_names
    pairs = np.array([[table[c][k] for k in contacts] for c in cases], dtype=float)
    rigid = None if plan.utilisation is None else pairs[:, :, 0]
    finite = pairs[np.isfinite(pairs)]
    top = 1.25 * max(1.2, float(finite.max())) if finite.size else 1.5
    first = tuple(result.first_slip_contact[c] for c in cases)
    return _Utilisation(cases, contacts, rigid, pairs[:, :, 1], top, first)


def _utilisation_bars(ax, x, values, offset, color, label, top) -> None:
    """Bars of ``values`` at ``x + offset``; infinite ones hatched up to ``top``."""
    infinite = np.isinf(values)
    bars = ax.bar(x + offset, np.where(infinite, top, values), width=0.38, color=color,
                  edgecolor="black", linewidth=0.5, label=label)  # fmt: skip
    for bar, endless in zip(bars, infinite, strict=True):
        if endless:
            bar.set_hatch("//")
            bar.set_alpha(0.6)


def utilisation_figure(
    plan: Plan, result: ComplianceResult, *, axes: Sequence[Axes] | None = None
) -> Figure:
    """Friction used by every contact, rigid beside compliant, one panel per load case.

    Grouped bars per contact: the rigid plan's utilisation at impending slip of the part (blue;
    absent when the plan has none) and the compliant analysis's ``1 / s`` at the task load
    (orange), with the line 1 where a contact slips; a load on a contact without friction
    capacity (utilisation ``∞``) is a hatched bar up to the axis top. The label of the contact
    that slips first as the task load grows is bold.

    Parameters
    ----------
    plan : Plan
        The rigid check whose forces ``result`` analysed.
    result : ComplianceResult
        Its compliant analysis (:func:`fixplan.motion.compliance.analyse`).
    axes : sequence of Axes, optional
        One per load case; default a new figure of up to :data:`UTILISATION_COLUMNS` panels
        a row.

    Returns
    -------
    Figure
    """
    data = _utilisation_data(plan, result)
    if axes is None:
        columns = min(UTILISATION_COLUMNS, len(data.cases))
        rows = -(-len(data.cases) // columns)
        width = max(4.0, 0.55 * len(data.contacts) + 1.5)
        fig = _new_figure((width * columns, 3.4 * rows + 0.6))
        axes = fig.subplots(rows, columns, squeeze=False).ravel()
        for ax in axes[len(data.cases) :]:
            ax.set_visible(False)
    if len(axes) < len(data.cases):
        raise InvalidArgumentError(f"axes must hold {len(data.cases)} Axes, got {len(axes)}")
    x = np.arange(len(data.contacts))
    for k, (ax, case) in enumerate(zip(axes, data.cases, strict=False)):
        if data.rigid is not None:
            _utilisation_bars(ax, x, data.rigid[k], -0.2, _RIGID_COLOR,
                              "rigid, at impending slip", data.top)  # fmt: skip
        _utilisation_bars(ax, x, data.compliant[k], 0.2, _COMPLIANT_COLOR,
                          "compliant, at the task load", data.top)  # fmt: skip
        ax.axhline(1.0, color="black", linestyle="--", linewidth=1.0)
        ax.set_ylim(0.0, data.top)
        ax.set_xticks(x, data.contacts, rotation=30, ha="right", fontsize=8)
        for label, name in zip(ax.get_xticklabels(), data.contacts, strict=True):
            if name == data.first[k]:
                label.set_fontweight("bold")
        ax.set_title(case, fontsize=10)
        ax.set_ylabel("friction used")
    axes[0].legend(loc="upper left", fontsize=7)
    fig = axes[0].figure
    fig.suptitle("friction used per contact (1: slips; bold: slips first)", fontsize=11)
    return fig


# -- fixture limit surface --------------------------------------------------------------------


@dataclass(frozen=True, slots=True)
class _SetSections:
    pairs: tuple[tuple[str, str], ...]
    curves: tuple[np.ndarray, ...]  # (n, 2) per pair, in N and N m
    load: np.ndarray | None  # (k,) in subspace coordinates
    limit: np.ndarray | None  # load scaled onto the surface
    safety: float | None
    subspace: tuple[str, ...]


def _set_data(surface: ContactSetSurface, subspace, load, n: int) -> _SetSections:
    components = surface.subspace if subspace is None else tuple(subspace)
    if len(components) < 2 or any(c not in surface.subspace for c in components):
        raise InvalidArgumentError(
            f"subspace must name at least two of the surface's components {surface.subspace}, "
            f"got {components}"
        )
    pairs = tuple(itertools.combinations(components, 2))
    curves = tuple(surface.curve(pair, n) for pair in pairs)
    if load is None:
        return _SetSections(pairs, curves, None, None, None, surface.subspace)
    load = validation.finite_array("load", load, shape=(len(surface.subspace),))
    safety = surface.safety_factor(load)
    limit = load * safety if np.isfinite(safety) else None
    return _SetSections(pairs, curves, load, limit, safety, surface.subspace)


def _unit(component: str) -> str:
    return "N m" if component.startswith("m") else "N"


def contact_set_figure(
    surface: ContactSetSurface,
    subspace: Sequence[str] | None = None,
    *,
    load=None,
    n: int = 72,
    axes: Sequence[Axes] | None = None,
) -> Figure:
    """Central sections of the Minkowski-summed limit surface of a set of contacts.

    One panel per pair of the ``subspace`` components: the section of the surface by that
    coordinate plane (other components zero), in [N] and [N m] about the world origin. With
    ``load`` its projection is drawn (dot) and where its ray leaves the surface (cross).

    Parameters
    ----------
    surface : ContactSetSurface
        The surface (contacts with fixed normal forces).
    subspace : sequence of str, optional
        Components to pair (at least two of ``surface.subspace``); default all of them.
    load : array_like, optional
        A wrench in ``surface.subspace`` coordinates, e.g. the friction resultant of a plan.
    n : int, optional
        Points per section (each is one conic solve).
    axes : sequence of Axes, optional
        One per pair of components; default a new figure.

    Returns
    -------
    Figure
    """
    data = _set_data(surface, subspace, load, n)
    if axes is None:
        axes = _new_figure((4.0 * len(data.pairs) + 0.6, 4.4)).subplots(1, len(data.pairs))
        axes = np.atleast_1d(axes)
    if len(axes) != len(data.pairs):
        raise InvalidArgumentError(f"axes must hold {len(data.pairs)} Axes, got {len(axes)}")
    for ax, pair, curve in zip(axes, data.pairs, data.curves, strict=True):
        index = [data.subspace.index(c) for c in pair]
        _draw_section(
            ax, curve, "tab:purple", "limit surface section",
            None if data.load is None else data.load[index],
            None if data.load is None or data.limit is None else data.limit[index],
        )  # fmt: skip
        ax.axhline(0.0, color="0.8", linewidth=0.6)
        ax.axvline(0.0, color="0.8", linewidth=0.6)
        ax.set_xlabel(f"{pair[0]} [{_unit(pair[0])}]")
        ax.set_ylabel(f"{pair[1]} [{_unit(pair[1])}]")
        ax.set_title(f"section ({pair[0]}, {pair[1]})", fontsize=10)
    axes[0].legend(loc="lower left", fontsize=8)
    fig = axes[0].figure
    title = f"limit surface of the contact set in ({', '.join(data.subspace)})"
    if data.safety is not None:
        title += f"; safety factor of the load {_fmt(data.safety)}"
    fig.suptitle(title, fontsize=11)
    return fig


@dataclass(frozen=True, slots=True)
class _SurfaceSections:
    exact: tuple[np.ndarray, ...]  # (n, 2) normalised sections of the exact surface
    models: dict  # name -> tuple of (n, 2) sections (area models only)
    title: str
    point: bool  # the surface is the single load 0 (frictionless)


def _surface_data(surface: LimitSurface, models: dict) -> _SurfaceSections:
    if surface.frictionless:
        origin = np.zeros((1, 2))
        title = "frictionless contact (mu = 0): its limit surface and every model are the load 0"
        return _SurfaceSections(exact=(origin,) * 3, models={}, title=title, point=True)
    exact = tuple(
        surface.curve(plane, SECTION_POINTS, normalized=True)[:, [a, b]]
        for plane, a, b in _SECTION_PLANES
    )
    units = np.array([surface.max_force, surface.max_force, surface.max_moment])
    sections = {}
    for name, model in models.items():
        if not model.torsion:
            continue
        curves = []
        for plane, a, b in _SECTION_PLANES:
            loads = model.curve(plane, SECTION_POINTS, normal_force=surface.normal_force)
            curves.append((loads / units)[:, [a, b]])
        sections[name] = tuple(curves)
    title = (
        f"limit surface: max force {_fmt(surface.max_force)} N, max moment "
        f"{_fmt(surface.max_moment)} N m"
    )
    return _SurfaceSections(exact=exact, models=sections, title=title, point=False)


def surface_figure(surface: LimitSurface, models: dict, *, axes=None) -> Figure:
    """Sections of an exact limit surface with those of approximating ``models``.

    The (fx, m), (fy, m) and (fx, fy) sections in the paper's normalised coordinates (force
    over ``max_force``, moment over ``max_moment`` of the exact surface), as in its Figs. 3
    and 5. ``models`` maps a label to a friction model built from ``surface``. A frictionless
    surface is drawn as the point 0, which is also every model of it.
    """
    data = _surface_data(surface, models)
    if axes is None:
        fig = _new_figure((13.0, 4.6))
        axes = fig.subplots(1, 3)
    else:
        fig = axes[0].figure
    labels = (r"$f_x/f_{max}$", r"$f_y/f_{max}$", r"$m/m_{max}$")
    for index, (ax, (_, a, b)) in enumerate(zip(axes, _SECTION_PLANES, strict=True)):
        ax.plot(*_closed(data.exact[index]).T, color="black", linewidth=2.0,
                label="exact: the load 0" if data.point else "exact",
                marker="o" if data.point else None)  # fmt: skip
        for name, curves in data.models.items():
            ax.plot(*_closed(curves[index]).T, linewidth=1.0, label=name)
        if data.point:
            ax.set_xlim(-1.0, 1.0)
            ax.set_ylim(-1.0, 1.0)
        ax.set_xlabel(labels[a])
        ax.set_ylabel(labels[b])
        ax.set_aspect("equal")
        ax.grid(True, linewidth=0.3)
    axes[0].legend(fontsize=7, loc="lower left")
    fig.suptitle(data.title)
    return fig


def _closed(curve: np.ndarray) -> np.ndarray:
    """``curve`` with its first point repeated at the end (a closed line)."""
    return np.vstack([curve, curve[:1]])


def _draw_section(ax, curve, color, label, load, limit) -> None:
    """A closed, shaded section ``curve`` ``(n, 2)``, the load in it (``None``: no load) and
    the point where the load's ray leaves it (``None``: not drawn)."""
    closed = _closed(curve)
    ax.fill(*closed.T, color=color, alpha=0.12)
    ax.plot(*closed.T, color=color, linewidth=1.5, label=label)
    if load is None:
        return
    if limit is not None:
        ax.plot([0.0, limit[0]], [0.0, limit[1]], color="0.5", linewidth=0.8, linestyle="--")
        ax.plot(*limit, marker="x", color="tab:red", markersize=8, linestyle="none",
                label=r"load $\times$ safety factor")  # fmt: skip
    ax.plot(*load, marker="o", color="black", linestyle="none", label="load")


# -- pushing trajectories -----------------------------------------------------------------------

#: Colour of each contact mode in :func:`trajectory_figure` and :func:`save_gif`.
MODE_COLORS = {
    "sticking": "tab:green",
    "sliding-left": "tab:orange",
    "sliding-right": "tab:purple",
    "separated": "tab:gray",
}
#: Largest number of frames of :func:`save_gif` (longer trajectories are sampled evenly).
GIF_MAX_FRAMES = 40


@dataclass(frozen=True, slots=True)
class _Scene:
    """What a trajectory figure draws, in the world frame [mm]."""

    outlines: tuple[np.ndarray, ...]  # (k, 2) closed outline per drawn pose
    origins: np.ndarray  # (n + 1, 2) path of the part frame's origin
    pusher_path: np.ndarray  # (n + 1, 2)
    pushers: tuple[np.ndarray, ...]  # (k, 2) outline of the pusher per drawn pose
    contacts: np.ndarray  # (n, 2) contact points (NaN: none)
    modes: tuple[str, ...]
    indices: np.ndarray  # the drawn samples


def _world_outline(shape, pose: np.ndarray) -> np.ndarray:
    """Closed outline ``(k, 2)`` of ``shape`` at ``pose`` [m]; a disk gets a radius line so that
    its turning shows."""
    if len(shape.vertices):
        local = np.vstack([shape.vertices, shape.vertices[:1]])
    else:
        angles = np.linspace(0.0, 2.0 * np.pi, 73)
        circle = shape.radius * np.column_stack([np.cos(angles), np.sin(angles)])
        local = np.vstack([[0.0, 0.0], circle])
    c, s = np.cos(pose[2]), np.sin(pose[2])
    return local @ np.array([[c, s], [-s, c]]) + pose[:2]


def _pusher_outline(pusher, position: np.ndarray) -> np.ndarray:
    """The pusher's drawn shape at ``position`` [m]: a circle (a point for radius 0) or its face."""
    if hasattr(pusher, "width"):
        face = np.array([-pusher.normal[1], pusher.normal[0]]) * pusher.width / 2
        return np.vstack([position - face, position + face])
    angles = np.linspace(0.0, 2.0 * np.pi, 37)
    return position + pusher.radius * np.column_stack([np.cos(angles), np.sin(angles)])


def _scene(trajectory, frames: int) -> _Scene:
    poses = np.asarray(trajectory.poses)
    indices = np.unique(np.linspace(0, len(poses) - 1, max(2, frames)).round().astype(int))
    mm = 1e3
    positions = np.asarray(trajectory.pusher_positions)
    return _Scene(
        outlines=tuple(mm * _world_outline(trajectory.shape, poses[k]) for k in indices),
        origins=mm * poses[:, :2],
        pusher_path=mm * positions,
        pushers=tuple(mm * _pusher_outline(trajectory.pusher, positions[k]) for k in indices),
        contacts=mm * np.asarray(trajectory.contact_points),
        modes=tuple(trajectory.modes),
        indices=indices,
    )


def _scene_axes(ax, scene: _Scene) -> None:
    points = np.vstack([*scene.outlines, *scene.pushers, scene.pusher_path])
    low, high = points.min(axis=0), points.max(axis=0)
    margin = 0.05 * float(max(high - low)) + 1e-9
    ax.set_xlim(low[0] - margin, high[0] + margin)
    ax.set_ylim(low[1] - margin, high[1] + margin)
    ax.set_aspect("equal")
    ax.set_xlabel("x [mm]")
    ax.set_ylabel("y [mm]")


def trajectory_figure(trajectory, *, frames: int = 8, ax: Axes | None = None) -> Figure:
    """A pushed part's trajectory (:func:`fixplan.motion.push`) in the world plane [mm].

    The part's outline at ``frames`` evenly spaced instants (fading from the start to the end,
    the last bold), the path of the part frame's origin, the pusher's path (dashed) and the
    pusher at the same instants, and the contact points coloured by contact mode
    (:data:`MODE_COLORS`).

    Returns
    -------
    Figure
    """
    if frames < 2:
        raise InvalidArgumentError(f"frames must be at least 2, got {frames}")
    scene = _scene(trajectory, frames)
    if ax is None:
        ax = _new_figure((7.0, 5.0)).add_subplot()
    count = len(scene.outlines)
    for k, (outline, pusher) in enumerate(zip(scene.outlines, scene.pushers, strict=True)):
        shade = 0.25 + 0.75 * k / (count - 1)
        last = k == count - 1
        ax.plot(*outline.T, color="tab:blue", alpha=shade, linewidth=2.0 if last else 1.0,
                label="part" if last else None)  # fmt: skip
        ax.plot(*pusher.T, color="black", alpha=shade, linewidth=2.0 if last else 1.0,
                label="pusher" if last else None)  # fmt: skip
    ax.plot(*scene.origins.T, color="tab:blue", linestyle=":", linewidth=1.0,
            label="part frame origin")  # fmt: skip
    ax.plot(*scene.pusher_path.T, color="black", linestyle="--", linewidth=0.8,
            label="pusher path")  # fmt: skip
    modes = np.array(scene.modes)
    for mode, color in MODE_COLORS.items():
        chosen = (modes == mode) & np.all(np.isfinite(scene.contacts), axis=1)
        if chosen.any():
            ax.scatter(*scene.contacts[chosen].T, s=6, color=color, label=mode, zorder=3)
    _scene_axes(ax, scene)
    ax.legend(loc="best", fontsize=8)
    ax.set_title(f"pushed part over {trajectory.t[-1]:.3g} s", fontsize=11)
    return ax.figure


def save_gif(trajectory, path: str | os.PathLike[str], *, fps: int = 10) -> None:
    """Write an animated GIF of a pushed part (matplotlib's Pillow writer): the part and the
    pusher at up to :data:`GIF_MAX_FRAMES` evenly spaced instants, the part's outline coloured
    by the contact mode of the step it is in."""
    from matplotlib.animation import PillowWriter

    scene = _scene(trajectory, GIF_MAX_FRAMES)
    fig = _new_figure((6.0, 4.5))
    ax = fig.add_subplot()
    _scene_axes(ax, scene)
    ax.plot(*scene.pusher_path.T, color="black", linestyle="--", linewidth=0.8)
    (part,) = ax.plot([], [], linewidth=2.0)
    (pusher,) = ax.plot([], [], color="black", linewidth=2.0)
    (trace,) = ax.plot([], [], color="tab:blue", linestyle=":", linewidth=1.0)
    title = ax.set_title("t = 0 s, separated", fontsize=10)
    fig.canvas.draw()
    fig.set_layout_engine("none")  # laid out once: every frame has the same axes

    writer = PillowWriter(fps=fps)
    with writer.saving(fig, os.fspath(path), dpi=DPI):
        for frame, k in enumerate(scene.indices):
            mode = scene.modes[min(k, len(scene.modes) - 1)] if scene.modes else "separated"
            part.set_data(*scene.outlines[frame].T)
            part.set_color(MODE_COLORS[mode])
            pusher.set_data(*scene.pushers[frame].T)
            trace.set_data(*scene.origins[: k + 1].T)
            title.set_text(f"t = {trajectory.t[k]:.3g} s, {mode}")
            writer.grab_frame()
