"""The planner with exact friction models, against closed forms of the uniform disk.

Uniform disk of radius ``R``, friction ``mu``, normal force ``N``, centre of rotation at ``u R``
from the centre (DESIGN.md §4, elliptic integrals of modulus ``k`` as ``ellipe(k**2)``):

- ``u <= 1``: ``|f|/(mu N) = 4/(3πu) [(1+u²)E(u) - (1-u²)K(u)]``,
  ``|m|/(mu N R) = 4/(9π) [2(2-u²)E(u) - (1-u²)K(u)]``;
- ``u >= 1``: ``|f|/(mu N) = 4/(3π) [(1+u²)E(1/u) - (u²-1)K(1/u)]``,
  ``|m|/(mu N R) = 4/(9π) [2u(2-u²)E(1/u) + (u²-1)(2u²-3)/u K(1/u)]``;
- pure force ``mu N`` (``u → ∞``), pure moment ``(2/3) mu N R`` (``u = 0``).

A load ``(f, m)`` of the disk is on its limit surface at the ``N`` whose curve point has the
ratio ``m / (f R)``; the root in ``u`` is found with Brent's method on the formulas above, which
share no code with the library. Optima are compared to 1e-7 relative, and every contact load of
every plan lies inside its exact surface to 1e-9 (``EXACT_CUT_RTOL``).
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from scipy.optimize import brentq
from scipy.special import ellipe, ellipk
from test_kept_parameters import bench_fixture

from fixplan import Body, Contact, LimitSurface, Load, Problem, pressure
from fixplan.planner import osculating as osculating_rounds
from fixplan.planner import runner
from fixplan.planner.contact_models import contact_model
from fixplan.planner.exact_contacts import ExactContacts
from fixplan.planner.planner import Planner
from fixplan.tolerances import EXACT_CUT_RTOL, FRICTION_SET_RTOL

R, MU, HALF_GAP = 0.01, 0.5, 0.04
OPTIMUM_RTOL = 1e-7


def disk_curve(u: float) -> tuple[float, float]:
    """``(|f| / (mu N), |m| / (mu N R))`` of the uniform disk, rotation about ``u R``."""
    if u == 1.0:
        return 8.0 / (3.0 * math.pi), 8.0 / (9.0 * math.pi)
    if u < 1.0:
        e, k = ellipe(u * u), ellipk(u * u)
        force = 4.0 / (3.0 * math.pi * u) * ((1 + u * u) * e - (1 - u * u) * k)
        moment = 4.0 / (9.0 * math.pi) * (2.0 * (2 - u * u) * e - (1 - u * u) * k)
    else:
        e, k = ellipe(1.0 / u**2), ellipk(1.0 / u**2)
        force = 4.0 / (3.0 * math.pi) * ((1 + u * u) * e - (u * u - 1) * k)
        moment = (
            4.0
            / (9.0 * math.pi)
            * (2 * u * (2 - u * u) * e + (u * u - 1) * (2 * u * u - 3) / u * k)
        )
    return force, moment


def least_normal_force(force: float, moment: float) -> tuple[float, float]:
    """The normal force [N] that puts the disk load ``(|f|, |m|)`` on its limit surface, and the
    ``u`` of its centre of rotation."""
    if force == 0.0:
        return abs(moment) / (2.0 / 3.0 * MU * R), 0.0
    if moment == 0.0:
        return force / MU, math.inf
    ratio = abs(moment) / (force * R)
    u = brentq(lambda u: disk_curve(u)[1] / disk_curve(u)[0] - ratio, 1e-6, 100.0, xtol=1e-15)
    return force / (MU * disk_curve(u)[0]), u


def pinch(load: Load, objective: str = "min-max-normal-force", force=None) -> Problem:
    """Two fingers with uniform disk patches squeezing a weightless bar along y."""
    contacts = [
        Contact(name=name, role="finger", position=[0, side * HALF_GAP, 0], normal=[0, -side, 0],
                mu=MU, model="exact", patch=pressure.disk(R), force=force)
        for name, side in (("left", -1), ("right", 1))
    ]  # fmt: skip
    return Problem(body=Body(mass=0.0, center_of_mass=[0, 0, 0]), contacts=contacts,
                   loads=[load], objective=objective)  # fmt: skip


def assert_loads_inside_their_exact_surfaces(problem: Problem, plan) -> None:
    """Every pressed contact's load is inside its exact surface; normal forces below the
    solver's noise (``FRICTION_SET_RTOL`` of the largest) carry no meaningful load direction."""
    for i, contact in enumerate(problem.contacts):
        surface = contact_model(contact).surface  # at unit normal force
        for fn, load in zip(plan.normal_forces[i], plan.contact_wrenches[i, :, 1:], strict=True):
            if fn > FRICTION_SET_RTOL * plan.normal_forces.max():
                assert 1.0 / surface.safety_factor(load / fn) - 1.0 <= EXACT_CUT_RTOL


