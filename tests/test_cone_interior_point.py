"""The compiled interior-point method for cone programs in standard form, against Clarabel."""

import clarabel
import numpy as np
import pytest
import scipy.sparse as sp

from fixplan.planner.cone_interior_point import ConeInteriorPoint, pivot_rows

TOLERANCES = {"tol_feas": 1e-9, "tol_gap_abs": 1e-9, "tol_gap_rel": 1e-9}


def _cones(nonneg, dimensions):
    """(first row, dimension) of each cone after the equalities."""
    sizes = [1] * nonneg + list(dimensions)
    return list(zip(np.cumsum([0, *sizes[:-1]]), sizes, strict=True))


def _interior_point(rng, dimension):
    """A point well inside the second-order cone (a positive number for dimension 1)."""
    tail = rng.normal(size=dimension - 1)
    return np.r_[np.linalg.norm(tail) + rng.uniform(0.1, 2.0), tail]


def _program(rng, equalities, nonneg, dimensions, *, apex_duals=0, constants=0, repeats=0):
    """Clarabel's ``(q, A, b)`` whose cone rows (``s = h - G x``) hold one entry each, one
    per variable, in shuffled order and scaled, but for ``constants`` rows without one and
    ``repeats`` rows of variables that have another row already. Feasible with a strictly
    interior point; bounded by a dual point inside the cones (but for ``apex_duals`` cones
    whose multipliers are 0: those cones are slack at the optimum, or not, as the program
    decides)."""
    cones = _cones(nonneg, dimensions)
    m = sum(size for _, size in cones)
    n = m - constants - repeats
    rows = rng.permutation(m)
    variable = np.full(m, -1)
    variable[rows[:n]] = rng.permutation(n)
    variable[rows[n : n + repeats]] = rng.integers(0, n, repeats)
    g = np.zeros((m, n))
    placed = variable >= 0
    g[placed, variable[placed]] = rng.choice([-1.0, 1.0], placed.sum()) * rng.uniform(
        0.2, 5.0, placed.sum()
    )
    a_e = rng.normal(size=(equalities, n))
    slack = np.concatenate([_interior_point(rng, size) for _, size in cones])
    x0 = rng.normal(size=n)
    multipliers = [_interior_point(rng, size) for _, size in cones]
    for k in rng.choice(len(cones), apex_duals, replace=False):
        multipliers[k] = np.zeros_like(multipliers[k])
    z0 = np.concatenate(multipliers)
    q = -(a_e.T @ rng.normal(size=equalities) + g.T @ z0)
    return q, np.vstack([a_e, g]), np.r_[a_e @ x0, slack + g @ x0]


def _clarabel(q, a, b, equalities, nonneg, dimensions, tolerances=TOLERANCES):
    """Clarabel's ``x``, or ``None`` where it does not report the program solved."""
    settings = clarabel.DefaultSettings()
    settings.verbose = False
    for key, value in tolerances.items():
        setattr(settings, key, value)
    cones = [clarabel.ZeroConeT(equalities), clarabel.NonnegativeConeT(nonneg)]
    cones += [clarabel.SecondOrderConeT(d) for d in dimensions]
    n = len(q)
    solution = clarabel.DefaultSolver(
        sp.csc_matrix((n, n)), q, sp.csc_matrix(a), b, cones, settings
    ).solve()
    return np.asarray(solution.x) if str(solution.status) == "Solved" else None


def _cone_margin(values, equalities, nonneg, dimensions):
    """The least of ``u_0 - |u_1|`` over the cones (``u`` for a nonnegative row)."""
    rest = values[equalities:]
    return min(
        rest[first] - np.linalg.norm(rest[first + 1 : first + size])
        for first, size in _cones(nonneg, dimensions)
    )


@pytest.mark.parametrize(
    ("equalities", "nonneg", "dimensions", "apex_duals", "constants", "repeats"),
    [
        (6, 0, [4] * 8, 0, 0, 0),  # (the planner's bare re-solve: 8 contacts, 1 case)
        (6, 0, [3] * 8, 2, 0, 0),
        (3, 4, [3, 5, 2], 1, 0, 0),
        (1, 5, [], 0, 0, 0),
        (5, 2, [3] * 6, 3, 0, 0),
        (6, 2, [4] * 8, 0, 2, 1),  # (its analysis: given normal forces, a bounded multiple)
        (4, 3, [3, 3, 4], 1, 3, 3),
    ],
)
def test_optimum_agrees_with_clarabel_and_satisfies_the_optimality_conditions(
    equalities, nonneg, dimensions, apex_duals, constants, repeats
):
    rng = np.random.default_rng(len(dimensions) + 10 * nonneg + apex_duals + 100 * constants)
    for _ in range(20):
        q, a, b = _program(
            rng, equalities, nonneg, dimensions,
            apex_duals=apex_duals, constants=constants, repeats=repeats,
        )  # fmt: skip
        solver = ConeInteriorPoint(equalities, nonneg, dimensions, a, TOLERANCES)
        _assert_optimal(solver.solve(q, a, b), q, a, b, equalities, nonneg, dimensions)


