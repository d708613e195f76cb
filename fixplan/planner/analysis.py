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
from fixplan.planner.problem import Problem
from fixplan.planner.screw import Screw
from fixplan.planner.stacking import ContactLayout
from fixplan.tolerances import FRICTION_SET_RTOL, HELD_RTOL, MAX_SAFETY_FACTOR, MULTIPLE_ATOL


def analyse_cases(
    problem: Problem,
    layout: ContactLayout,
    friction_use: FrictionUse,
    highest: dict,
    lowest: dict | None,
    wrenches: np.ndarray,
    decided: np.ndarray,
    length_scale: float,
) -> dict:
    """Plan fields from the maximising (``highest``) and minimising (``lowest``) fixed-force
    solves of every load case; ``decided`` ``(C,)`` marks contacts whose normal force the solve
    chose (their normal velocity is projected out of the motion)."""
    names = tuple(load.name for load in problem.loads)
    k_max = np.maximum(highest["scale"], 0.0)  # the solver may return -1e-19 for 0
    k_max = np.where(k_max >= MAX_SAFETY_FACTOR * (1 - 1e-6), np.inf, k_max)
    k_min = np.zeros_like(k_max) if lowest is None else np.maximum(lowest["scale"], 0.0)
    k_min = np.where(k_min < MULTIPLE_ATOL, 0.0, k_min)
    with np.errstate(divide="ignore"):
        margin = np.minimum(k_max, np.where(k_min > 0.0, 1.0 / k_min, np.inf))
    normal, friction, dual = highest["normal"], highest["friction"], highest.get("dual")
    motions = {}
    for j, name in enumerate(names):
        twist = None if dual is None or not np.isfinite(k_max[j]) else dual[:, j]
        if twist is not None and np.any(twist):
            twist = keep_contact(twist, normal[:, j], decided, layout.normal_map, length_scale)
        if twist is None or not np.any(twist):
            motions[name] = None
            continue
        twist = twist if wrenches[:, j] @ twist >= 0.0 else -twist
        motions[name] = Screw.from_twist(twist, length_scale)
    noise = FRICTION_SET_RTOL * max(float(np.abs(normal).max()), 1e-12)
    known = highest.get("known_use")
    utilisation = np.minimum(friction_use(friction, normal, noise=noise, known=known), 1.0)
    # Cases tied with the smallest margin (within solver accuracy): the first.
    critical = int(np.flatnonzero(margin <= margin.min() * (1.0 + HELD_RTOL))[0])
    return {
        "safety_factors": dict(zip(names, map(float, k_max), strict=True)),
        "safety_factor": float(k_max.min()),
        "held_intervals": {
            name: (float(low), float(high))
            for name, low, high in zip(names, k_min, k_max, strict=True)
        },
        "held": {
            name: bool(low <= 1.0 + HELD_RTOL and high >= 1.0 - HELD_RTOL)
            for name, low, high in zip(names, k_min, k_max, strict=True)
        },
        "motions": motions,
        "utilisation": utilisation,
        "critical_load": names[critical],
        "critical_contact": problem.contacts[int(np.argmax(utilisation[:, critical]))].name,
    }


def keep_contact(
    twist: np.ndarray,
    normal_forces: np.ndarray,
    decided: np.ndarray,
    normal_map: np.ndarray,
    length_scale: float,
) -> np.ndarray:
    """The twist nearest ``twist`` in which every pressed contact of ``decided`` stays in contact.

    The normal velocity of the body at contact ``i`` is ``normal_map[:, i] · V``; it is
    projected out for the pressed decided contacts — unless that removes most of the motion
    (when they leave no sliding motion at all, one of them must lift off as it starts to slide);
    then the dual twist itself, which lifts no contact into the body, is the answer.
    """
    size = max(float(np.abs(normal_forces).max()), 1e-300)
    pressed = np.flatnonzero(decided & (normal_forces > FRICTION_SET_RTOL * size))
    if pressed.size == 0:
        return twist
    rows = normal_map[:, pressed].T
    _, singular, basis = np.linalg.svd(rows)
    rank = int(np.sum(singular > 1e-9 * length_scale))
    free = basis[rank:]
    projected = free.T @ (free @ twist)
    kept = np.linalg.norm(projected) >= 0.5 * np.linalg.norm(twist)
    return projected if kept else twist
