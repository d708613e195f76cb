"""A body turning about one of its point supports while that point sticks: against the closed
form of a bar turning about one end, the convex problem of a start solved by cvxpy, and an
independent integration with the friction of every point regularised (``-c v / sqrt(|v|² +
ε²)``, stiff, by Radau), whose answers approach the non-smooth ones in proportion to ``ε``."""

import warnings

import cvxpy as cp
import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

from fixplan import Contact, ContactSetSurface, LimitSurface, pressure
from fixplan.motion import slide, start_acceleration

MASS, INERTIA, NORMAL, MU = 0.5, 1e-3, 4.9, 0.3
#: A bar on two equal point supports 0.1 m apart (at x = -0.05 and 0.05 from its centre).
BAR = LimitSurface(pressure.points([[-0.05, 0.0], [0.05, 0.0]]), mu=MU, normal_force=NORMAL)
#: A part on three point supports (centred at their centroid).
TRIPOD = LimitSurface(
    pressure.points([[-0.04, -0.02], [0.04, -0.02], [0.0, 0.03]]), mu=MU, normal_force=NORMAL
)


def regularised(surface, twist0, load, duration, eps=1e-9):
    """Final world pose of the body sliding from rest pose 0 with the body-frame ``twist0``,
    every point's friction ``-c v / sqrt(|v|² + eps²)`` (``eps`` [m/s])."""
    points, friction = surface.point_supports

    def rate(t, y):
        c, s = np.cos(y[2]), np.sin(y[2])
        vx, vy = c * y[3] + s * y[4], -s * y[3] + c * y[4]
        velocities = np.stack([vx - y[5] * points[:, 1], vy + y[5] * points[:, 0]], axis=1)
        forces = -(friction / np.sqrt((velocities**2).sum(axis=1) + eps**2))[:, None] * velocities
        fx, fy = forces.sum(axis=0) + load[:2]
        moment = (points[:, 0] * forces[:, 1] - points[:, 1] * forces[:, 0]).sum() + load[2]
        return [y[3], y[4], y[5], (c * fx - s * fy) / MASS, (s * fx + c * fy) / MASS,
                moment / INERTIA]  # fmt: skip

    with warnings.catch_warnings():  # (overflows in Radau's finite-difference Jacobian)
        warnings.simplefilter("ignore", RuntimeWarning)
        solution = solve_ivp(rate, (0.0, duration), [0.0, 0.0, 0.0, *twist0], method="Radau",
                             rtol=1e-11, atol=1e-14)  # fmt: skip
    return solution.y[:3, -1]


def still_point(moved, index, surface):
    """World positions ``(n, 2)`` of point support ``index`` over the samples of ``moved``."""
    px, py = surface.point_supports[0][index]
    angles = moved.poses[:, 2]
    return moved.poses[:, :2] + np.stack(
        [np.cos(angles) * px - np.sin(angles) * py, np.sin(angles) * px + np.cos(angles) * py],
        axis=1,
    )


def test_point_supports_are_the_points_and_their_share_of_the_friction():
    points, friction = BAR.point_supports
    np.testing.assert_array_equal(points, [[-0.05, 0.0], [0.05, 0.0]])
    np.testing.assert_allclose(friction, [MU * NORMAL / 2] * 2, rtol=1e-15)
    assert LimitSurface(pressure.disk(0.02), mu=MU).point_supports[0].shape == (0, 2)


def test_a_bar_turning_about_one_end_stops_as_the_closed_form_says():
    """Turning about the support at x = -0.05, the other one slides on a circle of radius 0.1
    against its friction c: (I + m r²) ω' = -c d, so it stops at ω₀ I_p / (c d) after
    turning ω₀ t / 2, the still end holding the centripetal and tangential forces. (The body
    counts as stopped below 1e-9 of the run's speed scale: 2e-8 of the stop time here.)"""
    rate = 2.0
    moved = slide(BAR, mass=MASS, inertia=INERTIA, twist0=[0.0, 0.05 * rate, rate], duration=1.0)
    friction, span = MU * NORMAL / 2, 0.1
    about_end = INERTIA + MASS * 0.05**2
    stop = rate * about_end / (friction * span)
    assert moved.stopped == pytest.approx(stop, rel=1e-7)
    assert moved.poses[-1, 2] == pytest.approx(rate * stop / 2, rel=1e-12)
    ((start, end, index),) = moved.pivots
    assert (start, index) == (0.0, 0) and end == moved.stopped
    ends = still_point(moved, 0, BAR)
    np.testing.assert_allclose(ends, np.tile([-0.05, 0.0], (len(ends), 1)), atol=1e-17)


