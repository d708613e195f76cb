r"""Compliant grasps and fixtures: each contact's wrench, safety factor and slip under a load
(paper §4.4; Kao & Cutkosky 1992).

The rigid analysis of :mod:`fixplan.planner` asks whether *some* admissible set of reactions
holds a load. Here the contacts are linear springs in their own frames ``(t1, t2, n)``
(:class:`Stiffness`) and the body is rigid, so the reactions are determinate and every contact is
checked against its own friction model.

Model
-----
The body's small displacement ``δ = (u, θ)`` [m, rad] is taken about its centre of mass. A
contact ``i`` with wrench basis ``B_i`` (``(6, 4)``, :meth:`Contact.wrench_basis` moved to the
centre of mass) sees the displacement ``B_iᵀ δ`` of its variables ``(fn, ft1, ft2, mn)``: the gap
opening along its normal, the tangential slips and the twist about the normal. Its springs give

.. math:: f_i = r_i - k_i \odot B_i^T δ, \qquad k_i = (k_n, k_t, k_t, k_r),

about a reference force ``r_i``, except that the contact is **unilateral**: a contact whose
normal force would become negative lifts off and carries nothing (its tangential and torsional
springs are dropped with it). The tangential and torsional springs model friction as sticking;
whether each contact's friction can sustain its force is then checked against its own friction
model. Frictionless contacts (``mu = 0``) and contacts that bear no torsion carry no tangential
force or no moment.

Loading happens in two steps.

1. **Clamping.** The clamps and fingers push with their preloads (given forces, normal only);
   the locators and supports are springs that start just touching. How friction builds up while
   the part is clamped depends on the clamping sequence, which the problem does not give; two
   models are offered (``seating``):

   - ``"seated"`` (the default): the part seats on its locators, as when it is tapped or
     vibrated into place, so their friction springs start unloaded: the locators' normal springs
     alone balance the preloads and the weight (an exact frictionless equilibrium), and the
     friction springs of every contact start from that state. Where no such equilibrium exists
     (a grasp that holds the weight by friction, a part that would slide off) the ``"stuck"``
     model is used for that case, and ``seated[case]`` is false.
   - ``"stuck"``: every spring starts just touching and the locators' friction springs take
     their share of the preloads and the weight, as if the part were clamped with no slip at
     all (where the springs cannot carry the weight, as in a grasp without supports whose
     preloads balance each other, the weight is applied in the next step). A contact whose
     share exceeds its friction slides (one increment of the load ramp below), and is then at
     its limit: the first slip is at 0.
2. **Task.** Every contact becomes a spring about its clamped state, except that a clamp's
   normal force stays at its preload (a force-controlled clamp, as in the planner; its friction
   is still a sticking spring) while a finger's normal spring acts about its preload. Gravity
   (which a seated part already carries) plus ``λ`` times the task load are applied and ``λ`` rises from 0 (:mod:`fixplan.motion.
   load_ramp`): exactly up to the first contact that slips, then in increments in which sliding
   contacts carry their limit load, up to the multiple at which the part as a whole moves.

Each step is the minimum of the complementary energy of the springs, a convex program solved by
:mod:`fixplan.motion.contact_springs`; elastic steps are then polished to be exact.

An ``exact`` friction model is stated in a step by the ellipsoid that osculates its exact set
where the step's friction load meets it, moved until the step is the exact set's (see
:class:`~fixplan.motion.contact_springs.ContactQP`). One on point supports, where no ellipsoid
osculates at the facets, is stated exactly by a cone per point. Other sets with facets (point
supports beside a patch, or more than ``MAX_STATED_POINTS`` of them) are stated by their seed
polytopes (24 tangent planes, which hold the exact set): their sliding friction can lie outside
the exact set, and a warning says so.
"""

from __future__ import annotations

import warnings
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from fixplan import validation
from fixplan.errors import InvalidArgumentError
from fixplan.models import Exact
from fixplan.models.exact import MAX_STATED_POINTS
from fixplan.motion.contact_springs import (
    ComplianceError,
    ContactQP,
    InaccurateStepError,
    NoEquilibriumError,
    SpringSystem,
    WrongContactSetError,
)
from fixplan.motion.load_ramp import LoadRamp, State
from fixplan.planner.contact_models import contact_models
from fixplan.planner.osculating_contact import osculates
from fixplan.planner.plan import Plan
from fixplan.planner.problem import PASSIVE_ROLES, Contact, Problem
from fixplan.tolerances import MAX_SAFETY_FACTOR