# (weight along z through the grasp axis [N], torque about the grasp axis y [N m])
PINCH_LOADS = [(10.0, 0.0), (0.0, 0.4), (10.0, 0.05), (10.0, 0.2), (2.0, 0.4)]


@pytest.mark.parametrize(("weight", "torque"), PINCH_LOADS)
def test_a_uniform_disk_pinch_needs_the_closed_form_grip_force(weight, torque):
    # Each finger carries half of the weight and half of the torque about its own normal.
    load = Load(name="hold", force=[0, 0, -weight], point=[0, 0, 0], torque=[0, torque, 0])
    problem = pinch(load)
    plan = Planner(problem).solve()
    expected, _ = least_normal_force(weight / 2.0, torque / 2.0)
    assert plan.status == "optimal"
    assert plan.solver == "CLARABEL (osculating ellipsoids)"  # (which method answered)
    np.testing.assert_allclose(plan.normal_forces[:, 0], expected, rtol=OPTIMUM_RTOL)
    assert_loads_inside_their_exact_surfaces(problem, plan)
    # The analysis of the forces found: held with safety factor 1.
    assert plan.safety_factor == pytest.approx(1.0, rel=1e-6)


@pytest.mark.parametrize(("weight", "torque"), PINCH_LOADS)
def test_a_uniform_disk_pinch_with_given_forces_has_the_closed_form_safety_factor(weight, torque):
    grip = 60.0  # [N] per finger
    load = Load(name="hold", force=[0, 0, -weight], point=[0, 0, 0], torque=[0, torque, 0])
    problem = pinch(load, "max-safety-factor", force=grip)
    plan = Planner(problem).solve()
    # k (f, m) is on the surface at the grip: k = grip / N(f, m), N homogeneous of degree 1.
    needed, _ = least_normal_force(weight / 2.0, torque / 2.0)
    assert plan.status == "optimal"
    assert plan.safety_factor == pytest.approx(grip / needed, rel=OPTIMUM_RTOL)
    assert_loads_inside_their_exact_surfaces(problem, plan)


def plate(push: Load) -> Problem:
    """A 2 kg plate resting on one uniform disk patch, pushed in the plane."""
    support = Contact(name="base", role="support", position=[0, 0, 0], normal=[0, 0, 1], mu=MU,
                      model="exact", patch=pressure.disk(R))  # fmt: skip
    return Problem(body=Body(mass=2.0, center_of_mass=[0, 0, 0.01]), contacts=[support],
                   loads=[push], objective="max-safety-factor")  # fmt: skip


@pytest.mark.parametrize(("force", "torque"), [(3.0, 0.0), (0.0, 0.02), (3.0, 0.01), (1.0, 0.05)])
def test_a_plate_on_a_disk_patch_has_the_closed_form_safety_factor_and_motion(force, torque):
    push = Load(name="push", force=[force, 0, 0], point=[0, 0, 0], torque=[0, 0, torque])
    problem = plate(push)
    plan = Planner(problem).solve()
    weight = 2.0 * 9.81
    needed, u = least_normal_force(force, torque)
    assert plan.status == "optimal"
    assert plan.safety_factors["push"] == pytest.approx(weight / needed, rel=OPTIMUM_RTOL)
    assert_loads_inside_their_exact_surfaces(problem, plan)
    # The impending planar motion (dual of the equilibrium, (vx, vy, wz) of the twist):
    # rotation about a point u R from the patch centre on the y axis (the push is along x),
    # or a translation along x.
    vx, vy, w = plan.motions["push"].twist[[0, 1, 5]]
    if math.isinf(u):
        assert abs(vy) < 1e-7 * abs(vx) and abs(w) * R < 1e-7 * abs(vx)
    else:
        assert abs(vy) < 1e-7 * abs(w) * R
        assert abs(vx / w) == pytest.approx(u * R, rel=1e-6, abs=1e-9 * R)