def test_a_spinning_tripod_slides_then_turns_about_a_support_as_regularised_friction_says():
    """From a spin about its centroid it slides, turns about one support and stops (it ran
    until the integrator gave up before): the final pose of the regularised integration within
    1e-11 m and 1e-10 rad (at eps = 1e-9 m/s; it moves ~1e-11 per tenfold eps there)."""
    moved = slide(TRIPOD, mass=MASS, inertia=INERTIA, twist0=[0.0, 0.0, 1.0], duration=0.05)
    ((start, end, index),) = moved.pivots
    assert 0.0 < start < end == moved.stopped < 0.05
    reference = regularised(TRIPOD, [0.0, 0.0, 1.0], np.zeros(3), 0.05)
    np.testing.assert_allclose(moved.poses[-1, :2], reference[:2], atol=1e-11)
    assert moved.poses[-1, 2] == pytest.approx(reference[2], abs=1e-10)
    turning = (moved.t >= start) & (moved.t <= end)
    ends = still_point(moved, index, TRIPOD)[turning]
    np.testing.assert_allclose(ends, np.tile(ends[0], (len(ends), 1)), atol=1e-17)


@pytest.mark.parametrize("push", [0.8, 2.0])
def test_a_body_at_rest_starts_to_turn_about_a_support_where_the_convex_problem_says(push):
    """Pushed sideways at one support, the bar turns about the other: the minimiser of
    ``½aᵀMa - L·a + h(a)`` (a second-order cone program in cvxpy) to 1e-7."""
    load = np.array([0.0, push, 0.05 * push])
    points, friction = BAR.point_supports
    a = cp.Variable(3)
    dissipation = sum(
        c * cp.norm(cp.hstack([a[0] - a[2] * p[1], a[1] + a[2] * p[0]]))
        for p, c in zip(points, friction, strict=True)
    )
    masses = np.array([MASS, MASS, INERTIA])
    objective = 0.5 * cp.sum(cp.multiply(masses, cp.square(a))) - load @ a + dissipation
    cp.Problem(cp.Minimize(objective)).solve(solver=cp.CLARABEL, tol_gap_abs=1e-12,
                                              tol_gap_rel=1e-12, tol_feas=1e-12)  # fmt: skip
    found = start_acceleration(BAR, load, mass=MASS, inertia=INERTIA)
    np.testing.assert_allclose(found, a.value, rtol=1e-7, atol=1e-7 * np.abs(a.value).max())
    assert found[0] == 0.0 and found[1] == pytest.approx(0.05 * found[2], rel=1e-15)


def test_a_turn_ends_where_the_still_point_slips_and_the_body_slides_on_as_regularised():
    """Pushed at one end by 2 N, the bar turns about the other end with ω' constant until the
    centripetal force needed there exceeds its friction: the pivot ends at the root of |F(t)| =
    c (closed form), then the bar slides; the final pose as the regularised integration's
    within 3e-8 (SLIP_START: the slip starts at 10 times the stopping speed)."""
    push = 2.0
    load = np.array([0.0, push, 0.05 * push])
    friction = MU * NORMAL / 2
    about_end = INERTIA + MASS * 0.05**2
    alpha = (0.1 * push - 0.1 * friction) / about_end  # moments about the still end

    def excess(t):  # the still end's force F = m (α (p_y, -p_x) + ω² p) - f_a + f_o
        rate = alpha * t
        force = MASS * np.array([-0.05 * rate**2, 0.05 * alpha]) - [0.0, push] + [0.0, friction]
        return float(np.hypot(*force)) - friction

    slip = brentq(excess, 1e-6, 1.0, xtol=1e-15)
    moved = slide(BAR, mass=MASS, inertia=INERTIA, twist0=[0.0, 0.0, 0.0], duration=0.2,
                  load=lambda t, pose: load)  # fmt: skip
    ((start, end, index),) = moved.pivots
    assert (start, index) == (0.0, 0)
    assert end == pytest.approx(slip, rel=1e-9)
    reference = regularised(BAR, [0.0, 0.0, 0.0], load, 0.2)
    np.testing.assert_allclose(moved.poses[-1], reference, atol=3e-8)


