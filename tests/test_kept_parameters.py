"""Re-solves through the kept parameter vector of the last direct solve (``Runner._again``)
against solves whose parameters go through cvxpy, as on a first solve."""

import dataclasses

import cvxpy as cp
import numpy as np
import pytest

from fixplan import pressure
from fixplan.planner.answers import values_of
from fixplan.planner.direct_solve import DirectSolver
from fixplan.planner.planner import Planner
from fixplan.planner.problem import Body, Contact, Load, Problem
from fixplan.planner.runner import Runner
from fixplan.planner.stacking import set_given


def clamped_block(places, load, *, model, mu, mass):
    """A block (centre of mass 20 mm up) held at ``places`` (``(name, role, position, normal,
    patch)`` each), objective ``min-total-clamp-force``."""
    contacts = [
        Contact(name=n, role=r, position=x, normal=v, mu=mu, model=model, patch=patch)
        for n, r, x, v, patch in places
    ]
    body = Body(mass=mass, center_of_mass=[0.0, 0.0, 0.02])
    return Problem(body=body, contacts=contacts, loads=load, objective="min-total-clamp-force")


def bench_fixture(load, model):
    """A 120 x 80 x 40 mm block on three pads against two side locators and an end stop, under
    a top and a side clamp: benchmarks/bench_planner.py's fixture."""
    pad, jaw = pressure.disk(0.008), pressure.rectangle(0.03, 0.01)
    places = [
        ("pad-1", "support", [0.04, 0.0, 0.0], [0, 0, 1], pad),
        ("pad-2", "support", [-0.04, 0.03, 0.0], [0, 0, 1], pad),
        ("pad-3", "support", [-0.04, -0.03, 0.0], [0, 0, 1], pad),
        ("side-1", "locator", [0.03, -0.04, 0.02], [0, 1, 0], jaw),
        ("side-2", "locator", [-0.03, -0.04, 0.02], [0, 1, 0], jaw),
        ("end", "locator", [-0.06, 0.0, 0.02], [1, 0, 0], jaw),
        ("clamp-top", "clamp", [0.0, 0.0, 0.04], [0, 0, -1], pad),
        ("clamp-side", "clamp", [0.0, 0.04, 0.02], [0, -1, 0], jaw),
    ]
    return clamped_block(places, load, model=model, mu=0.3, mass=3.0)


def fixture(model, load):
    """A block on three pads against two locators, held by a top and a side clamp."""
    pad, jaw = pressure.disk(0.01), pressure.rectangle(0.02, 0.01)
    places = [
        ("pad-1", "support", [0.04, 0.0, 0.0], [0, 0, 1], pad),
        ("pad-2", "support", [-0.04, 0.03, 0.0], [0, 0, 1], pad),
        ("pad-3", "support", [-0.04, -0.03, 0.0], [0, 0, 1], pad),
        ("side", "locator", [0.0, -0.04, 0.02], [0, 1, 0], jaw),
        ("end", "locator", [-0.06, 0.0, 0.02], [1, 0, 0], jaw),
        ("clamp-top", "clamp", [0.0, 0.0, 0.04], [0, 0, -1], pad),
        ("clamp-side", "clamp", [0.0, 0.04, 0.02], [0, -1, 0], jaw),
    ]
    return clamped_block(places, load, model=model, mu=0.4, mass=2.0)


#: Optima of the same program from two warm starts (simplex) or two interior-point runs
#: stopped at gap 1e-9 (Clarabel), relative to the largest force or multiple.
RTOL = {"pyramid": 1e-9, "ellipsoid": 1e-6}


def path(count, *, scales=(1.0,)):
    """Loads of a turning cut, each scaled in turn by one of ``scales`` (new force units)."""
    angles = np.linspace(0.0, 2.0 * np.pi, count)
    return [
        [
            Load(
                name="cut",
                force=[80.0 * s * np.cos(a), 80.0 * s * np.sin(a), -30.0 * s],
                point=[0.02 * np.cos(a / 2), 0.01, 0.04],
                torque=[0.0, 0.0, 0.8 * s * np.sin(a)],
            )
        ]
        for a, s in zip(angles, np.resize(scales, count), strict=True)
    ]


def comparable(plan):
    """What a plan states that does not depend on which optimum the solver returned."""
    held = plan.held_intervals.get("cut", (np.nan, np.nan))
    return np.array([plan.objective_value, plan.safety_factor or np.nan, *held])


def assert_same(plan, reference, rtol):
    assert plan.status == reference.status == "optimal"
    assert plan.held == reference.held
    np.testing.assert_allclose(comparable(plan), comparable(reference), rtol=rtol, atol=rtol)


def through_cvxpy(planner):
    """``planner`` with its parameters set through cvxpy on every solve (no kept vector)."""
    planner._runner._again = lambda *args: (False, None)
    planner._runner.with_sense = lambda *args: None
    planner._runner.carried_ends = lambda *args: {}
    planner._runner.held_without_load = lambda *args: False
    return planner


