r"""Exact friction models in the planner: tangent-plane cuts added until every load is inside.

The planner takes this way where osculating ellipsoids (:mod:`fixplan.planner.osculating`) do
not apply or do not settle: surfaces with facets, solvers other than Clarabel, infeasible
problems (a relaxation proves them infeasible).

The set of an :class:`~fixplan.models.Exact` model is the intersection of the halfspaces
``L · V <= N h_1(V)`` over all twists ``V``. Its constraints state a seed polytope of such planes
(an outer approximation); a solve then gives contact loads ``ℓ_ij`` at normal forces ``n_ij``
that may lie outside the exact set. For each of those, the tangent plane at the load's ray,

.. math:: a_{ij} \cdot \ell \le n, \qquad a_{ij} = V^*_{ij} / h_1(V^*_{ij}),

with ``V*`` the load's sliding twist from the exact inverse map, cuts it off, and the problem is
re-solved, until every contact load is inside its exact surface to ``EXACT_CUT_RTOL``. Every cut
is valid for the exact set, so each solve is a relaxation of the exact problem: an infeasible
relaxation proves the exact problem infeasible, and the duals of the last solve (the impending
motions) are those of the exact problem at its optimum.

Four more planes, tilted around a centre twist, shape the polytope where the optimum's load is
heading. The centre is the contact's twist in the relaxation's impending motion (the multipliers
``y`` of the equilibrium mapped to the contact, ``-G_i^T y``) where the contact takes part in it:
those twists approach the optimum's far faster than the normals at the loads' rays (on the
fixture of ``benchmarks/bench_exact.py`` typically 10 to 100 times closer in every round), which
takes about 40 % fewer rounds of cutting there. Elsewhere the centre is the load's own sliding
twist.

The cuts sit in a fixed pool of ``CUT_SLOTS`` rows per (contact, load case), cvxpy Parameters
``A_k`` (one per load component, DPP), so the problem is compiled once; an empty slot has
``a = 0`` (the row ``0 <= n``, which the seed implies). New cuts take the slots whose cuts were
active (tight) longest ago, the loosest first among equals; the pool survives between solves, so
a re-solve with nearby loads starts from the cuts that were active last time.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from fixplan.planner.exact_contacts import ExactContacts
from fixplan.tolerances import EXACT_CUT_RTOL, FRICTION_SET_RTOL

#: Cut rows per (exact contact, load case) besides the seed polytope.
CUT_SLOTS = 12

#: Spread of the four planes tilted around the load's own sliding twist, in normalised twist
#: coordinates, per square root of the load's excess (the distance to the optimum's normal
#: shrinks like that root).
SPREAD = 1.0

#: The same around the contact's twist in the impending motion, which lies closer to the
#: optimum's normal (on the fixture of benchmarks/bench_exact.py, 0.35, 0.5 and 0.7 take 9.2, 8.8
#: and 10.4 rounds per re-solve on average over 20 re-solves, 1.0 takes 13.8).
DUAL_SPREAD = 0.5

#: The impending motion's twist of a contact centres its planes when its norm (in normalised
#: coordinates) exceeds this fraction of the largest such norm among the exact contacts.
DUAL_RTOL = 1e-6

#: Most solves of one problem while cutting; a problem not converged by then is reported.
MAX_CUT_ROUNDS = 60

#: Inaccurate solves in a row that end the rounds (status ``inaccurate``: the planner then tries
#: its fallback solver). Their loads are off by about the solver's own tolerance, so their cuts
#: do not bring the loads within ``EXACT_CUT_RTOL``: with SCS (``eps`` 1e-9, which it rarely
#: reaches) the fixture of benchmarks/bench_planner.py with 4 milling loads took 60 rounds of
#: 4.7 s, 58 of them inaccurate, and ended with a load 7.6e-2 outside before Clarabel, the
#: fallback, solved it in 3. One inaccurate solve between accurate ones is passed over.
MAX_INACCURATE_IN_A_ROW = 2

#: Cuts are tightened by this fraction (``a (1 + CUT_MARGIN) · ℓ <= n``) so that the solver's
#: feasibility error (about 1e-9 of the loads) does not leave a load outside by more than
#: ``EXACT_CUT_RTOL``; the optimum moves by about this fraction.
CUT_MARGIN = 1e-8

#: A cut counts as active when its slack is below this fraction of the normal force.
ACTIVE_RTOL = 1e-7


class CutPool(ExactContacts):
    """The cut Parameters of a stacked problem's exact contacts, and the rounds of cutting
    (``CUT_SLOTS`` per contact and load case; the other parameters are those of
    :class:`~fixplan.planner.exact_contacts.ExactContacts`)."""

    def __init__(self, models: dict, slices, normal, friction, *, normal_parts, wrenches, balance):
        super().__init__(models, slices, normal, friction, normal_parts=normal_parts,
                         wrenches=wrenches, balance=balance, slots=CUT_SLOTS, name="cut")  # fmt: skip
        self._used = np.full((CUT_SLOTS, len(self._contacts), friction.shape[1]), -1, np.int64)
        self._round = 0
        self.constraints = [self._cuts]

    def converge(self, solve: Callable[[], str], status: str) -> tuple[str, list[str]]:
        """Cut and re-solve (``solve()`` returns the status) from a first solve's ``status``
        until every exact contact load is inside its surface (or ``MAX_INACCURATE_IN_A_ROW``
        solves were inaccurate); the final status and notes (a load still outside after
        ``MAX_CUT_ROUNDS`` of accurate solves)."""
        inaccurate = 0
        for _ in range(MAX_CUT_ROUNDS):
            inaccurate = inaccurate + 1 if status == "inaccurate" else 0
            if status not in ("optimal", "inaccurate") or inaccurate >= MAX_INACCURATE_IN_A_ROW:
                return status, []
            worst = self.add_cuts()
            if worst <= EXACT_CUT_RTOL:
                return status, []
            status = solve()
        # (An inaccurate last solve goes to the fallback solver, whose rounds note their own.)
        if status == "optimal" and (worst := self.add_cuts()) > EXACT_CUT_RTOL:
            return status, [
                f"exact friction models: after {MAX_CUT_ROUNDS} rounds of cuts a contact load "
                f"still lies {worst:.2g} (relative) outside its limit surface"
            ]
        return status, []

    def add_cuts(self) -> float:
        """Cut off the contact loads of the last solve that lie outside their exact surfaces.

        Returns the largest relative excess ``1 / s - 1`` of a pressed contact's load (before
        the new cuts; negative when all are inside).
        """
        normal = self._normal_values()
        friction = np.asarray(self._friction.value, dtype=float)
        forces = normal[self._contacts]  # (E, K)
        loads = friction[self._rows].transpose(1, 0, 2)  # (3, E, K)
        self._round += 1
        slack = forces[None] - np.einsum("xpek,xek->pek", self._planes, loads)
        active = np.any(self._planes != 0.0, axis=0) & (slack <= ACTIVE_RTOL * forces[None])
        self._used[active] = self._round
        twists = self.motion_twists()  # (E, K, 3)
        noise = FRICTION_SET_RTOL * max(float(np.abs(normal).max(initial=0.0)), 1e-300)
        worst = -np.inf
        self.use[:] = np.nan
        for e, model in enumerate(self._models):
            cases = np.flatnonzero(forces[e] > noise)
            per_unit = loads[:, e, cases].T / forces[e, cases, None]
            moving = np.abs(per_unit).max(axis=1, initial=0.0) > 0.0
            cases, per_unit = cases[moving], per_unit[moving]
            if cases.size == 0:
                continue
            planes, excess = model.cut(per_unit)
            self.use[self._contacts[e], cases] = 1.0 + excess
            worst = max(worst, float(excess.max()))
            cut = excess > EXACT_CUT_RTOL
            cases, planes, per_unit = cases[cut], planes[cut], per_unit[cut]
            if cases.size == 0:
                continue
            root = np.sqrt(excess[cut])
            centres, spread = planes, SPREAD * root
            if twists is not None:
                motion = twists[e, cases]
                motion *= np.sign(np.einsum("ij,ij->i", motion, per_unit))[:, None]  # outward
                moved = np.any(motion != 0.0, axis=1)
                centres = np.where(moved[:, None], motion, centres)
                spread = np.where(moved, DUAL_SPREAD * root, spread)
            around = model.planes(_around(centres, model.rho, spread).reshape(-1, 3))
            new = [planes, *around.reshape(4, -1, 3)]
            order = _slots(self._used[:, e, cases], slack[:, e, cases] / forces[e, cases])
            for rows, slots in zip(new, order[: len(new)], strict=True):
                self._planes[:, slots, e, cases] = rows.T * (1.0 + CUT_MARGIN)
                self._used[slots, e, cases] = self._round
        self._assign_cuts()
        return worst

    def motion_twists(self) -> np.ndarray | None:
        """``(E, K, 3)`` twists ``(vx, vy, w)`` of the exact contacts in the last solve's
        impending motion (``-G_i^T y``), zero where the contact takes no part in it; ``None``
        without multipliers."""
        twists = self._twists()
        if twists is None:
            return None
        rho = np.array([m.rho for m in self._models])[:, None]
        size = np.hypot(np.hypot(twists[..., 0], twists[..., 1]), rho * twists[..., 2])
        twists[size <= DUAL_RTOL * size.max(initial=0.0)] = 0.0
        return twists


def _slots(used: np.ndarray, slack: np.ndarray) -> np.ndarray:
    """Slots ``(P, K)`` of each column in the order new cuts take them: the cuts active longest
    ago (``used``, the round of their last activity ``(P, K)``) first, the loosest (``slack``
    relative to the normal force) first among equals, so the cuts of one round never share a
    slot."""
    return np.lexsort((-slack, used), axis=0)


def _around(twists: np.ndarray, rho: float, spread: np.ndarray) -> np.ndarray:
    """Four twists ``(4, K, 3)`` around each twist of ``twists`` ``(K, 3)``, tilted by ``±spread``
    along two directions normal to it in normalised coordinates ``(vx, vy, rho w)``."""
    scale = np.array([1.0, 1.0, rho])
    unit = twists * scale
    unit /= np.linalg.norm(unit, axis=1, keepdims=True)
    helper = np.eye(3)[np.argmin(np.abs(unit), axis=1)]
    first = np.cross(unit, helper)
    first /= np.linalg.norm(first, axis=1, keepdims=True)
    second = np.cross(unit, first)
    tilt = np.minimum(spread, 0.5)[:, None]
    around = [unit + tilt * first, unit - tilt * first, unit + tilt * second, unit - tilt * second]
    return np.array(around) / scale
