r"""An independent reference of the planner, written the plain way, to judge fixplan's planner.

Nothing here is shared with ``fixplan/planner/planner.py``: every (contact, load case) gets its
own cvxpy variables and its own friction constraint, every load case its own equilibrium
constraint, built in plain loops (no stacking, no Parameters, no DPP, no re-solves). It is slow
for big problems on purpose; use it on the small problems of the tests.

Conventions (DESIGN.md §2, SI units: N, m, N m). Contact ``i`` pushes the body with
``F = fn n + ft1 t1 + ft2 t2`` at its position ``p`` plus a torsional moment ``mn n``; its
wrench on the body about the world origin is ``(F, p × F + mn n)``. Load case ``j`` (task wrench
``W_j`` about the world origin, :attr:`fixplan.Load.wrench`) is held at multiple ``k`` when

.. math:: \sum_i w_{ij} + k \, W_j + W_g = 0, \qquad (f_{t1}, f_{t2}[, m_n])_{ij} \in
          f_{n,ij} \, \mathcal F_i, \qquad f_{n,ij} \ge 0,

with ``W_g`` the gravity wrench (:attr:`fixplan.Body.weight_wrench`). Normal forces: a passive
contact (locator, support) has a free reaction per case; a clamp has one force for all cases;
a finger a force per case.

Friction sets ``F_i``:

- ``"point-cone"``: Coulomb's cone ``‖(ft1, ft2)‖ <= mu fn``, written here by hand; it does
  not depend on the tangent frame, so the frame is built here too (:func:`tangent_frame`).
  The normal force acts at ``contact.position`` (``wrench_basis`` puts it at the centre of
  pressure of a patch; the two differ only for a point model given an off-centre patch).
- every other model (``"point-pyramid"``, the area models ``"ellipsoid"``, ``"cone"``,
  ``"pyramid"``, ``"exact"`` and model objects): the set is defined in the contact's patch
  frame, so the loads ``(fn, ft1, ft2[, mn])`` are mapped by the columns of
  :meth:`fixplan.Contact.wrench_basis` (normal force at the centre of pressure) and constrained
  by the per-contact API ``contact_model(contact).constraints(load, normal_force)``.

Every problem is solved by Clarabel with ``tol_gap_abs = tol_gap_rel = tol_feas = 1e-10``
(and the infeasibility tolerances of :data:`SOLVER_OPTIONS`).
A solver status other than optimal or infeasible raises :class:`ReferenceSolveError` (with the
status): the reference never hands back a number it does not trust.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Mapping, Sequence

import cvxpy as cp
import numpy as np

from fixplan import Body, Contact, Load, Problem
from fixplan.planner.contact_models import contact_model

#: Clarabel settings of every reference solve: optimality at 1e-10. Infeasibility: Clarabel
#: tests a Farkas certificate ``z`` once ``κ/τ > 1000 / tol_ktratio`` and accepts it when
#: ``b·z < -tol_infeas_abs`` and ``‖Aᵀz‖ / max(1, ‖z‖) < -tol_infeas_rel b·z``. With its
#: defaults (1e-6; 1e-8, 1e-8) problems 1e-8 to 1e-5 (relative) beyond an end of a held
#: interval come back "infeasible_inaccurate" or fail: ``b·z`` is only about 1e-9, ``‖Aᵀz‖``
#: stalls near 1e-15, and ``κ/τ`` can peak below 1e9 and fall back. These settings test the
#: certificate from ``κ/τ > 1e6`` on and accept ``b·z < -1e-12`` with a residual below 1e-6 of
#: it: still a proof of infeasibility with a margin a million times its residual.
SOLVER_OPTIONS = {
    "tol_gap_abs": 1e-10,
    "tol_gap_rel": 1e-10,
    "tol_feas": 1e-10,
    "tol_infeas_abs": 1e-12,
    "tol_infeas_rel": 1e-6,
    "tol_ktratio": 1e-3,
}

#: :func:`feasible` and the largest multiple ask again with these when Clarabel ends
#: "optimal_inaccurate" at ``SOLVER_OPTIONS``: a feasibility problem has no objective to close a
#: gap on, and its residual can stall above 1e-10. On the nose cone 1e-6 inside the low end of
#: its held interval, 4 of 20 solves with the finger forces changed by 1e-9 ended so; with
#: Clarabel's default ``tol_feas`` (1e-8, still 30 times below that margin in force) all 20 were
#: optimal. A largest multiple far above the forces stalls too: a plate of
#: tests/test_squeeze_brute_force.py held to k = 1237 ended so on a Xeon at 2.8 GHz (optimal on
#: others), and optimal at 1e-8 with the same k to 5e-9.
FEASIBLE_RETRY_OPTIONS = {**SOLVER_OPTIONS, "tol_gap_abs": 1e-8, "tol_gap_rel": 1e-8,
                          "tol_feas": 1e-8}  # fmt: skip

#: Default cap on the task-load multiple ``k`` of :func:`held_interval`.
K_MAX = 1e6

PASSIVE = ("locator", "support")
FORCE_OBJECTIVES = (
    "min-total-clamp-force",
    "min-max-normal-force",
    "min-total-normal-force",
    "min-squared-normal-force",
)


class ReferenceSolveError(RuntimeError):
    """Clarabel ended with a status that is neither optimal nor infeasible."""


# ------------------------------------------------------------------------------------------
# One contact in one load case
# ------------------------------------------------------------------------------------------


def tangent_frame(normal: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Unit tangents ``t1, t2`` with ``t1 × t2 = normal`` (for frame-free friction sets).

    Parameters
    ----------
    normal : array (3,)
        Unit normal.

    Returns
    -------
    tuple of numpy.ndarray
        ``t1`` (the world axis least aligned with ``normal``, made orthogonal) and
        ``t2 = normal × t1``.
    """
    n = np.asarray(normal, dtype=float)
    seed = np.zeros(3)
    seed[int(np.argmin(np.abs(n)))] = 1.0
    t1 = np.cross(seed, n)
    t1 /= np.linalg.norm(t1)
    return t1, np.cross(n, t1)


