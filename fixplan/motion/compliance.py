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
   the locators and supports are springs that start just touching. Their reactions balance the
   preloads (gravity is not part of this step, so that a grasp without supports, whose preloads
   balance each other, is well posed).
2. **Task.** Every contact becomes a spring about its clamped state, except that a clamp's
   normal force stays at its preload (a force-controlled clamp, as in the planner; its friction
   is still a sticking spring) while a finger's normal spring acts about its preload. Gravity
   plus ``λ`` times the task load are applied; ``λ = 1`` is the load case.

Each step is the minimum of the complementary energy, a convex quadratic program solved exactly
(Clarabel through cvxpy), whose multipliers of equilibrium are the displacement:

.. math:: \min_f \sum_i \tfrac12 (f_i - r_i)^T k_i^{-1} (f_i - r_i)
    \quad \text{s.t.} \quad \sum_i B_i f_i + W = 0,\; f_{n,i} \ge 0.

Its KKT conditions are the spring law above with ``f_n = max(0, r_n - k_n g)``. The solution is
polished on its set of contacts that touch: with that set fixed the problem is linear,
``K δ = Σ B_i r_i + W`` with ``K = Σ B_i diag(k_i) B_iᵀ``, and the polished answer is accepted
only if it satisfies the conditions of the QP (nonnegative normal forces, lifted contacts with
open gaps) to :data:`KKT_RTOL`. Dropping the tangential springs of lifted contacts is repeated
until the set of lifted contacts no longer changes.

Not modelled yet: sliding contacts carrying their limit load while the load keeps rising (the
multiple at which the part as a whole moves, ``collapse``).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np
from scipy.optimize import brentq

from fixplan import validation
from fixplan.errors import ConvergenceError, InvalidArgumentError
from fixplan.planner.contact_models import contact_model
from fixplan.planner.plan import Plan
from fixplan.planner.problem import PASSIVE_ROLES, Contact, Problem
from fixplan.tolerances import MAX_SAFETY_FACTOR

#: A polished solution is accepted when its equilibrium residual, negative normal forces and
#: closed gaps of lifted contacts are below this fraction of the largest force of the step.
KKT_RTOL = 1e-7

#: A normal force below this fraction of the step's largest force counts as lifted off.
LIFT_RTOL = 1e-7

#: Most re-solves while dropping the tangential springs of lifted contacts, per contact.
MAX_LIFT_ROUNDS_PER_CONTACT = 2

#: The first-slip multiple is located to this relative accuracy.
SLIP_RTOL = 1e-10


