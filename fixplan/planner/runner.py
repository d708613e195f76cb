"""Solving the stacked problems: compiled once, re-solved with new loads, block by block.

A :class:`Runner` keeps one compiled problem per objective. The fixed-force objectives solve
their load cases (independent, since the active forces are given) in blocks
(:mod:`fixplan.planner.blocks`), so that one compiled problem serves any number of cases; force
objectives solve all cases at once. A compiled problem is re-solved straight through Clarabel once cvxpy
has solved it twice (:mod:`fixplan.planner.direct_solve`): re-solves of a force objective with
new loads, and the blocks of a fixed-force objective after the second. A solver failure retries
once with a fallback solver (:mod:`fixplan.planner.solver_calls`); a fixed-force block of several
load cases is solved case by case instead (the fallback, SCS, is far less accurate). The answers
are read and joined by :mod:`fixplan.planner.answers`.

Every block is solved in a force unit of its own, a power of two (which divides without
rounding) that puts its largest force (the components of the task forces, of the task torques
over the contacts' longest lever, the weight, the given forces) near ``FORCE_IN_UNITS``: the
task and gravity wrenches, the given forces and the ``max_force`` bounds are divided by it and
the answers multiplied back.
The friction sets are cones, so the program in other units is the same program, but Clarabel's
answers are not equally good in all of them (its tolerances are partly absolute).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import cvxpy as cp
import numpy as np

from fixplan.planner.answers import SEVERITY, Reader, in_newtons, joined, merge_blocks, values_of
from fixplan.planner.blocks import CASES_PER_BLOCK, block_of, similar_order
from fixplan.planner.carried import Carried, WithoutLoad
from fixplan.planner.direct_solve import DirectSolver, same_values
from fixplan.planner.osculating import COMPLEMENTARITY_RTOL, OsculatingPool, smooth
from fixplan.planner.parameters import assign
from fixplan.planner.problem import FIXED_FORCE_OBJECTIVES, Problem
from fixplan.planner.solver_calls import FALLBACK, SOLVER_OPTIONS, call, uses_dpp
from fixplan.planner.stacking import ContactLayout, Stacked, build, set_given, set_units
from fixplan.planner.verify import LARGEST_SCALED_MAGNITUDE
from fixplan.tolerances import CAPPED_BLOCK_RTOL, CERTIFICATE_RTOL, MAX_SAFETY_FACTOR

#: The largest force of a block in the units it is solved in (see the module). Measured on the
#: 6-contact exact fixture of tests/test_exact_planner.py with given clamp forces (max-safety-
#: factor, largest force 120 N) and on a plate loaded with 7e4 N: with the largest force at 4 to
#: 1,024 units both are solved right, the first with osculating ellipsoids that settle in 8-9
#: rounds; at 1 unit or less those rounds stop 1e-7 outside the exact sets and fall back to the
#: cutting planes, at 4,096 and more too; in newtons (7e4 units) the plate's safety factor came
#: out 0.966 where 1 holds.
FORCE_IN_UNITS = 64.0

#: A load case of exact models starts its rounds from the osculating ellipsoids last placed
#: for it where its task wrench moved by at most this fraction of itself since (loads that
#: change smoothly), else from the ellipsoids through the exact sets' axis points. On the
#: fixture of benchmarks/bench_exact.py (12 pairs of independent milling loads ``A`` and ``C``,
#: each re-solve with ``A + t (C - A)`` after one with ``A``), the kept ellipsoids took 2.25,
#: 2.58, 3.17, 3.50 and 4.08 rounds at ``t`` = 0.1, 0.25, 0.5, 0.75 and 1, the axis ones 3.67,
#: 3.42, 3.50, 3.58 and 3.67.
START_CHANGE = 1.0


class Runner:
    """Compiled stacked problems of one :class:`~fixplan.Problem`, and their solves.

    A result is a dict with ``status``, ``solver``, ``warnings`` and, when solved, ``normal``
    ``(C, K)``, ``friction`` ``(D, K)``, ``scale`` ``(K,)``, ``dual`` ``(6, K)`` (the
    equilibrium multipliers: the twist of impending motion per case) and, with exact models,
    ``known_use`` ``(C, K)`` (their loads' friction use from the last round of cuts, NaN
    elsewhere).
    """

    def __init__(
        self,
        problem: Problem,
        layout: ContactLayout,
        solver: str,
        *,
        squeeze: bool,
        switchable: bool = False,
    ):
        self.problem = problem
        self.layout = layout
        self.solver = solver
        self.squeeze = squeeze
        self.switchable = switchable
        # Compiled problems and their direct solvers, keyed by (objective, osculating).
        self._built: dict[tuple, Stacked] = {}
        self._direct: dict[tuple, DirectSolver | None] = {}
        self._solves: dict[tuple, int] = {}
        self._given: dict[tuple, tuple | None] = {}  # (unit, given forces) last set, if scalars
        self._units: dict[tuple, float] = {}  # the force unit [N] each problem was last set in
        self._kept: dict[tuple, _Kept] = {}  # see _again
        self._readers: dict[tuple, Reader | None] = {}  # of the direct solves' answers
        #: The key of the program whose direct solve gave the last result (``None``: the last
        #: solve went through cvxpy), and the maps of its optimum into ``check``'s (see
        #: :meth:`carried_ends`, :meth:`held_without_load`).
        self._source: tuple | None = None
        #: The key of the program whose last solve went through its direct solver (``None``:
        #: through cvxpy); an osculating program settled so is a source too.
        self._directly: tuple | None = None
        self._carry: dict[tuple, Carried | None] = {}
        self._without_load: dict[tuple, WithoutLoad] = {}
        # Task torques over the longest lever [m] of a contact's normal force are forces.
        lever = max(float(np.linalg.norm(layout.normal_map[3:], axis=0).max()), 1e-3)
        self._per_force = np.repeat([1.0, 1.0 / lever], 3)  # task wrench rows -> forces
        self._weight = float(np.linalg.norm(problem.body.weight_wrench[:3]))
        #: Smooth exact models are first solved with osculating ellipsoids, conic programs that
        #: Clarabel solves (:mod:`fixplan.planner.osculating`); the cutting planes take over
        #: where those rounds do not settle.
        self.osculating = solver == "CLARABEL" and smooth(layout.models)
        self._layouts = {False: layout}
        # The last ellipsoids (E, 3, 3) of each load case, whichever program placed them, and of
        # each (objective, sense, load case), with the task wrench they were placed for. A
        # program starts from those placed for the same wrench, its own first (a re-solve with
        # the same loads), else the latest (a check after a force objective with new loads);
        # for a new wrench, from its own (loads that change smoothly) unless the wrench moved by
        # more than START_CHANGE of itself, then from the axis ellipsoids.
        self._ellipsoids: dict = {}
        if self.osculating:
            self._layouts[True] = ContactLayout.of(problem, list(layout.models), osculating=True)
        #: Whether the fixed-force programs are linear (pyramid models): their cases are then
        #: solved one by one, in an order of similar loads (see :meth:`run`).
        self.linear = all(_linear(model) for model in layout.models)

    def block_size(self, objective: str) -> int:
        """Load cases per compiled problem: the fixed-force objectives split into blocks."""
        cases = len(self.problem.loads)
        if objective not in FIXED_FORCE_OBJECTIVES:
            return cases
        return 1 if self.linear and self.solver == "CLARABEL" else min(cases, CASES_PER_BLOCK)

    def stacked(self, objective: str, osculating: bool = False) -> Stacked:
        """The compiled problem of ``objective`` (built on first use), with the exact contacts'
        osculating ellipsoids or (default) their cutting planes."""
        key = (objective, osculating)
        if key not in self._built:
            stacked = build(
                self.problem, self._layouts[osculating], objective, self.block_size(objective),
                squeeze=self.squeeze, switchable=self.switchable,
            )  # fmt: skip
            self._built[key] = stacked
        return self._built[key]

    def run(
        self,
        objective: str,
        wrenches: np.ndarray,
        given: dict,
        *,
        sense: float = 1.0,
        unloaded: np.ndarray | None = None,
        accurate: bool = False,
        progress=None,
        disabled: np.ndarray | None = None,
        cases: np.ndarray | None = None,
    ) -> dict:
        """Solve all load cases (task ``wrenches`` ``(6, K)``), block by block.

        ``given`` maps contact index -> its given normal force (float or ``(K,)``) [N];
        ``sense`` -1 minimises the task-load multiples instead of maximising them;
        ``unloaded`` ``(passive, K)`` marks passive contacts held without normal force;
        ``accurate`` turns Clarabel's iterative refinement on (for a retry when an answer failed
        verification); ``disabled`` ``(C,)`` bool switches contacts off (a runner built
        ``switchable``); ``cases`` ``(K,)`` numbers the load cases among the problem's (default
        ``0 ... K-1``). The last block is padded with copies of its first case.
        """
        numbers = cases
        cases = wrenches.shape[1]
        tried = False
        one_block = objective not in FIXED_FORCE_OBJECTIVES and cases == len(self.problem.loads)
        if one_block and not (accurate or self.osculating):
            # A force objective's cases are one block: straight to its kept direct solve where
            # there is one (re-solves in a control loop), the layers below only where it fails.
            tried, result = self._again(objective, wrenches, given, sense, unloaded, disabled)
            if result is not None:
                if progress is not None:
                    progress(cases, cases)
                return result
        numbers = np.arange(cases) if numbers is None else np.asarray(numbers)
        block = self.block_size(objective)
        if cases == block:  # one block, no padding (re-solves in a control loop)
            result = self._run_block(
                objective, wrenches, given, unloaded, numbers, sense, accurate, disabled,
                direct_failed=tried,
            )  # fmt: skip
            if progress is not None:
                progress(cases, cases)
            return result
        # One by one (linear programs), the cases go in an order of similar loads, so that
        # each starts the simplex from a nearby basis.
        order = similar_order(wrenches) if block == 1 else np.arange(cases)
        scalars = all(isinstance(value, float) for value in given.values())
        if block == 1 and unloaded is None and not accurate and scalars:
            results = self._one_by_one(objective, wrenches, given, order, numbers, sense,
                                       disabled, progress)  # fmt: skip
        else:
            results = []
            for start in range(0, cases, block):
                index = order[start : min(start + block, cases)]
                result = self._run_block(
                    objective, *block_of(index, block, wrenches, given, unloaded, numbers),
                    sense, accurate, disabled,
                )  # fmt: skip
                results.append((result, len(index)))
                if progress is not None:
                    progress(min(start + block, cases), cases)
        merged = merge_blocks(results)
        if block == 1:  # back to the cases' own order
            back = np.argsort(order)
            for key in ("normal", "friction", "scale", "dual", "known_use"):
                if merged.get(key) is not None:
                    merged[key] = merged[key][..., back]
        return merged

    def _one_by_one(
        self, objective, wrenches, given, order, numbers, sense, disabled, progress
    ) -> list[tuple[dict, int]]:
        """The results of the cases of a linear fixed-force objective whose given forces are
        plain numbers, one by one in ``order``: each through :meth:`_again` where it applies
        (only its task wrench written), else through :meth:`_run_block`."""
        results = []
        for position, j in enumerate(order):
            wrench = wrenches[:, j : j + 1]
            tried, result = self._again(objective, wrench, given, sense, None, disabled)
            if result is None:
                result = self._run_block(
                    objective, *block_of(order[position : position + 1], 1, wrenches, given,
                                          None, numbers), sense, False, disabled,
                    direct_failed=tried,
                )  # fmt: skip
            results.append((result, 1))
            if progress is not None:
                progress(position + 1, len(order))
        return results

    def _again(self, objective, wrenches, given, sense, unloaded, disabled) -> tuple:
        """A block straight through the direct solver of ``objective``, its parameters written
        into the parameter vector of its last direct solve (:meth:`_written`).

        Returns ``(tried, result)``: whether the direct solver was tried, and the result in
        newtons (optimal, or infeasible with Clarabel's certificate; ``None`` where it did not
        apply or failed: the caller then takes the full path, :meth:`_solve_block`)."""
        key = (objective, False)
        kept = self._written(key, wrenches, given, sense, unloaded, disabled)
        if kept is None:
            return False, None
        return True, self._direct_result(key, self._built[key], kept.vector, kept.unit)

    def _written(self, key, wrenches, given, sense, unloaded, disabled) -> _Kept | None:
        """The kept state of ``key``'s last direct solve (:class:`_Kept`) with these task
        wrenches, and the given forces, ``sense`` and force unit where they changed, written
        into its parameter vector rather than set through cvxpy. Applies where that solve had
        the same contacts disabled and none ``unloaded`` (else ``None``).
        """
        kept = self._kept.get(key)
        if kept is None or unloaded is not None or kept.disabled != _bytes(disabled):
            return None
        stacked, direct = self._built[key], self._direct[key]
        vector = kept.vector
        unit = self._force_unit(wrenches, given)
        if unit != kept.unit:  # (the Parameters keep theirs: see _set_parameters)
            set_units(stacked, self.problem.body.weight_wrench, unit,
                      put=lambda parameter, value: direct.write(vector, parameter, value))  # fmt: skip
            kept.unit, kept.given = unit, None  # (the given forces are written again)
        direct.write(vector, stacked.task, wrenches / unit)
        kept.wrenches = wrenches.copy()
        state = _given_state(given)
        if state is None or state != kept.given:
            # Into the vector alone: the Parameters keep the forces that _given names (a solve
            # through cvxpy sets them again where these differ), but where an answer is read
            # from them (no Reader).
            through_parameters = self._readers[key] is None

            def put(parameter, value):
                if through_parameters:
                    assign(parameter, value)
                direct.write(vector, parameter, value)

            set_given(stacked, given, unit, put=put)
            kept.given = state
            if through_parameters:
                self._given[key] = None if state is None else (unit, state)
        self._sensed(key, sense)
        return kept

    def _sensed(self, key, sense: float) -> None:
        """Write ``sense`` into ``key``'s kept parameter vector where it differs."""
        kept, stacked = self._kept[key], self._built[key]
        if stacked.sense is not None and sense != kept.sense:
            self._direct[key].write(kept.vector, stacked.sense, float(sense))
            kept.sense = sense

    def carried_ends(self, wrenches: np.ndarray, given: dict, disabled=None) -> dict:
        """The ends of the held interval of a single load case (task wrench ``(6, 1)``) at the
        ``given`` forces that need no solve of ``check`` (:mod:`fixplan.planner.carried`):
        ``"highest"`` where the last solve, direct and of a force objective whose forces these
        are, certifies ``k_max = 1`` (a result as :meth:`run` returns it, with the multipliers,
        but for the normal forces and friction loads: those of the force solve),
        ``"lowest"`` where it certifies ``k_min = 1`` or the forces hold the part without task
        load (``k_min = 0``, :meth:`held_without_load`); where ``"highest"`` is not certified,
        ``"solved"``: the maximising solve of ``check``, direct in the vector just written (where
        it is optimal). Empty where ``check`` has no kept direct solve for these forces."""
        key = ("check", False)
        if wrenches.shape[1] != 1:
            return {}
        if self._source is not None and self._source[0][1]:
            return self._osculated_ends(wrenches, given, disabled)
        kept = self._written(key, wrenches, given, 1.0, None, disabled)
        if kept is None:
            return {}
        direct, without = self._direct[key], self._without_load.get(key) or self._without(key)
        ends = {}
        source, unit = self._source or (None, 1.0)
        forces_solved = source is not None and source[0] not in FIXED_FORCE_OBJECTIVES
        carried = None
        if forces_solved:
            carried = self._carry[source] if source in self._carry else self._carried(source)
        held = -1  # (not tested yet)
        if carried is not None:
            solution, ratio = self._direct[source].solution, unit / kept.unit
            alpha, worst, held, _, z, program = carried.carry_at(
                solution, ratio, kept.vector, direct, without
            )
            if alpha < 0.0:  # the other end: the multiple minimised
                self._sensed(key, -1.0)
                alpha, worst, held, _, z, program = carried.carry_at(
                    solution, ratio, kept.vector, direct, without
                )
            if worst <= CERTIFICATE_RTOL and kept.sense > 0.0:
                ends["highest"] = _carried_result(kept, z[carried.balance])
            elif worst <= CERTIFICATE_RTOL:
                ends["lowest"] = {"status": "optimal", "scale": np.ones(1)}
        else:
            program = direct.program(kept.vector)
        if "lowest" not in ends and (held == 1 or (held < 0 and without.held(*program[1:]))):
            ends["lowest"] = {"status": "optimal", "scale": np.zeros(1)}
        if "highest" not in ends:
            # Solved where the vector was just written (the path through run() writes it again
            # and passes the layers of blocks: about as long as the solve).
            self._sensed(key, 1.0)
            solved = self._direct_result(key, self._built[key], kept.vector, kept.unit)
            if solved is not None and solved["status"] == "optimal":
                ends["solved"] = solved
        return ends

    def held_without_load(self, wrenches: np.ndarray, given: dict, disabled=None) -> bool:
        """Whether the ``given`` forces and the weight alone are held with no friction, so that
        a single load case (task wrench ``(6, 1)``) has ``k_min = 0`` without a solve
        (:class:`~fixplan.planner.carried.WithoutLoad`); ``False`` where this does not show it
        (or ``check`` has no kept direct solve for these forces)."""
        key = ("check", False)
        if wrenches.shape[1] != 1:
            return False
        kept = self._written(key, wrenches, given, -1.0, None, disabled)
        if kept is None:
            return False
        _, values, b = self._direct[key].program(kept.vector)
        return self._without(key).held(values, b)

    def _without(self, key: tuple) -> WithoutLoad:
        """The point of ``key``'s program without task load (built once)."""
        if key not in self._without_load:
            self._without_load[key] = WithoutLoad(self._built[key], self._direct[key])
        return self._without_load[key]

    def _carried(self, source: tuple) -> Carried | None:
        """The map from ``source``'s program to ``check``'s of the same kind (osculating or not;
        built once)."""
        key = ("check", source[1])
        if source not in self._carry:
            if key not in self._readers:
                self._readers[key] = Reader.of(self._built[key], self._direct[key])
            carried = None
            # (Else its answers are read through cvxpy; an osculating program's always are.)
            if self._readers[key] is not None or source[1]:
                carried = Carried.between(
                    self._built[source], self._direct[source], self._built[key], self._direct[key]
                )
            self._carry[source] = carried
        return self._carry[source]

    def _osculated_ends(self, wrenches: np.ndarray, given: dict, disabled=None) -> dict:
        """:meth:`carried_ends` after a force solve of osculating ellipsoids that settled in a
        direct solve: its optimum carried into ``check``'s osculating program, set with the
        ellipsoids and cuts of that solve's last round. Where the pair is optimal there, it is
        at the exact problem's too: the settled loads and twists, which met the exact problem's
        optimality conditions, are the pair's (the twists scaled by ``α > 0``; what its limiting
        loads left inside their sets cost, scaled alike, must be within ``check``'s own
        ``COMPLEMENTARITY_RTOL``). The point without load has no friction, which every exact
        set holds. (No ``"solved"``: ``check`` is solved in its rounds.)"""
        (source, unit), key = self._source, ("check", True)
        direct = self._direct.get(key)
        if (
            source[0] in FIXED_FORCE_OBJECTIVES
            or direct is None
            or self._direct.get(source) is None
        ):
            return {}  # (not a force solve, or ``check`` has had no direct solve yet)
        stacked = self.stacked(*key)
        check_unit = self._force_unit(wrenches, given)
        stacked.exact.follow(self._built[source].exact)
        carried = self._carried(source)
        if carried is None:
            return {}
        ends = {}
        # What the force solve's limiting loads left inside their sets cost it, in check's
        # units (its twists are the force solve's times α, its forces times the units' ratio):
        # held to check's own COMPLEMENTARITY_RTOL of the multiple 1.
        held_back = float(self._built[source].exact.held_back.sum()) * unit / check_unit
        for sense in (1.0, -1.0):  # (the other end where the multiple is minimised: α < 0)
            self._set_parameters(key, stacked, wrenches / check_unit, given, sense, None,
                                 disabled, check_unit)  # fmt: skip
            q, values, b = direct.program(direct.parameter_vector())
            alpha, worst, _, z = carried.carry(
                self._direct[source].solution, unit / check_unit, q, values, b
            )
            if abs(alpha) * held_back > COMPLEMENTARITY_RTOL:
                worst = np.inf  # (check's own rounds find that end)
            if worst <= CERTIFICATE_RTOL and sense > 0.0:
                ends["highest"] = {"status": "optimal", "solver": "carried from the force solve",
                                   "warnings": [], "scale": np.array([1.0]),
                                   "dual": z[carried.balance][:, None] / check_unit}  # fmt: skip
            elif worst <= CERTIFICATE_RTOL:
                ends["lowest"] = {"status": "optimal", "scale": np.ones(1)}
            if alpha >= 0.0:
                break
        if "lowest" not in ends and self._without(key).held(values, b):
            ends["lowest"] = {"status": "optimal", "scale": np.zeros(1)}
        return ends

    def with_sense(self, objective, wrenches, given, sense, disabled=None) -> dict | None:
        """The fixed-force ``objective`` solved again with ``sense`` where the parameter
        vector of its last direct solve holds these task ``wrenches`` ``(6, K)`` (all in one
        block) and ``given`` forces (plain numbers), the same contacts ``disabled`` and none
        unloaded: only the sense is written (the other end of the held intervals just solved).
        The result in newtons, or ``None`` where this does not apply or the solve fails."""
        key = (objective, False)
        kept = self._kept.get(key)
        if (
            kept is None
            or self.osculating
            or kept.given is None
            or kept.given != _given_state(given)
            or kept.disabled != _bytes(disabled)
            or not same_values(kept.wrenches, wrenches)
        ):
            return None
        self._sensed(key, sense)
        return self._direct_result(key, self._built[key], kept.vector, kept.unit)

    def _run_block(
        self, objective, wrenches, given, unloaded, numbers, sense, accurate, disabled,
        direct_failed=False,
    ) -> dict:  # fmt: skip
        """One block (its load cases ``numbers`` among the problem's), and again for the cases
        whose largest multiple shared it with cases at the cap ``MAX_SAFETY_FACTOR``.

        Those carry forces ``MAX_SAFETY_FACTOR`` times their task loads, and the solver's
        tolerances, relative to the largest terms, blur the others: a case held at every
        multiple with a friction margin of 1e-4 came out held to 0.497, reported optimal.

        A fixed-force block that Clarabel does not solve is solved case by case
        (:meth:`_case_by_case`) rather than by the fallback solver. ``direct_failed``: the
        direct solver has just failed on this block's parameters (see :meth:`_solve_block`)."""
        separable = (
            objective in FIXED_FORCE_OBJECTIVES and len(numbers) > 1 and np.unique(numbers).size > 1
        )
        result = self._solve_block(
            objective, wrenches, given, unloaded, numbers, sense, accurate, disabled,
            fallback=not separable, direct_failed=direct_failed,
        )  # fmt: skip
        if separable and result["status"] in ("solver-error", "inaccurate"):
            return self._case_by_case(
                objective, wrenches, given, unloaded, numbers, sense, accurate, disabled, result
            )
        if (
            objective not in FIXED_FORCE_OBJECTIVES
            or sense < 0
            or result["status"] not in ("optimal", "inaccurate")
        ):
            return result
        capped = result["scale"] >= MAX_SAFETY_FACTOR * (1.0 - CAPPED_BLOCK_RTOL)
        if not capped.any():
            return result
        again = np.flatnonzero(~capped)
        if again.size == 0:
            return result
        # Through this method again where that leaves fewer cases (a case can reach the cap
        # only without its capped block mates, and then blurs the others in turn); not where
        # only copies of a case reached the cap (padding), which would repeat the same block.
        fewer = np.unique(numbers[again]).size < np.unique(numbers).size
        block = block_of(again, len(numbers), wrenches, given, unloaded, numbers)
        if fewer:
            redo = self._run_block(objective, *block, sense, accurate, disabled)
        else:
            redo = self._solve_block(objective, *block, sense, accurate, disabled, fallback=False)
            if redo["status"] in ("solver-error", "inaccurate"):
                redo = self._case_by_case(objective, *block, sense, accurate, disabled, redo)
        if redo["status"] not in ("optimal", "inaccurate"):
            return result
        for key in ("normal", "friction", "scale", "dual", "known_use"):
            if result.get(key) is not None and redo.get(key) is not None:
                result[key][..., again] = redo[key][..., : again.size]
        result["status"] = max(result["status"], redo["status"], key=SEVERITY.index)
        result["solver"] = joined((result["solver"], redo["solver"]))
        result["warnings"] = list(dict.fromkeys(result["warnings"] + redo["warnings"]))
        return result

    def _case_by_case(
        self, objective, wrenches, given, unloaded, numbers, sense, accurate, disabled, failed
    ) -> dict:
        """The distinct cases of a fixed-force block that the solver ``failed`` on (its result),
        each solved alone (with the fallback solver where Clarabel fails again).

        The fallback (SCS) on the whole block can be far off: a case held to 0.373 (the
        reference) came out held to 0.765, beside block mates held near the cap."""
        _, first, column = np.unique(numbers, return_index=True, return_inverse=True)
        solved = [
            (self._run_block(
                objective, *block_of(first[j : j + 1], len(numbers), wrenches, given, unloaded,
                                      numbers), sense, accurate, disabled,
            ), 1)
            for j in range(first.size)
        ]  # fmt: skip
        merged = merge_blocks(solved)
        for key in ("normal", "friction", "scale", "dual", "known_use"):
            if merged.get(key) is not None:
                merged[key] = merged[key][..., np.ravel(column)]
        note = (
            f"{failed['solver']} returned {failed['status']} on a block of {first.size} load "
            "cases; solved them one by one"
        )
        merged["warnings"] = list(dict.fromkeys([*failed["warnings"], note, *merged["warnings"]]))
        return merged

    def _solve_block(
        self,
        objective,
        wrenches,
        given,
        unloaded,
        numbers,
        sense,
        accurate,
        disabled,
        fallback=True,
        direct_failed=False,
    ) -> dict:
        """One block: with osculating ellipsoids first where they apply, else (or where their
        rounds do not settle) with cutting planes or no exact models at all; without
        ``fallback``, a solver failure is returned as it is (no retry with another solver);
        with ``direct_failed`` (the direct solver failed on these parameters just before),
        straight to the solve that :meth:`_direct_result` would have preceded."""
        if not (accurate or direct_failed or self.osculating):
            direct_failed, result = self._again(
                objective, wrenches, given, sense, unloaded, disabled
            )
            if result is not None:
                return result
        unit = self._force_unit(wrenches, given)
        for osculating in (True, False) if self.osculating else (False,):
            key = (objective, osculating)
            stacked = self.stacked(*key)
            self._set_parameters(key, stacked, wrenches / unit, given, sense, unloaded, disabled,
                                 unit)  # fmt: skip
            exact = stacked.exact is not None  # rounds follow every solve
            # One try of the direct solver per block: each failed try of its simplex counts as
            # a missed warm start (see :mod:`fixplan.planner.dual_simplex`).
            tried = direct_failed and not osculating
            if not (accurate or exact or tried):
                direct = self._direct.get(key)
                vector = None if direct is None else direct.parameter_vector()
                result = None if vector is None else self._direct_result(key, stacked, vector, unit)
                if result is not None:
                    if unloaded is None:  # (osculating programs are never solved directly)
                        self._kept[key] = _Kept(unit, _bytes(disabled), _given_state(given),
                                                float(sense), vector, wrenches.copy())  # fmt: skip
                    return result
                tried = key in self._direct
            if osculating:
                cases = [(objective, sense, n, wrenches[:, j]) for j, n in enumerate(numbers)]
                stacked.exact.place([self._start(*case) for case in cases])
            notes = []
            status, settled = self._solve(key, stacked, self.solver, accurate, notes,
                                          direct_first=not tried)  # fmt: skip
            if osculating:
                self._remember(cases, stacked.exact.ellipsoids)
                if not settled:
                    continue
                # Settled: the loads meet the exact problem's optimality conditions, checked
                # here whatever the solver said of its accuracy.
                solver = f"{self.solver} (osculating ellipsoids)"
                if self._directly == key:  # (its optimum is the direct solver's: carried_ends)
                    self._source = (key, unit)
                return in_newtons(self._result(stacked, "optimal", solver, notes), unit, objective)
            solver = self.solver
            if status in ("solver-error", "inaccurate") and not fallback:
                return {"status": status, "solver": solver, "warnings": notes}
            if status in ("solver-error", "inaccurate"):
                notes.append(f"{solver} returned {status}; retried with {FALLBACK[solver]}")
                solver = FALLBACK[solver]
                status, _ = self._solve(key, stacked, solver, False, notes)
            if exact:
                solver = f"{solver} (cutting planes)"
            return in_newtons(self._result(stacked, status, solver, notes), unit, objective)

    def _force_unit(self, wrenches: np.ndarray, given: dict) -> float:
        """The force unit [N] of a block with task ``wrenches`` ``(6, K)`` and ``given`` forces:
        the power of two that puts its largest force nearest ``FORCE_IN_UNITS``; 1 N for none."""
        largest = max(LARGEST_SCALED_MAGNITUDE(wrenches, self._per_force), self._weight)
        for value in given.values():  # (plain numbers, or arrays of the cases)
            largest = max(largest, value if isinstance(value, float) else float(np.max(value)))
        return 2.0 ** round(math.log2(largest / FORCE_IN_UNITS)) if largest > 0.0 else 1.0

    def _start(self, objective, sense, case, wrench: np.ndarray) -> np.ndarray | None:
        """The ellipsoids ``(E, 3, 3)`` a program starts from for ``case`` (see ``__init__``)."""
        own = self._ellipsoids.get((objective, sense, int(case)))
        latest = self._ellipsoids.get(int(case))
        for kept in (own, latest):
            if kept is not None and same_values(kept[0], wrench):
                return kept[1]
        kept = own if own is not None else latest
        if kept is None or self._moved(kept[0], wrench) > START_CHANGE:
            return None  # (the axis ellipsoids)
        return kept[1]

    def _moved(self, old: np.ndarray, new: np.ndarray) -> float:
        """How far the task wrench moved from ``old`` to ``new`` ``(6,)``, relative to ``old``
        (torques as forces at the longest lever)."""
        change = np.linalg.norm((new - old) * self._per_force)
        size = np.linalg.norm(old * self._per_force)
        return float(change / size) if size > 0.0 else np.inf

    def _remember(self, cases: list, ellipsoids: np.ndarray) -> None:
        """Keep the ellipsoids ``(E, K, 3, 3)`` a program placed for its ``cases``
        (``(objective, sense, case, wrench)`` each)."""
        for j, (objective, sense, case, wrench) in enumerate(cases):
            kept = (wrench.copy(), ellipsoids[:, j])
            self._ellipsoids[int(case)] = self._ellipsoids[(objective, sense, int(case))] = kept

    def _set_parameters(
        self, key, stacked, wrenches, given, sense, unloaded, disabled, unit
    ) -> None:
        """Set the task ``wrenches`` (already in the force ``unit``), the ``given`` forces [N]
        and the rest of ``stacked``'s parameters."""
        assign(stacked.task, wrenches)
        if self._units.get(key) != unit:
            set_units(stacked, self.problem.body.weight_wrench, unit)
            self._units[key] = unit
        scalars = _given_state(given)
        state = None if scalars is None else (unit, scalars)
        if state is None or self._given.get(key) != state:
            set_given(stacked, given, unit)  # (not again for the same forces)
            self._given[key] = state
        if stacked.sense is not None:
            assign(stacked.sense, float(sense))
        if stacked.unloaded is not None:
            assign(stacked.unloaded, 0.0 if unloaded is None else unloaded.astype(float))
        if stacked.disabled is not None:
            assign(stacked.disabled, 0.0 if disabled is None else disabled.astype(float))

    @staticmethod
    def _result(stacked: Stacked, status: str, solver: str, notes: list) -> dict:
        result = {"status": status, "solver": solver, "warnings": notes}
        if status in ("optimal", "inaccurate"):
            result.update(values_of(stacked))
            if stacked.exact is not None:
                result["known_use"] = stacked.exact.use.copy()
        if status in ("optimal", "inaccurate", "infeasible"):
            dual = stacked.balance.dual_value
            result["dual"] = None if dual is None else np.asarray(dual, dtype=float)
        return result

    def _solve(
        self, key, stacked: Stacked, solver: str, accurate: bool, notes, *, direct_first=True
    ) -> tuple:
        """Solve ``stacked``, with the rounds of its exact contacts (notes are appended); each
        solve goes through Clarabel directly once a direct solver exists (the first only with
        ``direct_first``: not where the direct solver just failed). Returns the status and
        whether the rounds settled (always, but for osculating ellipsoids)."""
        direct = direct_first
        self._source = None

        def once() -> str:
            nonlocal direct
            use, direct = direct and not accurate and solver == self.solver, True
            self._directly = None
            if use and self._direct_into(key, stacked):
                self._directly = key
                return "optimal"
            status = call(stacked.problem, solver, accurate=accurate)
            if status == "optimal" and solver == self.solver:
                self._prepare_direct(key, stacked)
            return status

        def value() -> float:
            if self._directly == key:
                return self._direct[key].objective_value
            found = stacked.problem.value
            return float("nan") if found is None else float(found)  # (NaN: the rounds go on)

        status = once()
        if stacked.exact is None:
            return status, True
        if isinstance(stacked.exact, OsculatingPool):
            return stacked.exact.converge(once, status, value)
        status, more = stacked.exact.converge(once, status)
        notes.extend(more)
        return status, True

    def _direct_into(self, key: tuple, stacked: Stacked) -> bool:
        """Solve through Clarabel directly into the cvxpy variables and the equilibrium's
        multipliers, where a direct solver exists and solves the problem."""
        direct = self._direct.get(key)
        values = None if direct is None else direct.solve()
        dual = None if values is None else direct.dual(stacked.balance)
        if dual is None:
            return False
        for variable in stacked.problem.variables():
            variable.save_value(values[variable.id])
        stacked.balance.save_dual_value(dual)
        return True

    def _direct_result(self, key: tuple, stacked: Stacked, vector, unit: float) -> dict | None:
        """Solve straight through Clarabel when a direct solver exists for ``key`` (with the
        parameters of the parameter ``vector``, in the force ``unit`` [N]; the answer read from
        the solution, not through the cvxpy variables), the result in newtons. Where Clarabel
        finds the problem infeasible, its certificate is the equilibrium's multipliers, as cvxpy
        would report them."""
        self._source = None
        direct = self._direct.get(key)
        if direct is None:
            return None
        if key not in self._readers:  # (before any answer: _written asks for it after either)
            self._readers[key] = Reader.of(stacked, direct)
        if not direct.solved(vector=vector):
            if not direct.infeasible:
                return None
            result = {"status": "infeasible", "solver": "CLARABEL (direct)", "warnings": [],
                      "dual": direct.dual(stacked.balance)}  # fmt: skip
            return in_newtons(result, unit, key[0])
        reader = self._readers[key]
        answer = values_of(stacked, direct.values()) if reader is None else reader(direct)
        self._source = (key, unit)
        result = {"status": "optimal", "solver": f"{direct.method} (direct)", "warnings": [],
                  **answer, "dual": direct.dual(stacked.balance)}  # fmt: skip
        return in_newtons(result, unit, key[0])

    def _prepare_direct(self, key: tuple, stacked: Stacked) -> None:
        """Build the direct solver of an objective after its second cvxpy solve.

        It is checked against that solve's answer (same parameters); one-off problems never
        pay for it.
        """
        if self.solver != "CLARABEL":
            return
        if key in self._direct or stacked.problem.status != cp.OPTIMAL:
            return
        if not uses_dpp(stacked.problem):
            return
        self._solves[key] = self._solves.get(key, 0) + 1
        if self._solves[key] >= 2:
            self._direct[key] = DirectSolver.create(stacked.problem, SOLVER_OPTIONS["CLARABEL"])


