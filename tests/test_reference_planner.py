"""The reference planner of tests/reference_planner.py against closed forms.

These tests judge the reference itself, so that it can judge the production planner: pinches
and a clamped block whose answers follow from Coulomb's law by hand, the ellipsoid pinch of the
paper's Table 2, the sign of the slip twist, and the nose-cone grasp whose held interval is
bounded on both sides (squeezing harder pushes the body out).
"""

import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest
import reference_planner as ref

import fixplan
from fixplan import Body, Contact, Load, Problem, pressure

PROBLEMS = Path(__file__).resolve().parents[1] / "problems"
MU, WEIGHT, HALF_GAP = 0.3, 10.0, 0.02
MASSLESS = Body(mass=0.0, center_of_mass=[0.0, 0.0, 0.0])


def pinch(*, forces=None, objective="min-max-normal-force", role="finger", model="point-cone"):
    """Two fingers at (0, ∓HALF_GAP, 0) squeezing along y; task load: WEIGHT down at the origin."""
    patch = None if model.startswith("point") else pressure.disk(0.006, "hertz")
    contacts = [
        Contact(
            name=name,
            role=role,
            position=[0.0, side * HALF_GAP, 0.0],
            normal=[0.0, -side, 0.0],
            mu=MU,
            model=model,
            patch=patch,
            force=forces,
        )
        for name, side in (("left", -1), ("right", 1))
    ]
    load = Load(name="weight", force=[0.0, 0.0, -WEIGHT], point=[0.0, 0.0, 0.0])
    return Problem(body=MASSLESS, contacts=contacts, loads=[load], objective=objective)


@pytest.mark.parametrize(
    ("objective", "role", "expected"),
    [
        ("min-max-normal-force", "finger", WEIGHT / (2 * MU)),
        ("min-total-normal-force", "finger", WEIGHT / MU),
        ("min-squared-normal-force", "finger", 2 * (WEIGHT / (2 * MU)) ** 2),
        ("min-total-clamp-force", "clamp", WEIGHT / MU),
    ],
)
def test_a_point_pinch_needs_half_the_weight_over_mu_per_finger(objective, role, expected):
    # Each finger's friction carries half the weight: f = W / 2 <= mu N.
    value = ref.min_force_objective(pinch(objective=objective, role=role))
    assert value == pytest.approx(expected, rel=1e-8)


def test_a_pinch_whose_fingers_are_capped_below_the_need_is_infeasible():
    problem = pinch()
    cap = 0.9 * WEIGHT / (2 * MU)
    contacts = [dataclasses.replace(c, max_force=cap) for c in problem.contacts]
    assert ref.min_force_objective(dataclasses.replace(problem, contacts=contacts)) is None


@pytest.mark.parametrize("force", [5.0, 40.0])
def test_a_point_pinch_with_given_forces_holds_up_to_two_mu_f_over_w_times_the_weight(force):
    interval = ref.held_interval(pinch(), 0, {"left": force, "right": force})
    assert interval[0] == pytest.approx(0.0, abs=1e-9)
    assert interval[1] == pytest.approx(2 * MU * force / WEIGHT, rel=1e-8)


def test_a_point_pinch_with_unequal_forces_holds_nothing():
    # The two normal forces do not balance and friction acts only across the grasp axis.
    assert ref.held_interval(pinch(), 0, {"left": 5.0, "right": 6.0}) is None


# -- a block clamped on an inclined plate -------------------------------------------------------

TILT, BLOCK_MASS, MU_PLATE, MU_CLAMP = math.radians(40.0), 2.0, 0.15, 0.4
HEIGHT, PUSH_HEIGHT, COM_HEIGHT, PUSH = 0.05, 0.03, 0.02, 10.0


