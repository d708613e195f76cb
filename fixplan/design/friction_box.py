"""The smallest box around a friction model's set, per unit normal force: an outer polyhedral
approximation for the cheap feasibility test of :mod:`fixplan.design.prune`.

The box is that of the set the planner states (the model's :meth:`conic_form`: for the exact model
an outer polytope, or its exact set on point supports), so it contains every friction load the
planner can use.
"""

from __future__ import annotations

import cvxpy as cp
import numpy as np

from fixplan.models.base import FrictionModel
from fixplan.models.conic import soc_columns

#: Relative margin added to each half-width, so that solver rounding never cuts into the set.
BOX_MARGIN = 1e-6


def friction_box(model: FrictionModel) -> np.ndarray:
    """Half-widths ``(d,)`` of the box ``|ℓ_k| <= b_k`` around ``model``'s friction loads at
    unit normal force [N, N m per N], ``ℓ = (ft1, ft2[, mn])`` (sets are centrally symmetric)."""
    form = model.conic_form()
    dimension = form.load.shape[1]
    if model.frictionless:
        return np.zeros(dimension)
    load = cp.Variable(dimension)
    aux = cp.Variable(form.aux.shape[1]) if form.aux.shape[1] else None
    direction = cp.Parameter(dimension)
    constraints, start = [], 0
    for kind, size in form.cones:
        rows = slice(start, start + size)
        start += size
        expression = form.normal[rows] + form.load[rows] @ load
        if aux is not None:
            expression = expression + form.aux[rows] @ aux
        if kind == "zero":
            constraints.append(expression == 0)
        elif kind == "nonneg":
            constraints.append(expression >= 0)
        else:
            constraints.append(soc_columns(cp.reshape(expression, (size, 1), order="F"), size))
    problem = cp.Problem(cp.Maximize(direction @ load), constraints)
    half = np.zeros(dimension)
    for k in range(dimension):
        direction.value = np.eye(dimension)[k]
        problem.solve(solver=cp.CLARABEL)
        half[k] = float(problem.value)
    return half * (1.0 + BOX_MARGIN) + BOX_MARGIN * half.max()
