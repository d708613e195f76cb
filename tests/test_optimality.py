"""Optimality checks of conic programs (fixplan.planner.optimality) against pairs optimal by
construction, Clarabel's own answers and a plain numpy statement of the residuals."""

import clarabel
import numpy as np
import pytest
import scipy.sparse as sp

from fixplan.planner.optimality import Pattern
from fixplan.tolerances import CERTIFICATE_RTOL

SHAPES = [  # (equality rows, nonnegative rows, second-order cone sizes)
    (0, 4, ()),
    (3, 0, (3,)),
    (6, 2, (4, 4, 4)),
    (2, 5, (3, 5, 1)),
]


def _on_boundary(rng, size):
    """A point on the boundary of the second-order cone of ``size`` rows, and a nonzero dual
    point complementary to it (their product 0)."""
    if size == 1:
        return np.zeros(1), rng.uniform(0.5, 2.0, 1)
    tail = rng.normal(size=size - 1)
    norm = np.linalg.norm(tail)
    return np.r_[norm, tail], rng.uniform(0.5, 2.0) * np.r_[norm, -tail] / norm


def optimal_program(rng, zero, nonneg, socs, *, columns=None):
    """``(q, A, b, x, z, pattern)``: a program with the optimal pair ``x, z`` built in, from
    the optimality conditions (``A x + s = b``, ``Aᵀz + q = 0``, ``s`` and ``z`` in their
    cones and complementary), with about a third of ``A``'s entries zero."""
    s_parts, z_parts = [np.zeros(zero)], [rng.normal(size=zero)]
    for _ in range(nonneg):  # half slack, half tight
        if rng.uniform() < 0.5:
            s_parts.append(rng.uniform(0.5, 2.0, 1))
            z_parts.append(np.zeros(1))
        else:
            s_parts.append(np.zeros(1))
            z_parts.append(rng.uniform(0.5, 2.0, 1))
    for size in socs:
        s, z = _on_boundary(rng, size)
        if rng.uniform() < 0.3:  # the apex of one, the inside of the other
            s, z = np.zeros(size), np.r_[np.linalg.norm(z[1:]) + 1.0, z[1:]]
        s_parts.append(s)
        z_parts.append(z)
    s, z = np.concatenate(s_parts), np.concatenate(z_parts)
    rows = s.size
    columns = columns or rows + 2
    a = rng.normal(size=(rows, columns)) * (rng.uniform(size=(rows, columns)) < 0.67)
    x = rng.normal(size=columns)
    b = a @ x + s
    q = -a.T @ z
    sparse = sp.csc_array(a)
    pattern = Pattern.of(sparse.indices, sparse.indptr, zero, nonneg, socs)
    return q, sparse.data.copy(), b, x, z, pattern


def numpy_residuals(q, a, b, x, z, zero, nonneg, socs):
    """The residuals of :meth:`Pattern.residuals`, stated plainly in numpy."""
    s, product = b - a @ x, a @ x

    def outside(v, free_zero):
        worst = [0.0] if free_zero else [np.abs(v[:zero]).max(initial=0.0)]
        worst.append((-v[zero : zero + nonneg]).max(initial=0.0))
        start = zero + nonneg
        for size in socs:
            block = v[start : start + size]
            worst.append(np.linalg.norm(block[1:]) - block[0])
            start += size
        return max(worst)

    primal = outside(s, False) / max(1.0, np.abs(b).max(), np.abs(product).max())
    transposed = a.T @ z
    stationary = np.abs(transposed + q).max() / max(1.0, np.abs(q).max(), np.abs(transposed).max())
    cone = outside(z, True) / max(1.0, np.abs(z).max())
    value, bound = q @ x, -b @ z
    gap = abs(value - bound) / max(1.0, abs(value), abs(bound))
    return primal, max(stationary, cone), gap