def test_point_supports_are_planned_on_their_facets_exactly():
    # Three point supports: pushing about a support point slides the plate on that facet; the
    # safety factor is the exact surface's (a facet of the point set, not a smoothed one).
    points = pressure.points([[0.03, 0.0], [-0.02, 0.025], [-0.02, -0.03]], [1.0, 2.0, 1.5])
    support = Contact(name="base", role="support", position=[0, 0, 0], normal=[0, 0, 1], mu=MU,
                      model="exact", patch=points)  # fmt: skip
    body = Body(mass=2.0, center_of_mass=[0, 0, 0.01])
    surface = LimitSurface(points, mu=MU, normal_force=2.0 * 9.81)
    xy = points.pose.apply(points.xy)[0]
    facet = surface.load(np.array([xy[1], -xy[0], 1.0]))  # rotation about support point 0
    push = Load(name="push", force=[facet[0], facet[1], 0], point=[0, 0, 0],
                torque=[0, 0, facet[2]])  # fmt: skip
    problem = Problem(body=body, contacts=[support], loads=[push], objective="max-safety-factor")
    plan = Planner(problem).solve()
    assert plan.status == "optimal"
    assert plan.safety_factors["push"] == pytest.approx(1.0, rel=OPTIMUM_RTOL)
    vx, vy, w = plan.motions["push"].twist[[0, 1, 5]]
    np.testing.assert_allclose([-vy / w, vx / w], xy, rtol=1e-6)  # centre of rotation


def test_re_solves_keep_every_contact_load_inside_its_exact_surface():
    planner = Planner(pinch(Load(name="hold", force=[0, 0, -10.0], point=[0, 0, 0])))
    rng = np.random.default_rng(3)
    for _ in range(5):
        weight, torque, offset = rng.uniform(1.0, 20.0), rng.uniform(0.0, 0.3), rng.normal(0, 0.02)
        load = Load(name="hold", force=[0, 0, -weight], point=[offset, 0, 0], torque=[0, torque, 0])
        plan = planner.solve([load])
        assert plan.status == "optimal"
        assert_loads_inside_their_exact_surfaces(planner.problem, plan)
        # The weight at x = offset adds the moment weight * offset about the grasp axis y.
        total = torque + weight * offset
        expected, _ = least_normal_force(weight / 2.0, abs(total) / 2.0)
        np.testing.assert_allclose(plan.normal_forces[:, 0], expected, rtol=OPTIMUM_RTOL)


@pytest.mark.parametrize("osculating", [True, False])
def test_the_impending_motion_of_each_pinching_finger_is_the_normal_at_its_load(
    osculating, monkeypatch
):
    # Normality: at the optimum each finger's twist in the impending motion (the equilibrium's
    # multipliers mapped to the contact) is the outward normal of its exact surface at its load,
    # i.e. the load's sliding twist from the inverse map; with osculating ellipsoids and with
    # cutting planes alone.
    if not osculating:
        monkeypatch.setattr(runner, "smooth", lambda models: False)
    load = Load(name="hold", force=[0, 0, -10.0], point=[0, 0, 0], torque=[0, 0.1, 0])
    problem = pinch(load)
    planner = Planner(problem)
    plan = planner.solve(analyse=False)
    assert plan.status == "optimal"
    stacked = planner._runner.stacked(problem.objective, osculating)
    dual = np.asarray(stacked.balance.dual_value)[:, 0]
    scale = np.array([1.0, 1.0, R])  # normalised twist coordinates of the disk
    for i, contact in enumerate(problem.contacts):
        twist = -planner.layout.friction_map[:, planner.layout.slices[i]].T @ dual
        surface = contact_model(contact).surface
        sliding = surface.motion(plan.contact_wrenches[i, 0, 1:] / plan.normal_forces[i, 0])
        a, b = twist * scale, sliding * scale
        assert np.dot(a, b) / (np.linalg.norm(a) * np.linalg.norm(b)) > 1.0 - 1e-6


def milling_fixture(model: str, seed: int) -> Problem:
    """A block on two disk pads and a rectangular locator, two clamps, 6 random milling loads."""
    rng = np.random.default_rng(seed)
    pads = [
        ("pad-a", "support", [-0.04, -0.03, 0], [0, 0, 1], pressure.disk(R)),
        ("pad-b", "support", [0.04, -0.03, 0], [0, 0, 1], pressure.disk(R)),
        ("pad-c", "support", [0.0, 0.04, 0], [0, 0, 1], pressure.rectangle(0.02, 0.01)),
        ("side", "locator", [-0.06, 0, 0.02], [1, 0, 0], pressure.disk(0.008)),
        ("clamp-top", "clamp", [0, 0, 0.04], [0, 0, -1], pressure.disk(0.006)),
        ("clamp-side", "clamp", [0.06, 0, 0.02], [-1, 0, 0], pressure.disk(0.006)),
    ]
    contacts = [
        Contact(name=name, role=role, position=p, normal=n, mu=0.3, model=model, patch=patch)
        for name, role, p, n, patch in pads
    ]
    loads = [
        Load(name=f"cut-{k}", force=rng.normal(0, 40, 3), point=[0, 0, 0.03],
             torque=rng.normal(0, 0.5, 3))
        for k in range(6)
    ]  # fmt: skip
    return Problem(body=Body(mass=1.0, center_of_mass=[0, 0, 0.02]), contacts=contacts,
                   loads=loads, objective="min-total-clamp-force")  # fmt: skip


