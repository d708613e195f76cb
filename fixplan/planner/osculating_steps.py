"""The array steps of a round of osculating ellipsoids, compiled
(:meth:`fixplan.planner.osculating.OsculatingPool.move`).

A round reads the solve's loads and twists, lists the pairs (exact contact, load case) whose
loads the exact models are asked about, and after those queries tests whether the solve met the
exact problem's optimality conditions and moves the ellipsoids and cuts. As some forty NumPy
steps on the few pairs of a grasp, that took as much time as the queries and the solve together;
here it is two compiled passes over the pairs. The rules and tolerances are those of
:mod:`fixplan.planner.osculating`, which passes them in.
"""

from __future__ import annotations

import numpy as np

from fixplan.surface.point_kernel import compiled_scalar


def pair_buffers(pairs: int) -> tuple:
    """Output arrays of :func:`solved_pairs` for up to ``pairs`` pairs, in its order."""

    def index():
        return np.empty(pairs, dtype=np.int64)

    return (index(), index(), np.empty((pairs, 3)), np.empty((pairs, 3)), np.empty(pairs),
            index(), index(), np.empty((pairs, 3)), np.empty(pairs))  # fmt: skip


def solved_pairs(
    forces, friction, rows, noise, factors, twists, units, counted,
    owner, cases, per_unit, used, power, idle_owner, idle_cases, idle_twists, idle_reach,
):  # fmt: skip  # pragma: no cover - compiled
    """The pairs of a solve to query, in order of contact then case; returns their count, that
    of the unpressed pairs to test and whether every pressed pair's load is finite (``(moving,
    idle, finite)``: a round with a load that is not finite cannot settle).

    Parameters
    ----------
    forces : numpy.ndarray
        ``(E, K)`` normal forces [N] of the exact contacts; a pair is pressed above ``noise``.
    friction : numpy.ndarray
        ``(D, K)`` friction loads of the solve, the rows ``rows`` ``(E, 3)`` each contact's.
    factors : numpy.ndarray
        ``(E, K, 3, 3)`` the ellipsoids ``‖R q‖ <= 1`` the solve used.
    twists, units, counted : numpy.ndarray
        ``(E, K, 3)`` normalised twists of the solve, ``(E, 3)`` the contacts' units, ``(E, K)``
        the twists' weights in the settle tests.
    owner, cases, per_unit, used, power : numpy.ndarray
        Out: the pressed pairs with load (contact, case), their loads per unit normal force
        ``(P, 3)``, the normals ``RᵀR q`` of their ellipsoids there and the power ``|L · V|``
        of each load ``L`` in its contact's twist ``V`` (load space; the program's units: the
        objective's).
    idle_owner, idle_cases, idle_twists, idle_reach : numpy.ndarray
        Out: the unpressed pairs of weight above 0, their load-space twists ``V`` ``(I, 3)``
        and their ellipsoids' supports ``‖R⁻ᵀ V‖`` there.
    """
    moving, idle, finite = 0, 0, True
    for e in range(forces.shape[0]):
        for k in range(forces.shape[1]):
            force = forces[e, k]
            r = factors[e, k]
            if not force > noise:
                if counted[e, k] > 0.0:
                    # Rᵀ y = V by forward substitution; the support is |y|.
                    v0 = twists[e, k, 0] / units[e, 0]
                    v1 = twists[e, k, 1] / units[e, 1]
                    v2 = twists[e, k, 2] / units[e, 2]
                    y0 = v0 / r[0, 0]
                    y1 = (v1 - r[0, 1] * y0) / r[1, 1]
                    y2 = (v2 - r[0, 2] * y0 - r[1, 2] * y1) / r[2, 2]
                    idle_owner[idle], idle_cases[idle] = e, k
                    idle_twists[idle, 0], idle_twists[idle, 1], idle_twists[idle, 2] = v0, v1, v2
                    idle_reach[idle] = np.sqrt(y0 * y0 + y1 * y1 + y2 * y2)
                    idle += 1
                continue
            q0 = friction[rows[e, 0], k] / force
            q1 = friction[rows[e, 1], k] / force
            q2 = friction[rows[e, 2], k] / force
            if not (np.isfinite(q0) and np.isfinite(q1) and np.isfinite(q2)):
                finite = False
            elif q0 != 0.0 or q1 != 0.0 or q2 != 0.0:
                owner[moving], cases[moving] = e, k
                per_unit[moving, 0], per_unit[moving, 1], per_unit[moving, 2] = q0, q1, q2
                _normal(r, q0, q1, q2, used[moving])
                power[moving] = force * abs(
                    q0 * twists[e, k, 0] / units[e, 0]
                    + q1 * twists[e, k, 1] / units[e, 1]
                    + q2 * twists[e, k, 2] / units[e, 2]
                )
                moving += 1
    return moving, idle, finite


