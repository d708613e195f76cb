r"""Passive contacts that squeeze each other, and the rule that keeps them from doing so.

A *squeeze* is a set of passive normal forces ``s >= 0``, ``s != 0``, whose wrenches cancel,
``G_p s = 0`` (two opposing locators pressing on each other through the part). A rigid model admits any
amount of it, and with it friction that no active force or load causes: a block between two opposing
point locators (mu 0.3, pushed sideways with 100 N) is "held" by 253 N that each locator applies to
the other. Which squeeze really acts depends on the compliance and the preload of the contacts,
which the rigid model does not know.

Rule: the passive normal forces of every load case are *squeeze-free*: no squeeze fits under
them (there is no ``s`` with ``0 <= s <= f_p``), i.e. in every squeeze at least one contact carries
no normal force. It is enforced by unloading: after a solve, the largest squeeze under the
passive forces of each case is found (a linear program); of its contacts, the one it loads most
in proportion (``f_i / s_i`` smallest) is held without normal force in that case, and the problem
is solved again, until no case contains a squeeze.

The rule is conservative: it only removes reactions that the rigid model admits, so forces are
never lower and safety factors never higher than the rigid model's, and it never relies on a
preload that nothing applies. It is not unique (another unloading order may hold where this one
does not); the compliant analysis gives the determinate answer.
"""

from __future__ import annotations

import numpy as np
from scipy.optimize import linprog

from fixplan.tolerances import SQUEEZE_RTOL


def squeezing(normal_map: np.ndarray, length_scale: float) -> np.ndarray:
    """Which contacts (columns of ``normal_map`` ``(6, P)``, passive contacts' wrenches per unit
    normal force) take part in some squeeze: ``(P,)`` bool. ``length_scale`` [m] makes moments
    comparable with forces."""
    count = normal_map.shape[1]
    found = np.zeros(count, dtype=bool)
    # Each linear program finds a squeeze that loads contacts not yet found, until none does.
    while not found.all():
        squeeze = _largest_squeeze(normal_map, np.ones(count), length_scale, weights=~found)
        new = (squeeze > SQUEEZE_RTOL) & ~found
        if not new.any():
            break
        found |= squeeze > SQUEEZE_RTOL
    return found


def unload_squeezes(
    normal_map: np.ndarray, passive_forces: np.ndarray, length_scale: float
) -> np.ndarray:
    """Contacts to unload, ``(P, K)`` bool: per load case (columns of ``passive_forces``
    ``(P, K)`` [N]) the contact of the largest squeeze under the forces that the squeeze loads
    most in proportion; none where a case holds no squeeze."""
    unload = np.zeros(passive_forces.shape, dtype=bool)
    for j, forces in enumerate(passive_forces.T):
        forces = np.maximum(forces, 0.0)
        largest = forces.max(initial=0.0)
        if largest == 0.0:
            continue
        squeeze = _largest_squeeze(normal_map, forces / largest, length_scale)
        if squeeze.sum() <= SQUEEZE_RTOL:
            continue
        members = np.flatnonzero(squeeze > SQUEEZE_RTOL)
        unload[members[np.argmin(forces[members] / squeeze[members])], j] = True
    return unload


def _largest_squeeze(
    normal_map: np.ndarray, bound: np.ndarray, length_scale: float, *, weights=None
) -> np.ndarray:
    """The squeeze ``0 <= s <= bound`` of largest (``weights``-weighted) total: a linear
    program."""
    # Moments over the body's length, so that the equality weighs them like the forces; entries
    # of rounding size (a centre of pressure 1e-19 m off the contact point) are zero.
    rows = normal_map / np.array([1.0, 1.0, 1.0, length_scale, length_scale, length_scale])[:, None]
    rows = np.where(np.abs(rows) > 1e-12, rows, 0.0)
    weights = np.ones(len(bound)) if weights is None else np.asarray(weights, dtype=float)
    result = linprog(
        -weights, A_eq=rows, b_eq=np.zeros(6),
        bounds=list(zip(np.zeros(len(bound)), bound, strict=True)), method="highs",
    )  # fmt: skip
    if result.status != 0:  # pragma: no cover - the LP is feasible (s = 0) and bounded
        return np.zeros(len(bound))
    return np.where(bound > 0.0, result.x, 0.0)