def test_a_body_whose_point_support_comes_to_rest_as_it_stops_stops():
    """A fuzzer's part on five points, whose slowest point came to rest with the body's rate at
    2e-13 rad/s: a turn at that rate flipped its friction at every step (a ConvergenceError
    after 100,000 evaluations); now it is a stop, and the body stays."""
    points = [[-0.0261, -0.0207], [-0.1221, 0.09], [0.0572, -0.0163], [0.0387, 0.0141],
              [-0.0277, 0.0489]]  # fmt: skip
    surface = LimitSurface(pressure.points(points, [0.47, 0.979, 1.405, 0.961, 1.34]),
                           mu=0.971, normal_force=13.978)  # fmt: skip
    moved = slide(surface, mass=0.844, inertia=0.001133, twist0=[0.1683, 0.0376, 1.6529],
                  duration=0.5)  # fmt: skip
    assert moved.stops == (moved.stopped,) and 0.0 < moved.stopped < 0.5
    np.testing.assert_array_equal(moved.twists[moved.t > moved.stopped], 0.0)


def test_a_start_just_outside_the_surface_of_point_supports_meets_its_optimality_condition():
    """A load 6e-8 outside the surface of five points (a fuzzer's): Powell's method stalled at
    a residual of 3.8e-9 of the load; the start found satisfies ``M a - L + ∇h(a) = 0`` to
    1e-9 of the load."""
    points = [[-0.0066, 0.032], [0.0052, -0.0268], [0.0181, 0.0652], [0.0474, -0.0352],
              [-0.0633, -0.0312]]  # fmt: skip
    surface = LimitSurface(pressure.points(points, [0.205, 1.743, 0.26, 1.513, 0.516]),
                           mu=0.877, normal_force=11.288)  # fmt: skip
    direction = np.array([6.21412909, 0.64662295, -0.25569191])
    load = direction * surface.safety_factor(direction) * (1 + 6e-8)
    masses = np.array([0.669, 0.669, 0.001608])
    found = start_acceleration(surface, load, mass=0.669, inertia=0.001608)
    residual = (masses * found - load + surface.load(found)) / np.sqrt(masses)
    assert np.linalg.norm(residual) <= 1e-9 * np.linalg.norm(load / np.sqrt(masses))


def test_a_load_ramped_through_a_facet_starts_a_turn_at_the_instant_it_leaves():
    """The bar pushed sideways at one end by ``5 t`` N: the load leaves the surface through the
    facet of the turn about the other end when the push equals that end's friction ``c``, at
    ``t0 = c / 5``; the bar then turns with ``α = 0.1 (5 t - c) / I_end`` (moments about the
    still end), so ``θ = 0.5 (t - t0)³ / (6 I_end)``, and the still end does not slip in 0.3 s.
    At ``t0`` the load lies on the surface, where the turn's acceleration is 0 to rounding:
    decided there, the start was no turn, and the smooth start failed at the still end's kink
    (a ConvergenceError)."""
    friction = MU * NORMAL / 2
    about_end = INERTIA + MASS * 0.05**2
    start = friction / 5.0
    moved = slide(BAR, mass=MASS, inertia=INERTIA, twist0=[0.0, 0.0, 0.0], duration=0.3,
                  load=lambda t, pose: np.array([0.0, 5.0 * t, 0.25 * t]))  # fmt: skip
    assert moved.starts == pytest.approx((start,), rel=1e-15)
    ((begin, end, index),) = moved.pivots
    assert (begin, end, index) == (moved.starts[0], 0.3, 0)
    turning = np.clip(moved.t - start, 0.0, None)
    angle = 0.5 * turning**3 / (6 * about_end)
    np.testing.assert_allclose(moved.poses[:, 2], angle, rtol=0, atol=1e-14 * angle.max())
    rate = 0.5 * turning**2 / (2 * about_end)
    np.testing.assert_allclose(moved.twists[:, 2], rate, rtol=0, atol=1e-14 * rate.max())
    ends = still_point(moved, 0, BAR)
    np.testing.assert_allclose(ends, np.tile(ends[0], (len(ends), 1)), atol=1e-17)