def test_a_solve_starts_from_the_last_optimum_of_its_cost():
    """Loads that change little (a control loop): the solves after the first start from the
    last optimum of the same cost and take fewer iterations; a jump still solves."""
    rng = np.random.default_rng(11)
    cones = (6, 0, [4] * 8)
    q, a, b = _program(rng, *cones, apex_duals=2)
    solver = ConeInteriorPoint(*cones, a, TOLERANCES)
    _assert_optimal(solver.solve(q, a, b), q, a, b, *cones)
    cold = solver.iterations
    direction = rng.normal(size=len(q))
    warm = []
    for step in range(1, 11):
        moved = b.copy()
        moved[:6] += 1e-3 * step * (a[:6] @ direction)
        _assert_optimal(solver.solve(q, a, moved), q, a, moved, *cones)
        warm.append(solver.iterations)
    assert max(warm) < cold, (warm, cold)
    _assert_optimal(solver.solve(2.0 * q, a, b), 2.0 * q, a, b, *cones)  # (from its own start)
    _assert_optimal(solver.solve(q, a, moved), q, a, moved, *cones)
    assert solver.iterations < cold  # (q's optimum kept beside 2q's)
    jumped = b.copy()
    jumped[:6] += a[:6] @ direction
    _assert_optimal(solver.solve(q, a, jumped), q, a, jumped, *cones)


def _assert_optimal(found, q, a, b, equalities, nonneg, dimensions):
    """``found`` (``x``, ``z``) is optimal: the optimality conditions to the tolerances, and
    Clarabel's optimum."""
    assert found is not None
    x, z = found
    reference = _clarabel(q, a, b, equalities, nonneg, dimensions)
    if reference is not None:  # (Clarabel at 1e-9 missed 1 of 2,050 such programs)
        # Both stop at residuals of 1e-9 of the data's size: on 1,050 programs of the seven
        # shapes above their optima were within 8.5e-9 (this method) and 1.7e-8 (Clarabel) of
        # Clarabel's at 1e-10, and within 1.6e-8 of each other, relative to the optimum.
        scale = max(1.0, abs(q @ reference))
        assert q @ x == pytest.approx(q @ reference, abs=3e-8 * scale)
    slack = b - a @ x
    size = 1.0 + np.abs(b).max() + np.abs(x).max()
    assert np.abs(slack[:equalities]).max() <= 1e-8 * size
    assert _cone_margin(slack, equalities, nonneg, dimensions) >= -1e-8 * size
    assert np.abs(q + a.T @ z).max() <= 1e-8 * (1.0 + np.abs(q).max() + np.abs(z).max())
    assert _cone_margin(z, equalities, nonneg, dimensions) >= 0.0
    # Complementary: the method's gap is relative to its standard form's objective, which
    # differs from q'x by a constant (up to 1.3e-8 of |q'x| on the programs with cut rows).
    assert slack[equalities:] @ z[equalities:] <= 3e-8 * max(1.0, abs(q @ x))


def test_an_infeasible_program_is_given_up():
    """``x >= 1`` (``s = -1 + x``) and ``x <= 0`` through the equality ``x + t = 0`` with
    ``t >= 0``: no point; the caller then asks Clarabel for the certificate. The iterates run
    off along the ray of the certificate, and the method stops there."""
    q = np.array([1.0, 0.0])
    a = np.array([[1.0, 1.0], [-1.0, 0.0], [0.0, -1.0]])
    b = np.array([0.0, -1.0, 0.0])
    solver = ConeInteriorPoint(1, 2, [], a)
    assert solver.solve(q, a, b) is None
    assert solver.iterations < 10  # (stopped at the ray, not at MAX_ITERATIONS)


