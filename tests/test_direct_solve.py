"""Clarabel called directly on compiled conic data against cvxpy's own answers."""

import cvxpy as cp
import numpy as np
import pytest

from fixplan.planner.direct_solve import INFEASIBLE, DirectSolver

SETTINGS = {"tol_gap_abs": 1e-10, "tol_gap_rel": 1e-10, "tol_feas": 1e-10}


def _spring_like_qp(rng):
    """A QP shaped like the contact-spring steps: a sum of squares with a parametric linear
    term, an equality with a parametric right-hand side, bounds and second-order cones whose
    radii are parameters."""
    x = cp.Variable(8)
    reference, load, radius = cp.Parameter(8), cp.Parameter(3), cp.Parameter(2, nonneg=True)
    matrix = rng.normal(size=(3, 8))
    balance = matrix @ x + load == 0
    constraints = [balance, x[[0, 4]] >= 0]
    constraints += [cp.norm(x[1:3]) <= radius[0], cp.norm(x[5:7]) <= radius[1]]
    problem = cp.Problem(cp.Minimize(cp.sum_squares(x) - 2 * reference @ x), constraints)
    return problem, x, (reference, load, radius), balance


def _draw(parameters, rng):
    reference, load, radius = parameters
    reference.value = rng.normal(size=8)
    load.value = rng.normal(size=3)
    radius.value = rng.uniform(0.5, 2.0, 2)


def test_the_direct_path_matches_cvxpy_in_values_objective_and_equality_multipliers():
    rng = np.random.default_rng(4)
    problem, x, parameters, balance = _spring_like_qp(rng)
    _draw(parameters, rng)
    problem.solve(solver=cp.CLARABEL, **SETTINGS)
    direct = DirectSolver.create(problem, SETTINGS)
    assert direct is not None
    for _ in range(5):
        _draw(parameters, rng)
        problem.solve(solver=cp.CLARABEL, **SETTINGS)
        values = direct.solve()
        assert direct.status == "Solved"
        # Two interior-point runs stopped at gap 1e-10 agree in the optimum to about its
        # square root (the objective is strongly convex), in the value to the gap.
        np.testing.assert_allclose(values[x.id], x.value, atol=1e-5)
        assert direct.objective_value == pytest.approx(problem.value, abs=1e-8)
        dual = direct.dual(balance)
        np.testing.assert_allclose(dual, balance.dual_value, atol=1e-5)


def test_a_load_that_nothing_balances_is_reported_infeasible():
    x = cp.Variable(3)
    load = cp.Parameter(3)
    problem = cp.Problem(cp.Minimize(cp.sum_squares(x)), [x + load == 0, x >= 0])
    load.value = -np.ones(3)
    problem.solve(solver=cp.CLARABEL, **SETTINGS)
    direct = DirectSolver.create(problem, SETTINGS)
    load.value = np.array([-1.0, 2.0, -1.0])  # x1 = -2 < 0
    assert direct.solve() is None
    assert direct.status in INFEASIBLE


def test_parameters_that_move_the_constraint_matrix_are_applied():
    # A load multiple times a parametric wrench, as in the planner's fixed-force objectives.
    rng = np.random.default_rng(6)
    x, multiple = cp.Variable(6), cp.Variable()
    wrench = cp.Parameter(3)
    matrix = rng.normal(size=(3, 6))
    balance = matrix @ x + multiple * wrench == 0
    constraints = [balance, cp.norm(x, 1) <= 1.0]
    problem = cp.Problem(cp.Maximize(multiple), constraints)
    wrench.value = rng.normal(size=3)
    problem.solve(solver=cp.CLARABEL, **SETTINGS)
    direct = DirectSolver.create(problem, SETTINGS)
    assert direct is not None
    for _ in range(5):
        wrench.value = rng.normal(size=3)
        problem.solve(solver=cp.CLARABEL, **SETTINGS)
        values = direct.solve()
        assert values[multiple.id] == pytest.approx(multiple.value, rel=1e-7)
        np.testing.assert_allclose(direct.dual(balance), balance.dual_value, atol=1e-6)


def test_a_parametric_quadratic_cost_is_refused():
    x = cp.Variable(2)
    weight = cp.Parameter(nonneg=True)
    problem = cp.Problem(cp.Minimize(weight * cp.sum_squares(x) + cp.sum(x)), [x >= -1])
    weight.value = 2.0
    problem.solve(solver=cp.CLARABEL)
    assert DirectSolver.create(problem, SETTINGS) is None