#: Increments from the first slip to the task load (see :mod:`fixplan.motion.load_ramp`).
DEFAULT_STEPS = 20

#: A contact whose safety factor is below ``1 + SLIDING_RTOL`` slides.
SLIDING_RTOL = 1e-6

#: How friction builds up during clamping (see the module doc).
SEATINGS = ("seated", "stuck")


@dataclass(frozen=True, slots=True, kw_only=True)
class Stiffness:
    """Linear stiffness of one contact, in its frame.

    Attributes
    ----------
    normal : float
        Along the normal [N/m], > 0.
    tangential : float
        Along each tangent (isotropic) [N/m], >= 0; 0 lets the contact slide freely.
    torsional : float or None
        About the normal [N m/rad], >= 0; ``None`` (or 0) for a contact that carries no moment.
    """

    normal: float
    tangential: float
    torsional: float | None = None

    def __post_init__(self):
        try:
            normal = validation.positive_scalar("stiffness.normal", self.normal)
            tangential = validation.nonnegative_scalar("stiffness.tangential", self.tangential)
            torsional = (
                None
                if self.torsional is None
                else validation.nonnegative_scalar("stiffness.torsional", self.torsional)
            )
        except InvalidArgumentError as exc:
            raise ComplianceError(f"{exc} [N/m, N/m, N m/rad]") from None
        object.__setattr__(self, "normal", normal)
        object.__setattr__(self, "tangential", tangential)
        object.__setattr__(self, "torsional", torsional)


@dataclass(frozen=True, slots=True, kw_only=True)
class ComplianceResult:
    """The compliant analysis of a problem, per load case name (and contact name).

    The state of a case is taken at its task load, or at ``collapse[case]`` times it when the
    part moves before (``held[case]`` is then false).

    Attributes
    ----------
    wrenches : dict
        ``wrenches[case][contact]``: ``(fn, ft1, ft2, mn)`` [N, N, N, N m] in the contact's frame
        (the contact's wrench on the body).
    safety_factors : dict
        ``safety_factors[case][contact]``: the factor by which the contact's friction load
        ``(ft1, ft2, mn)`` could grow at its normal force before it reaches the contact's own
        friction set (1 for a sliding contact; ``inf`` for one that carries no friction load or
        lifts off).
    slip_directions : dict
        ``slip_directions[case][contact]``: unit twist ``(vx, vy, w)`` in the contact's patch
        frame in which the body slides (or would start to) over the contact, by normality on the
        contact's friction model at the load it resists; NaN where the model has no motion map
        (cones, pyramids), for a lifted contact and for a zero friction load.
    displacement : dict
        ``displacement[case]``: ``(ux, uy, uz, θx, θy, θz)`` [m, rad] of the body about its
        centre of mass, from the just-touching position (clamping included). Directions in which
        no spring holds the body (a singular stiffness) get 0.
    clamped_displacement : dict
        Per case: the same after clamping, before the task load (and before gravity where the
        clamped springs could not carry it).
    seated : dict
        Per case: whether the part was seated (``seating="seated"`` and a frictionless
        equilibrium of the clamping exists) rather than clamped stuck.
    lifted, sliding : dict
        Per case: names of the contacts that carry no force, and of those that slide.
    first_slip : dict
        Per case: the smallest multiple of the task load (gravity kept) at which some contact's
        wrench reaches its friction set (0 if one is there without the task load; ``inf`` if
        none is up to ``max_multiple``), or at which the body leaves its contacts or moves where
        no spring holds it (a moment about a grasp axis without torsional springs: at once).
    first_slip_contact : dict
        Per case: the contact that slips first (``None`` when ``first_slip`` is infinite or the
        body lifts off).
    collapse : dict
        Per case: the multiple of the task load at which the part as a whole moves (its
        contacts can no longer balance the load); ``inf`` if it does not up to ``max_multiple``;
        NaN if the increments did not bracket it within their budget (the friction bounds'
        fixed point failing along a stretch of the path; see :mod:`fixplan.motion.load_ramp`).
    held : dict
        Per case: whether the part stays put under the task load (``collapse >= 1``, or the task
        load was reached when ``collapse`` is NaN).
    """

    load_names: tuple[str, ...]
    contact_names: tuple[str, ...]
    wrenches: dict
    safety_factors: dict
    slip_directions: dict
    displacement: dict
    clamped_displacement: dict
    seated: dict
    lifted: dict
    sliding: dict
    first_slip: dict
    first_slip_contact: dict
    collapse: dict
    held: dict


