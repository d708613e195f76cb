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
passive forces of each case is found (a linear program); one of its contacts is held without
normal force in that case, and the problem is solved again, until no case contains a squeeze.

Which contact: the squeeze-free problem is not convex (a union over the choices), and the
solver's answer, one of many optima of the rigid problem, says nothing reliable about it (the
forces a squeeze loads most in proportion flip with rounding: 426 N or 13,698 N for the same
fixture). So every member is tried, case by case (:func:`choose_unloading`;
:mod:`fixplan.planner.unloading` rates the trials): each load case takes the member that serves
it best on its own (the least forces, or the largest multiple of a fixed-force objective), ties
going to the first contact. A trial is rated squeeze-free: where the case still holds a squeeze
under it (the largest squeeze can join independent ones), by its best completion. With one free
clamp force coupling the cases, and more clamp force losing no case, this is the least force
over all choices; with several it is each case's own best, and another combination may need
less. Where the cases' own bests do not hold together (a clamp beside the supports, whose force
can tip the part in another case), one contact is unloaded in every case whose squeeze holds it
(:func:`same_contact_trials`), the best that holds.

The rule is conservative: it only removes reactions that the rigid model admits, so forces are
never lower and safety factors never higher than the rigid model's, and it never relies on a
preload that nothing applies. The compliant analysis gives the determinate answer.
"""

from __future__ import annotations

from collections.abc import Callable

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


def squeeze_members(
    normal_map: np.ndarray, passive_forces: np.ndarray, length_scale: float
) -> list[np.ndarray]:
    """The passive contacts (indices into the columns of ``normal_map``) of the largest squeeze
    under the forces of each load case (columns of ``passive_forces`` ``(P, K)`` [N]), in
    increasing order; empty where a case holds no squeeze."""
    members = []
    for forces in passive_forces.T:
        forces = np.maximum(forces, 0.0)
        largest = forces.max(initial=0.0)
        squeeze = np.zeros(len(forces))
        if largest > 0.0:
            squeeze = _largest_squeeze(normal_map, forces / largest, length_scale)
        members.append(np.flatnonzero(squeeze > SQUEEZE_RTOL) if squeeze.sum() > SQUEEZE_RTOL
                       else np.zeros(0, dtype=int))  # fmt: skip
    return members


def choose_unloading(
    members: list[np.ndarray],
    unloaded: np.ndarray,
    scores: Callable[[np.ndarray, np.ndarray], np.ndarray],
) -> np.ndarray:
    """``unloaded`` ``(P, K)`` with one more contact of each case's squeeze ``members`` (see
    :func:`squeeze_members`) unloaded: the member whose trial serves its case best.

    ``scores(trial, cases)`` rates a trial unloading ``(P, K)`` for the ``cases`` ``(K,)`` bool
    that it decides: ``(K,)``, lower is better, ``inf`` where not solved. Trial ``t`` unloads
    the ``t``-th member of every case; scores within ``SQUEEZE_RTOL`` of a case's best go to
    its first member, so that the choice does not depend on rounding.
    """
    trials = member_trials(members, unloaded)
    count = len(trials)
    if count <= 1:
        return trials[0] if trials else unloaded.copy()
    sizes = np.array([len(m) for m in members])
    table = np.stack([scores(trial, sizes > t) for t, trial in enumerate(trials)])  # (T, K)
    table[np.arange(count)[:, None] >= sizes[None, :]] = np.inf  # (trials that repeat a member)
    best = np.min(table, axis=0)
    slack = SQUEEZE_RTOL * np.maximum(np.abs(np.where(np.isfinite(best), best, 0.0)), 1.0)
    chosen = np.argmax(table <= (best + slack)[None, :], axis=0)  # first within; 0 if none solved
    return np.stack(trials)[chosen, :, np.arange(len(members))].T


def member_trials(members: list[np.ndarray], unloaded: np.ndarray) -> list[np.ndarray]:
    """The trials ``(P, K)`` of :func:`choose_unloading`: ``unloaded`` with the ``t``-th of
    each case's squeeze ``members`` unloaded too (its last where it has fewer),
    ``t = 0, 1, ...``."""
    trials = []
    for t in range(max((len(m) for m in members), default=0)):
        trial = unloaded.copy()
        for j, m in enumerate(members):
            if len(m):
                trial[m[min(t, len(m) - 1)], j] = True
        trials.append(trial)
    return trials


def same_contact_trials(members: list[np.ndarray], unloaded: np.ndarray) -> list[np.ndarray]:
    """The trials ``(P, K)`` that unload one contact in every case whose squeeze ``members``
    hold it, one trial per contact of any case's squeeze (in increasing order)."""
    trials = []
    for contact in np.unique(np.concatenate([np.zeros(0, dtype=int), *members])):
        trial = unloaded.copy()
        for j, m in enumerate(members):
            if contact in m:
                trial[contact, j] = True
        trials.append(trial)
    return trials


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
