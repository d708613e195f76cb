"""Why a problem cannot be held: the unresisted motions of an infeasible problem, in words.

The dual of the equilibrium constraints of an infeasible problem is a Farkas certificate: per
load case a twist that the applied wrenches (gravity, given forces, task loads) drive with
positive power while no contact can resist it: every force a contact's friction cone allows does
power of its own sign on it (for Coulomb cones, that motion leaves the contacts).
"""

from __future__ import annotations

import numpy as np

from fixplan.planner.screw import Screw


def certificate(
    names: tuple, dual: np.ndarray | None, wrenches: np.ndarray, applied: np.ndarray, *,
    fixed_forces: bool, length_scale: float,
) -> tuple[dict, str]:  # fmt: skip
    """The unresisted motion of each load case that cannot be held, and the whole in words.

    ``names`` are the load cases' names; ``dual`` ``(6, K)`` is the equilibrium dual of the
    infeasible solve (``None`` when the solver gave none); ``wrenches`` ``(6, K)`` are the task
    wrenches and ``applied`` ``(6, K)`` the wrenches that no contact of the program decides:
    gravity, the given active forces and, for the force objectives, the task loads. The motion
    is the dual's direction in which they do positive power (the solver's sign is its own);
    ``fixed_forces``: the active forces were given (then no multiple of the task load, not even
    0, is held).
    """
    if dual is None:
        return {}, "the problem is infeasible (the solver gave no certificate)"
    finite = np.isfinite(dual).all(axis=0)  # (a case without a certificate: not reported)
    size = np.abs(dual[:, finite]).max(initial=0.0)
    motions, lines = {}, []
    for j, name in enumerate(names):
        twist = dual[:, j]
        if not finite[j] or size == 0.0 or np.abs(twist).max() <= 1e-6 * size:
            continue
        power = applied[:, j] @ twist
        if abs(power) <= 1e-9 * np.abs(applied[:, j]).max(initial=0.0) * np.abs(twist).max():
            power = wrenches[:, j] @ twist  # (nothing applied drives it: the task load does)
        twist = twist if power >= 0.0 else -twist
        screw = Screw.from_twist(twist, length_scale)
        motions[name] = screw
        cause = (
            " at any multiple of its task load, not even without it (with the given active "
            "forces and the weight)"
            if fixed_forces
            else ""
        )
        lines.append(
            f"load case {name!r} cannot be held{cause}: nothing resists the motion in which "
            f"the body {screw.describe()}"
        )
    if not lines:
        return {}, "the problem is infeasible (the certificate is empty)"
    return motions, "; ".join(lines)
