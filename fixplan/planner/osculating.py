r"""Exact friction models in the planner: osculating ellipsoids, moved until they agree.

A smooth exact set (a patch without point supports) is replaced, per (contact, load case), by
an ellipsoid ``‖R_ij ℓ_ij‖ <= n_ij`` with Parameters ``R`` (so the problem is compiled once),
first the ellipsoid through the set's axis points, then after every solve the ellipsoid that
osculates the exact set where the ray of the solved load meets it
(:meth:`~fixplan.models.Exact.osculating`: same point, tangent plane and curvature), or, for a
load that its last round brought little closer, where the exact set's normal is the contact's
twist in the solve (:meth:`~fixplan.models.Exact.osculating_at`, ``PROGRESS``). This is
sequential convex programming with exact second-order models: near the optimum each round
squares the distance to it, where tangent planes alone (:mod:`fixplan.planner.cuts`) gain a
constant factor per round. Each round is a conic problem of the size of the ellipsoid model's.

The ellipsoids are not outer approximations, so a round is not a relaxation: the rounds stop
when the solve meets the optimality conditions of the exact problem. Every contact load lies
inside its exact set (to ``EXACT_CUT_RTOL``); where a contact limits the optimum (its twist in
the impending motion, the equilibrium's multipliers mapped to the contact, ``V_ij = -G_iᵀ y_j``,
is not zero), the solve made that twist the normal of the ellipsoid it used at the load, so
that ellipsoid's normal there must be the exact set's (``STATIONARITY_RTOL``, weighed by the
twist's size relative to the largest, of the load case for the fixed-force objectives, whose
cases are independent; the normals are compared rather than the twist, whose direction an
interior-point solve gives to about 1e-5) and the load must lie on the exact surface: what
limiting loads left inside their sets cost the objective, to first order their powers ``P =
L·V`` times the fractions they are inside, at most ``COMPLEMENTARITY_RTOL`` of it (of each
case's multiple, in a fixed-force block). Loads of contacts that do not limit the optimum may
be anywhere inside (an optimum's loads are often not unique). A fixed-force case whose multiple
sits at a bound (0, or the cap) needs no stationarity: its exactly feasible loads prove that
multiple optimal. A contact without load (not pressed) that takes part in the impending motion is held at no normal
force because its set looks too small in the direction of its twist ``V``: its ellipsoid must
reach as far as the exact set there (``SUPPORT_RTOL``), else it is moved to osculate at the
exact set's point with normal ``V``. Rounds that do not get there (``MAX_ROUNDS``), or a
solve that is not optimal (an ellipsoid can cut off a feasible load), leave the problem to the
cutting planes, whose relaxations also certify infeasibility.
"""

from __future__ import annotations

from collections.abc import Callable

import cvxpy as cp
import numpy as np

from fixplan.planner.exact_contacts import ExactContacts, takes_rounds
from fixplan.planner.osculating_steps import SETTLE, SOLVED_PAIRS, pair_buffers
from fixplan.planner.parameters import assign
from fixplan.tolerances import (
    CAP_RTOL,
    EXACT_CUT_RTOL,
    FRICTION_SET_RTOL,
    MAX_SAFETY_FACTOR,
    MULTIPLE_ATOL,
)

#: Most solves of one problem; a problem not settled by then goes to the cutting planes.
MAX_ROUNDS = 12

#: Largest distance between the unit normals (normalised coordinates) of the ellipsoid a solve
#: used and of the exact set at a contact's load, times the size of the contact's twist in the
#: impending motion relative to the largest.
STATIONARITY_RTOL = 1e-6

