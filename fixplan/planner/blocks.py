"""Load cases in blocks: how many a compiled fixed-force problem takes, which go together, and
in which order linear programs take them one by one."""

from __future__ import annotations

import numpy as np

#: Load cases per compiled problem of the fixed-force objectives (their cases are independent)
#: when Clarabel solves them; linear programs go one case at a time through the simplex.
#: Clarabel's time per case grows with the block, the Python work per block falls: `check` of
#: 1,000 cases of benchmarks/bench_planner.py through Clarabel, blocks of 1 / 4 / 16 / 64 cases:
#: fixture-321 (pyramids) 2,276 / 2,359 / 1,728 / 1,195 cases/s; the ellipsoid fixture (blocks
#: of 1 / 4 / 8 / 64) 3,021 / 3,930 / 3,615 / 3,102 cases/s.
CASES_PER_BLOCK = 4


#: Up to this many cases are ordered by nearest neighbours (quadratic time); more by angle.
NEAREST_ORDER_MAX_CASES = 2_000


def similar_order(wrenches: np.ndarray) -> np.ndarray:
    """An order of the cases in which consecutive task wrenches ``(6, K)`` point in similar
    directions: greedy nearest neighbours from the first, or for many cases the angle in the
    plane of their two principal directions. (On 1,000 random milling loads of fixture-321 the
    simplex then needs a mean of 8.5 pivots per case instead of 21.5.)"""
    cases = wrenches.shape[1]
    lengths = np.linalg.norm(wrenches, axis=0)
    unit = wrenches / np.where(lengths > 0.0, lengths, 1.0)
    if cases > NEAREST_ORDER_MAX_CASES:
        basis = np.linalg.svd(unit, full_matrices=False)[0][:, :2]
        plane = basis.T @ unit
        return np.argsort(np.arctan2(plane[1], plane[0]), kind="stable")
    order = np.empty(cases, dtype=np.intp)
    left = np.ones(cases, dtype=bool)
    current = 0
    for position in range(cases):
        order[position] = current
        left[current] = False
        if position + 1 < cases:
            similarity = np.where(left, unit[:, current] @ unit, -np.inf)
            current = int(np.argmax(similarity))
    return order


def block_of(index, size, wrenches, given, unloaded, numbers) -> tuple:
    """The task wrenches, given forces, unloaded contacts and case numbers of the cases
    ``index`` (columns of ``wrenches``), padded with copies of the first to ``size`` cases."""
    padded = np.concatenate([index, np.full(size - len(index), index[0])])
    cases = wrenches.shape[1]
    values = {
        i: v if np.ndim(v) == 0 else np.broadcast_to(v, (cases,))[padded] for i, v in given.items()
    }
    mask = None if unloaded is None else unloaded[:, padded]
    return wrenches[:, padded], values, mask, numbers[padded]