def contact_wrench(contact: Contact, fn) -> tuple[cp.Expression, list]:
    """The body wrench of ``contact`` in one load case and its friction constraint.

    Parameters
    ----------
    contact : fixplan.Contact
        The contact.
    fn : float or cvxpy expression
        Its normal force in this load case [N] (a given number or a scalar variable).

    Returns
    -------
    wrench : cvxpy expression (6,)
        ``(F, p × F + mn n)`` about the world origin [N, N m], affine in new friction variables.
    constraints : list
        The friction constraint(s) of this (contact, case): one second-order cone for
        ``"point-cone"``, the model's own constraints otherwise.
    """
    if contact.model == "point-cone":
        n, p = contact.normal, contact.position
        t1, t2 = tangent_frame(n)
        tangential = cp.Variable(2)
        columns = [np.concatenate([d, np.cross(p, d)]) for d in (n, t1, t2)]
        wrench = fn * columns[0] + tangential[0] * columns[1] + tangential[1] * columns[2]
        return wrench, [cp.norm(tangential, 2) <= contact.mu * fn]
    model = contact_model(contact)
    basis = contact.wrench_basis()
    load = cp.Variable(model.load_dimension)
    wrench = fn * basis[:, 0] + basis[:, 1 : 1 + model.load_dimension] @ load
    return wrench, list(model.constraints(load, fn))


