"""The warm-started dual simplex against HiGHS (scipy's linprog), and in the planner."""

import dataclasses
from pathlib import Path

import numpy as np
import pytest
from scipy.optimize import linprog
from test_kept_parameters import bench_fixture

from fixplan.io.problem_file import load_problem
from fixplan.planner.dual_simplex import DualSimplex
from fixplan.planner.planner import Planner
from fixplan.planner.problem import Body, Contact, Load, Problem

#: Optimal values agree with HiGHS to this relative tolerance; optimality conditions hold to it.
RTOL = 1e-9


def _random_program(rng, n, equalities, inequalities):
    """A program ``(A, q)`` of random rows with a box, and ``b(shift)``: the right-hand side
    of a feasible point moved by ``shift`` with random slacks (feasible and bounded)."""
    rows = rng.normal(size=(equalities + inequalities, n))
    a = np.vstack([rows, np.eye(n), -np.eye(n)])
    point = rng.normal(size=n)

    def right_hand_side(shift):
        moved = point + shift * rng.normal(size=n)
        b = rows @ moved
        b[equalities:] += rng.uniform(0.0, 1.0, size=inequalities)
        return np.r_[b, np.full(2 * n, 10.0 + np.abs(point).max() + shift * 10.0)]

    return a, rng.normal(size=n), right_hand_side


def _highs(a, b, q, equalities):
    return linprog(
        q, A_ub=a[equalities:], b_ub=b[equalities:], A_eq=a[:equalities] if equalities else None,
        b_eq=b[:equalities] if equalities else None, bounds=(None, None), method="highs",
    )  # fmt: skip


def _assert_optimal(a, b, q, equalities, x, z, expected):
    scale = max(1.0, abs(expected))
    assert q @ x == pytest.approx(expected, abs=RTOL * scale)
    residual = a @ x - b
    size = np.abs(b) + np.abs(a).sum(axis=1) * np.abs(x).max()
    assert np.all(np.abs(residual[:equalities]) <= RTOL * size[:equalities])
    assert np.all(residual[equalities:] <= RTOL * size[equalities:])  # feasible
    np.testing.assert_allclose(q + a.T @ z, 0.0, atol=RTOL * np.abs(q).max())  # stationary
    assert np.all(z[equalities:] >= -RTOL * np.abs(q).max())  # dual feasible
    assert np.all(np.abs(z * residual)[equalities:] <= RTOL * scale)  # complementary


@pytest.mark.parametrize("seed", range(6))
def test_warm_re_solves_with_new_right_hand_sides_match_highs(seed):
    rng = np.random.default_rng(seed)
    n = int(rng.integers(3, 30))
    equalities = int(rng.integers(0, min(n, 7)))
    a, q, right_hand_side = _random_program(rng, n, equalities, int(rng.integers(n, 4 * n)))
    simplex = DualSimplex(equalities)
    pivots = []
    for step in range(12):
        b = right_hand_side(0.1 * step)
        reference = _highs(a, b, q, equalities)
        assert reference.status == 0
        x, z = simplex.solve(a, q, b)
        _assert_optimal(a, b, q, equalities, x, z, reference.fun)
        pivots.append(simplex.pivots)
    assert max(pivots[1:]) > 0  # the warm starts pivoted


def test_a_degenerate_vertex_of_many_rows_is_found():
    # min -x - y under 40 lines through (1, 1) (a pyramid's facets meeting at one vertex), and
    # the same rows duplicated: massively degenerate.
    angles = np.linspace(0.05, np.pi / 2 - 0.05, 40)
    rows = np.column_stack([np.cos(angles), np.sin(angles)])
    a = np.vstack([rows, rows])
    b = a @ np.ones(2)
    x, z = DualSimplex(0).solve(a, np.array([-1.0, -1.0]), b)
    np.testing.assert_allclose(x, [1.0, 1.0], rtol=1e-12)
    np.testing.assert_allclose(a.T @ z, [1.0, 1.0], rtol=1e-12)


def test_infeasible_and_unbounded_programs_give_none():
    infeasible = np.array([[1.0], [-1.0]])  # x <= -1 and x >= 1
    assert DualSimplex(0).solve(infeasible, np.array([1.0]), np.array([-1.0, -1.0])) is None
    below = np.array([[1.0]])  # min x with x <= 1
    assert DualSimplex(0).solve(below, np.array([1.0]), np.array([1.0])) is None