#: Largest first-order cost to the objective, relative to it (at least 1 in the program's units:
#: newtons over the block's force unit, or load multiples; in a fixed-force block, to each case's
#: multiple of its own pairs), of the limiting loads a solve left inside their exact sets:
#: ``Σ P_i max(1 - 1/s_i - MARGIN, 0)``, where ``P_i = L_i·V_i`` is the
#: power of contact load ``L_i`` in its twist (the multiplier of its set: the objective's
#: derivative in the set's size) and the ``MARGIN`` the ellipsoids are tightened by is not
#: counted. Interior-point solves leave about 1e-8 of the objective so (their duality gap).
#: Weighed instead by the twists' sizes relative to the largest (``STATIONARITY_RTOL``'s
#: weights) and held to 1e-6 per load, a re-solve of a random pinch settled 7.6e-7 above the
#: cutting planes' optimum, and on the path of benchmarks/bench_realtime.py a safety analysis
#: settled with a support pad's load 5.8e-5 inside (twist weight 0.015, but 17 % of the power):
#: ``k_max`` 4.3e-5 low; at 1e-7 so, the fixed-force fixtures of tests/test_exact_planner.py
#: did not settle in ``MAX_ROUNDS`` and 5 of the path's 10,000 steps went to the cutting planes.
#: Now none does (1.70 rounds per step with the analysis, 1.23 bare), and the fixture of
#: benchmarks/bench_exact.py takes 4.33 rounds per re-solve against 4.15.
COMPLEMENTARITY_RTOL = 1e-7

#: Largest relative shortfall ``1 - h_E(V) / h_1(V)`` of the support of an unpressed contact's
#: ellipsoid below the exact set's in the direction of its twist ``V``, times the twist's size
#: relative to the largest: where the ellipsoid reaches less far than the exact set, pressing the
#: contact may lower the exact problem's objective (an osculated ellipsoid's shortfall is the
#: ``MARGIN``).
SUPPORT_RTOL = 1e-7

#: Smallest normalised twist (``V * units``, dimensionless) of a force objective that counts as
#: a limiting contact's (smaller ones weigh 0 in the tests of a settled round), and the least
#: size the weights are relative to: the objective changes by one per newton of each free normal
#: force, so a contact that limits it has a twist of about ``mu / K`` (``K`` load cases sharing
#: the force); where the optimum needs no force at all, the twists are solver noise (1e-11 to
#: 3e-10). Weighed relative to this floor instead of counted as none, noise twists of 3e-10
#: failed the complementarity test of loads a quarter inside their sets round after round: 22
#: of every twentieth step of the path of benchmarks/bench_realtime.py (exact grasp, one
#: planner) went to the cutting planes.
FORCE_DUAL_FLOOR = 1e-6

#: A pair in the impending motion whose load is still outside its exact set after a round whose
#: excess fell by less than this factor is moved to osculate at the exact set's point whose
#: normal is its twist in the solve (:meth:`~fixplan.models.Exact.osculating_at`) rather than
#: at its load's ray. Where many contacts share a load, the rounds move the loads between them
#: more than the twists (the body's motion), and the ray's point lagged behind: on the fixture
#: of benchmarks/bench_exact.py (seeds 1-15 and 100-114 of its loads) rounds per re-solve
#: 5.3 and 5.1 -> 4.3 and 4.1, from scratch 4.7 and 4.0 -> 4.1 and 3.5. Never in a first
#: round: on its pinch, whose two contacts share the load by statics, the ray's point settled
#: in 2 rounds, the normal's in 3. Any load whose excess fell by less than this factor also
#: gets the tangent plane itself as its cut (see ``CUT_SLACK``).
PROGRESS = 0.1

#: Tangent-plane cuts per (contact, load case) besides the ellipsoid: each load outside its
#: exact set leaves the tangent plane at its ray (valid for the exact set), moved out by
#: ``CUT_SLACK``, which keeps later solves from it; new cuts replace the oldest. Without them,
#: loads of contacts that do not limit the optimum (any of a face of optima) and, far from the
#: optimum, limiting loads too swing between points outside their sets (on the fixture of
#: benchmarks/bench_exact.py a check block did not settle in 12 rounds). One slot is not enough
#: there either; each slot costs a row per contact and case (2 slots: 6.2 ms of Clarabel per
#: round against 2.9 ms without, runs of their own; one round's program with its cut rows taken
#: out: 3.9 ms and 15 iterations against 3.1 ms and 14; both before ``CUT_SLACK``).
CUT_SLOTS = 2

