r"""Passive contacts that squeeze each other, and the rule that keeps them from doing so.

A *squeeze* is a set of passive normal forces ``s >= 0``, ``s != 0``, whose wrenches cancel,
``G_p s = 0`` (two opposing locators pressing on each other through the part). A rigid model
admits any amount of it, and with it friction that no active force or load causes: a block
between two opposing locators is "held" by 276 N that each locator applies to the other. Which
squeeze really acts depends on the compliance and the preload of the contacts, which the rigid
model does not know.

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


def squeezing(normal_map: np.ndarray) -> np.ndarray:
    """Which contacts (columns of ``normal_map`` ``(6, P)``, passive contacts' wrenches per unit
    normal force) belong to some squeeze: ``(P,)`` bool."""
    count = normal_map.shape[1]
    if count < 2:
        return np.zeros(count, dtype=bool)
    # The largest squeeze with every force at most 1 has the largest support: every contact
    # that takes part in some squeeze carries force in it.
    found = _largest_squeeze(normal_map, np.ones(count))
    return found > SQUEEZE_RTOL


def unload_squeezes(normal_map: np.ndarray, passive_forces: np.ndarray) -> np.ndarray:
    """Contacts to unload, ``(P, K)`` bool: per load case (columns of ``passive_forces``
    ``(P, K)`` [N]) the contact of the largest squeeze under the forces that the squeeze loads
    most in proportion; none where a case holds no squeeze."""
    unload = np.zeros(passive_forces.shape, dtype=bool)
    for j, forces in enumerate(passive_forces.T):
        forces = np.maximum(forces, 0.0)
        largest = forces.max(initial=0.0)
        if largest == 0.0:
            continue
        squeeze = _largest_squeeze(normal_map, forces / largest)
        if squeeze.sum() <= SQUEEZE_RTOL:
            continue
        members = np.flatnonzero(squeeze > SQUEEZE_RTOL)
        unload[members[np.argmin(forces[members] / squeeze[members])], j] = True
    return unload


def _largest_squeeze(normal_map: np.ndarray, bound: np.ndarray) -> np.ndarray:
    """The squeeze ``0 <= s <= bound`` of largest total (a linear program)."""
    # Forces and moments in comparable units: each row scaled to unit size.
    rows = normal_map / np.maximum(np.abs(normal_map).max(axis=1, keepdims=True), 1e-300)
    result = linprog(
        -np.ones(len(bound)), A_eq=rows, b_eq=np.zeros(6),
        bounds=list(zip(np.zeros(len(bound)), bound, strict=True)), method="highs",
    )  # fmt: skip
    if result.status != 0:  # pragma: no cover - the LP is feasible (s = 0) and bounded
        return np.zeros(len(bound))
    return np.where(bound > 0.0, result.x, 0.0)