@pytest.mark.parametrize("seed", range(4))
def test_a_warm_start_that_finds_the_program_infeasible_gives_up_without_an_artificial_start(
    seed, monkeypatch
):
    """Box rows crossed (``x_0 <= -l - 1`` and ``x_0 >= -l``): the pivots from the last basis
    end on a dual ray, and the solve gives up at once; the next right-hand side starts from
    the basis kept before."""
    rng = np.random.default_rng(seed)
    n = int(rng.integers(3, 30))
    equalities = int(rng.integers(0, min(n, 7)))
    inequalities = int(rng.integers(n, 4 * n))
    a, q, right_hand_side = _random_program(rng, n, equalities, inequalities)
    simplex = DualSimplex(equalities)
    assert simplex.solve(a, q, right_hand_side(0.0)) is not None
    monkeypatch.setattr(DualSimplex, "_cold", lambda *args: pytest.fail("an artificial start"))
    crossed = right_hand_side(0.1)
    upper = equalities + inequalities
    crossed[upper] = -crossed[upper + n] - 1.0
    assert _highs(a, crossed, q, equalities).status == 2  # (infeasible)
    assert simplex.solve(a, q, crossed) is None
    b = right_hand_side(0.2)
    x, z = simplex.solve(a, q, b)
    _assert_optimal(a, b, q, equalities, x, z, _highs(a, b, q, equalities).fun)


def _pyramid_grasp(load):
    contacts = [
        Contact(name=name, role="finger", position=[0.0, side * 0.03, 0.0],
                normal=[0.0, -side, 0.0], mu=0.4, model="point-pyramid", facets=8)
        for name, side in (("left", -1), ("right", 1))
    ]  # fmt: skip
    contacts.append(
        Contact(name="palm", role="support", position=[0.0, 0.0, -0.02], normal=[0.0, 0.0, 1.0],
                mu=0.3, model="point-pyramid", facets=6)
    )  # fmt: skip
    body = Body(mass=0.3, center_of_mass=[0.0, 0.0, 0.0])
    return Problem(body=body, contacts=tuple(contacts), loads=(load,),
                   objective="min-total-normal-force")  # fmt: skip


def test_planner_re_solves_through_the_simplex_equal_fresh_solves():
    def load(angle):
        return Load(name="push", force=[4.0 * np.cos(angle), 2.0, -5.0 + np.sin(angle)],
                    point=[0.01, 0.0, 0.01])  # fmt: skip

    planner = Planner(_pyramid_grasp(load(0.0)))
    for angle in np.linspace(0.0, 2.0, 4):  # cvxpy twice, then the direct path
        planner.solve([load(angle)])
    for angle in np.linspace(0.0, 6.0, 15):
        plan = planner.solve([load(angle)])  # with the safety analysis: fixed-force programs
        fresh = Planner(_pyramid_grasp(load(angle))).solve()
        assert plan.solver == "dual simplex (direct)"
        assert plan.status == fresh.status == "optimal"
        assert plan.objective_value == pytest.approx(fresh.objective_value, rel=1e-7)
        low, high = plan.held_intervals["push"]
        fresh_low, fresh_high = fresh.held_intervals["push"]
        # The fresh solves are Clarabel's, which stops at duality gaps of about 1e-9 of its
        # scaled problem: multiples agree to 1e-7.
        assert high == pytest.approx(fresh_high, rel=1e-7)
        assert low == pytest.approx(fresh_low, abs=1e-7)
        # (Which contact is critical is a tie in these grasps: the optima are not unique.)
        assert plan.utilisation.max() == pytest.approx(fresh.utilisation.max(), rel=1e-6)


def test_cold_starts_of_dually_degenerate_programs_stay_in_the_simplex():
    # The least multiple k_min of the safety analysis is 0 here: its program minimises one
    # variable, and most multipliers of the artificial start are exactly 0. Unperturbed, the
    # ties of the ratio test stalled 4 of these 12 cold starts past their pivot limit, and
    # Clarabel solved them (about 6 ms each); with perturbed costs the simplex solves all.
    def cut(angle):
        return [Load(name="cut", force=[80.0 * np.cos(angle), 80.0 * np.sin(angle), -30.0],
                     point=[0.02 * np.cos(angle / 2), 0.01, 0.04],
                     torque=[0.0, 0.0, 0.8 * np.sin(angle)])]  # fmt: skip

    for angle in np.linspace(0.0, 2.0 * np.pi, 12, endpoint=False):
        planner = Planner(bench_fixture(cut(angle), "pyramid"))
        planner.solve(cut(angle + 0.5))  # (cvxpy's solves; the direct solvers are built)
        plan = planner.solve(cut(angle))  # the fixed-force programs start cold
        assert planner._runner._direct[("check", False)].method == "dual simplex"
        fresh = Planner(
            bench_fixture(cut(angle), "pyramid")
        ).solve()  # (through cvxpy and Clarabel)
        low, high = plan.held_intervals["cut"]
        fresh_low, fresh_high = fresh.held_intervals["cut"]
        assert low == pytest.approx(fresh_low, abs=1e-7)
        assert high == pytest.approx(fresh_high, rel=1e-7)