def solved_both_ways(problem: Problem, loads, monkeypatch) -> tuple[list, list]:
    """Plans of ``problem`` and a re-solve with ``loads``: with osculating ellipsoids (checked
    to have settled without the cutting planes) and with cutting planes alone."""
    osculating = Planner(problem)
    found = [osculating.solve(), osculating.solve(loads)]
    assert osculating._runner.osculating
    assert (problem.objective, False) not in osculating._runner._built  # no fallback
    with monkeypatch.context() as patch:
        patch.setattr(runner, "smooth", lambda models: False)
        cutting = Planner(problem)
        assert not cutting._runner.osculating
        expected = [cutting.solve(), cutting.solve(loads)]
    for plan, reference in zip(found, expected, strict=True):
        assert plan.status == reference.status == "optimal"
        assert_loads_inside_their_exact_surfaces(problem, plan)
    return found, expected


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_osculating_ellipsoids_find_the_least_clamp_force_of_the_cutting_planes(seed, monkeypatch):
    """The two ways of stating exact models agree: the cutting planes (relaxations, exact when
    every load is inside) and the osculating ellipsoids (stopped by the optimality conditions),
    on a fixture of disk and rectangle patches, first solve and re-solve with new loads. (The
    split of the least total between the two clamps need not be unique, so the safety factors of
    the forces found are compared with 1: the contacts pressed below ``FRICTION_SET_RTOL`` of
    the largest force are not held to their exact sets, which leaves them up to 1e-5 short.)"""
    problem = milling_fixture("exact", seed)
    found, expected = solved_both_ways(problem, milling_fixture("exact", seed + 10).loads,
                                       monkeypatch)  # fmt: skip
    for plan, reference in zip(found, expected, strict=True):
        assert plan.objective_value == pytest.approx(reference.objective_value, rel=OPTIMUM_RTOL)
        assert plan.safety_factor == pytest.approx(1.0, abs=1e-5)


@pytest.mark.parametrize("seed", [0, 1])
def test_osculating_ellipsoids_find_the_held_intervals_of_the_cutting_planes(seed, monkeypatch):
    """Given clamp forces: every load case's held interval (both ends, six cases in blocks)
    agrees between the two ways within 5e-7: both end in interior-point solves, which leave the
    limiting loads a few 1e-7 inside their exact surfaces (here the cutting planes' 14.4941062
    against 14.4941085, whose loads are all inside too, so the exact optimum is at least that)."""
    problem = milling_fixture("exact", seed)
    contacts = [
        dataclasses.replace(c, force=80.0 + 40.0 * k) if c.role == "clamp" else c
        for k, c in enumerate(problem.contacts)
    ]
    problem = dataclasses.replace(problem, contacts=contacts, objective="max-safety-factor")
    found, expected = solved_both_ways(problem, milling_fixture("exact", seed + 10).loads,
                                       monkeypatch)  # fmt: skip
    for plan, reference in zip(found, expected, strict=True):
        for name, (low, high) in reference.held_intervals.items():
            assert plan.held_intervals[name][0] == pytest.approx(low, rel=5e-7, abs=1e-7)
            assert plan.held_intervals[name][1] == pytest.approx(high, rel=5e-7)


def test_rounds_that_do_not_settle_leave_the_problem_to_the_cutting_planes(monkeypatch):
    monkeypatch.setattr(osculating_rounds, "MAX_ROUNDS", 1)
    load = Load(name="hold", force=[0, 0, -10.0], point=[0, 0, 0], torque=[0, 0.2, 0])
    problem = pinch(load)
    planner = Planner(problem)
    plan = planner.solve(analyse=False)
    assert (problem.objective, False) in planner._runner._built
    expected, _ = least_normal_force(5.0, 0.1)
    assert plan.status == "optimal"
    assert plan.solver == "CLARABEL (cutting planes)"
    np.testing.assert_allclose(plan.normal_forces[:, 0], expected, rtol=OPTIMUM_RTOL)


def test_an_infeasible_exact_problem_is_certified_by_the_cutting_planes():
    # Fingers limited to 5 N cannot hold a 20 N weight at mu = 0.5: the ellipsoids' solve is
    # infeasible, and so is the cutting planes' relaxation, which proves it.
    contacts = [
        Contact(name=name, role="finger", position=[0, side * HALF_GAP, 0], normal=[0, -side, 0],
                mu=MU, model="exact", patch=pressure.disk(R), max_force=5.0)
        for name, side in (("left", -1), ("right", 1))
    ]  # fmt: skip
    load = Load(name="hold", force=[0, 0, -20.0], point=[0, 0, 0])
    problem = Problem(body=Body(mass=0.0, center_of_mass=[0, 0, 0]), contacts=contacts,
                      loads=[load], objective="min-max-normal-force")  # fmt: skip
    planner = Planner(problem)
    plan = planner.solve()
    assert plan.status == "infeasible"
    assert (problem.objective, False) in planner._runner._built