@dataclass(slots=True)
class _Kept:
    """The parameter ``vector`` of an objective's last direct solve (none unloaded), and what
    it was set for: the force ``unit`` [N], the ``disabled`` contacts (:func:`_bytes`), the
    ``given`` forces (:func:`_given_state`; ``None``: arrays), the ``sense`` and the task
    ``wrenches`` ``(6, K)`` [N, N m] (a copy)."""

    unit: float
    disabled: bytes | None
    given: tuple | None
    sense: float
    vector: np.ndarray
    wrenches: np.ndarray


def _carried_result(kept: _Kept, dual: np.ndarray) -> dict:
    """The result of ``check`` (one load case) at the carried point: the multiple 1
    and the equilibrium's multipliers ``dual`` ``(6,)`` in newtons (its forces are the
    force solve's)."""
    return {"status": "optimal", "solver": "carried from the force solve", "warnings": [],
            "scale": np.array([1.0]), "dual": dual[:, None] / kept.unit}  # fmt: skip


def _bytes(disabled: np.ndarray | None) -> bytes | None:
    return None if disabled is None else disabled.tobytes()


def _given_state(given: dict) -> tuple | None:
    """Given forces that are plain numbers as a comparable tuple; ``None`` if any is an array."""
    if not given:
        return ()
    for value in given.values():
        if not isinstance(value, float):
            return None
    return tuple(given.items())


def _linear(model) -> bool:
    """Whether a contact's friction set is polyhedral (its program rows are linear)."""
    terms = model.gauge_terms()
    return model.frictionless or (terms is not None and all(k == "max" for k, _ in terms))