def analyse(
    problem: Problem,
    forces: Plan | Mapping[str, object] | None,
    *,
    stiffness: Stiffness | Mapping[str, Stiffness],
    steps: int = DEFAULT_STEPS,
    max_multiple: float = MAX_SAFETY_FACTOR,
    seating: str = "seated",
) -> ComplianceResult:
    """Analyse every load case of ``problem`` with compliant contacts (see the module doc).

    Parameters
    ----------
    problem : Problem
        Body, contacts and load cases.
    forces : Plan or mapping or None
        Preloads of the clamps and fingers [N]: a plan's ``forces``, or a mapping from contact
        name to a force (a clamp) or to forces per load case (a finger); ``None`` or a missing
        name takes the contact's own ``force``.
    stiffness : Stiffness or mapping
        One stiffness for every contact, or one per contact name.
    steps : int, keyword-only
        Load increments from the first slip to the task load (finer follows the sliding
        contacts' path more closely; see :mod:`fixplan.motion.load_ramp`).
    max_multiple : float, keyword-only
        Largest multiple of the task load searched for the first slip and the collapse.
    seating : {"seated", "stuck"}, keyword-only
        How friction builds up during clamping (see the module doc).

    Raises
    ------
    ComplianceError
        A contact lacks a preload or stiffness, or the springs cannot balance the clamping or
        the weight (the preloads push the body off its supports).
    """
    contacts = problem.contacts
    names = tuple(c.name for c in contacts)
    springs = np.array(
        [_spring(c, s) for c, s in zip(contacts, _stiffnesses(contacts, stiffness), strict=True)]
    )
    steps = validation.positive_int("steps", steps)
    limit = validation.positive_scalar("max_multiple", max_multiple)
    if seating not in SEATINGS:
        raise ComplianceError(f"seating must be one of {', '.join(SEATINGS)}, got {seating!r}")
    centre = problem.body.center_of_mass
    bases = np.stack([_about(c.wrench_basis(), centre) for c in contacts])
    passive = np.array([c.role in PASSIVE_ROLES for c in contacts])
    clamp = np.array([c.role == "clamp" for c in contacts])
    gravity = _about(problem.body.weight_wrench[:, None], centre)[:, 0]
    tasks = list(_about(problem.task_wrenches(), centre).T)
    preloads = [_preloads(problem, forces, index) for index in range(len(problem.loads))]
    models = contact_models(contacts)
    _warn_of_exact_models(names, models)
    scale = max(np.abs(np.r_[gravity[:3], np.ravel(preloads), np.ravel(tasks)]).max(), 1.0)
    # Clamping: the active contacts push with their preloads (an external wrench) and carry
    # nothing else. Task: a clamp's normal force stays at its preload (force-controlled).
    clamping = _system(bases, np.where(passive[:, None], springs, 0.0), models, scale)
    seat = None
    if seating == "seated":  # the locators' normal springs only: friction held at 0
        seat = _system(
            bases, np.where(passive[:, None] & (np.arange(4) == 0), springs, 0.0), models, scale
        )
    loading = _system(
        bases, np.where(clamp[:, None] & (np.arange(4) == 0), 0.0, springs), models, scale
    )
    fields = {key: {} for key in ComplianceResult.__slots__[2:]}
    for load, task, preload in zip(problem.loads, tasks, preloads, strict=True):
        case = load.name
        pushed = preload @ bases[:, :, 0]
        seated = None if seat is None else _seated(seat, pushed + gravity, case)
        clamped, delta0 = seated or _clamp(clamping, pushed, gravity, models, case)
        fields["seated"][case] = seated is not None
        # Every contact becomes a spring about its clamped state; a passive contact that lifted
        # off during clamping keeps its open gap as a negative reference normal force.
        reference = clamped.copy()
        reference[~passive, 0] = preload[~passive]
        gaps = np.einsum("kc,k->c", bases[:, :, 0].T, delta0)
        reference[passive, 0] = -springs[passive, 0] * gaps[passive]
        ramp = LoadRamp(loading, reference, gravity, task, models, case)
        state, collapse, first, who = _task_state(ramp, steps, limit)
        fields["first_slip"][case] = first
        fields["first_slip_contact"][case] = None if who is None else names[who]
        fields["collapse"][case] = collapse
        fields["held"][case] = bool(collapse >= 1.0 or (np.isnan(collapse) and state.multiple >= 1))
        _record(fields, case, names, contacts, models, state, delta0)
    return ComplianceResult(
        load_names=tuple(load.name for load in problem.loads), contact_names=names, **fields
    )


