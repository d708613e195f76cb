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


def wedged_plate() -> Problem:
    """A random fixture of the squeeze review (ellipsoid disks of 5 mm, mu as drawn, one side
    locator, the top clamp at 0 N) whose second load lifts the plate: held at every multiple by
    friction at the side and back locators, with a margin of 1.3e-4 in mu (measured by
    bisection against the reference), while the other two loads press it down."""
    placed = [
        ("pad-0", "support", [-0.03565170641423568, -0.03438353343927993, 0.0], [0, 0, 1],
         0.8997417506587491),
        ("pad-1", "support", [0.03165449835996233, -0.0206045736141428, 0.0], [0, 0, 1],
         0.9534887936829477),
        ("pad-2", "support", [0.0012785349073590416, 0.04288641924302493, 0.0], [0, 0, 1],
         0.12286352923447935),
        ("side-left", "locator", [-0.06, 0.0030748585401043638, 0.019260829091898083],
         [1, 0, 0], 0.7642347266792089),
        ("back", "locator", [-0.01510392040608572, -0.05, 0.02], [0, 1, 0], 0.6626688764401196),
        ("clamp-top", "clamp", [-0.0012363464299029949, -0.011870213407558144, 0.04],
         [0, 0, -1], 0.6738617691217591),
    ]  # fmt: skip
    loads = [
        ([-44.84749301617592, 15.139933321973132, 34.45101728233159],
         [-0.029555937640526418, 0.025262629632862486, -0.02216212935521631],
         [-0.24858785455429078, 0.1013970937698132, 0.21651088764364257]),
        ([5.931433061174687, -13.473614806525575, 45.6379460602727],
         [-0.006202643962148202, 0.022410939494303846, -0.010206997656316441],
         [0.25143904673710815, 0.6996356438783746, -0.7603447419876843]),
        ([-39.49224030181236, 27.391620328854316, -44.918253073274144],
         [-0.028978159224760595, -0.018560510735780966, -0.006315299783890248],
         [0.40530446561671796, 0.4004641134205731, -0.5715156703411741]),
    ]  # fmt: skip
    patch = pressure.disk(0.004996528846087864)
    contacts = [
        Contact(name=n, role=r, position=p, normal=d, mu=mu, model="ellipsoid", patch=patch,
                force=0.0 if r == "clamp" else None)
        for n, r, p, d, mu in placed
    ]  # fmt: skip
    return Problem(
        body=Body(mass=1.0612625486423115, center_of_mass=[0.0, 0.0, 0.02]),
        contacts=contacts,
        loads=[Load(name=f"L{k}", force=f, point=p, torque=t) for k, (f, p, t) in enumerate(loads)],
        objective="max-safety-factor",
    )


def test_a_case_is_not_blurred_by_block_mates_at_the_safety_factor_cap():
    # The three cases share a block; the first and the last are held at every multiple, so the
    # solve carries them at the cap (1e3 times their loads), and the middle one came out held
    # only to 0.497 ("optimal"): the tolerances, relative to the largest terms, swallowed its
    # thin margin. Solved again without them it is held at every multiple, as the reference
    # (one cvxpy constraint per contact, k uncapped) and the case alone say.
    import reference_planner as ref

    problem = wedged_plate()
    plan = Planner(problem).solve()
    assert plan.status == "optimal"
    for j, load in enumerate(problem.loads):
        low, high = ref.held_interval(problem, j, None)
        assert high >= 1e3  # the reference: held beyond the cap
        assert plan.safety_factors[load.name] == np.inf
        assert plan.held_intervals[load.name][0] == pytest.approx(low, abs=1e-7)
    alone = dataclasses.replace(problem, loads=[problem.loads[1]])
    assert Planner(alone).solve().safety_factors["L1"] == np.inf


def test_a_case_is_not_blurred_by_a_block_mate_that_reaches_the_cap_only_when_solved_again():
    # The wedged plate with pad-1's friction cut to 30 %: the last load is still held at every
    # multiple, the second only to 0.0986. Beside them, a blend of the first two loads held to
    # 1002 (beyond the cap) came out 930 in their block (the last at the cap), and at the cap
    # in the re-solve without the last, where it blurred the second: 0.0986237 (the reference:
    # 0.0986212). Its re-solve goes on without the blend.
    import reference_planner as ref

    wedged = wedged_plate()
    contacts = [dataclasses.replace(c, mu=0.3 * c.mu) if c.name == "pad-1" else c
                for c in wedged.contacts]  # fmt: skip
    first, second = (np.asarray(load.wrench, dtype=float) for load in wedged.loads[:2])
    t = 0.07280537323856354  # (the edge of the held-at-every-multiple loads: 0.0728064)
    blend = (1.0 - t) * first + t * second
    loads = [
        wedged.loads[2],
        Load(name="blend", force=blend[:3], point=[0.0, 0.0, 0.0], torque=blend[3:]),
        wedged.loads[1],
    ]
    problem = dataclasses.replace(wedged, contacts=contacts, loads=loads)
    plan = Planner(problem).solve()
    assert plan.status in ("optimal", "inaccurate")  # (the first block needs SCS)
    highs = [ref.held_interval(problem, j, None)[1] for j in range(len(loads))]
    assert min(highs[:2]) >= 1e3
    assert plan.safety_factors["L2"] == np.inf
    # The blend alone needs SCS: beyond the cap (1002), it comes back within 2e-6 of it.
    assert plan.safety_factors["blend"] >= 1e3 * (1.0 - 2e-6)
    assert plan.safety_factors["L1"] == pytest.approx(highs[2], rel=1e-6)


def test_the_cases_of_a_block_the_solver_fails_on_are_solved_one_by_one():
    # The wedged plate with pad-1's friction cut to 30 %, and three loads in one block: the
    # last of the plate's (held at every multiple), a blend of the first two on the edge of
    # those held at every multiple (Clarabel ends inaccurate on it, alone too) and their
    # midpoint, held to 0.373. Clarabel ends inaccurate on the block, and SCS on the whole
    # block said 0.765: an unsafe safety factor, twice the true one. Each case alone is right.
    import reference_planner as ref

    wedged = wedged_plate()
    contacts = [dataclasses.replace(c, mu=0.3 * c.mu) if c.name == "pad-1" else c
                for c in wedged.contacts]  # fmt: skip
    first, second = (np.asarray(load.wrench, dtype=float) for load in wedged.loads[:2])
    t = 0.07280627323856354  # (the edge: 0.0728064)
    wrenches = {"edge": (1.0 - t) * first + t * second, "middle": 0.5 * (first + second)}
    loads = [wedged.loads[2]] + [
        Load(name=name, force=w[:3], point=[0.0, 0.0, 0.0], torque=w[3:])
        for name, w in wrenches.items()
    ]
    problem = dataclasses.replace(wedged, contacts=contacts, loads=loads)
    plan = Planner(problem).solve()
    assert plan.status in ("optimal", "inaccurate")  # (the edge case alone needs SCS)
    assert any("solved them one by one" in note for note in plan.warnings)
    low, high = ref.held_interval(problem, 2, None)
    assert plan.safety_factors["middle"] == pytest.approx(high, rel=1e-6)
    assert plan.held_intervals["middle"][0] == pytest.approx(low, abs=1e-7)
    assert plan.safety_factors["L2"] == np.inf