def given_forces(problem: Problem, forces: Mapping | None) -> dict[str, np.ndarray | float]:
    """The given normal force of every active contact: ``forces`` first, then ``contact.force``.

    Raises
    ------
    ValueError
        A name is not an active contact, a value is negative or of the wrong length, or an
        active contact has no force.
    """
    forces = {} if forces is None else dict(forces)
    active = {c.name: c for c in problem.contacts if c.role not in PASSIVE}
    unknown = set(forces) - set(active)
    if unknown:
        raise ValueError(f"not active contacts: {sorted(unknown)}")
    cases = len(problem.loads)
    given = {}
    for name, contact in active.items():
        value = forces.get(name, contact.force)
        if value is None:
            raise ValueError(f"active contact {name!r} has no given force")
        value = np.asarray(value, dtype=float)
        if contact.role == "clamp" and value.size != 1:
            raise ValueError(f"clamp {name!r} takes one force for all load cases")
        if value.size not in (1, cases) or np.any(value < 0) or not np.all(np.isfinite(value)):
            raise ValueError(f"force of {name!r} must be >= 0, one value or one per load case")
        given[name] = float(value.ravel()[0]) if value.size == 1 else value.ravel()
    return given


def _force_in_case(value, case: int) -> float:
    return float(value) if np.ndim(value) == 0 else float(value[case])


def _solve(problem: cp.Problem, *, unbounded: bool = False, options=None) -> str:
    """Solve with Clarabel (``options``, default ``SOLVER_OPTIONS``); ``"optimal"``,
    ``"infeasible"`` or (when allowed) ``"unbounded"``.

    Any other outcome (inaccurate statuses, solver failure) raises :class:`ReferenceSolveError`.
    """
    try:
        with warnings.catch_warnings():  # cvxpy warns of inaccurate statuses; they raise below
            warnings.simplefilter("ignore", UserWarning)
            problem.solve(solver=cp.CLARABEL, **(options or SOLVER_OPTIONS))
    except cp.error.SolverError as exc:
        raise ReferenceSolveError(f"Clarabel failed: {exc}") from exc
    allowed = (
        (cp.OPTIMAL, cp.INFEASIBLE, cp.UNBOUNDED) if unbounded else (cp.OPTIMAL, cp.INFEASIBLE)
    )
    if problem.status not in allowed:
        raise ReferenceSolveError(f"Clarabel ended with status {problem.status!r}")
    return problem.status


def _held_constraints(problem: Problem, case: int, given: dict, k) -> tuple[list, cp.Constraint]:
    """Constraints of load case ``case`` held at multiple ``k`` with the active forces given.

    Returns the friction constraints (one set per contact) and the equilibrium constraint.
    """
    constraints = []
    total = problem.body.weight_wrench + k * problem.loads[case].wrench
    for contact in problem.contacts:
        if contact.role in PASSIVE:
            fn = cp.Variable(nonneg=True)
        else:
            fn = _force_in_case(given[contact.name], case)
        wrench, friction = contact_wrench(contact, fn)
        constraints += friction
        total = total + wrench
    balance = total == 0
    return constraints, balance


# ------------------------------------------------------------------------------------------
# The four questions
# ------------------------------------------------------------------------------------------


