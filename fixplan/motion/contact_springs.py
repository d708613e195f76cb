r"""A rigid body on linear contact springs that are unilateral along their normals and bounded
by friction: the equilibrium of one loading step (used by :mod:`fixplan.motion.compliance`).

Contact ``i`` has the wrench basis ``B_i`` (``(6, 4)`` about the body's centre of mass, columns
``(fn, ft1, ft2, mn)``) and spring constants ``k_i = (k_n, k_t, k_t, k_r)`` [N/m, N/m, N/m,
N m/rad]. A body displacement ``Δδ = (u, θ)`` [m, rad] moves the contact by ``B_iᵀ Δδ`` (gap
opening, tangential slips, twist), and a step is the minimum of the complementary energy

.. math:: \min_f \sum_i \tfrac12 (f_i - r_i)^T k_i^{-1} (f_i - r_i)
    \quad \text{s.t.} \quad \sum_i B_i f_i + W = 0,\quad f_{n,i} \ge 0,\quad
    (f_{t1}, f_{t2}, m_n)_i \in g_i\, S_i,

about reference forces ``r_i`` (the state before the step, with a negative normal reference for
an open gap), with ``W`` the external wrench, ``S_i`` the contact's friction set per unit normal
force and ``g_i`` its friction bound [N]. The multipliers of equilibrium are the displacement
``Δδ``; the KKT conditions are the spring law ``f_i = r_i - k_i ⊙ B_iᵀ Δδ`` for sticking
components, ``f_n = max(0, r_n - k_n g)`` along the normal, and, for a contact whose trial
friction load leaves ``g_i S_i``, the closest point of ``g_i S_i`` in the metric ``k_i⁻¹`` (the
return map of a contact that slides along the normal of its own friction set). A component with a
zero spring constant is held at its reference (a force-controlled clamp's normal force; no
tangential force on a frictionless contact; no moment at a contact without torsional stiffness).

:class:`ContactQP` compiles that problem once (cvxpy Parameters for ``r``, ``W`` and ``g``) and
solves it with Clarabel. An exact friction model's set is stated by an ellipsoid ``‖R ℓ‖ <= g``
(``R`` a Parameter) that osculates the exact set (same point, tangent plane and curvature;
:meth:`~fixplan.models.Exact.osculating`) where the ray of the step's load meets it, moved after
each solve until every exact contact's load is inside its exact set and, where its ellipsoid
holds it back, on the exact surface with the ellipsoid's normal there the exact surface's: there
the step meets the exact problem's optimality conditions (sequential convex programming with
exact second-order models, as the planner's rounds, :mod:`fixplan.planner.osculating`). One on
point supports is stated exactly, a cone per point (:attr:`~fixplan.models.Exact.stated_exactly`);
other sets with facets (point supports beside a patch, or very many) keep their seed polytopes.
:class:`SpringSystem` solves purely elastic steps exactly: the QP (with unlimited friction,
except none at lifted contacts) tells which contacts touch, and with that set fixed the step is
linear,
``K Δδ = Σ B_i r_i + W`` with ``K = Σ B_i diag(k_i) B_iᵀ``; the polished answer is accepted only
if it meets the QP's optimality conditions to :data:`KKT_RTOL`.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np

from fixplan.errors import ConvergenceError, InvalidArgumentError
from fixplan.planner.direct_solve import INFEASIBLE, DirectSolver
from fixplan.planner.osculating_contact import (
    MAX_OSCULATING_ROUNDS,
    OsculatingContact,
    osculates,
)
from fixplan.planner.parameters import assign

#: A polished solution is accepted when its equilibrium residual, negative normal forces and
#: closed gaps of lifted contacts are below this fraction of the step's force scale.
KKT_RTOL = 1e-7

#: A normal force below this fraction of the step's force scale counts as lifted off.
LIFT_RTOL = 1e-7

#: Friction bound, in units of the force scale, of a contact whose friction is not limited (an
#: elastic step): far above any force a step can produce, so the constraint stays inactive.
UNLIMITED = 1e4

#: Most re-solves while dropping the tangential springs of lifted contacts, per contact.
MAX_LIFT_ROUNDS_PER_CONTACT = 2


#: Clarabel's tolerances: tighter than its defaults, since the forces of steps in which contacts
#: slide are taken from the QP as they are.
SOLVER_OPTIONS = {"tol_gap_abs": 1e-10, "tol_gap_rel": 1e-10, "tol_feas": 1e-10}


class ComplianceError(InvalidArgumentError):
    """The contact springs cannot hold a load, or the compliance inputs are invalid."""


class NoEquilibriumError(ComplianceError):
    """No contact forces within the bounds balance the step's load."""