def test_an_unbounded_program_is_given_up():
    """``min -x`` with ``x >= 0`` and ``x - t = 0``, ``t >= 0``."""
    q = np.array([-1.0, 0.0])
    a = np.array([[1.0, -1.0], [-1.0, 0.0], [0.0, -1.0]])
    b = np.zeros(3)
    solver = ConeInteriorPoint(1, 2, [], a)
    assert solver.solve(q, a, b) is None
    assert solver.iterations < 10


def test_a_zero_where_the_pattern_has_an_entry_is_given_up():
    rng = np.random.default_rng(3)
    q, a, b = _program(rng, 2, 1, [3])
    solver = ConeInteriorPoint(2, 1, [3], a)
    a = a.copy()
    a[2, np.flatnonzero(a[2])[0]] = 0.0
    assert solver.solve(q, a, b) is None


def test_cone_rows_that_each_variable_can_stand_for_fit():
    """A program fits where every variable has a cone row of its own (a matching): rows of one
    entry each, or of several (an ellipsoid's factor ``R`` times a friction load, a cut's
    plane); not where a variable is in no cone row or two share the only row they are in."""
    identity = np.vstack([np.ones((2, 3)), -np.eye(3)])
    assert ConeInteriorPoint.fits(2, 0, identity)
    assert ConeInteriorPoint.fits(2, 0, identity[[0, 1, 3, 4, 2]])  # (cone rows permuted)
    assert ConeInteriorPoint.fits(2, 0, np.vstack([identity, np.zeros(3), [0.0, 2.0, 0.0]]))
    triangular = np.vstack([np.ones((2, 3)), np.triu(np.ones((3, 3)))])
    assert ConeInteriorPoint.fits(2, 0, triangular)
    assert ConeInteriorPoint.fits(2, 1, np.vstack([triangular[:2], np.ones(3), triangular[2:]]))
    free_variable = np.vstack([np.ones((2, 4)), np.c_[-np.eye(3), np.zeros(3)]])
    assert not ConeInteriorPoint.fits(2, 0, free_variable)
    shared = np.vstack([np.ones((2, 3)), [1.0, 1.0, 0.0], [0.0, 0.0, 1.0], [0.0, 0.0, 2.0]])
    assert not ConeInteriorPoint.fits(2, 0, shared)


def test_pivot_rows_prefer_second_order_cones_then_fewer_entries():
    """A friction load ``l`` in an ellipsoid's cone (``‖R l‖ <= n``, ``R`` upper triangular)
    and in a cut's row (``p·l <= h``, nonnegative, before the cone): its coordinates stand for
    the cone's rows, whose block is triangular, not for the cut's row, which is empty until a
    cut is placed; with one entry per row in cones of one kind, each variable's first row."""
    cut = [[1.0, 1.0, 1.0, 0.0]]
    cone = [[0.0, 0.0, 0.0, 1.0]] + np.c_[np.triu(np.ones((3, 3))), np.zeros(3)].tolist()
    rows = pivot_rows(np.array(cut + cone) != 0.0, 1)
    np.testing.assert_array_equal(rows, [2, 3, 4, 1])
    one_entry = np.array([[0.0, 1.0], [1.0, 0.0], [0.0, 3.0], [2.0, 0.0]]) != 0.0
    np.testing.assert_array_equal(pivot_rows(one_entry, 0), [1, 0])
    np.testing.assert_array_equal(pivot_rows(one_entry, 2), [3, 2])


def _mixed(q, a, rng, block=3):
    """The program of ``(q, a)`` in the variables ``x = T y`` (``T`` block upper triangular,
    blocks of ``block`` variables, well conditioned): ``(T'q, a T)``, whose cone rows hold
    several entries each, as an osculating ellipsoid's do."""
    n = len(q)
    mixing = np.eye(n)
    for first in range(0, n, block):
        last = min(first + block, n)
        mixing[first:last, first:last] += np.triu(rng.uniform(-0.5, 0.5, (last - first,) * 2), 1)
    return mixing.T @ q, a @ mixing