def clamped_block(clamp_force):
    """A block on a plate tilted 40° (gravity along +x and -z), clamped from above on the same
    vertical line as its plate contact, pushed back up the slope (-x) at height PUSH_HEIGHT."""
    gravity = 9.81 * np.array([math.sin(TILT), 0.0, -math.cos(TILT)])
    body = Body(mass=BLOCK_MASS, center_of_mass=[0.0, 0.0, COM_HEIGHT], gravity=gravity)
    contacts = [
        Contact(name="plate", role="support", position=[0, 0, 0], normal=[0, 0, 1], mu=MU_PLATE,
                model="point-cone"),
        Contact(name="clamp", role="clamp", position=[0, 0, HEIGHT], normal=[0, 0, -1],
                mu=MU_CLAMP, model="point-cone", force=clamp_force),
    ]  # fmt: skip
    load = Load(name="push", force=[-PUSH, 0, 0], point=[0, 0, PUSH_HEIGHT])
    return Problem(body=body, contacts=contacts, loads=[load], objective="check")


def coulomb_interval(clamp_force):
    """Held multiples k of the push, by hand.

    Moment about y fixes the clamp's friction, force balance along x the plate's:
    ``H fc = h k P - zc m gx`` and ``fp = k P (1 - h/H) - m gx (1 - zc/H)``; Coulomb:
    ``|fc| <= mu_c F``, ``|fp| <= mu_p (F + m gz)``. Each is an interval of k; intersect them.
    """
    gx, gz = 9.81 * math.sin(TILT), 9.81 * math.cos(TILT)
    rows = [  # |a k + b| <= c
        (PUSH_HEIGHT * PUSH / HEIGHT, -COM_HEIGHT * BLOCK_MASS * gx / HEIGHT, MU_CLAMP * clamp_force),
        (PUSH * (1 - PUSH_HEIGHT / HEIGHT), -BLOCK_MASS * gx * (1 - COM_HEIGHT / HEIGHT),
         MU_PLATE * (clamp_force + BLOCK_MASS * gz)),
    ]  # fmt: skip
    low = max([0.0] + [(-c - b) / a for a, b, c in rows])
    high = min((c - b) / a for a, b, c in rows)
    return (low, high) if low <= high else None


def test_a_clamped_block_on_an_incline_holds_the_coulomb_interval_of_pushes():
    expected = coulomb_interval(10.0)
    assert expected[0] > 0.5  # the block slides down without a push: k_min > 0
    interval = ref.held_interval(clamped_block(10.0), 0, None)
    assert interval == pytest.approx(expected, rel=1e-8)


def test_a_weakly_clamped_block_on_an_incline_holds_no_push():
    assert coulomb_interval(2.0) is None
    assert ref.held_interval(clamped_block(2.0), 0, {"clamp": 2.0}) is None


def test_a_load_pressing_into_the_plate_is_held_up_to_the_cap_and_never_slides():
    problem = clamped_block(10.0)
    press = Load(name="press", force=[0, 0, -1.0], point=[0, 0, 0])
    problem = Problem(body=MASSLESS, contacts=problem.contacts, loads=[press], objective="check")
    low, high = ref.held_interval(problem, 0, None, k_max=1e3)
    assert low == pytest.approx(0.0, abs=1e-9)
    assert high == pytest.approx(1e3, rel=1e-9)
    assert ref.slip_twist(problem, 0, None) is None


# -- area contacts: the ellipsoid pinch (paper Table 2) ---------------------------------------------


@pytest.mark.parametrize("offset", [0.0, 0.01, 0.04])
def test_an_ellipsoid_pinch_holds_up_to_the_closed_form_multiple(offset):
    # Hertz disk R = 6 mm: m_max = (3π/16) mu N R. Each finger carries f = kW/2 and the torsion
    # m = kW offset / 2 about the grasp axis; (f/(mu N))² + (m/(mu κ R N))² = 1 at k_max.
    force, radius, kappa = 20.0, 0.006, 3 * math.pi / 16
    base = pinch(model="ellipsoid", forces=force, objective="check")
    load = Load(name="off-axis", force=[0, 0, -WEIGHT], point=[offset, 0, 0])
    problem = Problem(body=MASSLESS, contacts=base.contacts, loads=[load], objective="check")
    expected = 2 / np.hypot(WEIGHT / (MU * force), WEIGHT * offset / (MU * kappa * radius * force))
    low, high = ref.held_interval(problem, 0, None)
    assert low == pytest.approx(0.0, abs=1e-9)
    assert high == pytest.approx(expected, rel=1e-7)


