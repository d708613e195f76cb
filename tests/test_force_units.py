"""Every program is solved in a force unit of its own (:mod:`fixplan.planner.runner`).

Friction sets are cones, so a problem whose forces (loads, weight, given forces, ``max_force``
bounds) are all multiplied by ``s`` has the forces of the original times ``s`` and the same
safety factors and motions: checked against the closed form of the uniform-disk pinch
(:mod:`tests.test_exact_planner`) from 1e-4 N to 1e5 N, and as a law on a fixture of every model
kind. In newtons, the fixture at 1e4 times its loads (tens of kN) gave safety factors of 0.97
where 1 holds.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from test_exact_planner import (
    OPTIMUM_RTOL,
    assert_loads_inside_their_exact_surfaces,
    least_normal_force,
    pinch,
)

from fixplan import Body, Contact, Load, Problem, pressure
from fixplan.planner.planner import Planner
from fixplan.planner.runner import FORCE_IN_UNITS, Runner

SCALES = [1e-4, 1e4, 1e5]


def scaled(problem: Problem, s: float) -> Problem:
    """``problem`` with every force multiplied by ``s``: loads, weight (the mass), given forces
    and ``max_force`` bounds."""
    loads = [dataclasses.replace(x, force=s * x.force, torque=s * x.torque) for x in problem.loads]
    contacts = [
        dataclasses.replace(
            c,
            force=None if c.force is None else s * c.force,
            max_force=None if c.max_force is None else s * c.max_force,
        )
        for c in problem.contacts
    ]
    body = dataclasses.replace(problem.body, mass=s * problem.body.mass)
    return dataclasses.replace(problem, loads=loads, contacts=contacts, body=body)


@pytest.mark.parametrize("s", SCALES)
def test_a_disk_pinch_needs_the_closed_form_grip_at_any_size(s):
    weight, torque = 10.0 * s, 0.05 * s
    load = Load(name="hold", force=[0, 0, -weight], point=[0, 0, 0], torque=[0, torque, 0])
    problem = pinch(load)
    plan = Planner(problem).solve()
    expected, _ = least_normal_force(weight / 2.0, torque / 2.0)
    assert plan.status == "optimal"
    np.testing.assert_allclose(plan.normal_forces[:, 0], expected, rtol=OPTIMUM_RTOL)
    assert_loads_inside_their_exact_surfaces(problem, plan)
    assert plan.safety_factor == pytest.approx(1.0, rel=1e-6)


@pytest.mark.parametrize("s", SCALES)
def test_a_disk_pinch_with_given_forces_has_the_closed_form_safety_factor_at_any_size(s):
    grip, weight, torque = 60.0 * s, 10.0 * s, 0.2 * s
    load = Load(name="hold", force=[0, 0, -weight], point=[0, 0, 0], torque=[0, torque, 0])
    plan = Planner(pinch(load, "max-safety-factor", force=grip)).solve()
    needed, _ = least_normal_force(weight / 2.0, torque / 2.0)
    assert plan.status == "optimal"
    assert plan.safety_factor == pytest.approx(grip / needed, rel=OPTIMUM_RTOL)


def mixed_fixture(objective: str = "min-total-clamp-force") -> Problem:
    """A 2 kg block on pads of every model kind, a side locator and two clamps, 5 random
    milling loads of tens of newtons."""
    rng = np.random.default_rng(7)
    places = [
        ("pad-a", "support", [-0.04, -0.03, 0], [0, 0, 1], "exact", pressure.disk(0.01)),
        ("pad-b", "support", [0.04, -0.03, 0], [0, 0, 1], "ellipsoid", pressure.disk(0.01)),
        ("pad-c", "support", [0.0, 0.04, 0], [0, 0, 1], "pyramid", pressure.disk(0.01)),
        ("side", "locator", [-0.06, 0, 0.02], [1, 0, 0], "point-cone", None),
        ("clamp-top", "clamp", [0, 0, 0.04], [0, 0, -1], "exact", pressure.disk(0.006)),
        ("clamp-side", "clamp", [0.06, 0, 0.02], [-1, 0, 0], "ellipsoid", pressure.disk(0.006)),
    ]
    contacts = [
        Contact(name=name, role=role, position=p, normal=n, mu=0.3, model=model, patch=patch)
        for name, role, p, n, model, patch in places
    ]
    loads = [
        Load(name=f"cut-{k}", force=rng.normal(0, 40, 3), point=[0, 0, 0.03],
             torque=rng.normal(0, 0.5, 3))
        for k in range(5)
    ]  # fmt: skip
    return Problem(body=Body(mass=2.0, center_of_mass=[0, 0, 0.02]), contacts=contacts,
                   loads=loads, objective=objective)  # fmt: skip


@pytest.mark.parametrize("s", SCALES)
def test_a_fixture_of_every_model_kind_scales_with_its_forces(s):
    reference = Planner(mixed_fixture()).solve()
    plan = Planner(scaled(mixed_fixture(), s)).solve()
    assert plan.status == reference.status == "optimal"
    assert plan.objective_value == pytest.approx(s * reference.objective_value, rel=OPTIMUM_RTOL)
    for name, (low, high) in reference.held_intervals.items():
        assert plan.held_intervals[name][0] == pytest.approx(low, rel=1e-6, abs=1e-7)
        assert plan.held_intervals[name][1] == pytest.approx(high, rel=1e-6)
    assert plan.critical_load == reference.critical_load
    motion, expected = plan.motions[plan.critical_load], reference.motions[plan.critical_load]
    np.testing.assert_allclose(motion.twist, expected.twist, atol=1e-5)


@pytest.mark.parametrize("s", SCALES)
def test_max_force_bounds_are_kept_in_the_units_of_the_solve(s):
    """A clamp bound just below the least clamp force leaves the problem infeasible, one just
    above it changes nothing, at any size."""
    least = Planner(mixed_fixture()).solve(analyse=False).forces

    def bounded(factor: float) -> Problem:
        contacts = [
            dataclasses.replace(c, max_force=factor * float(least[c.name]))
            if c.role == "clamp" else c
            for c in mixed_fixture().contacts
        ]  # fmt: skip
        one_clamp = dataclasses.replace(mixed_fixture(), contacts=contacts)
        return scaled(one_clamp, s)

    # The least total is met only by the least clamp forces if every clamp is bounded by its
    # own: the total is then at its bound.
    short = Planner(bounded(1.0 - 1e-4)).solve(analyse=False)
    assert short.status == "infeasible"
    enough = Planner(bounded(1.0 + 1e-4)).solve(analyse=False)
    assert enough.status == "optimal"
    total = sum(float(f) for f in least.values())
    assert enough.objective_value == pytest.approx(s * total, rel=OPTIMUM_RTOL)


@pytest.mark.parametrize("largest", [0.0, 3e-7, 1.0, 63.0, 91.0, 1.2e5])
def test_the_force_unit_is_the_power_of_two_that_brings_the_largest_force_near_its_target(
    largest,
):
    problem = mixed_fixture()
    planner = Planner(dataclasses.replace(problem, body=Body(mass=0.0, center_of_mass=[0, 0, 0])))
    wrenches = np.zeros((6, 2))
    wrenches[:3, 1] = [0.0, -largest, 0.5 * largest]
    unit = Runner._force_unit(planner._runner, wrenches, {})
    exponent = np.log2(unit)
    assert exponent == round(exponent)
    if largest == 0.0:
        assert unit == 1.0
    else:
        assert FORCE_IN_UNITS / np.sqrt(2) <= largest / unit <= FORCE_IN_UNITS * np.sqrt(2)