#: Fuzzed parts on four and five points with a disk patch, masses ``(m, m, I)`` and loads about
#: 1e-9 outside their surfaces, where the root finders in the acceleration stalled.
BARELY_OUTSIDE = [
    (
        [[-0.148805558575489, -0.015251194029628387], [0.07249439611993984, -0.06219807359282814],
         [0.00266052988578339, 0.07499308101051352], [-0.058410237696540225, 0.04053108156280281],
         [0.09494489539055573, 0.022348211712440183]],
        [1.283450407003479, 0.27611424299593224, 0.8119963093548805, 0.3470597555036824,
         1.9482300289636443],
        (0.6299016792748217, 10.6458647620788, 0.029518738272406607, 2.1664907216205513),
        (0.9200795873696686, 0.002625951971485497),
        [6.332381068496494, 1.779782875185692, 0.3112434929012648],
    ),
    (
        [[-0.018139454975427637, -0.11836399035990273], [0.05217819174567628, -0.060509314294145355],
         [-0.008488909188619699, 0.03188862866524147], [0.007222382083640937, -0.04298824672694563]],
        [0.588756340429972, 0.8902243499962925, 0.9484649860147152, 0.753502166526899],
        (0.4189171153212212, 15.128910857000424, 0.013257589694512167, 2.961881214327359),
        (0.3329276829096791, 0.0008038957670758671),
        [-2.541637258894765, 3.2820265765952614, 0.296498206001015],
    ),
]  # fmt: skip


@pytest.mark.parametrize(("points", "weights", "support", "body", "load"), BARELY_OUTSIDE)
def test_a_start_barely_outside_a_surface_of_points_and_a_patch_meets_its_optimality_condition(
    points, weights, support, body, load
):
    """Loads 1.1e-9 and 1.7e-9 outside (fuzzed slides): the acceleration, 1e-9 of the load's
    size, was not found to 1e-9 of the load (Powell's method and Levenberg–Marquardt stalled);
    solved for its direction alone, it meets ``M a - L + ∇h(a) = 0`` to 1e-14 of the load."""
    mu, normal_force, radius, disk_force = support
    surface = LimitSurface.combine([
        LimitSurface(pressure.points(points, weights), mu=mu, normal_force=normal_force),
        LimitSurface(pressure.disk(radius), mu=0.3, normal_force=disk_force),
    ])  # fmt: skip
    load = np.array(load)
    assert 1e-9 < 1.0 - surface.safety_factor(load) < 2e-9
    mass, inertia = body
    masses = np.array([mass, mass, inertia])
    found = start_acceleration(surface, load, mass=mass, inertia=inertia)
    residual = (masses * found - load + surface.load(found)) / np.sqrt(masses)
    assert np.linalg.norm(residual) <= 1e-14 * np.linalg.norm(load / np.sqrt(masses))


def _point_contacts(places, mus, normals=None, model="point-cone"):
    normals = normals or [[0.0, 0.0, 1.0]] * len(places)
    return [
        Contact(name=f"p{i}", role="support", position=np.array([x, y, 0.01 * i]),
                normal=np.array(normal), mu=mu, model=model,
                patch=None if model.startswith("point") else pressure.disk(0.01))
        for i, ((x, y), mu, normal) in enumerate(zip(places, mus, normals, strict=True))
    ]  # fmt: skip