def _warn_of_exact_models(names, models) -> None:
    """Warn where contacts with friction have exact models with facets that the steps state
    by their seed polytopes (see the module doc)."""
    exact = [(n, m) for n, m in zip(names, models, strict=True)
             if isinstance(m, Exact) and not osculates(m) and not m.stated_exactly]  # fmt: skip
    if exact:
        gap = max(m.constraint_error for _, m in exact)
        warnings.warn(
            f"compliant analysis: the exact friction models of {', '.join(n for n, _ in exact)} "
            f"have facets (point supports beside a patch, or more than {MAX_STATED_POINTS} of "
            f"them) and are stated by their seed polytopes, up to "
            f"{gap:.1%} outside the exact sets: the first slip is exact, but a sliding "
            "contact's friction can exceed its exact set and the collapse come out too large",
            stacklevel=3,
        )


def _system(bases, springs, models, scale) -> SpringSystem:
    return SpringSystem(
        bases=bases, springs=springs, qp=ContactQP(bases, springs, models, scale=scale)
    )


def _seated(seat: SpringSystem, wrench, case) -> tuple[np.ndarray, np.ndarray] | None:
    """Contact forces ``(m, 4)`` and displacement ``(6,)`` of the frictionless equilibrium of
    the clamping and the weight on the locators' normal springs (exact), or ``None`` if there is
    none."""
    try:
        forces, delta = seat.solve(np.zeros_like(seat.springs), wrench, case)[:2]
    except (NoEquilibriumError, WrongContactSetError, InaccurateStepError):
        return None
    return forces, delta


def _clamp(clamping: SpringSystem, pushed, gravity, models, case) -> tuple[np.ndarray, ...]:
    """Contact forces ``(m, 4)`` and displacement ``(6,)`` after stuck clamping, with the weight
    where the springs can carry it (else without: a grasp without supports, whose preloads
    balance each other): elastic and exact, or, where no state with every contact sticking
    exists, one increment with sliding contacts."""
    try:
        return _stuck(clamping, pushed + gravity, models, case)
    except (NoEquilibriumError, InaccurateStepError):  # (Clarabel fails where no spring acts)
        pass
    try:
        return _stuck(clamping, pushed, models, case)
    except NoEquilibriumError:
        raise NoEquilibriumError(
            f"load case {case!r}: the supports and locators cannot balance the clamp and finger "
            "preloads (with or without the weight) with their normal forces pressing: the "
            "preloads push the part off them while it is clamped"
        ) from None


def _stuck(clamping: SpringSystem, wrench, models, case) -> tuple[np.ndarray, np.ndarray]:
    try:
        return clamping.solve(np.zeros_like(clamping.springs), wrench, case)[:2]
    except WrongContactSetError:
        zero = np.zeros(6)
        ramp = LoadRamp(clamping, np.zeros_like(clamping.springs), wrench, zero, models, case)
        reached = ramp.increment(ramp.origin(), 0.0)
        return reached.forces, reached.delta


def _task_state(ramp: LoadRamp, steps, limit) -> tuple[State, float, float, int | None]:
    """The state at the task load (or where the body moves, if before), the collapse multiple,
    the first-slip multiple and the contact that slips first."""
    first, who, reached = ramp.first_slip(limit)
    if who is None:  # elastic up to the limit, or until the body leaves its contacts
        return (ramp.at(1.0)[0] if first >= 1.0 else reached), first, first, None
    collapse, last, at_task = ramp.follow(reached, steps, limit)
    if first >= 1.0:
        return ramp.at(1.0)[0], collapse, first, who
    return (last if at_task is None else at_task), collapse, first, who


def _record(fields, case, names, contacts, models, state: State, delta0) -> None:
    """Store the contact wrenches, their friction and the displacement of one case."""
    wrench = state.forces
    fields["wrenches"][case] = {n: tuple(map(float, w)) for n, w in zip(names, wrench, strict=True)}
    safety, slips = _friction(contacts, models, wrench)
    fields["safety_factors"][case], fields["slip_directions"][case] = safety, slips
    fields["displacement"][case] = _frozen(delta0 + state.delta)
    fields["clamped_displacement"][case] = _frozen(delta0)
    fields["lifted"][case] = tuple(n for n, w in zip(names, wrench, strict=True) if w[0] <= 0.0)
    fields["sliding"][case] = tuple(n for n in names if safety[n] < 1.0 + SLIDING_RTOL)