class ComplianceError(InvalidArgumentError):
    """The contact springs cannot hold a load, or the compliance inputs are invalid."""


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

    Attributes
    ----------
    wrenches : dict
        ``wrenches[case][contact]``: ``(fn, ft1, ft2, mn)`` [N, N, N, N m] at the task load, in
        the contact's frame (the contact's wrench on the body).
    safety_factors : dict
        ``safety_factors[case][contact]``: the factor by which the contact's friction load
        ``(ft1, ft2, mn)`` could grow at its normal force before it reaches the contact's own
        friction set (``inf`` for a contact that carries no friction load or lifts off).
    slip_directions : dict
        ``slip_directions[case][contact]``: unit twist ``(vx, vy, w)`` in the contact's patch
        frame in which the body would start to slide over the contact, by normality on the
        contact's friction model at the load it resists; NaN where the model has no motion map
        (cones, pyramids), for a lifted contact and for a zero friction load.
    displacement : dict
        ``displacement[case]``: ``(ux, uy, uz, θx, θy, θz)`` [m, rad] of the body about its
        centre of mass at the task load, from the just-touching position (clamping included).
        Directions in which no spring holds the body (a singular stiffness) get 0.
    clamped_displacement : dict
        Per case: the same after clamping, before gravity and the task load.
    lifted : dict
        Per case: names of the contacts that carry no force at the task load.
    first_slip : dict
        Per case: the smallest multiple of the task load (gravity kept) at which some contact's
        wrench reaches its friction set (0 if one is there without the task load; ``inf`` if
        none is up to ``max_multiple``), or at which the body leaves all its contacts.
    first_slip_contact : dict
        Per case: the contact that slips first (``None`` when ``first_slip`` is infinite or the
        body lifts off).
    """

    load_names: tuple[str, ...]
    contact_names: tuple[str, ...]
    wrenches: dict
    safety_factors: dict
    slip_directions: dict
    displacement: dict
    clamped_displacement: dict
    lifted: dict
    first_slip: dict
    first_slip_contact: dict


def analyse(
    problem: Problem,
    forces: Plan | Mapping[str, object] | None,
    *,
    stiffness: Stiffness | Mapping[str, Stiffness],
    max_multiple: float = MAX_SAFETY_FACTOR,
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
    max_multiple : float, keyword-only
        Largest multiple of the task load searched for the first slip.

    Raises
    ------
    ComplianceError
        A contact lacks a preload or stiffness, or the springs cannot balance a load case (the
        preloads push the body off its supports, or the load pulls it off every contact).
    """
    contacts = problem.contacts
    names = tuple(c.name for c in contacts)
    stiffnesses = _stiffnesses(contacts, stiffness)
    springs = np.array([_spring(c, s) for c, s in zip(contacts, stiffnesses, strict=True)])
    centre = problem.body.center_of_mass
    bases = np.stack([_about(c.wrench_basis(), centre) for c in contacts])
    passive = np.array([c.role in PASSIVE_ROLES for c in contacts])
    gravity = _about(problem.body.weight_wrench[:, None], centre)[:, 0]
    models = [contact_model(c) for c in contacts]
    limit = validation.positive_scalar("max_multiple", max_multiple)
    fields = {key: {} for key in ComplianceResult.__slots__[2:]}
    for index, load in enumerate(problem.loads):
        preloads = _preloads(problem, forces, index)
        system = _System(bases=bases, springs=springs, names=names)
        # Clamps hold their force (force-controlled); fingers are springs about their preload.
        locked = springs.copy()
        locked[[c.role == "clamp" for c in contacts], 0] = 0.0
        clamping = preloads @ bases[:, :, 0]
        clamped, delta0, *_ = system.solve(
            reference=np.zeros_like(springs), wrench=clamping, use=passive, case=load.name
        )
        # Every contact becomes a spring about its clamped state; a passive contact that lifted
        # off during clamping keeps its open gap as a negative reference normal force.
        reference = clamped.copy()
        reference[~passive, 0] = preloads[~passive]
        gaps = np.einsum("kc,k->c", bases[:, :, 0].T, delta0)
        reference[passive, 0] = -springs[passive, 0] * gaps[passive]
        task = _about(load.wrench[:, None], centre)[:, 0]
        ramp = _Ramp(
            _System(bases=bases, springs=locked, names=names), reference, gravity, task, load.name
        )
        wrench, delta, *_ = ramp.at(1.0)
        case = load.name
        fields["wrenches"][case] = {
            n: tuple(map(float, w)) for n, w in zip(names, wrench, strict=True)
        }
        fields["safety_factors"][case], fields["slip_directions"][case] = _friction(
            contacts, models, wrench
        )
        fields["displacement"][case] = _frozen(delta0 + delta)
        fields["clamped_displacement"][case] = _frozen(delta0)
        fields["lifted"][case] = tuple(n for n, w in zip(names, wrench, strict=True) if w[0] == 0.0)
        multiple, who = ramp.first_slip(models, limit)
        fields["first_slip"][case] = multiple
        fields["first_slip_contact"][case] = None if who is None else names[who]
    return ComplianceResult(
        load_names=tuple(load.name for load in problem.loads), contact_names=names, **fields
    )


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