def min_force_objective(problem: Problem) -> float | None:
    """Optimal value of the problem's force objective, every load case at ``k = 1``.

    Active contacts with a ``force`` keep it; the others are free: a clamp has one normal force
    for all cases, a finger one per case; ``contact.max_force`` bounds them. Objectives, over
    the *free* active forces only:

    - ``min-total-clamp-force``: sum of the clamp forces + max over cases of the sum of the
      finger forces;
    - ``min-max-normal-force``: max over cases and contacts of the normal force;
    - ``min-total-normal-force``: max over cases of the sum of the normal forces;
    - ``min-squared-normal-force``: sum over cases and contacts of the squared normal forces
      (a clamp counts once per case).

    These are the quantities the production planner minimises. Its reported
    ``Plan.objective_value`` also counts the *given* active forces (e.g. a fixed finger adds
    to min-total-normal-force), so compare the two only on problems without given forces.

    Parameters
    ----------
    problem : fixplan.Problem
        A problem with a force objective.

    Returns
    -------
    float or None
        The optimal value [N, or N² for the squared objective]; None when no forces hold every
        load case (within the ``max_force`` bounds).
    """
    if problem.objective not in FORCE_OBJECTIVES:
        raise ValueError(f"{problem.objective!r} is not a force objective")
    cases = range(len(problem.loads))
    constraints = []
    totals = [problem.body.weight_wrench + load.wrench for load in problem.loads]
    clamps, fingers = [], [[] for _ in cases]  # free variables; fingers per case
    for contact in problem.contacts:
        free = contact.role not in PASSIVE and contact.force is None
        shared = cp.Variable(nonneg=True) if free and contact.role == "clamp" else None
        if shared is not None:
            clamps.append(shared)
            if contact.max_force is not None:
                constraints.append(shared <= contact.max_force)
        for j in cases:
            if contact.role in PASSIVE:
                fn = cp.Variable(nonneg=True)
            elif shared is not None:
                fn = shared
            elif free:
                fn = cp.Variable(nonneg=True)
                fingers[j].append(fn)
                if contact.max_force is not None:
                    constraints.append(fn <= contact.max_force)
            else:
                fn = float(contact.force)
            wrench, friction = contact_wrench(contact, fn)
            constraints += friction
            totals[j] = totals[j] + wrench
    constraints += [total == 0 for total in totals]
    per_case = [clamps + fingers[j] for j in cases]  # free active normal forces of case j
    if problem.objective == "min-total-clamp-force":
        goal = sum(clamps)
        if any(fingers):
            goal = goal + cp.max(cp.hstack([sum(f) if f else 0.0 for f in fingers]))
    elif problem.objective == "min-max-normal-force":
        goal = cp.max(cp.hstack([f for forces in per_case for f in forces]))
    elif problem.objective == "min-total-normal-force":
        goal = cp.max(cp.hstack([sum(forces) for forces in per_case]))
    else:
        goal = sum(cp.square(f) for forces in per_case for f in forces)
    solved = cp.Problem(cp.Minimize(goal), constraints)
    status = _solve(solved)
    if status == cp.INFEASIBLE:
        # The early certificate test of SOLVER_OPTIONS can accept a premature certificate on a
        # badly scaled problem (a pinch needing 800 N against a 20 N weight came back
        # infeasible after 2 iterations): confirm it with Clarabel's own test.
        status = _solve(solved, options={**SOLVER_OPTIONS, "tol_ktratio": 1e-6})
    return float(solved.value) if status == cp.OPTIMAL else None


def held_interval(
    problem: Problem, case: int, forces: Mapping | None, *, k_max: float = K_MAX
) -> tuple[float, float] | None:
    """The multiples ``k`` of load case ``case``'s task wrench that the given forces hold.

    The set of such ``k`` is convex (an interval); it is cut to ``0 <= k <= k_max``. Its ends
    come from two SOCPs: minimise ``k`` subject to ``k >= 0``, and maximise ``k`` (uncapped;
    an unbounded maximum gives ``k_max``).

    Parameters
    ----------
    problem : fixplan.Problem
        The problem (its objective is ignored).
    case : int
        Index of the load case.
    forces : mapping or None
        Active contact name -> normal force [N]: a float for a clamp, a float or an array over
        the load cases for a finger. Active contacts left out use ``contact.force``.
    k_max : float, optional
        Cap on ``k``; an interval ending at ``k_max`` means "held for every larger k too, up
        to the cap".

    Returns
    -------
    (k_min, k_max) or None
        The interval (dimensionless multiples of the task load); None when no ``k`` in
        ``[0, k_max]`` is held (e.g. the weight alone cannot be held, or the forces squeeze
        the body out for every load up to the cap).
    """
    given = given_forces(problem, forces)
    low = _smallest_multiple(problem, case, given)
    if low is None or low > k_max:
        return None
    high = _largest_multiple(problem, case, given)[0]
    return low, max(low, min(high, k_max))