class InaccurateStepError(ConvergenceError):
    """Clarabel failed or could not solve the step accurately (as at the brink of
    infeasibility)."""


class WrongContactSetError(ConvergenceError):
    """An elastic step polished on a set of touching contacts misses the QP's optimality
    conditions."""


class ContactQP:
    """The complementary-energy QP of one kind of step, compiled once.

    Parameters
    ----------
    bases : array (m, 6, 4)
        Contact wrench bases about the centre of mass.
    springs : array (m, 4)
        Spring constants; a zero holds that component at its reference.
    models : sequence of FrictionModel
        Each contact's friction model (per unit normal force).
    scale : float
        Force scale of the problem [N] (the QP works in units of it).
    """

    def __init__(self, bases, springs, models, *, scale: float):
        import cvxpy as cp

        count = len(models)
        self.scale = float(scale)
        self.length = max(float(np.abs(bases[:, 3:]).max()), 1e-3)
        self.rows = np.r_[np.ones(3), np.full(3, self.length)] * self.scale
        flat = np.asarray(springs, float).ravel()
        fixed = flat == 0.0
        # Variables in units that make every spring's weight 1 (the complementary energy is then
        # a plain sum of squares): force = units * variable.
        units = np.tile([1.0, 1.0, 1.0, self.length], count) * self.scale
        compliance = np.where(fixed, 1.0, units**2 / np.where(fixed, 1.0, flat))
        self._energy = float(np.exp(np.log(compliance[~fixed]).mean())) if (~fixed).any() else 1.0
        self.units = units * np.where(fixed, 1.0, np.sqrt(self._energy / compliance))
        matrix = np.concatenate(list(bases), axis=1) * self.units[None, :] / self.rows[:, None]

        self.reference = cp.Parameter(4 * count)
        self.wrench = cp.Parameter(6)
        self.bound = cp.Parameter(count, nonneg=True)
        forces = cp.Variable(4 * count)
        free = np.flatnonzero(~fixed)
        # |f - r|² without its constant |r|² (cvxpy cannot take a Parameter inside a square).
        cost = cp.sum_squares(forces[free]) - 2.0 * self.reference[free] @ forces[free]
        self._matrix, self._models = matrix, models
        self._balance = matrix @ forces + self.wrench == 0
        constraints = [self._balance]
        if fixed.any():
            held = np.flatnonzero(fixed)
            constraints.append(forces[held] == self.reference[held])
        pressing = [4 * i for i in range(count) if not fixed[4 * i]]
        if pressing:
            constraints.append(forces[pressing] >= 0)
        self._osculating: dict[int, OsculatingContact] = {}
        self._case: str | None = None  # (the load case of the last step)
        for i, model in enumerate(models):
            if model.frictionless or fixed[4 * i + 1 : 4 * i + 4].all():
                continue
            u = self.units[4 * i : 4 * i + 4] / self.scale
            if model.torsion:
                load = cp.hstack([u[p] * forces[4 * i + p] for p in (1, 2, 3)])
            else:
                load = cp.hstack([u[p] * forces[4 * i + p] for p in (1, 2)])
            if osculates(model):
                self._osculating[i] = OsculatingContact(model)
                constraints.append(self._osculating[i].constraint(load, self.bound[i]))
            else:
                constraints += model.constraints(load, self.bound[i])
        self._forces = forces
        self._problem = cp.Problem(cp.Minimize(cost), constraints)
        self._direct, self._tried_direct = None, False

    def solve(self, reference, wrench, bound, case: str) -> tuple[np.ndarray, np.ndarray]:
        """Contact forces ``(m, 4)`` and displacement ``(6,)`` of the step: springs about
        ``reference`` ``(m, 4)``, external ``wrench`` ``(6,)``, friction bounds ``bound`` ``(m,)``
        [N]. Raises :class:`NoEquilibriumError` when nothing balances the load.

        Solved by Clarabel directly on the compiled data once cvxpy has solved the QP once
        (:class:`~fixplan.planner.direct_solve.DirectSolver`); through cvxpy where that path
        does not give an answer."""
        assign(self.reference, np.ravel(reference) / self.units)
        assign(self.wrench, np.asarray(wrench, float) / self.rows)
        assign(self.bound, np.maximum(bound, 0.0) / self.scale)
        for ellipsoid in self._osculating.values():
            ellipsoid.start()
            if case != self._case:  # (each load case from the same start: its answer is its own)
                ellipsoid.reset()
        self._case = case
        for _ in range(MAX_OSCULATING_ROUNDS):
            forces, delta = self._solve_once(case)
            bounds = self.bound.value * self.scale
            try:
                moved = [e.follow(forces[i, 1:4], bounds[i]) for i, e in self._osculating.items()]
            except ConvergenceError as exc:
                raise InaccurateStepError(f"load case {case!r}: {exc}") from exc
            if not any(moved):
                return forces, delta
        raise InaccurateStepError(
            f"load case {case!r}: the ellipsoids of its exact contacts did not settle on their "
            f"exact sets in {MAX_OSCULATING_ROUNDS} solves"
        )

    def _solve_once(self, case: str) -> tuple[np.ndarray, np.ndarray]:
        """The step with the parameters as set: through the direct solver where it answers,
        else through cvxpy."""
        if self._direct is not None:
            values = self._direct.solve(accept_inaccurate=True)
            if self._direct.status in INFEASIBLE:
                raise self._no_equilibrium(case)
            if values is not None:
                forces = values[self._forces.id] * self.units
                if self._direct.status == "Solved" or self._admissible(forces):
                    dual = self._direct.dual(self._balance)
                    return forces.reshape(-1, 4), self._displacement(dual)
        return self._solve_with_cvxpy(case)

    def _solve_with_cvxpy(self, case: str) -> tuple[np.ndarray, np.ndarray]:
        import cvxpy as cp

        try:
            with warnings.catch_warnings():  # an inaccurate answer is reported below
                warnings.simplefilter("ignore", UserWarning)
                # (cvxpy evaluates the cost at an infeasibility certificate's huge values)
                warnings.simplefilter("ignore", RuntimeWarning)
                self._problem.solve(solver=cp.CLARABEL, **SOLVER_OPTIONS)
        except cp.SolverError as exc:
            raise InaccurateStepError(f"load case {case!r}: Clarabel failed: {exc}") from exc
        status = self._problem.status
        if status in ("infeasible", "infeasible_inaccurate"):
            raise self._no_equilibrium(case)
        forces = None if self._forces.value is None else self._forces.value * self.units
        if status != "optimal" and not (
            status == "optimal_inaccurate" and self._admissible(forces)
        ):
            raise InaccurateStepError(f"load case {case!r}: the contact QP ended {status!r}")
        if status == "optimal" and self._direct is None and not self._tried_direct:
            self._tried_direct = True
            self._direct = DirectSolver.create(self._problem, SOLVER_OPTIONS)
        return forces.reshape(-1, 4), self._displacement(self._balance.dual_value)

    @staticmethod
    def _no_equilibrium(case: str) -> NoEquilibriumError:
        return NoEquilibriumError(
            f"load case {case!r}: no contact forces within the contacts' friction and "
            "unilateral limits balance the load; the body leaves its contacts or slides"
        )

    def _admissible(self, forces) -> bool:
        """Whether ``forces`` (flat, [N]) balance the step's load within the friction and
        unilateral limits to :data:`KKT_RTOL`: an answer Clarabel calls inaccurate (as at the
        brink of infeasibility) is still taken when it does."""
        if forces is None:
            return False
        scaled = forces / self.units
        residual = self._matrix @ scaled + self.wrench.value
        wrenches = forces.reshape(-1, 4)
        if np.abs(residual).max() > KKT_RTOL or wrenches[:, 0].min() < -KKT_RTOL * self.scale:
            return False
        bounds = self.bound.value * self.scale
        for i, (model, (_, *load), bound) in enumerate(zip(self._models, wrenches, bounds,
                                                            strict=True)):  # fmt: skip
            friction = np.array(load[: model.load_dimension])
            if np.abs(friction).max() <= KKT_RTOL * self.scale:
                continue
            if bound <= 0.0:
                return False
            held = self._osculating.get(i, model)  # (an exact contact's: its ellipsoid's)
            if held.safety_factor(friction, normal_force=bound) < 1 - KKT_RTOL:
                return False
        return True

    def _displacement(self, dual) -> np.ndarray:
        """The displacement from the multipliers of equilibrium: the cost is ``2 / w`` times the
        complementary energy in scaled forces, so ``Δδ = w y / 2`` per scaled row."""
        return 0.5 * self._energy * np.asarray(dual, float) / self.rows


