r"""What a fixed-force solve says about each load case: held interval, motion, utilisation.

With the active forces given, the multiples ``k >= 0`` of a task load that the contacts hold
form an interval ``[k_min, k_max]`` (the feasible set of a convex problem, cut by the line of
multiples). It starts at 0 only when the active forces and the weight alone are held: fingers or
clamps whose forces do not balance each other push the part out unless enough task load pushes
back. The task load is held when ``k_min <= 1 <= k_max``. The safety factor of a case is
``k_max``; its margin is ``min(k_max, 1 / k_min)``, below 1 exactly when it is not held.

The impending motion of a case is the dual of its equilibrium constraint at ``k_max``: the twist
``V`` that maximises the power of the task load against the contacts' dissipation (normality).
Contacts whose normal force is decided by the solve (passive contacts) stay in contact: the
associated flow of the Coulomb cone would lift them off by ``mu`` times their sliding speed, so
their normal velocity is projected out. Contacts whose force is given follow the part (a finger
or clamp keeps pressing), so there the dual is kept as it is.
"""

from __future__ import annotations

import numpy as np

from fixplan.planner.friction_use import FrictionUse
from fixplan.planner.screw import Screw
from fixplan.planner.verify import LARGEST_MAGNITUDE
from fixplan.surface.point_kernel import compiled_scalar
from fixplan.tolerances import (
    CAP_RTOL,
    FRICTION_SET_RTOL,
    HELD_RTOL,
    MAX_SAFETY_FACTOR,
    MULTIPLE_ATOL,
)


def analyse_cases(
    names: tuple,
    contact_names: tuple,
    friction_use: FrictionUse,
    staying: StayingInContact,
    highest: dict,
    lowest: dict | None,
    wrenches: np.ndarray,
    length_scale: float,
) -> dict:
    """Plan fields of the load cases ``names`` (those solved, in order) from the maximising
    (``highest``) and minimising (``lowest``) fixed-force solves of each; ``staying`` projects
    the motions onto those that keep the contacts whose normal force the solve chose in contact
    (``contact_names`` in the problem's order). ``highest`` may hold the friction use of its
    loads (``"use"``, already verified), else it is computed here."""
    normal, friction, dual = highest["normal"], highest["friction"], highest.get("dual")
    use = highest.get("use")
    if use is None:
        noise = FRICTION_SET_RTOL * max(LARGEST_MAGNITUDE(normal), 1e-12)
        use = friction_use(friction, normal, noise=noise, known=highest.get("known_use"))
    cases = len(names)
    k_max, k_min, held = np.empty(cases), np.empty(cases), np.empty(cases, dtype=np.bool_)
    utilisation = np.empty(use.shape)
    critical, contact = _SUMMARY(
        np.asarray(highest["scale"], dtype=float),
        _NO_MULTIPLES if lowest is None else np.asarray(lowest["scale"], dtype=float),
        use, MAX_SAFETY_FACTOR * (1.0 - CAP_RTOL), MULTIPLE_ATOL, HELD_RTOL, k_max, k_min, held,
        utilisation,
    )  # fmt: skip
    high, low = k_max.tolist(), k_min.tolist()
    motions = dict.fromkeys(names)
    if dual is not None:
        twists, moving = staying(dual, normal, wrenches)
        for j in range(cases):
            if high[j] < np.inf and moving[j]:
                motions[names[j]] = Screw(twists[:, j], length_scale)  # (twists: a new array)
    return {
        "safety_factors": dict(zip(names, high, strict=True)),
        "safety_factor": min(high),
        "held_intervals": dict(zip(names, zip(low, high, strict=True), strict=True)),
        "held": dict(zip(names, held.tolist(), strict=True)),
        "motions": motions,
        "utilisation": utilisation,
        "critical_load": names[critical],
        "critical_contact": contact_names[contact],
    }