# -- the slip twist -------------------------------------------------------------------------------


def test_the_raw_equality_dual_does_unit_power_with_the_task_wrench():
    # cvxpy's sign convention, which slip_twist relies on and documents: maximising k (cvxpy
    # minimises -k) with the equality Σw + kW + Wg == 0 has the Lagrangian -k + y·(...), so
    # W·y = 1 at the optimum, y being the constraint's dual_value.
    problem = pinch()
    given = ref.given_forces(problem, {"left": 40.0, "right": 40.0})
    high, dual = ref._largest_multiple(problem, 0, given)
    assert high == pytest.approx(2 * MU * 40.0 / WEIGHT, rel=1e-8)
    assert problem.loads[0].wrench @ dual == pytest.approx(1.0, rel=1e-8)


def test_a_point_pinch_slips_by_translating_along_its_load():
    # At k_max both fingers slide down together: V = (0, 0, -1, 0, 0, 0), the direction of the
    # weight (W·V = W > 0). Rotations about x that keep both contacts sliding down are also
    # dual-optimal; the interior-point method returns the centre of that segment, the
    # symmetric translation, to about 1e-6 of its half-width (1 / HALF_GAP in these units).
    twist = ref.slip_twist(pinch(), 0, {"left": 40.0, "right": 40.0})
    assert twist == pytest.approx([0, 0, -1, 0, 0, 0], abs=1e-4)
    assert np.linalg.norm(twist) == pytest.approx(1.0, rel=1e-12)


def test_a_clamped_block_slips_up_the_slope_where_friction_runs_out_first():
    # The push saturates the clamp first (coulomb_interval): the block turns about the plate
    # contact, whose friction is not saturated, so that point (the origin) stays put; the clamp
    # point moves along the push (-x): V = (0, 0, 0, 0, -1, 0), a rotation about -y.
    twist = ref.slip_twist(clamped_block(10.0), 0, None)
    assert twist == pytest.approx([0, 0, 0, 0, -1, 0], abs=1e-6)
    assert clamped_block(10.0).loads[0].wrench @ twist > 0


# -- the nose cone --------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def nose_cone_forces():
    """The production planner's min-max finger forces of the nose cone (k = 1 at its k_max)."""
    problem = ref.nose_cone_problem()
    plan = fixplan.solve(problem)
    assert plan.status == "optimal"
    assert plan.objective_value == pytest.approx(ref.min_force_objective(problem), rel=1e-6)
    return np.array([float(np.ravel(plan.forces[c.name])[0]) for c in problem.contacts])


def _scaled(forces, scale):
    return {f"finger-{i + 1}": scale * f for i, f in enumerate(forces)}


def _largest_held_scale(forces, low=1.2, high=4.0, rtol=1e-8):
    """Bisection on the finger-force scale s for which k = 1 is still held.

    A midpoint too close to the answer for Clarabel to decide (an inaccurate status) ends
    the bisection there.
    """
    problem = ref.nose_cone_problem()
    assert ref.feasible(problem, 0, _scaled(forces, low), 1.0)
    assert not ref.feasible(problem, 0, _scaled(forces, high), 1.0)
    while high - low > rtol * low:
        middle = 0.5 * (low + high)
        try:
            held = ref.feasible(problem, 0, _scaled(forces, middle), 1.0)
        except ref.ReferenceSolveError:
            return middle
        low, high = (middle, high) if held else (low, middle)
    return 0.5 * (low + high)


def test_the_nose_cone_fingers_hold_the_load_only_up_to_a_largest_squeeze(nose_cone_forces):
    problem = ref.nose_cone_problem()
    low, high = ref.held_interval(problem, 0, _scaled(nose_cone_forces, 1.0))
    assert 0.0 < low < 1.0
    assert high == pytest.approx(1.0, rel=1e-7)  # min-max: the load is just held
    # Forces and load scale together, so the largest scale is 1 / k_min.
    largest = _largest_held_scale(nose_cone_forces)
    assert largest == pytest.approx(1.0 / low, rel=1e-6)
    assert largest == pytest.approx(2.2085, rel=1e-3)  # this geometry (the issue's: ~1.64)
    squeezed = ref.held_interval(problem, 0, _scaled(nose_cone_forces, 1.05 * largest))
    assert squeezed[0] > 1.0


