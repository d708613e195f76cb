r"""The large mode's convex relaxation: every candidate on, few of them carrying force.

The planner's stacked problem over all contacts (:func:`fixplan.planner.stacking.build`) gets a
group-sparse penalty on the normal forces, one group per contact over the load cases,

.. math:: \text{objective} + \sum_i w_i \, \lVert n_{i,:} \rVert_2, \qquad
   w_i = \frac{\lambda}{\lVert n_{i,:}^{\text{prev}} \rVert_2 + \epsilon},

re-solved ``RELAXATION_ROUNDS`` times with the weights of the previous answer (reweighted
:math:`\ell_1`, Candès–Wakin–Boyd), starting from the plain plan with every candidate on.
``λ`` is that plan's objective value over the number of contacts to choose, so that a contact
that carries force costs about as much as its share of the objective. The answer ranks the
candidates by the force they still carry; it is a heuristic (the squeeze rule and the cuts of
exact models are left out), which the local search of :mod:`fixplan.design.layout` then improves
with exact re-solves.
"""

from __future__ import annotations

import cvxpy as cp
import numpy as np

from fixplan.planner.parameters import assign
from fixplan.planner.planner import Planner
from fixplan.planner.problem import SOLVED_AS
from fixplan.planner.stacking import build, normal_forces, set_given, set_units

#: Reweighting rounds.
RELAXATION_ROUNDS = 4
#: ``ε`` of the weights, relative to the largest group norm.
REWEIGHT_EPS = 1e-2


def relaxed_forces(planner: Planner, chosen: int) -> np.ndarray | None:
    """Per contact of ``planner``'s problem, the norm over the load cases of its normal force
    [N] after the reweighted relaxation (``chosen``: how many contacts a layout has); ``None``
    when the problem with every contact on is not solved to optimality."""
    problem = planner.problem
    plan = planner.solve(analyse=False)
    if plan.status != "optimal":
        return None
    forces = np.linalg.norm(plan.normal_forces, axis=1)
    scale = max(abs(float(plan.objective_value)), 1e-9) / max(chosen, 1)
    objective = SOLVED_AS.get(problem.objective, problem.objective)
    cases = len(problem.loads)
    stacked = build(problem, planner.layout, objective, cases, squeeze=False)
    assign(stacked.task, problem.task_wrenches())
    set_units(stacked, problem.body.weight_wrench)
    set_given(stacked, {i: c.force for i, c in enumerate(problem.contacts) if c.force is not None})
    if stacked.sense is not None:
        assign(stacked.sense, 1.0)
    penalty, weights = 0, []
    for index, piece in stacked.normal_parts:
        if not isinstance(piece, cp.Variable):
            continue
        weight = cp.Parameter(len(index), nonneg=True)
        norms = cp.norm(piece, 2, axis=1) if piece.ndim == 2 else np.sqrt(cases) * cp.abs(piece)
        penalty = penalty + weight @ norms
        weights.append((index, weight))
    base = stacked.problem.objective
    goal = (
        cp.Maximize(base.expr - penalty)
        if isinstance(base, cp.Maximize)
        else cp.Minimize(base.expr + penalty)
    )
    relaxed = cp.Problem(goal, stacked.problem.constraints)
    for _ in range(RELAXATION_ROUNDS):
        eps = REWEIGHT_EPS * max(forces.max(), 1e-12)
        for index, weight in weights:
            weight.value = scale / (forces[index] + eps)
        relaxed.solve(solver=cp.CLARABEL)
        if relaxed.status not in (cp.OPTIMAL, cp.OPTIMAL_INACCURATE):
            break
        forces = np.linalg.norm(normal_forces(stacked), axis=1)
    return forces
