"""The cases of a linear fixed-force objective, one by one straight through the direct solver
(``Runner._one_by_one``), against the general path of one block per case; and the certificate
of a case held at no multiple, against the conditions of Farkas's lemma."""

import dataclasses

import numpy as np
import pytest
from test_dual_simplex import turned_fixture_321

from fixplan.planner.blocks import block_of
from fixplan.planner.planner import Planner
from fixplan.planner.problem import Body, Contact, Load, Problem
from fixplan.planner.runner import Runner


def _block_by_block(self, objective, wrenches, given, order, numbers, sense, disabled, progress):
    """The general path in the lane's place: one block per case, in the lane's order."""
    return [
        (self._run_block(objective, *block_of(order[p : p + 1], 1, wrenches, given, None,
                                              numbers), sense, False, disabled), 1)
        for p in range(len(order))
    ]  # fmt: skip


@pytest.fixture
def block_path(monkeypatch):
    """Plans through the general path instead of the one-by-one lane."""

    def solve(problem):
        with monkeypatch.context() as patch:
            patch.setattr(Runner, "_one_by_one", _block_by_block)
            return Planner(problem).solve()

    return solve


@pytest.fixture
def lane_used(monkeypatch):
    """The number of cases of each call of the one-by-one lane."""
    answered = []
    original = Runner._one_by_one

    def spy(self, *args):
        results = original(self, *args)
        answered.append(len(results))
        return results

    monkeypatch.setattr(Runner, "_one_by_one", spy)
    return answered


def _assert_same_plans(plan, reference):
    assert plan.status == reference.status
    assert plan.solver == reference.solver
    assert plan.warnings == reference.warnings
    assert plan.safety_factors == reference.safety_factors
    assert plan.held_intervals == reference.held_intervals
    assert plan.held == reference.held
    np.testing.assert_array_equal(plan.normal_forces, reference.normal_forces)
    np.testing.assert_array_equal(plan.contact_wrenches, reference.contact_wrenches)
    for name in plan.load_names:
        motion, expected = plan.motions[name], reference.motions[name]
        assert (motion is None) == (expected is None)
        if motion is not None:
            np.testing.assert_array_equal(motion.twist, expected.twist)


def test_the_lane_gives_the_plan_of_one_block_per_case(block_path, lane_used):
    # The same parameter vectors and the same simplex in the same order of cases: the same
    # numbers to the last bit, for loads of sizes 0.2 to 3 (several force units).
    problem = turned_fixture_321(40, seed=7, sizes=(0.2, 3.0))
    plan = Planner(problem).solve()
    assert 40 in lane_used
    assert "dual simplex (direct)" in plan.solver
    reference = block_path(problem)
    _assert_same_plans(plan, reference)
    assert not all(plan.held.values()) and any(plan.held.values())


def _pushed_block() -> Problem:
    """A block on three supports, pushed along +x by a frictionless clamp of 10 N: friction
    (mu 0.3 of 9.8 N) cannot hold that alone, so a case is held only where its load pushes
    back (along -x) enough and not too much; a load along +x is held at no multiple."""
    supports = [
        Contact(name=f"pad-{k}", role="support", position=[x, y, 0.0], normal=[0.0, 0.0, 1.0],
                mu=0.3, model="point-pyramid", facets=8, inscribed=False)
        for k, (x, y) in enumerate([(-0.03, -0.03), (0.03, -0.03), (0.0, 0.04)])
    ]  # fmt: skip
    clamp = Contact(name="pusher", role="clamp", position=[-0.05, 0.0, 0.01],
                    normal=[1.0, 0.0, 0.0], mu=0.0, model="point-pyramid", facets=8,
                    force=10.0)  # fmt: skip
    loads = [
        Load(name=f"{sign}{size:g}", force=[float(f"{sign}1") * size, 0.0, 0.0],
             point=[0.05, 0.0, 0.01])
        for sign, size in (("-", 10.0), ("-", 8.0), ("+", 5.0), ("-", 14.0), ("-", 9.0))
    ]  # fmt: skip
    return Problem(body=Body(mass=1.0, center_of_mass=[0.0, 0.0, 0.01]),
                   contacts=(*supports, clamp), loads=tuple(loads), objective="check")  # fmt: skip


def test_a_case_held_at_no_multiple_makes_the_check_infeasible_as_on_the_block_path(
    block_path, lane_used
):
    problem = _pushed_block()
    planner = Planner(problem)
    for _ in range(3):  # the direct solver exists from the second solve on
        plan = planner.solve()
    assert 5 in lane_used
    assert plan.status == "infeasible"
    reference = block_path(problem)
    assert reference.status == "infeasible"
    assert plan.certificate == reference.certificate
    for name in problem.loads[0:2]:
        assert (plan.infeasible_motions or {}).get(name.name) is None


