"""Objective values of layouts: one switchable planner over every contact, re-solved with the
contacts left out switched off (no recompilation), behind the cheap feasibility test."""

from __future__ import annotations

import dataclasses
import math

from fixplan.design.friction_box import friction_box
from fixplan.design.prune import FeasibilityTest
from fixplan.planner.planner import Planner
from fixplan.planner.problem import FIXED_FORCE_OBJECTIVES, Problem, ProblemError


@dataclasses.dataclass(slots=True)
class Counts:
    """What a search did: layouts ``invalid`` (the objective has no free force to choose),
    ``pruned`` (the feasibility test failed), ``solved`` (masked re-solves), ``feasible``
    (solved to optimality)."""

    invalid: int = 0
    pruned: int = 0
    solved: int = 0
    feasible: int = 0


class Evaluator:
    """Evaluates layouts of ``problem`` (all contacts: the fixed ones and the candidates).

    A layout is a sorted tuple of contact indices (fixed ones included). Its score is the
    objective value turned into a cost (the safety factor of the fixed-force objectives
    negated); ``inf`` for layouts that are invalid, pruned or not solved to optimality.
    """

    def __init__(self, problem: Problem, *, prune: bool = True):
        self.problem = problem
        self.planner = Planner(problem, switchable=True)
        self.maximise = problem.objective in FIXED_FORCE_OBJECTIVES
        self.counts = Counts()
        self._names = [c.name for c in problem.contacts]
        self._cache: dict[tuple[int, ...], float] = {}
        self._test = None
        if prune:
            boxes, known = [], {}
            for model in self.planner.models:
                if id(model) not in known:
                    known[id(model)] = friction_box(model)
                boxes.append(known[id(model)])
            self._test = FeasibilityTest(problem, boxes, self.planner.length_scale)

    def subproblem(self, layout: tuple[int, ...]) -> Problem:
        """The problem with only the contacts of ``layout`` (raises ``ProblemError`` if the
        objective has nothing to choose in it)."""
        contacts = tuple(self.problem.contacts[i] for i in layout)
        return dataclasses.replace(self.problem, contacts=contacts)

    def score(self, layout: tuple[int, ...]) -> float:
        """The cost of ``layout`` (lower is better; ``inf``: not a holding layout)."""
        if layout in self._cache:
            return self._cache[layout]
        value = self._solve(layout)
        self._cache[layout] = value
        return value

    def ranked(self) -> list[tuple[int, ...]]:
        """The holding layouts scored so far, best first."""
        found = [(s, layout) for layout, s in self._cache.items() if math.isfinite(s)]
        return [layout for _, layout in sorted(found)]

    def value(self, score: float) -> float:
        """The objective value of a finite ``score``."""
        return -score if self.maximise else score

    def _solve(self, layout: tuple[int, ...]) -> float:
        try:
            self.subproblem(layout)
        except ProblemError:
            self.counts.invalid += 1
            return math.inf
        if self._test is not None and not self._test.holds(layout):
            self.counts.pruned += 1
            return math.inf
        chosen = set(layout)
        disabled = [name for i, name in enumerate(self._names) if i not in chosen]
        self.counts.solved += 1
        plan = self.planner.solve(disabled=disabled, analyse=False)
        if plan.status != "optimal" or plan.objective_value is None:
            return math.inf
        self.counts.feasible += 1
        value = float(plan.objective_value)
        return -value if self.maximise else value