def test_a_set_of_point_contacts_slides_and_turns_about_one_as_its_points_do():
    """Three point contacts (each its own mu and normal force, one normal pointing down) as a
    ContactSetSurface: the LimitSurface of their points, whose support and forward map are the
    closed forms' (sums over the points) to 1e-14 and the conic programs' (what sets of other
    models are queried with) to 1e-8 on random twists, so a spinning part on them turns about
    one and stops as the regularised integration of the points' friction says (3e-12 m and rad).
    Before, each call of the forward map was a conic solve whose friction at a point at rest is
    any of its disk: after 100,000 evaluations (130 s) the integrator gave up."""
    places, mus, forces = (
        [[-0.04, -0.02], [0.04, -0.02], [0.0, 0.03]],
        [0.3, 0.4, 0.2],
        [1.5, 2, 1.4],
    )
    normals = [[0.0, 0.0, -1.0], [0.0, 0.0, 1.0], [0.0, 0.0, 1.0]]
    surface = ContactSetSurface(_point_contacts(places, mus, normals), forces)
    points = surface.as_limit_surface()
    np.testing.assert_array_equal(points.point_supports[0], places)
    np.testing.assert_allclose(points.point_supports[1], np.multiply(mus, forces), rtol=1e-15)
    friction, (x, y) = np.multiply(mus, forces), np.transpose(places)
    for twist in np.random.default_rng(3).normal(size=(10, 3)) * [1.0, 1.0, 20.0]:
        speeds = np.stack([twist[0] - twist[2] * y, twist[1] + twist[2] * x], axis=1)
        fx, fy = (friction[:, None] * speeds / np.linalg.norm(speeds, axis=1, keepdims=True)).T
        closed = np.array([fx.sum(), fy.sum(), (x * fy - y * fx).sum()])
        assert surface.support(twist) == pytest.approx(closed @ twist, rel=1e-14)
        np.testing.assert_allclose(surface.load(twist), closed, rtol=1e-14, atol=1e-15)
        conic, wrench = surface._conic.support(twist)
        assert points.support(twist) == pytest.approx(conic, rel=1e-8)
        np.testing.assert_allclose(points.load(twist), wrench, rtol=0, atol=1e-8)
    moved = slide(surface, mass=MASS, inertia=INERTIA, twist0=[0.0, 0.0, 1.0], duration=0.05)
    assert [index for _, _, index in moved.pivots] == [1] and moved.stopped < 0.05
    supports = type("Points", (), {"point_supports": points.point_supports})
    reference = regularised(supports, [0.0, 0.0, 1.0], np.zeros(3), 0.05)
    np.testing.assert_allclose(moved.poses[-1], reference, rtol=0, atol=1e-11)


@pytest.mark.parametrize(
    ("contacts", "subspace"),
    [
        (_point_contacts([[-0.04, 0.0], [0.04, 0.0]], [0.3, 0.3], model="cone"), None),
        (_point_contacts([[-0.04, 0.0], [0.04, 0.0]], [0.3, 0.3], model="point-pyramid"), None),
        (_point_contacts([[-0.04, 0.0], [0.04, 0.0]], [0.3, 0.3], [[0, 0, 1.0], [0, 0.6, 0.8]]),
         None),
        (_point_contacts([[-0.04, 0.0], [0.04, 0.0]], [0.3, 0.0]), None),  # (one with friction)
        (_point_contacts([[-0.04, 0.0], [0.04, 0.0]], [0.3, 0.3]), ("fx", "mz", "fy")),
        (_point_contacts([[-0.04, 0.0], [0.04, 0.0]], [0.3, 0.3], [[0, 0, 1.0], [1e-5, 0, 1.0]]),
         None),
    ],
)  # fmt: skip
def test_other_contact_sets_are_no_surface_of_points(contacts, subspace):
    surface = ContactSetSurface(contacts, [1.0, 1.0], subspace or ("fx", "fy", "mz"))
    assert surface.as_limit_surface() is None
    tiny = ContactSetSurface(_point_contacts([[-0.04, 0.0], [0.04, 0.0]], [0.3, 0.3]), [1e-101] * 2)
    assert tiny.as_limit_surface() is None  # (friction below what a surface takes)


def test_contacts_without_friction_are_left_out_and_those_at_one_place_merged():
    """A frictionless locator and an unloaded support take no part; a clamp above a support
    (same place, another height) adds its friction to that point's; a normal tilted by 1e-7 rad
    counts as vertical."""
    contacts = [
        *_point_contacts([[-0.04, 0.0], [0.04, 0.0]], [0.3, 0.3], [[0, 0, 1.0], [1e-7, 0, 1.0]]),
        *_point_contacts([[0.04, 0.0]], [0.5], [[0.0, 0.0, -1.0]]),
        *_point_contacts([[0.0, 0.05]], [0.0], [[1.0, 0.0, 0.0]], model="point-pyramid"),
        *_point_contacts([[0.0, -0.05]], [0.4]),
    ]
    surface = ContactSetSurface(contacts, [1.0, 2.0, 3.0, 4.0, 0.0])
    points = surface.as_limit_surface()
    np.testing.assert_array_equal(points.point_supports[0], [[-0.04, 0.0], [0.04, 0.0]])
    np.testing.assert_allclose(points.point_supports[1], [0.3, 0.6 + 1.5], rtol=1e-15)
    for twist in np.random.default_rng(4).normal(size=(5, 3)) * [1.0, 1.0, 20.0]:
        assert points.support(twist) == pytest.approx(surface.support(twist), rel=1e-8)