def test_the_pushed_block_without_its_unheld_case_has_the_closed_form_intervals(block_path):
    # The clamp's 10 N against friction of mu (9.8 N + 0) and the task load k F along -x: held
    # while |10 - k F| <= 0.3 * 9.80665 N (the supports' pyramids have 8 facets, so their
    # friction along x is mu times the normal force exactly).
    problem = _pushed_block()
    problem = dataclasses.replace(problem, loads=[x for x in problem.loads if x.name[0] == "-"])
    plan = Planner(problem).solve()
    reference = block_path(problem)
    _assert_same_plans(plan, reference)
    friction = 0.3 * 9.81
    for load in problem.loads:
        size = -load.force[0]
        low, high = plan.held_intervals[load.name]
        assert low == pytest.approx((10.0 - friction) / size, rel=1e-7)
        assert high == pytest.approx((10.0 + friction) / size, rel=1e-7)


def test_the_certificate_of_the_pushed_block_moves_it_the_way_the_clamp_pushes():
    # A Farkas certificate: a twist that gravity and the given clamp force drive with positive
    # power while every force the supports' cones allow does power >= 0 on it (it lifts the
    # block off them, by the associated flow of Coulomb's cone). Its sign came from the task
    # load and gravity alone, without the clamp: the block was said to move into its supports.
    problem = _pushed_block()
    plan = Planner(problem).solve()
    assert plan.status == "infeasible"
    twist = plan.infeasible_motions["+5"].twist
    v, omega = twist[:3], twist[3:]
    for contact in problem.contacts[:3]:  # the supports
        velocity = v + np.cross(omega, contact.position)
        assert velocity[2] >= 0.3 * np.cos(np.pi / 8) * np.hypot(*velocity[:2]) - 1e-7
    clamp = problem.contacts[3]
    clamp_force = clamp.force * clamp.normal  # pushing on the block along +x
    at_clamp = v + np.cross(omega, clamp.position)
    at_centre = v + np.cross(omega, problem.body.center_of_mass)
    weight = problem.body.mass * np.array([0.0, 0.0, -9.81])
    assert clamp_force @ at_clamp + weight @ at_centre > 0.0
    assert at_centre[0] > 0.0


def _counted_plans(monkeypatch, problem, later, *, lane):
    """Two plans of ``problem`` and one with the ``later`` loads by one planner, with the
    direct solves of each (the lane declined unless ``lane``)."""
    from fixplan.planner.direct_solve import DirectSolver

    calls = [0]
    solve = DirectSolver.solve

    def counted(self, **options):
        calls[0] += 1
        return solve(self, **options)

    plans, counts = [], []
    with monkeypatch.context() as patch:
        patch.setattr(DirectSolver, "solve", counted)
        if not lane:
            patch.setattr(Runner, "_one_by_one", _block_by_block)
        planner = Planner(problem)
        for loads in (None, None, later):
            calls[0] = 0
            plans.append(planner.solve(loads))
            counts.append(calls[0])
    return plans, counts


def test_a_case_the_direct_solver_fails_on_is_not_given_to_it_twice(monkeypatch, lane_used):
    # Every fifth case pushes along +x (held at no multiple): the direct solver fails on it and
    # cvxpy gives the certificate. The lane must hand such a case to the block path without
    # that path trying the direct solver on it once more: each try counts as a missed warm
    # start of the simplex, and with more of them the simplex gives up on the objective sooner
    # than on the block path (Clarabel then for every later case of the planner, and other
    # numbers in the last bits). The same direct solves as the block path, the same plans.
    base = _pushed_block()
    sizes = np.linspace(7.0, 13.0, 40)
    sideways = np.linspace(-0.5, 0.5, 40)[::-1]
    loads = [
        Load(name=f"case-{k}", force=[(1.0 if k % 5 == 4 else -1.0) * size, y, 0.0],
             point=[0.05, 0.0, 0.01])
        for k, (size, y) in enumerate(zip(sizes, sideways, strict=True))
    ]  # fmt: skip
    held = [dataclasses.replace(load, force=[-abs(load.force[0]), *load.force[1:]])
            for load in loads]  # fmt: skip
    problem = dataclasses.replace(base, loads=tuple(loads))
    plans, counts = _counted_plans(monkeypatch, problem, held, lane=True)
    assert 40 in lane_used
    references, reference_counts = _counted_plans(monkeypatch, problem, held, lane=False)
    assert [plan.status for plan in plans] == ["infeasible", "infeasible", "optimal"]
    for plan, reference in zip(plans[:2], references[:2], strict=True):
        assert plan.solver == reference.solver
        assert plan.certificate == reference.certificate
        motions, expected = plan.infeasible_motions, reference.infeasible_motions
        assert motions.keys() == expected.keys()
        for name, motion in motions.items():
            np.testing.assert_array_equal(motion.twist, expected[name].twist)
    _assert_same_plans(plans[2], references[2])
    assert counts == reference_counts
