"""The planner's objectives, as cvxpy expressions and evaluated on a verified answer.

Force objectives minimise the free active normal forces with every task load applied; the
fixed-force objectives (``check``, ``max-safety-factor``) take the active forces as given and
find how far each task load can be scaled. Given forces are constants and stay out of a force
objective, so that it does not go flat.
"""

from __future__ import annotations

import cvxpy as cp
import numpy as np

from fixplan.planner.problem import FIXED_FORCE_OBJECTIVES


def objective_expression(objective, *, scale, sense, clamps, fingers, free_forces):
    """The cvxpy objective.

    ``clamps`` ``(c,)`` and ``fingers`` ``(f, K)`` are the free clamp and finger forces (or
    ``None``), ``free_forces`` ``(c + f, K)`` all free active normal forces per case, ``scale``
    ``(K,)`` the task-load multiples and ``sense`` (+1 or -1) whether they are maximised or
    minimised (fixed-force objectives).
    """
    if objective in FIXED_FORCE_OBJECTIVES:
        return cp.Maximize(sense * cp.sum(scale))
    # Without a free clamp the load cases are independent: minimising the sum of the per-case
    # worst values gives every case its own least forces, and the largest of them is the
    # min-max. A free clamp couples the cases, and then the max is minimised directly.
    worst = cp.max if clamps is not None else cp.sum
    if objective == "min-total-clamp-force":
        total = cp.sum(clamps) if clamps is not None else 0.0
        if fingers is not None:
            total = total + worst(cp.sum(fingers, axis=0))
        return cp.Minimize(total)
    if objective == "min-max-normal-force":
        return cp.Minimize(worst(cp.max(free_forces, axis=0)))
    if objective == "min-total-normal-force":
        return cp.Minimize(worst(cp.sum(free_forces, axis=0)))
    return cp.Minimize(cp.sum_squares(free_forces))  # min-squared-normal-force


class ActiveForces:
    """The active contacts of a problem: their normal forces and a force objective's value.

    Parameters
    ----------
    contacts : sequence of Contact
        The problem's contacts; rows of the normal forces below are in their order.
    """

    def __init__(self, contacts):
        #: (row, name, whether a clamp) of each clamp and finger.
        self._active = [
            (i, c.name, c.role == "clamp")
            for i, c in enumerate(contacts)
            if c.role in ("clamp", "finger")
        ]
        self._clamps = [name for _, name, clamp in self._active if clamp]
        self._fingers = [name for _, name, clamp in self._active if not clamp]

    def forces(self, normal: np.ndarray) -> dict:
        """The active normal forces of ``normal`` ``(C, K)`` [N] by contact name: a clamp's one
        force, a finger's ``(K,)`` (negative solver noise clipped to 0)."""
        forces = {}
        for i, name, clamp in self._active:
            forces[name] = max(float(normal[i, 0]), 0.0) if clamp else np.maximum(normal[i], 0.0)
        return forces

    def value(self, objective: str, forces: dict, scale: np.ndarray) -> float:
        """The objective's value for the active ``forces`` (from :meth:`forces`) [N or N²];
        for the fixed-force objectives the smallest task-load multiple ``scale`` ``(K,)``."""
        if objective in FIXED_FORCE_OBJECTIVES:
            return float(scale.min())
        if objective == "min-total-clamp-force":
            total = sum(forces[name] for name in self._clamps)
            if self._fingers:
                total += np.max(np.sum([forces[name] for name in self._fingers], axis=0))
            return float(total)
        per_case = [np.broadcast_to(value, scale.shape) for value in forces.values()]
        if objective == "min-max-normal-force":
            return float(np.max(per_case))
        if objective == "min-total-normal-force":
            return float(np.max(np.sum(per_case, axis=0)))
        return float(np.sum(np.square(per_case)))  # min-squared-normal-force