@pytest.mark.parametrize(("zero", "nonneg", "socs"), SHAPES)
@pytest.mark.parametrize("seed", range(5))
def test_pairs_optimal_by_construction_are_optimal(seed, zero, nonneg, socs):
    rng = np.random.default_rng(seed)
    q, values, b, x, z, pattern = optimal_program(rng, zero, nonneg, socs)
    assert max(pattern.residuals(q, values, b, x, z)) < 1e-13
    assert pattern.optimal(q, values, b, x, z)
    assert pattern.feasible(values, b, x)


@pytest.mark.parametrize(("zero", "nonneg", "socs"), SHAPES)
@pytest.mark.parametrize("seed", range(5))
def test_residuals_are_those_stated_plainly(seed, zero, nonneg, socs):
    rng = np.random.default_rng(100 + seed)
    q, values, b, x, z, pattern = optimal_program(rng, zero, nonneg, socs)
    a = sp.csc_array((values, pattern.rows, pattern.indptr), shape=(b.size, x.size)).toarray()
    x_off, z_off = x + rng.normal(size=x.size), z + rng.normal(size=z.size)
    found = pattern.residuals(q, values, b, x_off, z_off)
    expected = numpy_residuals(q, a, b, x_off, z_off, zero, nonneg, socs)
    np.testing.assert_allclose(found, expected, rtol=1e-12, atol=1e-15)


def test_each_broken_condition_is_caught():
    rng = np.random.default_rng(7)
    zero, nonneg, socs = 3, 4, (4, 3)
    q, values, b, x, z, pattern = optimal_program(rng, zero, nonneg, socs)
    # A point off the equality rows, or outside a cone: not feasible.
    moved = b.copy()
    moved[0] += 1e-6 * max(1.0, np.abs(b).max())
    assert not pattern.feasible(values, moved, x)
    outside = b.copy()
    outside[zero + nonneg] -= 1e-6 * max(1.0, np.abs(b).max())  # the first cone's t below ‖u‖
    assert not pattern.feasible(values, outside, x)
    # Multipliers not stationary, outside their cones, or with a duality gap.
    assert not pattern.optimal(q + 1e-6 * np.abs(q).max(), values, b, x, z)
    assert not pattern.optimal(q, values, b, x, np.r_[z[:zero], -np.abs(z[zero:]) - 1e-6])
    inside = np.r_[np.zeros(zero), np.ones(nonneg), np.zeros(b.size - zero - nonneg)]
    inside[pattern.heads] = 1.0
    slack_both = b + inside  # s strictly inside its cones: a gap b·z > 0
    assert pattern.feasible(values, slack_both, x)
    assert not pattern.optimal(q, values, slack_both, x, z)
    # Within the tolerance, a little noise is accepted.
    noise = 0.1 * CERTIFICATE_RTOL * max(1.0, np.abs(b).max())
    assert pattern.optimal(q, values, b + noise * (np.arange(b.size) < zero), x, z)


@pytest.mark.parametrize(("zero", "nonneg", "socs"), SHAPES[1:])
@pytest.mark.parametrize("seed", range(3))
def test_clarabels_answers_are_optimal(seed, zero, nonneg, socs):
    rng = np.random.default_rng(200 + seed)
    q, values, b, _, _, pattern = optimal_program(rng, zero, nonneg, socs)
    a = sp.csc_matrix((values, pattern.rows, pattern.indptr), shape=(b.size, q.size))
    settings = clarabel.DefaultSettings()
    settings.verbose = False
    settings.tol_gap_abs = settings.tol_gap_rel = settings.tol_feas = 1e-9  # the planner's
    cones = [clarabel.ZeroConeT(zero), clarabel.NonnegativeConeT(nonneg)]
    cones += [clarabel.SecondOrderConeT(size) for size in socs]
    solution = clarabel.DefaultSolver(
        sp.csc_matrix((q.size, q.size)), q, a, b, cones, settings
    ).solve()
    assert str(solution.status) == "Solved"
    x, z = np.asarray(solution.x), np.asarray(solution.z)
    assert pattern.optimal(q, values, b, x, z)
    assert not pattern.optimal(q, values, b, x, 1.5 * z)  # the same multipliers, scaled: a gap