def settle(
    owner, cases, excess, points, found, used, power, counted, weights, contacts,
    use, previous, factors, planes, next_slot, slow,
    exact_rtol, stationarity_rtol, held_back_max, by_case, progress, margin, cut_slack,
):  # fmt: skip  # pragma: no cover - compiled
    """After the queries of the pairs ``(owner, cases)`` ``(P,)`` (:func:`solved_pairs`): whether
    the solve met the optimality conditions, whether a cut was placed, and the power held back
    (``(settled, cut, held_back)``, the last as ``held_back_max``).

    ``excess`` ``(P,)``, ``points`` ``(P, 3)`` and ``found`` ``(P, 3, 3)`` are the queries'
    answers (:meth:`~fixplan.models.Exact.osculating`), ``used`` the normals the solve used and
    ``power`` the pairs' powers. The optimality conditions: every load inside its exact set
    (``exact_rtol``); at each pair of weight (``counted``) above 0, the exact set's normal the
    solve's (``stationarity_rtol``, weighed), and the power that these loads hold back inside
    their sets beyond the ``margin`` the ellipsoids are tightened by, ``Σ P_i max(-excess_i -
    margin, 0)``, at most ``held_back_max`` (in the objective's units: its first-order cost):
    ``(1,)`` for all pairs, or with ``by_case`` ``(K,)`` for each load case's pairs (the cases
    of a fixed-force block, each with its own multiple).
    """
    count = owner.shape[0]
    settled, cut = True, False
    held_back = np.zeros(held_back_max.shape[0])
    last = np.empty(count)
    for p in range(count):
        last[p] = previous[owner[p], cases[p]]
    previous[:] = np.nan
    normal = np.empty(3)
    for p in range(count):
        e, k, over = owner[p], cases[p], excess[p]
        use[contacts[e], k] = 1.0 + over
        previous[e, k] = over
        r = found[p]
        _normal(r, points[p, 0], points[p, 1], points[p, 2], normal)
        weight = counted[e, k]
        if not over <= exact_rtol:
            settled = False
        if weight > 0.0:
            if not weight * _chord(used[p], normal) <= stationarity_rtol:
                settled = False
            held_back[k if by_case else 0] += power[p] * max(-over - margin, 0.0)
        beyond = over > exact_rtol
        stalled = beyond and over >= progress * last[p]
        slow[p] = stalled and weights[e, k] > 0.0
        if not np.all(np.isfinite(r)):
            continue
        for i in range(3):
            for j in range(3):
                factors[e, k, i, j] = r[i, j] * (1.0 + margin)
        if beyond:
            scale = (1.0 + margin) if stalled else 1.0 / (1.0 + cut_slack)
            offset = normal[0] * points[p, 0] + normal[1] * points[p, 1] + normal[2] * points[p, 2]
            slot = next_slot[e, k]
            for i in range(3):
                planes[i, slot, e, k] = normal[i] / offset * scale
            next_slot[e, k] = (slot + 1) % planes.shape[1]
            cut = True
    for group in range(held_back.shape[0]):
        if not held_back[group] <= held_back_max[group]:
            settled = False
    return settled, cut, held_back


def _normal(r, q0, q1, q2, out):  # pragma: no cover - compiled
    """The outward normal ``RᵀR q`` of the ellipsoid ``‖R q‖ <= 1`` at ``q`` into ``out``."""
    y0 = r[0, 0] * q0 + r[0, 1] * q1 + r[0, 2] * q2
    y1 = r[1, 0] * q0 + r[1, 1] * q1 + r[1, 2] * q2
    y2 = r[2, 0] * q0 + r[2, 1] * q1 + r[2, 2] * q2
    for c in range(3):
        out[c] = r[0, c] * y0 + r[1, c] * y1 + r[2, c] * y2


def _chord(first, second):  # pragma: no cover - compiled
    """Distance between the unit directions of ``first`` and ``second`` ``(3,)`` (NaN where
    one is not finite)."""
    a = np.sqrt(first[0] ** 2 + first[1] ** 2 + first[2] ** 2)
    b = np.sqrt(second[0] ** 2 + second[1] ** 2 + second[2] ** 2)
    total = 0.0
    for c in range(3):
        total += (first[c] / a - second[c] / b) ** 2
    return np.sqrt(total)


_normal = compiled_scalar(_normal, inline=True)
_chord = compiled_scalar(_chord, inline=True)
SOLVED_PAIRS = compiled_scalar(solved_pairs)
SETTLE = compiled_scalar(settle)