@dataclass(frozen=True, slots=True, kw_only=True)
class SpringSystem:
    """Contact springs of one body: bases ``(m, 6, 4)`` about the centre of mass, spring
    constants ``(m, 4)`` and the compiled QP of their steps."""

    bases: np.ndarray
    springs: np.ndarray
    qp: ContactQP

    def solve(self, reference, wrench, case: str) -> tuple[np.ndarray, ...]:
        """An elastic step, exact: contact forces ``(m, 4)``, displacement ``(6,)``, which
        contacts touch ``(m,)``, and the spring constants and references in effect ``(m, 4)``
        (lifted contacts lose their tangential springs and forces). The QP finds the contacts
        that touch; :meth:`touching` polishes."""
        count = len(self.springs)
        dropped = (reference[:, 0] < 0.0) & (self.springs[:, 0] > 0.0)  # open gaps
        for _ in range(MAX_LIFT_ROUNDS_PER_CONTACT * count + 1):
            bound = np.where(dropped, 0.0, UNLIMITED * self.qp.scale)
            forces, _ = self.qp.solve(
                np.where(dropped[:, None], 0.0, reference), wrench, bound, case
            )
            touching = (forces[:, 0] > LIFT_RTOL * self.qp.scale) | (self.springs[:, 0] == 0.0)
            try:  # the QP's set holds once the lifted contacts' tangential springs are dropped
                polished = self.touching(reference, wrench, touching, case)
                return polished[0], polished[1], touching, *polished[2:]
            except WrongContactSetError:
                dropped = ~touching
        raise WrongContactSetError(
            f"load case {case!r}: no set of touching contacts holds with sticking springs (a "
            "contact at the verge of lifting would slide)"
        )

    def touching(self, reference, wrench, touching, case: str) -> tuple[np.ndarray, ...]:
        """The elastic step with the contacts ``touching`` given: forces ``(m, 4)``,
        displacement ``(6,)`` and the springs and references in effect ``(m, 4)``; raises
        :class:`WrongContactSetError` unless it meets the QP's optimality conditions."""
        springs = np.where(touching[:, None], self.springs, 0.0)
        springs[~touching, 0] = self.springs[~touching, 0]
        effective = np.where(touching[:, None], reference, 0.0)
        effective[~touching, 0] = reference[~touching, 0]
        forces, delta = self._polish(effective, springs, wrench, touching, case)
        return forces, delta, springs, effective

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

    def balances(self, forces, wrench) -> bool:
        """Whether contact forces ``(m, 4)`` balance ``wrench`` to :data:`KKT_RTOL`."""
        return self._imbalance(forces, wrench) <= KKT_RTOL

    def _imbalance(self, forces, wrench) -> float:
        """Largest equilibrium residual, in units of the force scale (moments over length)."""
        residual = (np.einsum("iap,ip->a", self.bases, forces) + wrench) / self.qp.rows
        return float(np.abs(residual).max())

    def _polish(self, reference, springs, wrench, touching, case):
        """:meth:`linear`, checked against the QP's optimality conditions."""
        forces, delta, motion = self.linear(reference, springs, wrench, touching)
        would_be = reference[:, 0] - springs[:, 0] * motion[:, 0]
        worst = max(
            self._imbalance(forces, wrench),
            float(-forces[touching, 0].min(initial=0.0)) / self.qp.scale,
            float(would_be[~touching].max(initial=0.0)) / self.qp.scale,
        )
        if worst > KKT_RTOL:
            raise WrongContactSetError(
                f"load case {case!r}: the polished contact forces miss the QP's optimality "
                f"conditions by {worst:.3g} of the force scale (the springs may leave the body "
                "free)"
            )
        return forces, delta