def test_few_point_supports_are_stated_exactly_and_many_take_the_cutting_planes(monkeypatch):
    """Facets have no curvature to osculate. Up to ``MAX_STATED_POINTS`` point supports are
    stated exactly, a cone per point: one solve, whose optimum is that of the cutting planes on
    the same supports (where they are more than that) to 1e-7 (seen: 1.5e-9)."""
    from fixplan.models import exact

    patch = pressure.points([[0.01, 0.0], [-0.01, 0.0], [0.0, 0.01]], [1.0, 1.0, 1.0])
    contacts = [
        Contact(name=name, role="finger", position=[0, side * HALF_GAP, 0], normal=[0, -side, 0],
                mu=MU, model="exact", patch=patch)
        for name, side in (("left", -1), ("right", 1))
    ]  # fmt: skip
    load = Load(name="hold", force=[0, 0, -10.0], point=[0, 0, 0], torque=[0, 0.05, 0])
    problem = Problem(body=Body(mass=0.0, center_of_mass=[0, 0, 0]), contacts=contacts,
                      loads=[load], objective="min-max-normal-force")  # fmt: skip
    plans = {}
    for most, solver in ((3, "CLARABEL"), (2, "CLARABEL (cutting planes)")):
        monkeypatch.setattr(exact, "MAX_STATED_POINTS", most)
        planner = Planner(problem)
        assert not planner._runner.osculating
        plans[most] = plan = planner.solve()
        assert plan.status == "optimal" and plan.solver == solver
        assert_loads_inside_their_exact_surfaces(problem, plan)
    assert plans[3].objective_value == pytest.approx(plans[2].objective_value, rel=1e-7)


@pytest.mark.parametrize("torque", [0.0, 0.05, 0.2])
def test_a_finger_on_point_supports_beside_a_smooth_one_keeps_the_osculating_ellipsoids(
    monkeypatch, torque
):
    """A pinch between a disk and three point supports: the points stated exactly, the disk by
    osculating ellipsoids, at the optimum of the cutting planes on both to 1e-7 (seen: 1.8e-9
    to 7.5e-9)."""
    from fixplan.models import exact

    patches = (pressure.disk(R), pressure.points([[0.01, 0.0], [-0.01, 0.0], [0.0, 0.01]]))
    contacts = [
        Contact(name=name, role="finger", position=[0, side * HALF_GAP, 0], normal=[0, -side, 0],
                mu=MU, model="exact", patch=patch)
        for name, side, patch in zip(("left", "right"), (-1, 1), patches, strict=True)
    ]  # fmt: skip
    load = Load(name="hold", force=[0, 0, -10.0], point=[0.003, 0, 0], torque=[0, torque, 0.01])
    problem = Problem(body=Body(mass=0.0, center_of_mass=[0, 0, 0]), contacts=contacts,
                      loads=[load], objective="min-max-normal-force")  # fmt: skip
    plan = Planner(problem).solve()
    assert plan.status == "optimal" and plan.solver == "CLARABEL (osculating ellipsoids)"
    assert_loads_inside_their_exact_surfaces(problem, plan)
    monkeypatch.setattr(exact, "MAX_STATED_POINTS", 0)
    cut = Planner(problem).solve()
    assert cut.solver == "CLARABEL (cutting planes)"
    assert plan.objective_value == pytest.approx(cut.objective_value, rel=1e-7)


def test_the_uses_kept_from_the_last_cutting_round_are_those_of_the_final_loads():
    """Verification and the analysis take the exact contacts' friction use from the last round
    of cuts instead of asking the exact surfaces again: it must be that of the final loads."""
    planner = Planner(pinch(Load(name="hold", force=[0, 0, -8.0], point=[0.01, 0, 0],
                                 torque=[0, 0.1, 0])))  # fmt: skip
    plan = planner.solve()
    assert plan.status == "optimal"
    wrenches = planner.problem.task_wrenches()
    forces = {i: plan.normal_forces[i, 0] for i in range(2)}
    result = planner._runner.run("check", wrenches, forces)
    known = result["known_use"]
    noise = 1e-9 * float(np.abs(result["normal"]).max())
    asked = planner.friction_use(result["friction"], result["normal"], noise=noise)
    assert np.all(np.isfinite(known))
    np.testing.assert_allclose(known, asked, rtol=1e-12)


