"""Which of two opposing locators the planner unloads (:mod:`fixplan.planner.squeeze`).

A plate on three pads with two side locators facing each other, a back locator and one free
top clamp, eight load cases. Without the rule a rigid model lets the side locators squeeze the
plate; under it, in every case one of them carries no normal force. The squeeze-free forces of
a case are those of the problem without the left locator or without the right one, so the
least clamp force of a case is the better of those two (the reference planner, one cvxpy
constraint per contact, solved for each), and with one clamp force for all cases the answer is
the largest of the cases' least forces; a fixed-force case holds up to the larger of its two
multiples. The previous rule unloaded the locator that the solver's (one of many) optimum
loaded least, and gave 29.36 N or 21.67 N on a fixture of this kind, depending on rounding.

Tolerances: the planner solves at 1e-9 and the reference at 1e-10 (relative); answers agree to
1e-6 relative.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
import reference_planner as ref
from test_squeeze_brute_force import largest_multiple, without

from fixplan import Body, Contact, Load, Planner, Problem
from fixplan.planner import runner
from fixplan.planner.squeeze import same_contact_trials

SIDES = ("side-left", "side-right")
AGREEMENT_RTOL = 1e-6

#: (force [N], point [m], torque [N m]) of the cases: loads of a random milling fixture.
LOADS = [
    ([39.96, -8.07, 52.36], [0.041, 0.009, -0.027], [-0.969, -0.105, 1.066]),
    ([22.74, -7.53, -22.32], [0.007, -0.022, -0.004], [0.307, 0.022, 0.315]),
    ([17.95, 12.14, -49.49], [-0.021, -0.014, 0.013], [0.181, 0.170, 0.104]),
    ([28.36, -16.64, -47.73], [0.013, -0.004, 0.001], [-0.104, -0.668, -0.906]),
    ([32.79, 27.94, 6.25], [0.005, -0.008, 0.001], [-0.242, -0.326, 0.123]),
    ([-56.51, 18.05, 20.27], [-0.024, 0.006, 0.002], [-0.278, -0.298, -0.844]),
    ([70.43, 47.59, -8.63], [0.006, 0.008, -0.016], [-0.155, 0.320, -0.253]),
    ([-38.04, 7.65, -10.11], [-0.006, 0.027, 0.002], [-0.430, -0.039, 1.295]),
]


def plate() -> Problem:
    """Coulomb point contacts (mu as on a random fixture), objective min-total-clamp-force."""
    placed = [
        ("pad-a", "support", [-0.04, -0.03, 0.0], [0, 0, 1], 0.98),
        ("pad-b", "support", [0.04, -0.03, 0.0], [0, 0, 1], 0.76),
        ("pad-c", "support", [0.0, 0.04, 0.0], [0, 0, 1], 0.22),
        ("side-left", "locator", [-0.06, 0.0, 0.02], [1, 0, 0], 0.31),
        ("side-right", "locator", [0.06, 0.0, 0.02], [-1, 0, 0], 0.23),
        ("back", "locator", [0.0, -0.05, 0.02], [0, 1, 0], 0.96),
        ("clamp-top", "clamp", [0.0, 0.0, 0.04], [0, 0, -1], 0.56),
    ]
    return Problem(
        body=Body(mass=1.55, center_of_mass=[0.0, 0.0, 0.02]),
        contacts=[
            Contact(name=name, role=role, position=p, normal=n, mu=mu, model="point-cone")
            for name, role, p, n, mu in placed
        ],
        loads=[Load(name=f"L{k}", force=f, point=p, torque=t) for k, (f, p, t) in enumerate(LOADS)],
        objective="min-total-clamp-force",
    )


@pytest.fixture(scope="module")
def case_least_forces():
    """Per case, the reference's least clamp force without each side locator (None:
    infeasible)."""
    problem = plate()
    return [
        {side: ref.min_force_objective(without(problem, {side}, j)) for side in SIDES}
        for j in range(len(LOADS))
    ]


def best(per_side: dict) -> float:
    found = [v for v in per_side.values() if v is not None]
    assert found, "the reference holds every case without one of the side locators"
    return min(found)


def test_each_case_unloads_the_side_locator_that_serves_it_best(case_least_forces):
    problem = plate()
    planner = Planner(problem)
    assert planner.squeeze_contacts == SIDES
    plan = planner.solve(analyse=False)
    assert plan.status == "optimal"
    expected = max(best(per_side) for per_side in case_least_forces)
    assert plan.objective_value == pytest.approx(expected, rel=AGREEMENT_RTOL)
    # The rule holds: in every case one side locator carries nothing (solver noise aside).
    sides = plan.normal_forces[[3, 4]]
    assert np.all(sides.min(axis=0) <= 1e-6 * np.abs(plan.normal_forces).max(axis=0))
    # The note names, per case, the side that carries nothing (and only that one).
    (note,) = [w for w in plan.warnings if "squeeze" in w]
    for load, side in zip(problem.loads, np.argmin(sides, axis=0), strict=True):
        assert f"{load.name!r}: {SIDES[side]};" in note or f"{load.name!r}: {SIDES[side]}." in note
    # A re-solve with loads of other names names those.
    renamed = [dataclasses.replace(load, name=f"new {load.name}") for load in problem.loads]
    (note,) = [w for w in planner.solve(renamed, analyse=False).warnings if "squeeze" in w]
    for load in renamed:
        assert f"{load.name!r}: " in note
    # The choices differ between cases: a single unloaded side for all of them costs more.
    worst_single = min(
        max(per_side[side] if per_side[side] is not None else np.inf
            for per_side in case_least_forces)
        for side in SIDES
    )  # fmt: skip
    assert worst_single > expected * (1 + 1e-3)


def unloaded_sides(plan) -> np.ndarray:
    """Per case, which side locator carries the smaller normal force (0 left, 1 right)."""
    return np.argmin(plan.normal_forces[[3, 4]], axis=0)


@pytest.mark.parametrize("force_in_units", [16.0, 1024.0])
def test_the_choice_does_not_depend_on_rounding(monkeypatch, force_in_units):
    # Another force unit changes the solver's path, and so which of the rigid optima it finds.
    problem = plate()
    reference = Planner(problem).solve(analyse=False)
    monkeypatch.setattr(runner, "FORCE_IN_UNITS", force_in_units)
    again = Planner(problem).solve(analyse=False)
    assert again.objective_value == pytest.approx(reference.objective_value, rel=AGREEMENT_RTOL)
    # (Passive forces below the optimum are not unique; which side carries nothing is.)
    np.testing.assert_array_equal(unloaded_sides(again), unloaded_sides(reference))


def test_a_fixed_force_case_holds_up_to_the_better_of_its_two_multiples():
    # The clamp at 60 N given: each case's safety factor is the larger of the reference's
    # largest multiples without the left and without the right locator.
    problem = plate()
    clamp = dataclasses.replace(problem.contacts[-1], force=60.0)
    given = dataclasses.replace(
        problem, contacts=[*problem.contacts[:-1], clamp], objective="max-safety-factor"
    )
    plan = Planner(given).solve()
    assert plan.status == "optimal"
    for j, load in enumerate(given.loads):
        expected = largest_multiple(given, j, [{side} for side in SIDES])
        assert plan.safety_factors[load.name] == pytest.approx(expected, rel=AGREEMENT_RTOL)


#: A random fixture of the review's brute force whose clamp stands beside the pads (x -0.047 m,
#: y 0.025 m): more clamp force tips the plate, so a case's own least force need not hold the
#: others.
BESIDE = [
    ("pad-0", "support", [-0.03976356750599487, -0.02099072607348129, 0.0], [0, 0, 1],
     0.5843289818973504),
    ("pad-1", "support", [0.03288319225439268, -0.021027011057255122, 0.0], [0, 0, 1],
     0.39675854484918294),
    ("pad-2", "support", [-0.003763370959790291, 0.03846652897945151, 0.0], [0, 0, 1],
     0.8095858330855639),
    ("side-left", "locator", [-0.06, 0.013108103752817669, 0.017275974091074838], [1, 0, 0],
     0.37287534636248054),
    ("side-right", "locator", [0.06, 0.013108103752817669, 0.017275974091074838], [-1, 0, 0],
     0.5081481005325864),
    ("back", "locator", [0.00198374750692238, -0.05, 0.02], [0, 1, 0], 0.22063752752244828),
    ("clamp-top", "clamp", [-0.047244088675693165, 0.02535131086748066, 0.04], [0, 0, -1],
     0.4628016878024164),
]  # fmt: skip
BESIDE_LOADS = [
    ([-35.58537111886204, -28.52239914697806, 30.04376071560631],
     [-0.013175474520837605, -0.0008885415341018978, 0.028844231988074315],
     [0.9233143873275735, 0.4495798815470673, 0.08245371109486843]),
    ([-26.7730555145555, -40.72175894698478, 56.3910495859359],
     [0.0009641151328727213, -0.023048063251753778, 0.007409385332250024],
     [0.553366228684596, 0.22600660210608092, 0.8345954095818053]),
    ([-55.24885480029566, 3.430711591202595, -4.87969405375155],
     [-0.026259025251007463, 0.008479690148362494, 0.021157970308839404],
     [0.18588203620856802, -0.4798051045255536, 0.6797630420628176]),
    ([1.139505782581125, 1.30666613598396, 30.363624924261345],
     [-0.021124677852902604, 0.019177603147156615, 0.010997214360195427],
     [0.5741938831096021, -0.6167674819597295, 0.60472832226906]),
]  # fmt: skip


def test_a_clamp_beside_the_supports_falls_back_to_one_unloading_for_every_case():
    # Each case's own best asks for clamp forces that lose another case: that solve is
    # infeasible. Unloading the left locator in every case holds, at the largest of the cases'
    # least forces without it (the reference without side-left, case by case).
    contacts = [
        Contact(name=n, role=r, position=p, normal=d, mu=mu, model="point-cone")
        for n, r, p, d, mu in BESIDE
    ]
    loads = [
        Load(name=f"L{k}", force=f, point=p, torque=t) for k, (f, p, t) in enumerate(BESIDE_LOADS)
    ]
    problem = Problem(
        body=Body(mass=0.9783098151430007, center_of_mass=[0.0, 0.0, 0.02]),
        contacts=contacts,
        loads=loads,
        objective="min-total-clamp-force",
    )
    plan = Planner(problem).solve(analyse=False)
    assert plan.status == "optimal"
    expected = max(
        ref.min_force_objective(without(problem, {"side-left"}, j))
        for j in range(len(BESIDE_LOADS))
    )
    assert plan.objective_value == pytest.approx(expected, rel=AGREEMENT_RTOL)
    np.testing.assert_allclose(plan.normal_forces[3], 0.0, atol=1e-6 * plan.normal_forces.max())


def test_the_fallback_tries_each_contact_in_every_case_whose_squeeze_holds_it():
    # Cases squeezed by different pairs: unloading contact 1 in both is one of the trials.
    members = [np.array([0, 1]), np.array([1, 2])]
    trials = same_contact_trials(members, np.zeros((3, 2), dtype=bool))
    expected = [
        [[True, False], [False, False], [False, False]],
        [[False, False], [True, True], [False, False]],
        [[False, False], [False, False], [False, True]],
    ]
    np.testing.assert_array_equal(np.array(trials), expected)