@dataclass(frozen=True, slots=True, kw_only=True)
class _System:
    """The contact springs of one body: bases ``(m, 6, 4)`` about the centre of mass and spring
    constants ``(m, 4)``."""

    bases: np.ndarray
    springs: np.ndarray
    names: tuple[str, ...]

    def solve(self, *, reference, wrench, use, case) -> tuple[np.ndarray, ...]:
        """Contact forces ``(m, 4)``, displacement ``(6,)``, which contacts touch, and the
        springs and reference forces in effect ``(m, 4)``, for the springs ``use`` about ``reference`` under the
        external ``wrench``; exact (QP, then polished)."""
        dropped = ~use
        for _ in range(MAX_LIFT_ROUNDS_PER_CONTACT * len(self.names) + 1):
            springs = self.springs.copy()
            springs[dropped, 1:] = 0.0
            springs[~use] = 0.0
            # Lifted contacts carry no tangential force; unused ones carry nothing.
            effective = reference.copy()
            effective[dropped, 1:] = 0.0
            effective[~use] = 0.0
            touching = self._touching(effective, springs, wrench, case)
            forces, delta = self._polish(effective, springs, wrench, touching, case)
            lifted = ~touching
            if np.array_equal(lifted | ~use, dropped):
                return forces, delta, touching, springs, effective
            dropped = lifted | ~use
        raise ConvergenceError(
            f"load case {case!r}: the set of lifted contacts keeps changing when their "
            "tangential springs are dropped; the sticking-spring model has no consistent state"
        )

    def _touching(self, reference, springs, wrench, case) -> np.ndarray:
        """Which contacts touch at the minimum of the complementary energy (the QP)."""
        import cvxpy as cp

        active = springs > 0.0
        scale = _scale(reference, wrench)
        stiff = springs[active].max() if active.any() else 1.0
        length = max(float(np.abs(self.bases[:, 3:]).max()), 1e-3)
        units = np.ones(4)
        units[3] = length
        forces = cp.Variable((len(self.names), 4))
        weights = np.where(active, stiff / np.where(active, springs, 1.0), 0.0) / units**2
        target = reference / (scale * units)
        cost = cp.sum(cp.multiply(weights, cp.square(forces - target)))
        bases = self.bases * (units / length)[None, None, :]
        balance = sum(bases[i] @ forces[i] for i in range(len(self.names)))
        constraints = [
            balance + wrench / (scale * np.r_[np.ones(3), np.full(3, length)]) == 0,
            forces[:, 0] >= 0,
        ]
        if (~active).any():
            constraints.append(forces[~active] == target[~active])
        program = cp.Problem(cp.Minimize(cost), constraints)
        try:
            program.solve(solver=cp.CLARABEL)
        except cp.SolverError as exc:
            raise ConvergenceError(f"load case {case!r}: Clarabel failed: {exc}") from exc
        if program.status in ("infeasible", "infeasible_inaccurate"):
            raise ComplianceError(
                f"load case {case!r}: no nonnegative contact forces balance the load; the body "
                "leaves its contacts (check the preloads, the load and the contact normals)"
            )
        if program.status != "optimal":
            raise ConvergenceError(f"load case {case!r}: the contact QP ended {program.status!r}")
        normal = forces.value[:, 0] * scale
        return normal > LIFT_RTOL * scale

    def linear(self, reference, springs, wrench, touching):
        """Forces ``(m, 4)``, displacement ``(6,)`` and contact motions ``(m, 4)`` with the set
        of contacts ``touching`` fixed: ``K δ = Σ B_i r_i + W`` (minimum-norm ``δ``)."""
        k = np.where(touching[:, None], springs, 0.0)
        r = np.where(touching[:, None], reference, 0.0)
        stiffness = np.einsum("iap,ip,ibp->ab", self.bases, k, self.bases)
        rhs = np.einsum("iap,ip->a", self.bases, r) + wrench
        delta = np.linalg.lstsq(stiffness, rhs, rcond=None)[0]
        motion = np.einsum("iap,a->ip", self.bases, delta)
        forces = np.where(touching[:, None], r - k * motion, 0.0)
        return forces, delta, motion

    def _polish(self, reference, springs, wrench, touching, case):
        """:meth:`linear`, checked against the QP's optimality conditions."""
        forces, delta, motion = self.linear(reference, springs, wrench, touching)
        scale = _scale(reference, wrench)
        residual = np.einsum("iap,ip->a", self.bases, forces) + wrench
        would_be = reference[:, 0] - springs[:, 0] * motion[:, 0]
        worst = max(
            float(np.abs(residual[:3]).max()),
            float(np.abs(residual[3:]).max()) / max(float(np.abs(self.bases[:, 3:]).max()), 1e-3),
            float(-forces[touching, 0].min(initial=0.0)),
            float(would_be[~touching & (springs[:, 0] > 0.0)].max(initial=0.0)),
        )
        if worst > KKT_RTOL * scale:
            raise ConvergenceError(
                f"load case {case!r}: the polished contact forces miss the QP's optimality "
                f"conditions by {worst:.3g} N (the springs may leave the body free)"
            )
        return forces, delta