def test_an_unpressed_exact_contact_whose_ellipsoid_falls_short_is_not_left_out(monkeypatch):
    """At each finger of a pinch sit an exact 10:1 rectangle and an ellipsoid-model disk of the
    same ``rho``. The load's direction at each finger is where the rectangle's exact set reaches
    4 % beyond the ellipse through its axis points, and the disk's ellipsoid reaches 2 % beyond
    that ellipse: the exact optimum presses the rectangles only, while a solve with the
    rectangles' first ellipsoids presses the disks only. The rounds must not stop there (the
    rectangles take no load, but their ellipsoids reach less far than their sets in the
    direction of their twists)."""
    rectangle = pressure.rectangle(0.1, 0.01)
    rho = LimitSurface(rectangle, mu=1.0).characteristic_length
    contacts = [
        Contact(name=f"{kind}{side}", role="finger", position=[0, side * HALF_GAP, 0],
                normal=[0, -side, 0], axis=[1, 0, 0], mu=mu, model=model, patch=patch)
        for side in (-1, 1)
        for kind, mu, model, patch in (("rectangle", 1.0, "exact", rectangle),
                                       ("disk", 1.02, "ellipsoid", pressure.disk(1.5 * rho)))
    ]  # fmt: skip
    angle = 0.87  # of (f / F, m / M) on the rectangle's axis ellipse, its largest bulge
    load = Load(name="turn", force=[20 * math.cos(angle), 0, 0], point=[0, 0, 0],
                torque=[0, 20 * math.sin(angle) * rho, 0])  # fmt: skip
    problem = Problem(body=Body(mass=0.0, center_of_mass=[0, 0, 0]), contacts=contacts,
                      loads=[load], objective="min-total-normal-force")  # fmt: skip
    planner = Planner(problem)
    plan = planner.solve(analyse=False)
    monkeypatch.setattr(runner, "smooth", lambda models: False)
    reference = Planner(problem).solve(analyse=False)
    assert plan.status == reference.status == "optimal"
    assert plan.objective_value == pytest.approx(reference.objective_value, rel=OPTIMUM_RTOL)
    np.testing.assert_allclose(plan.normal_forces[[1, 3], 0], 0.0, atol=1e-6)  # the disks
    assert (problem.objective, False) not in planner._runner._built  # settled, no fallback


def milling_loads(seed: int) -> list[Load]:
    """20 random milling loads on the fixture of benchmarks/bench_planner.py."""
    rng = np.random.default_rng(seed)
    return [
        Load(name=f"cut-{k}", force=rng.normal(size=3) * [80.0, 80.0, 40.0],
             point=[rng.uniform(-0.05, 0.05), rng.uniform(-0.03, 0.03), 0.04],
             torque=[0.0, 0.0, rng.normal()])
        for k in range(20)
    ]  # fmt: skip


def test_rounds_slow_to_settle_move_to_the_exact_point_of_the_solves_twist(monkeypatch):
    """Where a load stays outside its exact set after a round, its ellipsoid then osculates
    where the exact normal is the contact's twist (``PROGRESS``): on the 8-contact fixture of
    benchmarks/bench_planner.py under 20 random milling loads, fewer rounds than from the
    load's ray alone, the same least clamp force, every load inside."""
    rounds = []
    move = osculating_rounds.OsculatingPool.move
    monkeypatch.setattr(osculating_rounds.OsculatingPool, "move",
                        lambda pool: rounds.append(1) or move(pool))  # fmt: skip

    def solved(seed):
        problem = bench_fixture(milling_loads(seed), "exact")
        rounds.clear()
        plan = Planner(problem).solve(analyse=False)
        assert plan.solver == "CLARABEL (osculating ellipsoids)"
        assert_loads_inside_their_exact_surfaces(problem, plan)
        return plan.objective_value, len(rounds)

    seeds = range(4)
    anchored = [solved(seed) for seed in seeds]
    monkeypatch.setattr(osculating_rounds, "PROGRESS", math.inf)
    on_rays = [solved(seed) for seed in seeds]
    for (value, _), (expected, _) in zip(anchored, on_rays, strict=True):
        assert value == pytest.approx(expected, rel=OPTIMUM_RTOL)
    assert sum(r for _, r in anchored) < sum(r for _, r in on_rays)