@pytest.fixture
def kept_solves(monkeypatch):
    """Counts the solves that went through the kept vector (``"kept"``), those of them that
    only wrote a sense into it (``"sense"``), and the ends of held intervals found there without
    a solve (``"carried"``, see :mod:`fixplan.planner.carried`)."""
    counts = {"kept": 0, "sense": 0, "carried": 0}
    again, with_sense = Runner._again, Runner.with_sense
    carried, without_load = Runner.carried_ends, Runner.held_without_load

    def counted_ends(self, *args):
        ends = carried(self, *args)
        counts["carried"] += len(set(ends) - {"solved"})  # (solved: not carried)
        return ends

    def counted_without_load(self, *args):
        held = without_load(self, *args)
        counts["carried"] += held
        return held

    def counted(self, *args):
        tried, result = again(self, *args)
        counts["kept"] += result is not None
        return tried, result

    def counted_sense(self, *args):
        result = with_sense(self, *args)
        counts["kept"] += result is not None
        counts["sense"] += result is not None
        return result

    monkeypatch.setattr(Runner, "_again", counted)
    monkeypatch.setattr(Runner, "with_sense", counted_sense)
    monkeypatch.setattr(Runner, "carried_ends", counted_ends)
    monkeypatch.setattr(Runner, "held_without_load", counted_without_load)
    return counts


@pytest.mark.parametrize("model", ["pyramid", "ellipsoid"])
def test_re_solves_with_their_analysis_match_solves_set_through_cvxpy(model, kept_solves):
    loads = path(24, scales=(1.0, 1.0, 1.0, 40.0, 0.02))  # force units change now and then
    planner = Planner(fixture(model, loads[0]))
    reference = through_cvxpy(Planner(fixture(model, loads[0])))
    for load in loads[:3]:
        planner.solve(load)
        reference.solve(load)
    kept_solves.update(kept=0, sense=0, carried=0)
    for load in loads[3:]:
        plan = planner.solve(load)
        assert_same(plan, reference.solve(load), RTOL[model])
    # Of the force solve and the two ends of each analysis, those whose force unit did not
    # change go through the kept vector (37 of 63 here): solved there, or found there without
    # a solve, carried from the force solve (k_max = 1 where the clamps are least) or from the
    # forces alone (k_min = 0: the clamps press the block into its locators, every time).
    assert kept_solves["kept"] + kept_solves["carried"] >= 37
    assert kept_solves["carried"] >= len(loads[3:])


def test_a_sense_alone_is_written_only_for_the_loads_and_forces_the_kept_vector_holds():
    loads = path(6)
    planner = Planner(fixture("pyramid", loads[0]))
    for load in loads[:5]:
        plan = planner.solve(load)
    runner = planner._runner
    wrenches = planner.problem.task_wrenches(loads[4])
    planned = {5: plan.forces["clamp-top"], 6: plan.forces["clamp-side"]}
    highest = runner.with_sense("check", wrenches, planned, 1.0)
    lowest = runner.with_sense("check", wrenches, planned, -1.0)
    assert (lowest["scale"][0], highest["scale"][0]) == pytest.approx(plan.held_intervals["cut"])
    other = planner.problem.task_wrenches(loads[5])
    assert runner.with_sense("check", other, planned, 1.0) is None
    assert runner.with_sense("check", wrenches, {5: planned[5] * 1.1, 6: planned[6]}, 1.0) is None
    assert runner.with_sense("check", wrenches, planned, 1.0, np.ones(7, dtype=bool)) is None


def test_given_forces_written_into_the_kept_vector_alone_reach_a_solve_through_cvxpy(
    monkeypatch,
):
    """A re-solve writes new given forces (an analysis's planned forces) into the kept vector
    and not into the Parameters; where the direct solver then fails, the solve through cvxpy
    that follows sets them first."""
    loads = path(6)
    planner = Planner(fixture("pyramid", loads[0]))
    reference = through_cvxpy(Planner(fixture("pyramid", loads[0])))
    for load in loads[:4]:
        planner.solve(load)
        reference.solve(load)
    check = planner._runner._direct[("check", False)]
    monkeypatch.setattr(check, "solved", lambda **options: False)
    for load in loads[4:]:
        assert_same(planner.solve(load), reference.solve(load), RTOL["pyramid"])


def test_disabled_contacts_are_part_of_the_kept_state(kept_solves):
    loads = path(12)
    planner = Planner(fixture("pyramid", loads[0]), switchable=True)
    reference = through_cvxpy(Planner(fixture("pyramid", loads[0]), switchable=True))
    choices = [(), ("clamp-side",), ("end",), ()]
    for k, load in enumerate(loads):
        disabled = choices[k % len(choices)]
        plan = planner.solve(load, disabled=disabled)
        assert_same(plan, reference.solve(load, disabled=disabled), RTOL["pyramid"])
        if "clamp-side" in disabled:  # (zero up to the solver's noise)
            assert abs(plan.forces["clamp-side"]) <= 1e-9 * plan.objective_value
    assert kept_solves["kept"] > 0