#: Cuts are placed this fraction beyond the exact set's tangent plane (``L·V <= (1 + CUT_SLACK)
#: h₁(V)``, still valid), but for a load whose excess the last round did not reduce by
#: ``PROGRESS``: that one gets the tangent plane itself. The tangent plane at the point where a
#: pair's next ellipsoid osculates is tangent to that ellipsoid there too: where the loads settle
#: near that point, both rows are active with the same normal, which slows the interior point
#: (degenerate multipliers). Moved out, the cuts still hold loads from swinging far outside: on
#: the fixture of benchmarks/bench_exact.py (90 re-solves with new loads, three planners)
#: Clarabel took 58.8 iterations and 4.03 rounds per re-solve against 71.3 and 4.39 with tangent
#: cuts, and 487 against 580 with the safety analysis (20 re-solves); 60 random problems of
#: tests/test_osculating_agreement.py's kinds took 904 rounds against 920, with the same two left
#: to the cutting planes. A load that its ellipsoid does not bring in (placed at its ray, on the
#: grasp of bench_realtime.py a load stayed 2e-7 outside round after round) needs the tangent
#: plane: with every cut moved out, 3 of that grasp's first 500 re-solves went to the cutting
#: planes (none with tangent cuts).
#: With every cut moved out by 5e-2 the iterations were about the same, but a problem whose
#: optimum needs no force did not settle in 12 rounds.
CUT_SLACK = 2e-2

#: Ellipsoids are tightened by this fraction (``(1 + MARGIN) ‖R ℓ‖ <= n``), so that the solver's
#: feasibility error (about 1e-9) does not leave a load outside by more than ``EXACT_CUT_RTOL``.
MARGIN = 1e-8


def smooth(models) -> bool:
    """Whether every exact model among ``models`` whose constraints hold its set only from
    outside (not :attr:`~fixplan.models.Exact.stated_exactly`) has a smooth set (no facets), so
    that the osculating ellipsoids apply; ``False`` without such models."""
    exact = [m for m in models if takes_rounds(m)]
    return bool(exact) and not any(m.surface.has_facets for m in exact)


