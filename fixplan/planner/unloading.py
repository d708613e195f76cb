"""Solves whose passive contacts hold no squeeze: the unloading of :mod:`fixplan.planner.squeeze`.

After a solve, each load case whose passive normal forces hold a squeeze has one of its members
unloaded, chosen by rating every member (:func:`~fixplan.planner.squeeze.choose_unloading`): a
fixed-force case by its multiple, a force objective's case by its least forces solved alone
(one load case of the same problem), each rated by its best squeeze-free completion; where the
cases' own choices do not hold together, one contact unloaded in every case whose squeeze holds
it. The problem is solved again until no case holds a squeeze.
"""

from __future__ import annotations

import dataclasses
import functools

import numpy as np

from fixplan.planner.objectives import ActiveForces
from fixplan.planner.problem import FIXED_FORCE_OBJECTIVES, PASSIVE_ROLES, Problem
from fixplan.planner.runner import Runner
from fixplan.planner.squeeze import choose_unloading, same_contact_trials, squeeze_members
from fixplan.planner.stacking import REFINE, ContactLayout


class SqueezeFree:
    """The squeeze-free solves of ``problem`` through ``runner``.

    Parameters
    ----------
    layout : ContactLayout
        The stacked contacts (their passive columns of ``normal_map``).
    length_scale : float
        The body's length scale [m] (moments against forces in the squeeze programs).
    squeezable : bool
        Whether some passive contacts can squeeze each other; without, a solve is the runner's.
    """

    def __init__(
        self, problem: Problem, layout: ContactLayout, runner: Runner, *, length_scale: float,
        squeezable: bool,
    ):  # fmt: skip
        self.problem = problem
        self._runner = runner
        self._passive = np.array([c.role in PASSIVE_ROLES for c in problem.contacts])
        self._passive_map = layout.normal_map[:, self._passive]
        self._active = ActiveForces(problem.contacts)
        self._length_scale = float(length_scale)
        self._squeezable = squeezable
        self._alone: Runner | None = None  # one load case, to rate unloadings

    def solve(
        self,
        objective,
        wrenches,
        given,
        squeezed,
        *,
        sense=1.0,
        accurate=False,
        progress=None,
        disabled=None,
        cases=None,
    ):
        """Solve ``objective``, unloading passive contacts until no case holds a squeeze.

        ``squeezed`` collects, per load case number, the contacts unloaded (for the notes);
        ``disabled`` ``(C,)`` bool marks the contacts switched off; ``cases`` numbers the load
        cases of ``wrenches`` among the problem's (default: all, in order).
        """
        options = {"sense": sense, "accurate": accurate, "progress": progress,
                   "disabled": disabled, "cases": cases}  # fmt: skip
        result = self._runner.run(objective, wrenches, given, **options)
        if not self._squeezable:
            return result
        unloaded = np.zeros((int(self._passive.sum()), wrenches.shape[1]), dtype=bool)
        passive_names = [c.name for c in self.problem.contacts if c.role in PASSIVE_ROLES]
        rate = functools.partial(self._trial_scores, objective, wrenches, given,
                                 options=dict(options, progress=None), memo={})  # fmt: skip
        for _ in range(len(passive_names)):
            if result["status"] not in ("optimal", "inaccurate"):
                break
            members = squeeze_members(
                self._passive_map, result["normal"][self._passive], self._length_scale
            )
            if not any(len(m) for m in members):
                break
            before, unloaded = unloaded, choose_unloading(members, unloaded, rate)
            result = self._runner.run(objective, wrenches, given, unloaded=unloaded, **options)
            if result["status"] == "infeasible" and objective not in FIXED_FORCE_OBJECTIVES:
                # Each case's own best need not hold together: with a clamp beside the
                # supports, more clamp force can lose a case. One contact unloaded in every
                # case may (the least objective of those that hold).
                found = self._uniform(objective, wrenches, given, members, before, options)
                if found is not None:
                    result, unloaded = found
        numbers = range(wrenches.shape[1]) if cases is None else np.asarray(cases).tolist()
        for j, number in enumerate(numbers):
            found = tuple(n for n, u in zip(passive_names, unloaded[:, j], strict=True) if u)
            if found:
                squeezed[number] = tuple(dict.fromkeys(squeezed.get(number, ()) + found))
        return result

    def _uniform(self, objective, wrenches, given, members, unloaded, options):
        """The best ``(result, unloading)`` of the force ``objective`` over the trials that
        unload one contact in every case whose squeeze holds it (``None`` if none holds)."""
        best, found = np.inf, None
        for trial in same_contact_trials(members, unloaded):
            result = self._runner.run(objective, wrenches, given, unloaded=trial, **options)
            if result["status"] not in ("optimal", "inaccurate"):
                continue
            value = self._force_objective(objective, result)
            if value < best:
                best, found = value, (result, trial)
        return found

    def _trial_scores(
        self, objective, wrenches, given, trial, decided, options, memo
    ) -> np.ndarray:
        """How well a trial unloading ``trial`` ``(passive, K)`` serves each load case
        ``decided`` ``(K,)`` on its own (see :func:`~fixplan.planner.squeeze.choose_unloading`):
        the task-load multiple (sign of ``sense``, larger first) of a fixed-force objective,
        whose cases are independent; else the objective of the case solved alone (free clamps
        couple the cases). ``inf`` where not solved or not decided.

        A case whose answer under the trial still holds a squeeze (the largest squeeze of a
        case can join several independent ones: two opposing pairs) is rated by the best of
        its squeeze-free completions (:meth:`_case_best`): rated as it stands, the other
        squeeze would still carry it, and every member would tie. ``memo`` keeps the ratings
        of (case, unloading) of one squeeze-free solve."""
        scores = np.full(wrenches.shape[1], np.inf)
        numbers = np.arange(wrenches.shape[1]) if options["cases"] is None else options["cases"]
        rest = decided.copy()
        if objective in FIXED_FORCE_OBJECTIVES:
            # Cases are independent: one run for all, and alone only the cases it does not
            # settle (still squeezed, or lost with the run: its status is its worst block's).
            result = self._runner.run(objective, wrenches, given, unloaded=trial, **options)
            if result["status"] in ("optimal", "inaccurate"):
                passive = result["normal"][self._passive]
                members = squeeze_members(self._passive_map, passive, self._length_scale)
                for j in np.flatnonzero(decided):
                    if not len(members[j]):
                        scores[j] = -options["sense"] * result["scale"][j]
                        rest[j] = False
        for j in np.flatnonzero(rest):
            values = {
                i: v if np.ndim(v) == 0 else float(np.asarray(v)[j]) for i, v in given.items()
            }
            scores[j] = self._case_best(
                objective, wrenches[:, [j]], values, trial[:, j].copy(), int(numbers[j]), options,
                memo,
            )  # fmt: skip
        return scores

    def _case_best(self, objective, wrench, values, column, number, options, memo) -> float:
        """The best rating (lower is better) of load case ``number`` solved alone (task
        ``wrench`` ``(6, 1)``, given forces ``values``) over the squeeze-free completions of
        the unloading ``column`` ``(passive,)``: where its answer holds a squeeze, each
        member is unloaded in turn."""
        key = (number, column.tobytes())
        if key in memo:
            return memo[key]
        memo[key] = np.inf  # (an unloading is only ever extended)
        ok = ("optimal", "inaccurate")
        run = {"sense": options["sense"], "accurate": options["accurate"],
               "disabled": options["disabled"], "cases": np.array([number])}  # fmt: skip
        if objective in FIXED_FORCE_OBJECTIVES:
            runner = self._runner
        else:
            if self._alone is None:
                alone = dataclasses.replace(self.problem, loads=self.problem.loads[:1])
                runner = self._runner
                self._alone = Runner(alone, runner.layout, runner.solver, squeeze=True,
                                     switchable=runner.switchable)  # fmt: skip
            runner = self._alone
        result = runner.run(objective, wrench, values, unloaded=column[:, None], **run)
        best = np.inf
        if result["status"] in ok:
            passive = result["normal"][self._passive]
            members = squeeze_members(self._passive_map, passive, self._length_scale)[0]
            if not len(members):
                if objective in FIXED_FORCE_OBJECTIVES:
                    best = -options["sense"] * float(result["scale"][0])
                else:
                    best = self._force_objective(objective, result)
            for member in members:
                more = column.copy()
                more[member] = True
                best = min(best, self._case_best(objective, wrench, values, more, number,
                                                 options, memo))  # fmt: skip
        memo[key] = best
        return best

    def _force_objective(self, objective: str, result: dict) -> float:
        """The value [N or N²] of the force ``objective`` (or its refining stage) at the active
        forces of ``result``."""
        forces = self._active.forces(result["normal"])
        return self._active.value(objective.removesuffix(REFINE), forces, result["scale"])