@pytest.mark.parametrize(
    ("equalities", "nonneg", "dimensions", "apex_duals", "constants", "repeats"),
    [
        (6, 0, [4] * 8, 0, 0, 0),  # (the exact grasp's round, but for its cut rows: 8 x 4)
        (6, 16, [4] * 8, 2, 0, 16),  # (with its 16 cut rows: nonnegative rows of loads)
        (3, 4, [3, 5, 2], 1, 0, 0),
        (4, 3, [3, 3, 4], 1, 3, 3),
    ],
)
def test_cone_rows_of_several_entries_are_solved_to_clarabels_optimum(
    equalities, nonneg, dimensions, apex_duals, constants, repeats
):
    """Cone rows that mix variables (``x`` for ``G_P^-1 (h_P - s_P)`` on the pivot rows):
    the optimality conditions hold and the optimum is Clarabel's, from a cold start and from
    the last optimum after the matrix changed a little (the osculating rounds' ellipsoids)."""
    rng = np.random.default_rng(7 + len(dimensions) + nonneg + repeats)
    for _ in range(10):
        q, a, b = _program(
            rng, equalities, nonneg, dimensions,
            apex_duals=apex_duals, constants=constants, repeats=repeats,
        )  # fmt: skip
        mixed_q, mixed_a = _mixed(q, a, rng)
        solver = ConeInteriorPoint(equalities, nonneg, dimensions, mixed_a, TOLERANCES)
        assert not solver._diagonal
        found = solver.solve(mixed_q, mixed_a, b)
        _assert_optimal(found, mixed_q, mixed_a, b, equalities, nonneg, dimensions)
        cold = solver.iterations
        moved_a = mixed_a + 1e-3 * (_mixed(q, a, np.random.default_rng(0))[1] - mixed_a)
        _assert_optimal(solver.solve(mixed_q, moved_a, b), mixed_q, moved_a, b, equalities,
                        nonneg, dimensions)  # fmt: skip
        assert solver.iterations <= cold


def test_a_singular_block_of_pivot_rows_is_given_up():
    """Where the values make the pivot rows' block singular (a cut's row that stands for a
    variable, still empty), the method gives up rather than divide by 0."""
    a = np.array([[1.0, 1.0], [-1.0, -1.0], [-1.0, 0.0], [0.0, -1.0]])
    solver = ConeInteriorPoint(1, 1, [2], a)
    empty = a.copy()
    empty[[2, 3]] = [[-1.0, -1.0], [-1.0, -1.0]]
    assert solver.solve(np.array([1.0, 2.0]), empty, np.array([1.0, 0.0, 0.0, 0.0])) is None


def test_the_scaling_is_nesterov_todds():
    """``W z = W^-1 s = lambda`` with ``W`` symmetric and ``W (J) W = (s'Js / z'Jz)^(1/2) J``
    on each cone (``J = diag(1, -1, ...)``), for points deep inside and near the boundary."""
    from fixplan.planner.cone_interior_point import _apply_scaling, _scaling

    rng = np.random.default_rng(5)
    dimensions = [1, 1, 3, 4, 6]
    start = np.array([0, 1, 2, 5, 9], dtype=np.int64)
    size = np.array(dimensions, dtype=np.int64)
    for margin in (1.0, 1e-6):
        s = np.concatenate([_interior_point(rng, d) for d in dimensions])
        z = np.concatenate([_interior_point(rng, d) for d in dimensions])
        s[start[2:]] = np.array([np.linalg.norm(s[f + 1 : f + d]) + margin
                                 for f, d in zip(start[2:], size[2:], strict=True)])  # fmt: skip
        beta, v, lam = np.ones(5), np.zeros(15), np.zeros(15)
        assert _scaling(s, z, start, size, 2, beta, v, lam)
        scaled_z, unscaled_s = z.copy(), s.copy()
        _apply_scaling(scaled_z, start, size, 2, beta, v, False)
        _apply_scaling(unscaled_s, start, size, 2, beta, v, True)
        np.testing.assert_allclose(scaled_z, lam, rtol=1e-9, atol=1e-12)
        np.testing.assert_allclose(unscaled_s, lam, rtol=1e-9, atol=1e-12)
        for first, d in zip(start[2:], size[2:], strict=True):
            w = np.empty((d, d))
            for column in range(d):
                unit = np.zeros(15)
                unit[first + column] = 1.0
                _apply_scaling(unit, start, size, 2, beta, v, False)
                w[:, column] = unit[first : first + d]
            j = np.diag(np.r_[1.0, -np.ones(d - 1)])
            rows = slice(first, first + d)
            ratio = np.sqrt((s[rows] @ j @ s[rows]) / (z[rows] @ j @ z[rows]))
            np.testing.assert_allclose(w, w.T, atol=1e-9 * np.abs(w).max())
            np.testing.assert_allclose(w @ j @ w, ratio * j, atol=1e-9 * np.abs(w).max() ** 2)