class StayingInContact:
    """Twists nearest given ones in which the pressed contacts of ``decided`` stay in contact.

    The normal velocity of the body at contact ``i`` is ``normal_map[:, i] · V``; it is
    projected out for the pressed decided contacts — unless that removes most of the motion
    (when they leave no sliding motion at all, one of them must lift off as it starts to slide);
    then the dual twist itself, which lifts no contact into the body, is the answer. The
    projection of each set of pressed contacts is computed once (an SVD) and kept; the twists
    are projected in one compiled loop.

    Parameters
    ----------
    normal_map : array (6, C)
        Body wrench of a unit normal force at each contact.
    decided : array (C,) of bool
        Contacts whose normal force the solve chose.
    length_scale : float
        The body's length scale [m]: sets the rank test of the contact normals.
    """

    def __init__(self, normal_map: np.ndarray, decided: np.ndarray, length_scale: float):
        self._normal_map = np.asarray(normal_map, dtype=float)
        self._decided = np.asarray(decided, dtype=bool)
        self._words = -(-len(self._decided) // 64)  # of the bits of the pressed contacts
        self._length_scale = float(length_scale)
        #: The projections ``(P, 6, 6)`` found so far, and the index of each set of pressed
        #: contacts (its words of bits) among them.
        self._projections = np.eye(6)[None]  # (none pressed: the identity)
        self._index: dict[bytes, int] = {}
        #: The words of the last call's pressed contacts and their groups (a control loop's
        #: cases keep their pressed contacts).
        self._last = (np.zeros((0, self._words), dtype=np.uint64), np.zeros(0, dtype=np.intp))

    def __call__(
        self, twists: np.ndarray, normal_forces: np.ndarray, towards: np.ndarray
    ) -> tuple[np.ndarray, list[bool]]:
        """The twists ``(6, K)`` kept in contact at the normal forces ``(C, K)`` [N], each signed
        to do nonnegative power with its wrench of ``towards`` ``(6, K)`` (the dual's sign is
        the solver's choice), and whether each is not zero."""
        normal_forces = np.asarray(normal_forces, dtype=float)
        twists, towards = np.asarray(twists, dtype=float), np.asarray(towards, dtype=float)
        words = np.empty((normal_forces.shape[1], self._words), dtype=np.uint64)
        out = np.empty(twists.shape)
        moving = np.empty(twists.shape[1], dtype=np.bool_)
        last_words, group = self._last
        if not _KEPT_AS_LAST(normal_forces, self._decided, FRICTION_SET_RTOL, words, last_words,
                             group, twists, self._projections, towards, out, moving):  # fmt: skip
            group = np.array([self._group(row) for row in words], dtype=np.intp)
            self._last = (words, group)
            _KEPT(twists, self._projections, group, towards, out, moving)
        return out, moving.tolist()

    def _group(self, words: np.ndarray) -> int:
        """The index of the projection of the pressed contacts whose bits are ``words`` (see
        :func:`pressed_contacts`)."""
        key = words.tobytes()
        found = self._index.get(key)
        if found is None:
            bits = np.unpackbits(words.astype("<u8").view(np.uint8), bitorder="little")
            pressed = bits[: len(self._decided)].astype(bool)
            found = 0
            if pressed.any():
                _, singular, basis = np.linalg.svd(self._normal_map[:, pressed].T)
                rank = int(np.sum(singular > 1e-9 * self._length_scale))
                free = basis[rank:]
                found = len(self._projections)
                self._projections = np.concatenate([self._projections, (free.T @ free)[None]])
            self._index[key] = found
        return found


def pressed_contacts(normal, decided, rtol, words):  # pragma: no cover - compiled
    """Bit ``c`` of ``words[j]`` ``(K, W)``: whether contact ``c`` is ``decided`` and pressed
    in case ``j``, by more than ``rtol`` of the largest normal force of ``normal`` ``(C, K)``."""
    words[:] = 0
    for j in range(normal.shape[1]):
        size = 1e-300
        for c in range(normal.shape[0]):
            size = max(size, abs(normal[c, j]))
        for c in range(normal.shape[0]):
            if decided[c] and normal[c, j] > rtol * size:
                words[j, c // 64] |= np.uint64(1) << np.uint64(c % 64)


_PRESSED = compiled_scalar(pressed_contacts)


def kept_in_contact(
    twists, projections, group, towards, out, moving
):  # pragma: no cover - compiled
    """``out[:, j]``: ``projections[group[j]] @ twists[:, j]`` where that keeps at least half of
    its norm (a quarter of its square), else the twist itself; signed towards ``towards``;
    ``moving[j]``: whether it is not zero."""
    for j in range(twists.shape[1]):
        projection = projections[group[j]]
        given, kept = 0.0, 0.0
        for row in range(6):
            total = 0.0
            for column in range(6):
                total += projection[row, column] * twists[column, j]
            out[row, j] = total
            given += twists[row, j] * twists[row, j]
            kept += total * total
        if kept < 0.25 * given:
            out[:, j] = twists[:, j]
        power = 0.0
        for row in range(6):
            power += towards[row, j] * out[row, j]
        if power < 0.0:
            out[:, j] = -out[:, j]
        moving[j] = False
        for row in range(6):
            moving[j] = moving[j] or out[row, j] != 0.0


_KEPT = compiled_scalar(kept_in_contact)


def kept_as_last(
    normal, decided, rtol, words, last_words, group, twists, projections, towards, out, moving
):  # pragma: no cover - compiled
    """:func:`pressed_contacts` into ``words``, and where they are ``last_words`` (the groups
    of the last call are then the same, ``group``), :func:`kept_in_contact`: returns whether it
    did that."""
    _PRESSED(normal, decided, rtol, words)
    if words.shape != last_words.shape:
        return False
    for j in range(words.shape[0]):
        for w in range(words.shape[1]):
            if words[j, w] != last_words[j, w]:
                return False
    _KEPT(twists, projections, group, towards, out, moving)
    return True


def summary(
    highest, lowest, use, cap, atol, held_rtol, k_max, k_min, held, utilisation
):  # pragma: no cover - compiled
    """The multiples of the two solves ``highest`` and ``lowest`` (empty: 0 for every case),
    cleaned into ``k_max`` and ``k_min`` (solver noise below 0, below ``atol`` as 0, from
    ``cap`` on as infinity, ``k_min`` above ``k_max`` by less than ``held_rtol`` as ``k_max``),
    the held cases into ``held`` and ``use`` ``(C, K)`` capped at 1 into ``utilisation``.
    Returns the critical case (the first of those tied within ``held_rtol`` with the smallest
    margin ``min(k_max, 1 / k_min)``) and its most used contact."""
    margins = np.empty(k_max.shape[0])
    for j in range(k_max.shape[0]):
        high = max(highest[j], 0.0)  # the solver may return -1e-19 for 0
        k_max[j] = np.inf if high >= cap else 0.0 if high < atol else high
        low = max(lowest[j], 0.0) if lowest.shape[0] else 0.0
        k_min[j] = 0.0 if low < atol else low
        # (Where the forces hold one multiple only, the two solves' noise may cross.)
        if k_max[j] < k_min[j] <= k_max[j] + held_rtol * max(1.0, k_min[j]):
            k_min[j] = k_max[j]
        margins[j] = min(k_max[j], 1.0 / k_min[j] if k_min[j] > 0.0 else np.inf)
        held[j] = k_min[j] <= 1.0 + held_rtol and k_max[j] >= 1.0 - held_rtol
    for c in range(use.shape[0]):
        for j in range(use.shape[1]):
            utilisation[c, j] = min(use[c, j], 1.0)
    smallest = margins.min()
    critical = 0
    for j in range(k_max.shape[0]):
        if margins[j] <= smallest * (1.0 + held_rtol):
            critical = j
            break
    contact = 0  # (the first of the largest, as argmax; NaN: the first NaN)
    for c in range(utilisation.shape[0]):
        value = utilisation[c, critical]
        if value != value:
            return critical, c
        if value > utilisation[contact, critical]:
            contact = c
    return critical, contact


#: The multiples of a missing minimising solve (:func:`summary`).
_NO_MULTIPLES = np.zeros(0)

_SUMMARY = compiled_scalar(summary)
_KEPT_AS_LAST = compiled_scalar(kept_as_last)