class OsculatingPool(ExactContacts):
    """The ellipsoid Parameters of a stacked problem's exact contacts, their ``CUT_SLOTS`` cut
    rows, and their rounds (the other parameters are those of
    :class:`~fixplan.planner.exact_contacts.ExactContacts`).

    Parameters
    ----------
    scale : cvxpy.Variable or None
        ``(K,)`` task-load multiples of a fixed-force objective (``None`` for the force
        objectives, whose cases share their optimum).
    """

    def __init__(
        self, models: dict, slices, normal, friction, *, normal_parts, wrenches, balance,
        scale=None,
    ):  # fmt: skip
        super().__init__(models, slices, normal, friction, normal_parts=normal_parts,
                         wrenches=wrenches, balance=balance, slots=CUT_SLOTS,
                         name="osculating_cut")  # fmt: skip
        self._scale = scale
        self._units = np.array([model._units() for model in self._models])  # (E, 3)
        count, cases = len(self._contacts), friction.shape[1]
        #: ``(E, 3, 3)`` the ellipsoids through the exact sets' axis points (a first solve's).
        self._axis = np.zeros((count, 3, 3))
        self._axis[:, [0, 1, 2], [0, 1, 2]] = (1.0 + MARGIN) / self._units
        self._factors = np.repeat(self._axis[:, None], cases, axis=1)
        self._next_slot = np.zeros((count, cases), dtype=int)
        #: ``(E, K)`` the excess of each pair's load in the last round of this solve (NaN: none).
        self._previous_excess = np.full((count, cases), np.nan)
        #: What the last round's limiting loads left inside their sets cost the objective,
        #: to first order (see ``COMPLEMENTARITY_RTOL``): ``(1,)``, or ``(K,)`` by load case for
        #: the fixed-force objectives.
        self.held_back = np.zeros(1)
        #: The objective value of the last solve (set by :meth:`converge`).
        self._objective: Callable[[], float] = lambda: float("nan")
        #: Buffers of a round's pairs (:func:`~fixplan.planner.osculating_steps.solved_pairs`).
        self._pairs = pair_buffers(count * cases)
        #: The ellipsoids and cut planes of the last solve (before :meth:`move` moved them).
        self._solved_with = (self._factors.copy(), self._planes.copy())
        self._entries = [(r, c) for r in range(3) for c in range(r, 3)]  # upper triangle
        self._parameters = [
            cp.Parameter((count, cases), name=f"osculating_{r}{c}") for r, c in self._entries
        ]
        rows = [0, 0, 0]
        for (r, c), parameter in zip(self._entries, self._parameters, strict=True):
            rows[r] = rows[r] + cp.multiply(parameter, friction[self._rows[:, c], :])
        stacked = cp.vstack([cp.vec(row, order="F") for row in rows])
        forces = cp.vec(normal[self._contacts, :], order="F")
        self.constraints = [cp.SOC(forces, stacked, axis=0), self._cuts]
        self._assign()

    @property
    def ellipsoids(self) -> np.ndarray:
        """``(E, K, 3, 3)`` the factors ``R`` of the ellipsoids the next solve uses."""
        return self._factors.copy()

    def place(self, ellipsoids: list) -> None:
        """Start from known ellipsoids: ``(E, 3, 3)`` factors per load case (``None``: those
        through the exact sets' axis points). An ellipsoid models its contact's set in any
        load case."""
        for j, factors in enumerate(ellipsoids):
            self._factors[:, j] = self._axis if factors is None else factors
        self._assign()

    def follow(self, other: OsculatingPool) -> None:
        """Take the ellipsoids and cuts of ``other``'s last solve (a pool of the same exact
        contacts and load cases)."""
        factors, planes = other._solved_with
        self._factors[:], self._planes[:] = factors, planes
        self._assign()

    def converge(
        self, solve: Callable[[], str], status: str, objective: Callable[[], float]
    ) -> tuple[str, bool]:
        """Move the ellipsoids and re-solve (``solve()`` returns the status) from a first
        solve's ``status``; the final status and whether the rounds settled on the exact
        optimum (otherwise the cutting planes take over). ``objective()`` is the last solve's
        objective value (in the program's units)."""
        self._objective = objective
        self._previous_excess[:] = np.nan
        for _ in range(MAX_ROUNDS):
            if status not in ("optimal", "inaccurate"):
                return status, False
            if self.move():
                return status, True
            status = solve()
        return status, False

    def move(self) -> bool:
        """Put each ellipsoid where its contact's solved load meets the exact set; whether the
        solve already met the exact problem's optimality conditions (see the module)."""
        self._solved_with = (self._factors.copy(), self._planes.copy())
        normal = self._normal_values()
        friction = np.asarray(self._friction.value, dtype=float)
        twists = self._twists() * self._units[:, None, :]  # (E, K, 3), normalised
        sizes = np.sqrt(np.einsum("ekc,ekc->ek", twists, twists))
        weights = self._weights(sizes)
        # Twists below the floor count as none in the tests of a settled round, but still
        # steer stalled loads (``slow``): counted as none there too, the fixture of
        # benchmarks/bench_exact.py took 4.30 rounds per re-solve instead of 4.04.
        counted = weights if self._scale is not None else weights * (sizes >= FORCE_DUAL_FLOOR)
        noise = FRICTION_SET_RTOL * max(float(np.abs(normal).max(initial=0.0)), 1e-300)
        pairs = self._pairs
        moving, idle, finite = SOLVED_PAIRS(
            normal[self._contacts], friction, self._rows, noise, self._factors, twists,
            self._units, counted, *pairs,
        )  # fmt: skip
        owner, cases, per_unit, used, power = (array[:moving] for array in pairs[:5])
        self.use[:] = np.nan
        settled = self._reach(*(array[:idle] for array in pairs[5:]), counted)
        settled &= finite and bool(np.all(np.isfinite(weights)))  # (NaN twists weigh nothing)
        if moving == 0:
            self.held_back = np.zeros_like(self.held_back)  # (no load holds anything back)
            self._assign()
            return settled
        # The normals of the ellipsoids the solve used, at its loads (``used``): the exact
        # sliding twists near the optimum (stationarity), where the inverse map starts.
        excess, points = np.empty(moving), np.empty((moving, 3))
        found = np.empty((moving, 3, 3))
        for model, rows in self._by_model(owner):
            excess[rows], points[rows], found[rows] = model.osculating(per_unit[rows], used[rows])
        slow = np.empty(moving, dtype=bool)
        solved, cut, self.held_back = SETTLE(
            owner, cases, excess, points, found, used, power, counted, weights, self._contacts,
            self.use, self._previous_excess, self._factors, self._planes, self._next_slot, slow,
            EXACT_CUT_RTOL, STATIONARITY_RTOL, self._held_back_max(), self._scale is not None,
            PROGRESS, MARGIN, CUT_SLACK,
        )  # fmt: skip
        if slow.any():
            e, k = owner[slow], cases[slow]
            self._osculate_at(e, k, twists[e, k] / self._units[e])
        self._assign(cuts=cut)
        return settled and solved

    def _held_back_max(self) -> np.ndarray:
        """What the limiting loads left inside may cost the objective (``COMPLEMENTARITY_RTOL``
        of it, at least of 1): ``(1,)`` for a force objective, ``(K,)`` for the load multiples
        of a fixed-force block, each case's against its own (its loads move only it)."""
        if self._scale is None:
            return np.array([COMPLEMENTARITY_RTOL * max(abs(self._objective()), 1.0)])
        multiples = np.abs(np.asarray(self._scale.value, dtype=float))
        return COMPLEMENTARITY_RTOL * np.maximum(multiples, 1.0)

    def _osculate_at(self, owner: np.ndarray, cases: np.ndarray, twists: np.ndarray) -> None:
        """Move the ellipsoids of the pairs ``(owner, cases)`` to osculate where the exact set's
        normal is the pair's load-space twist ``(P, 3)`` (the pair's twist in the solve: see
        ``PROGRESS`` and :meth:`_reach`), where those ellipsoids are finite."""
        for model, rows in self._by_model(owner):
            e, k = owner[rows], cases[rows]
            found = model.osculating_at(twists[rows])[1]
            finite = np.all(np.isfinite(found), axis=(1, 2))
            self._factors[e[finite], k[finite]] = found[finite] * (1.0 + MARGIN)

    def _weights(self, sizes: np.ndarray) -> np.ndarray:
        """``(E, K)`` twist sizes relative to the largest (per case for fixed-force objectives,
        0 where the case's multiple sits at a bound)."""
        if self._scale is None:
            return sizes / max(float(sizes.max(initial=0.0)), FORCE_DUAL_FLOOR)
        weights = sizes / np.maximum(sizes.max(axis=0, initial=0.0), 1e-300)
        multiples = np.asarray(self._scale.value, dtype=float)
        weights[
            :, (multiples <= MULTIPLE_ATOL) | (multiples >= MAX_SAFETY_FACTOR * (1 - CAP_RTOL))
        ] = 0
        return weights

    def _reach(self, owner, cases, twists, reach, weights) -> bool:
        """Whether the ellipsoids of the unpressed pairs ``(owner, cases)`` of weight above 0
        reach as far as their exact sets in the directions of their load-space ``twists``
        (``SUPPORT_RTOL``; ``reach`` the ellipsoids' supports there); those that fall short
        are moved to osculate at the exact point with that normal."""
        if owner.size == 0:
            return True
        exact = np.empty(owner.size)
        for model, rows in self._by_model(owner):
            surface = model.surface
            exact[rows] = surface._trusted_support(twists[rows]) / surface.normal_force
        loose = weights[owner, cases] * (1.0 - reach / exact) > SUPPORT_RTOL
        if not loose.any():
            return True
        self._osculate_at(owner[loose], cases[loose], twists[loose])
        return False

    def _assign(self, cuts: bool = True) -> None:
        """Set the ellipsoids' Parameters (and the cuts', with ``cuts``)."""
        for (r, c), parameter in zip(self._entries, self._parameters, strict=True):
            assign(parameter, self._factors[:, :, r, c])
        if cuts:
            self._assign_cuts()