def test_load_cases_that_moved_far_start_from_the_axis_ellipsoids(monkeypatch):
    """A re-solve starts each load case's rounds from the ellipsoids kept for it where its task
    wrench moved by at most ``START_CHANGE`` of itself, else from those through the exact sets'
    axis points: on the fixture of benchmarks/bench_planner.py, re-solved under new random
    milling loads, fewer rounds than from the kept ones, the optima of fresh planners, every
    load inside."""
    rounds, starts = [], []
    pool = osculating_rounds.OsculatingPool
    move, place = pool.move, pool.place
    monkeypatch.setattr(pool, "move", lambda self: rounds.append(1) or move(self))
    monkeypatch.setattr(
        pool, "place", lambda self, found: starts.append(found) or place(self, found)
    )

    def re_solved(first, then):
        planner = Planner(bench_fixture(milling_loads(first), "exact"))
        planner.solve(analyse=False)
        rounds.clear()
        starts.clear()
        plan = planner.solve(milling_loads(then), analyse=False)
        assert_loads_inside_their_exact_surfaces(planner.problem, plan)
        moved = [
            planner._runner._moved(np.asarray(old.wrench), np.asarray(new.wrench))
            for old, new in zip(milling_loads(first), milling_loads(then), strict=True)
        ]
        far = [found is None for found in starts[0]]
        assert far == [change > runner.START_CHANGE for change in moved]
        return plan.objective_value, len(rounds), far

    seeds = [(2 * k + 1, 2 * k + 2) for k in range(6)]  # (20 rounds against 25)
    found = [re_solved(*pair) for pair in seeds]
    for (value, _, far), (_, then) in zip(found, seeds, strict=True):
        assert any(far) and not all(far)
        fresh = Planner(bench_fixture(milling_loads(then), "exact")).solve(analyse=False)
        assert value == pytest.approx(fresh.objective_value, rel=OPTIMUM_RTOL)
    monkeypatch.setattr(runner, "START_CHANGE", math.inf)
    kept = [re_solved(*pair)[1] for pair in seeds]
    assert sum(r for _, r, _ in found) < sum(kept)


def counted_clarabel_iterations(monkeypatch) -> list:
    """The interior-point iterations of every Clarabel solve from now on: its solver class
    replaced by one that appends them to the list returned (cvxpy's Clarabel interface and the
    direct solver both build their solvers from the module)."""
    import clarabel

    original, iterations = clarabel.DefaultSolver, []

    class Counted:
        def __init__(self, *args):
            self._solver = original(*args)

        def solve(self):
            solution = self._solver.solve()
            iterations.append(solution.iterations)
            return solution

        def __getattr__(self, name):
            return getattr(self._solver, name)

    monkeypatch.setattr(clarabel, "DefaultSolver", Counted)
    return iterations


def test_cuts_moved_off_the_tangent_plane_save_interior_point_iterations(monkeypatch):
    """A cut at the exact set's tangent plane is tangent to the ellipsoid that osculates there
    too; ``CUT_SLACK`` moves it out. On the 8-contact fixture of benchmarks/bench_planner.py,
    solved and re-solved under random milling loads, Clarabel then takes fewer iterations in
    all, and finds the same least clamp forces with every load inside its exact set."""
    iterations = counted_clarabel_iterations(monkeypatch)

    def solved():
        iterations.clear()
        problem = bench_fixture(milling_loads(0), "exact")
        planner = Planner(problem)
        values = []
        for seed in range(4):
            plan = planner.solve(milling_loads(seed), analyse=False)
            assert plan.solver == "CLARABEL (osculating ellipsoids)"
            assert_loads_inside_their_exact_surfaces(problem, plan)
            values.append(plan.objective_value)
        return values, sum(iterations)

    moved, moved_iterations = solved()
    monkeypatch.setattr(osculating_rounds, "CUT_SLACK", 0.0)
    tangent, tangent_iterations = solved()
    np.testing.assert_allclose(moved, tangent, rtol=OPTIMUM_RTOL)
    assert moved_iterations < 0.9 * tangent_iterations, (moved_iterations, tangent_iterations)


def realtime_loads(step: int) -> list[Load]:
    """The load case at ``step`` of the path of benchmarks/bench_realtime.py (10,000 steps): a
    cutting force of 80 N turning in the plane, a torque varying with it."""
    angle = np.linspace(0.0, 4.0 * np.pi, 10_000)[step]
    return [Load(name="cut", force=[80.0 * np.cos(angle), 80.0 * np.sin(angle), -30.0],
                 point=[0.02 * np.cos(angle / 2), 0.01, 0.04],
                 torque=[0.0, 0.0, 0.8 * np.sin(angle)])]  # fmt: skip