def _scale(reference: np.ndarray, wrench: np.ndarray) -> float:
    """Force scale of a step [N]."""
    return max(
        float(np.abs(reference[:, :3]).max(initial=0.0)), float(np.abs(wrench[:3]).max()), 1.0
    )


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


class _Ramp:
    """Gravity plus ``λ`` times the task load on the clamped springs; the answer is affine in
    ``λ`` while the set of lifted contacts stays the same."""

    def __init__(self, system: _System, reference, gravity, task, case):
        self.system, self.reference = system, reference
        self.gravity, self.task, self.case = gravity, task, case

    def at(self, multiple: float) -> tuple[np.ndarray, ...]:
        """:meth:`_System.solve` at ``multiple`` times the task load."""
        use = np.ones(len(self.system.names), dtype=bool)
        return self.system.solve(
            reference=self.reference,
            wrench=self.gravity + multiple * self.task,
            use=use,
            case=self.case,
        )

    def first_slip(self, models, limit: float) -> tuple[float, int | None]:
        """Smallest multiple in ``[0, limit]`` at which a contact reaches its friction set,
        followed piece by piece (a piece keeps its set of touching contacts)."""
        start = 0.0
        for _ in range(4 * len(models) + 4):
            try:
                forces, _, touching, springs, reference = self.at(start)
            except ComplianceError:
                return start, None
            zero = np.zeros_like(self.reference)
            slope, _, motion = self.system.linear(zero, springs, self.task, touching)
            # The piece ends where a touching contact's normal force falls to 0 or a lifted
            # one's would-be force (its spring law without the gap) rises to 0.
            _, _, motion0 = self.system.linear(reference, springs, self.gravity, touching)
            would_be = reference[:, 0] - self.system.springs[:, 0] * motion0[:, 0]
            would_rate = -self.system.springs[:, 0] * motion[:, 0]
            value = np.where(touching, forces[:, 0], would_be + start * would_rate)
            rate = np.where(touching, -slope[:, 0], would_rate)
            with np.errstate(divide="ignore", invalid="ignore"):
                crossing = np.where(touching, value / rate, -value / rate)
            ahead = (rate > 0.0) & np.isfinite(crossing)
            end = min(limit, start + float(crossing[ahead].min(initial=np.inf)))
            best, who = np.inf, None
            for i, model in enumerate(models):
                if touching[i]:
                    found = _slip_root(model, forces[i], slope[i], start, end)
                    if found is not None and found < best:
                        best, who = found, i
            if who is not None:
                return best, who
            if end >= limit:
                return np.inf, None
            start = end * (1.0 + SLIP_RTOL) + SLIP_RTOL
        raise ConvergenceError(f"load case {self.case!r}: too many changes of the lifted contacts")


def _slip_root(model, forces, slope, start, end) -> float | None:
    """First ``λ`` in ``[start, end]`` where ``gauge(L(λ)) = fn(λ)``: the excess is convex in
    ``λ`` (a gauge of an affine load minus an affine force), so its first root is unique."""

    def excess(multiple):
        fn, *load = forces + (multiple - start) * slope
        friction = np.array(load if model.torsion else load[:2])
        if not friction.any():
            return -fn
        return float(1.0 / model.safety_factor(friction, normal_force=1.0)) - fn

    if excess(start) >= 0.0:
        return start
    if excess(end) <= 0.0:
        return None
    return brentq(excess, start, end, rtol=SLIP_RTOL)