def test_written_parameters_give_the_vector_of_set_parameters():
    x = cp.Variable(3)
    task, given = cp.Parameter((2, 2)), cp.Parameter(2, nonneg=True)
    unused = cp.Parameter(4)
    problem = cp.Problem(
        cp.Minimize(cp.sum(x)),
        [x[:2] >= task[:, 0] + task[:, 1], x[2] >= given[0] - given[1], x >= -5],
    )
    task.value, given.value = np.ones((2, 2)), np.ones(2)
    problem.solve(solver=cp.CLARABEL)
    problem.solve(solver=cp.CLARABEL)
    direct = DirectSolver.create(problem, {})
    assert direct is not None
    vector = direct.parameter_vector()
    new_task, new_given = np.array([[1.0, 2.0], [3.0, 4.0]]), np.array([5.0, 1.5])
    direct.write(vector, task, new_task)
    direct.write(vector, given, new_given)
    direct.write(vector, unused, np.arange(4.0))  # not in the program: left out
    task.value, given.value = new_task, new_given
    np.testing.assert_array_equal(vector, direct.parameter_vector())
    # A linear program: solved by the simplex, whose objective value is taken when asked.
    direct.solve(vector=vector)
    assert direct.method == "dual simplex"
    # x >= (1 + 2, 3 + 4, 5 - 1.5): the sum is 13.5.
    assert direct.objective_value == pytest.approx(13.5, rel=1e-14)


def test_a_written_parameter_of_the_constraints_renews_them_and_a_cost_parameter_does_not():
    x = cp.Variable(2)
    bound, weight = cp.Parameter(2), cp.Parameter(nonneg=True)
    problem = cp.Problem(cp.Minimize(weight * x[0] + x[1]), [x >= bound, x <= 10.0])
    bound.value, weight.value = np.array([1.0, -2.0]), 1.0
    problem.solve(solver=cp.CLARABEL)
    problem.solve(solver=cp.CLARABEL)
    direct = DirectSolver.create(problem, {})
    vector = direct.parameter_vector()
    assert direct.solved(vector=vector)
    direct.write(vector, weight, -1.0)  # x[0] to its upper bound
    assert direct.solved(vector=vector)
    np.testing.assert_allclose(direct.values()[x.id], [10.0, -2.0], atol=1e-9)
    direct.write(vector, bound, [1.0, 3.0])
    assert direct.solved(vector=vector)
    np.testing.assert_allclose(direct.values()[x.id], [10.0, 3.0], atol=1e-9)


@pytest.mark.parametrize("model", ["pyramid", "ellipsoid"])
def test_answers_gathered_at_their_positions_are_the_variables_and_given_forces(model):
    """The normal forces (decided and given), friction loads and multiples that a direct
    solve's answer is read as equal those read through its variables and the Parameters."""
    cases = [
        [dataclasses.replace(load, name=f"cut-{j}") for j, [load] in enumerate(path(3 + k)[:3])]
        for k in range(4)
    ]  # three load cases, the fixed-force ones of the ellipsoid in one block of Clarabel
    planner = Planner(fixture(model, cases[0]))
    for loads in cases:
        planner.solve(loads)
    runner = planner._runner
    read, solution_only = 0, set()
    for key, direct in runner._direct.items():
        reader = runner._readers.get(key)
        if direct is None or reader is None:
            continue
        stacked = runner._built[key]
        kept = runner._kept[key]  # (its given forces were written into its vector alone)
        set_given(stacked, dict(kept.given), kept.unit)
        through_variables = values_of(stacked, direct.values())
        for name, value in reader(direct).items():
            np.testing.assert_array_equal(value, through_variables[name], err_msg=name)
        read += 1
        solution_only.add(reader.solution_only)
    assert read >= 2  # the force objective and the check (fixed forces: multiples variables)
    assert solution_only == {True, False}  # (the check reads its given forces from the vector)


def test_gather_reads_variables_parameters_and_zero():
    x = cp.Variable(2)
    bound = cp.Parameter(2)
    problem = cp.Problem(cp.Minimize(cp.sum(x)), [x >= bound])
    bound.value = np.array([1.0, -2.0])
    problem.solve(solver=cp.CLARABEL)
    problem.solve(solver=cp.CLARABEL)
    direct = DirectSolver.create(problem, {})
    assert direct.solved()
    positions = np.concatenate([direct.positions(x), direct.positions(bound), [-1]])
    np.testing.assert_allclose(direct.gather(positions), [1.0, -2.0, 1.0, -2.0, 0.0], atol=1e-12)
    variables = direct.positions(x)
    assert variables.max() < direct.variables <= direct.positions(bound).min()
    np.testing.assert_array_equal(
        direct.gather(variables, solution_only=True), direct.gather(variables)
    )