def _smallest_multiple(problem: Problem, case: int, given: dict) -> float | None:
    """Smallest held ``k >= 0``; None when no ``k >= 0`` is held."""
    k = cp.Variable()
    constraints, balance = _held_constraints(problem, case, given, k)
    lowest = cp.Problem(cp.Minimize(k), [*constraints, balance, k >= 0.0])
    if _solve(lowest) == cp.INFEASIBLE:
        return None
    return max(float(k.value), 0.0)


def _largest_multiple(problem: Problem, case: int, given: dict) -> tuple[float, np.ndarray]:
    """Largest held ``k >= 0`` (``inf`` when unbounded) and the dual of equilibrium there.

    ``k`` is not capped inside the SOCP: a cap far above the answer (1e6 against forces of a
    few newtons) stalls Clarabel at these tolerances ("insufficient progress"), so an unbounded
    maximum is reported by the solver (dual infeasibility) instead. Call it only when some
    ``k >= 0`` is held (:func:`_smallest_multiple`).
    """
    k = cp.Variable()
    constraints, balance = _held_constraints(problem, case, given, k)
    highest = cp.Problem(cp.Maximize(k), [*constraints, balance, k >= 0.0])
    try:
        status = _solve(highest, unbounded=True)
    except ReferenceSolveError:
        if highest.status != cp.OPTIMAL_INACCURATE:
            raise
        status = _solve(highest, unbounded=True, options=FEASIBLE_RETRY_OPTIONS)
    if status == cp.UNBOUNDED:
        return math.inf, np.zeros(6)
    if status == cp.INFEASIBLE:
        raise ReferenceSolveError("maximising k is infeasible where minimising it was not")
    return float(k.value), np.asarray(balance.dual_value, dtype=float)


def feasible(
    problem: Problem, case: int, forces: Mapping | None, k: float, *, strict: bool = False
) -> bool:
    """Whether load case ``case`` is held at multiple ``k`` of its task wrench.

    A feasibility SOCP (zero objective, no slack): the equilibrium of the case with the given
    active forces, passive reactions free, every friction constraint. ``forces`` as in
    :func:`held_interval`.

    Returns
    -------
    bool
        True when Clarabel reports optimal (a holding set of contact forces exists), False when
        it reports infeasible (it found a certificate); "optimal_inaccurate" is asked again with
        ``FEASIBLE_RETRY_OPTIONS`` (not with ``strict``: their looser feasibility tolerance
        holds multiples up to 1.5e-6 beyond the end of an ill-conditioned grasp's interval);
        any other status raises :class:`ReferenceSolveError`.
    """
    constraints, balance = _held_constraints(problem, case, given_forces(problem, forces), k)
    feasibility = cp.Problem(cp.Minimize(0.0), [*constraints, balance])
    try:
        return _solve(feasibility) == cp.OPTIMAL
    except ReferenceSolveError:
        if strict or feasibility.status != cp.OPTIMAL_INACCURATE:
            raise
        return _solve(feasibility, options=FEASIBLE_RETRY_OPTIONS) == cp.OPTIMAL