@pytest.mark.parametrize("scale", [1.0, 1.7])
def test_feasibility_of_the_nose_cone_agrees_with_its_held_interval(nose_cone_forces, scale):
    problem = ref.nose_cone_problem()
    forces = _scaled(nose_cone_forces, scale)
    low, high = ref.held_interval(problem, 0, forces)
    expected = {
        0.5 * low: False,
        low * (1 - 1e-6): False,
        low * (1 + 1e-6): True,
        0.5 * (low + high): True,
        high * (1 - 1e-6): True,
        high * (1 + 1e-6): False,
        1.5 * high: False,
    }
    for k, held in expected.items():
        assert ref.feasible(problem, 0, forces, k) is held, k


def test_the_nose_cone_problem_with_given_forces_is_a_check_problem(nose_cone_forces):
    problem = ref.nose_cone_problem(nose_cone_forces)
    assert problem.objective == "check"
    assert [c.force for c in problem.contacts] == pytest.approx(nose_cone_forces)
    normals = np.array([c.normal for c in problem.contacts])
    positions = np.array([c.position for c in problem.contacts])
    assert positions[:, 2] == pytest.approx(np.sum(positions[:, :2] ** 2, axis=1))
    assert np.all(normals[:, 2] > 0)  # every finger pushes the body up, out of the grasp


# -- agreement with the production planner ---------------------------------------------------------


@pytest.mark.parametrize("name", ["point-grasp", "hertz-pinch", "three-finger-grasp"])
def test_the_reference_force_objective_agrees_with_the_production_planner(name):
    problem = fixplan.load_problem(PROBLEMS / f"{name}.toml").problem
    plan = fixplan.solve(problem)
    assert plan.status == "optimal"
    assert ref.min_force_objective(problem) == pytest.approx(plan.objective_value, rel=1e-6)


def test_a_pinch_that_needs_forty_times_its_weight_is_found_feasible():
    # Two fingers on one line beside the centre of mass (found by hypothesis): only the disk
    # finger's torsion, (2/3) mu N R with R = 3.54 mm, holds the weight's moment about the
    # grasp axis (19.6 N at 43 mm), so each finger needs about 800 N. The early certificate test
    # once called this infeasible; the stacked planner (an independent formulation) finds and
    # verifies the optimum, which the reference must match.
    loads = [
        Load(name="a", force=[6.84612432, -6.3498168, -0.4379184],
             point=[-0.03140463, -0.03546699, -0.0306745]),
        Load(name="b", force=[-2.2084272, -6.9407712, -1.577448],
             point=[0.00575352, -0.04040439, -0.0308724]),
        Load(name="c", force=[-3.52830384, 3.04988976, -10.37560536],
             point=[-0.03020598, -0.03842943, 0.0037601]),
        Load(name="d", force=[-4.53222, -3.35988576, -3.3840576],
             point=[-0.01829939, -0.03077646, 0.0087076]),
    ]  # fmt: skip
    contacts = [
        Contact(name="point", role="finger", position=[-0.04257605, -0.08229, -0.03170358],
                normal=[0, 1, 0], mu=0.7942, model="point-cone"),
        Contact(name="disk", role="finger", position=[-0.04257605, 0.08229, -0.03170358],
                normal=[0, -1, 0], mu=0.4295, model="ellipsoid", patch=pressure.disk(0.00354)),
    ]  # fmt: skip
    problem = Problem(body=Body(mass=2.0, center_of_mass=[0, 0, 0]), contacts=contacts,
                      loads=loads, objective="min-squared-normal-force")  # fmt: skip
    plan = fixplan.Planner(problem).solve()
    assert plan.status == "optimal" and all(plan.held.values())
    assert np.all(plan.normal_forces > 700.0)
    assert ref.min_force_objective(problem) == pytest.approx(plan.objective_value, rel=1e-7)