def _frozen(array: np.ndarray) -> np.ndarray:
    array = np.array(array, dtype=float)
    array.setflags(write=False)
    return array


def _about(columns: np.ndarray, centre: np.ndarray) -> np.ndarray:
    """Wrenches ``(6, k)`` about the world origin moved to ``centre``: ``m - c × f``."""
    moved = columns.copy()
    moved[3:] -= np.cross(centre, columns[:3].T).T
    return moved


def _stiffnesses(contacts, stiffness) -> list[Stiffness]:
    if isinstance(stiffness, Stiffness):
        return [stiffness] * len(contacts)
    if not isinstance(stiffness, Mapping):
        raise ComplianceError(
            f"stiffness must be a Stiffness or a mapping by contact name, got {stiffness!r}"
        )
    names = {c.name for c in contacts}
    unknown = sorted(set(stiffness) - names)
    if unknown:
        raise ComplianceError(f"stiffness names contacts that do not exist: {', '.join(unknown)}")
    missing = [c.name for c in contacts if c.name not in stiffness]
    if missing:
        raise ComplianceError(f"stiffness is missing for contact(s) {', '.join(missing)}")
    for name, value in stiffness.items():
        if not isinstance(value, Stiffness):
            raise ComplianceError(f"stiffness[{name!r}] must be a Stiffness, got {value!r}")
    return [stiffness[c.name] for c in contacts]


def _spring(contact: Contact, stiffness: Stiffness) -> np.ndarray:
    """Spring constants ``(k_n, k_t, k_t, k_r)``; 0 for what the contact cannot carry."""
    tangential = stiffness.tangential if contact.mu > 0.0 else 0.0
    torsional = stiffness.torsional if contact.has_torsion and contact.mu > 0.0 else None
    return np.array([stiffness.normal, tangential, tangential, torsional or 0.0])


def _preloads(problem: Problem, forces, case: int) -> np.ndarray:
    """Normal preload [N] of every contact in load case ``case`` (0 for passive contacts)."""
    given = forces.forces if isinstance(forces, Plan) else ({} if forces is None else forces)
    if not isinstance(given, Mapping):
        raise ComplianceError(f"forces must be a Plan or a mapping by contact name, got {forces!r}")
    names = {c.name for c in problem.contacts if c.is_active}
    unknown = sorted(set(given) - names)
    if unknown:
        raise ComplianceError(f"forces name no clamp or finger: {', '.join(unknown)}")
    loads = len(problem.loads)
    values = np.zeros(len(problem.contacts))
    for i, contact in enumerate(problem.contacts):
        if not contact.is_active:
            continue
        value = given.get(contact.name, contact.force)
        if value is None:
            raise ComplianceError(
                f"contact {contact.name!r} ({contact.role}) has no preload: give it in forces "
                "or as the contact's force"
            )
        if np.ndim(value) == 1 and len(value) == loads:
            value = value[case]
        try:
            values[i] = validation.nonnegative_scalar(f"forces[{contact.name!r}]", value)
        except InvalidArgumentError as exc:
            raise ComplianceError(f"{exc} (a force [N], or one per load case)") from None
    return values


def _friction(contacts, models, wrench):
    """Safety factor and slip twist of every contact's friction load."""
    safety, slips = {}, {}
    for contact, model, (fn, *load) in zip(contacts, models, wrench, strict=True):
        friction = np.array(load if model.torsion else load[:2])
        if fn <= 0.0 or not friction.any():
            safety[contact.name] = np.inf
            slips[contact.name] = _frozen(np.full(3, np.nan))
            continue
        safety[contact.name] = float(model.safety_factor(friction, normal_force=fn))
        twist = np.full(3, np.nan)
        if model.has_motion and not model.frictionless:
            # The body slides along the load that friction resists: minus the friction force.
            twist[: model.load_dimension] = model.motion(-friction, normal_force=fn)[
                : model.load_dimension
            ]
            if not model.torsion:
                twist[2] = 0.0
        slips[contact.name] = _frozen(twist)
    return safety, slips