def test_a_program_whose_matrix_changes_is_solved_from_its_refactored_basis():
    # One column of A changes, as the load column of a fixed-force objective does: small
    # changes keep the basis dual feasible; every answer is HiGHS's.
    rng = np.random.default_rng(11)
    n, equalities = 12, 4
    a, q, right_hand_side = _random_program(rng, n, equalities, 30)
    b = right_hand_side(0.0)
    simplex = DualSimplex(equalities, changing=True)
    column = a[:, 0].copy()
    for step in range(20):
        a[: equalities + 30, 0] = column[: equalities + 30] * (1.0 + 0.01 * np.sin(step))
        reference = _highs(a, b, q, equalities)
        x, z = simplex.solve(a.copy(), q, b)
        _assert_optimal(a, b, q, equalities, x, z, reference.fun)


def test_a_changing_program_whose_warm_starts_keep_missing_is_left_to_the_caller():
    rng = np.random.default_rng(5)
    n, equalities = 10, 3
    a, q, right_hand_side = _random_program(rng, n, equalities, 25)
    simplex = DualSimplex(equalities, changing=True)
    answers = []
    for _ in range(40):
        a[: equalities + 25] = rng.normal(size=(equalities + 25, n))  # a new program each time
        b = right_hand_side(0.0)
        b[: equalities + 25] = (
            a[: equalities + 25] @ rng.normal(size=n)
            + np.r_[np.zeros(equalities), rng.uniform(0.0, 1.0, size=25)]
        )
        found = simplex.solve(a.copy(), q, b)
        if found is not None:
            _assert_optimal(a, b, q, equalities, *found, _highs(a, b, q, equalities).fun)
        answers.append(found is not None)
    assert not any(answers[-10:])  # it stopped trying


def turned_fixture_321(count: int, seed: int, sizes: tuple[float, float] | None = None) -> Problem:
    """fixture-321 (pyramids) at its planned clamp forces (objective ``check``), its loads in
    turn as ``count`` load cases, each turned about z at random (and scaled by a random factor
    within ``sizes``)."""
    problem = load_problem(Path(__file__).resolve().parents[1] / "problems" / "fixture-321.toml")
    problem = problem.problem
    forces = Planner(problem).solve().forces
    contacts = tuple(
        dataclasses.replace(c, force=float(forces[c.name])) if c.name in forces else c
        for c in problem.contacts
    )
    rng = np.random.default_rng(seed)
    loads = []
    for k in range(count):
        base = problem.loads[k % len(problem.loads)]
        angle = rng.uniform(-np.pi, np.pi)
        size = 1.0 if sizes is None else rng.uniform(*sizes)
        c, s = np.cos(angle), np.sin(angle)
        turn = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
        loads.append(Load(name=f"case-{k}", force=size * turn @ base.force,
                          point=turn @ base.point, torque=size * base.torque))  # fmt: skip
    return dataclasses.replace(problem, contacts=contacts, loads=tuple(loads), objective="check")


def test_a_linear_check_of_many_cases_equals_each_case_solved_alone():
    # fixture-321 (pyramids) at its planned clamp forces, 30 turned load cases: solved one by
    # one in an order of similar loads through the simplex (from the third solve on), and
    # returned in the cases' own order.
    checked = turned_fixture_321(30, seed=2)
    loads = checked.loads
    planner = Planner(checked)
    for _ in range(3):
        plan = planner.solve()
    assert "dual simplex" in plan.solver
    for load in loads[::3]:
        alone = Planner(dataclasses.replace(checked, loads=(load,))).solve()
        low, high = plan.held_intervals[load.name]
        alone_low, alone_high = alone.held_intervals[load.name]
        assert high == pytest.approx(alone_high, rel=1e-7)
        assert low == pytest.approx(alone_low, abs=1e-7)
        assert plan.held[load.name] == alone.held[load.name]


def test_a_basis_inverse_follows_a_changed_column_as_a_fresh_inverse_does():
    # Sherman-Morrison on the one column that changed, against numpy's inverse of the new
    # basis; a second changed column, or REFACTOR_EVERY updates in a row, invert afresh.
    from fixplan.planner.dual_simplex import REFACTOR_EVERY

    rng = np.random.default_rng(3)
    n = 12
    a = rng.normal(size=(3 * n, n))
    rows = rng.choice(3 * n, n, replace=False)
    inverse = np.linalg.inv(a[rows])
    updates = 0
    for step in range(REFACTOR_EVERY + 3):
        changed = a.copy()
        changed[:, step % n] += 0.3 * rng.normal(size=3 * n)
        expected = np.linalg.inv(changed[rows])
        updates_after = DualSimplex._refactored(changed, a, rows, inverse, updates)
        assert updates_after == (updates + 1 if updates < REFACTOR_EVERY else 0)
        np.testing.assert_allclose(inverse, expected, rtol=0, atol=1e-9 * np.abs(expected).max())
        a, updates = changed, updates_after
    two = a.copy()
    two[:, :2] += 1.0
    assert DualSimplex._refactored(two, a, rows, inverse, 0) == 0
    np.testing.assert_allclose(inverse @ two[rows], np.eye(n), atol=1e-9)
    assert DualSimplex._refactored(a, a.copy(), rows, inverse, 5) == 5  # (the same values)