def test_a_load_stuck_outside_its_exact_set_gets_the_tangent_plane_itself():
    """A load whose excess a round did not reduce (``PROGRESS``) gets the exact set's tangent
    plane as its cut, not the plane moved out by ``CUT_SLACK``: along the path of
    benchmarks/bench_realtime.py (the 8-contact grasp, one case, a cutting load that turns
    slowly), steps 337 and 338 left a load 2e-7 outside round after round with the moved plane
    (its ellipsoid, placed at the load's ray, did not bring it in) and went to the cutting
    planes. Every step up to there must settle in the rounds."""
    path = [realtime_loads(step) for step in range(340)]
    problem = bench_fixture(path[0], "exact")
    planner = Planner(problem)
    for loads in path[:3]:  # (as the benchmark warms up)
        planner.solve(loads)
    for loads in path:
        plan = planner.solve(loads, analyse=False)
        assert plan.solver == "CLARABEL (osculating ellipsoids)"
    assert_loads_inside_their_exact_surfaces(problem, plan)


def test_contacts_sharing_a_model_are_queried_together_with_the_same_answers(monkeypatch):
    """The three pads and the top clamp of the 8-contact fixture of benchmarks/bench_planner.py
    share one exact model and its jaws another (`contact_models`): the rounds query the
    loads of each model in one call. The plans, analysis included, are those of one call per
    contact, to the last bit."""
    problem = bench_fixture(milling_loads(0)[:4], "exact")
    new_loads = [milling_loads(seed)[:4] for seed in (1, 2)]
    together = Planner(problem)
    assert len({id(model) for model in together.models}) == 2
    plans = [together.solve(loads) for loads in new_loads]

    def one_call_per_contact(pool, owner):
        for e in np.unique(owner):
            yield pool._models[e], np.flatnonzero(owner == e)

    monkeypatch.setattr(ExactContacts, "_by_model", one_call_per_contact)
    apart = Planner(problem)
    for plan, loads in zip(plans, new_loads, strict=True):
        reference = apart.solve(loads)
        assert plan.solver == reference.solver == "CLARABEL (osculating ellipsoids)"
        assert plan.objective_value == reference.objective_value
        np.testing.assert_array_equal(plan.normal_forces, reference.normal_forces)
        np.testing.assert_array_equal(plan.contact_wrenches, reference.contact_wrenches)
        assert plan.safety_factors == reference.safety_factors


@pytest.mark.parametrize("step", [2540, 3900, 7500])
def test_a_grasp_that_needs_no_clamp_force_settles_in_the_rounds(step, monkeypatch):
    """Where the cutting load of benchmarks/bench_realtime.py's path (10,000 steps) is held
    without clamp force, the twists of the force solve are solver noise (1e-10 normalised):
    weighed against ``FORCE_DUAL_FLOOR`` rather than counted as zero, they failed the
    complementarity test round after round, and these steps (fresh planners; 22 of every
    twentieth step of the path from one planner) went to the cutting planes. The plan, its
    safety analysis included, is the cutting planes' (safety factors to 1e-7)."""
    loads = realtime_loads(step)
    problem = bench_fixture(loads, "exact")
    found, expected = solved_both_ways(problem, loads, monkeypatch)
    for plan, reference in zip(found, expected, strict=True):
        assert plan.solver == "CLARABEL (osculating ellipsoids)"
        assert abs(plan.objective_value) <= 1e-7 and abs(reference.objective_value) <= 1e-7  # [N]
        assert plan.safety_factor == pytest.approx(reference.safety_factor, rel=1e-7)


def test_the_rounds_of_a_small_grasp_go_to_the_compiled_interior_point(monkeypatch):
    """The osculating programs of the 8-contact grasp of benchmarks/bench_realtime.py (one
    case: rows of ``R l`` and of cuts mix a load's components) are solved by the compiled
    interior point once the planner re-solves; along its path the plans are those of rounds
    solved by Clarabel (a planner whose programs the interior point is told not to fit), to
    1e-7, with every load inside its exact surface."""
    from fixplan.planner.cone_interior_point import ConeInteriorPoint

    path = [realtime_loads(step) for step in range(40)]
    problem = bench_fixture(path[0], "exact")
    interior = Planner(problem)
    found = [interior.solve(loads) for loads in path]
    rounds = interior._runner._direct[(problem.objective, True)]
    assert rounds.method == "interior point"
    monkeypatch.setattr(ConeInteriorPoint, "fits", staticmethod(lambda *pattern: False))
    clarabel = Planner(problem)
    expected = [clarabel.solve(loads) for loads in path]
    assert clarabel._runner._direct[(problem.objective, True)].method == "CLARABEL"
    for plan, reference in zip(found, expected, strict=True):
        assert plan.solver == reference.solver == "CLARABEL (osculating ellipsoids)"
        assert plan.objective_value == pytest.approx(reference.objective_value, rel=OPTIMUM_RTOL)
        assert plan.safety_factor == pytest.approx(reference.safety_factor, rel=OPTIMUM_RTOL)
        assert_loads_inside_their_exact_surfaces(problem, plan)
