"""Setting cvxpy Parameters on the planner's hot paths."""

from __future__ import annotations

import cvxpy as cp
import numpy as np


def assign(parameter: cp.Parameter, value) -> None:
    """Set ``parameter`` to ``value`` (broadcast to its shape) without cvxpy's validation,
    which costs more than a direct re-solve (about 100 µs for a ``(8, 20)`` array): the
    planner's values are checked where they come from (loads, given forces >= 0, multiples,
    the exact models' ellipsoids and cuts)."""
    array = np.asarray(value, dtype=float)
    if array.shape != parameter.shape:
        array = np.broadcast_to(array, parameter.shape)
    parameter.save_value(np.array(array))  # a copy: the caller may change its array