def slip_twist(problem: Problem, case: int, forces: Mapping | None) -> np.ndarray | None:
    """The twist in which the body starts to slide when load case ``case`` reaches its ``k_max``.

    It is the dual variable of the equilibrium constraint of the maximise-``k`` problem of
    :func:`held_interval`. cvxpy's Lagrangian of ``minimise -k`` is ``-k + y · (Σ w + k W +
    W_g)`` for an equality ``expr == 0`` (its ``dual_value`` is ``y``), so stationarity in
    ``k`` gives ``W · y = 1``: the raw ``dual_value`` already does positive power with the
    task wrench, and its contact conditions are those of the sliding motion (friction opposes
    the sliding velocity at every sliding contact; a passive Coulomb contact separates at ``mu``
    times its sliding speed, the associated flow). The tests check this sign on a closed form.

    Parameters
    ----------
    problem, case, forces
        As in :func:`held_interval`.

    Returns
    -------
    numpy.ndarray (6,) or None
        ``V = (v, ω)``: velocity [m/s] of the body point at the world origin and angular
        velocity [rad/s], scaled to unit Euclidean norm (so its direction depends on the unit
        of length when it rotates) and signed so that ``W · V > 0`` with ``W`` the task wrench
        of the case. None when no ``k >= 0`` is held, or when every ``k`` above ``k_min`` is
        held (the maximum is unbounded: the task load never makes the body slide).
    """
    given = given_forces(problem, forces)
    if _smallest_multiple(problem, case, given) is None:
        return None
    high, twist = _largest_multiple(problem, case, given)
    size = np.linalg.norm(twist)
    if not math.isfinite(high) or size == 0.0:
        return None
    twist = twist / size
    # W·y = 1 > 0 already (see above); the guard keeps the documented sign should cvxpy's
    # convention ever change (test_the_raw_equality_dual_does_unit_power_with_the_task_wrench
    # would then fail and say so).
    return twist if problem.loads[case].wrench @ twist > 0.0 else -twist


# ------------------------------------------------------------------------------------------
# The nose-cone grasp (Lobo & Boyd's example, a squeeze-out grasp)
# ------------------------------------------------------------------------------------------

#: Radii [m] and polar angles [deg] of the five fingers on the paraboloid z = x² + y².
NOSE_CONE_RADII = (0.6, 0.8, 1.0, 0.7, 0.9)
NOSE_CONE_ANGLES = tuple(72.0 * i + 10.0 for i in range(5))
NOSE_CONE_MU = 0.3


def nose_cone_problem(finger_forces: Sequence[float] | None = None) -> Problem:
    """Five Coulomb fingers holding the nose cone ``z >= x² + y²`` against a 1 N load.

    Finger ``i`` (named ``finger-1`` … ``finger-5``) touches the paraboloid at radius
    :data:`NOSE_CONE_RADII` ``[i]`` and polar angle :data:`NOSE_CONE_ANGLES` ``[i]`` (72° apart,
    offset 10°), from outside: its normal ``(-2x, -2y, 1)/‖·‖`` points into the body.
    ``mu = 0.3``, model ``"point-cone"``. The body is massless (``Body`` allows mass 0); the
    only load, ``"weight"``, is the force ``(0, 0, -1)`` N at ``(0, 0, 0.5)`` m. Every finger
    pushes the body upwards, more than friction (``mu = 0.3``) can stop, so squeezing harder
    pushes the body out of the grasp: too large forces fail too.

    Parameters
    ----------
    finger_forces : sequence of 5 floats, optional
        Given finger forces [N] (objective ``"check"``); default: free forces and objective
        ``"min-max-normal-force"``.
    """
    contacts = []
    for i, (radius, angle) in enumerate(zip(NOSE_CONE_RADII, NOSE_CONE_ANGLES, strict=True)):
        x, y = radius * np.cos(np.radians(angle)), radius * np.sin(np.radians(angle))
        force = None if finger_forces is None else float(finger_forces[i])
        contacts.append(
            Contact(
                name=f"finger-{i + 1}",
                role="finger",
                position=[x, y, x * x + y * y],
                normal=[-2.0 * x, -2.0 * y, 1.0],
                mu=NOSE_CONE_MU,
                model="point-cone",
                force=force,
            )
        )
    return Problem(
        body=Body(mass=0.0, center_of_mass=[0.0, 0.0, 0.5]),
        contacts=tuple(contacts),
        loads=(Load(name="weight", force=[0.0, 0.0, -1.0], point=[0.0, 0.0, 0.5]),),
        objective="min-max-normal-force" if finger_forces is None else "check",
    )
