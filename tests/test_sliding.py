"""Sliding against independent integrations of the closed-form limit curves: the spinning puck
that stops sliding and turning at the same instant, a puck under an applied load, a body that
starts from rest (the convex problem solved independently) and stick–slip under a swinging push."""

import numpy as np
import pytest
from reference import disk_force_moment
from scipy.integrate import solve_ivp
from scipy.optimize import brentq, minimize
from scipy.special import ellipe, ellipk

from fixplan import LimitSurface, pressure
from fixplan.errors import InvalidArgumentError
from fixplan.models import Cone, Ellipsoid
from fixplan.motion import slide, start_acceleration

RADIUS, MASS, MU, GRAVITY = 0.04, 0.2, 0.3, 9.81
INERTIA = 0.5 * MASS * RADIUS**2
PUCK = LimitSurface(pressure.disk(RADIUS), mu=MU, normal_force=MASS * GRAVITY)


def puck_reference(speed, spin):
    """(stop time, distance, turn) of a uniform puck moving along +x while spinning, from the
    closed forms: the centre of rotation lies at u R = v / ω on the y axis, friction resists with
    mu N f(u) and mu N R m(u) (DESIGN.md §4), m v' = -mu N f(u), I ω' = -mu N R m(u)."""
    friction = MU * MASS * GRAVITY

    def rate(t, state):
        v, w = state[0], state[1]
        force, moment = disk_force_moment("uniform", v / (w * RADIUS))
        return [-friction * force / MASS, -friction * RADIUS * moment / INERTIA, v, w]

    def stops(t, state):
        return min(state[0], state[1] * RADIUS) - 1e-9 * speed

    stops.terminal = True
    solution = solve_ivp(rate, (0.0, 10.0), [speed, spin, 0.0, 0.0], events=stops, rtol=1e-11,
                         atol=1e-13)  # fmt: skip
    end = solution.y_events[0][0]
    return float(solution.t_events[0][0]), end[2], end[3], solution


@pytest.mark.parametrize(("speed", "spin"), [(0.5, 20.0), (1.0, 10.0), (0.2, 40.0)])
def test_a_spinning_puck_stops_sliding_and_turning_together_as_the_closed_forms_say(speed, spin):
    stop, distance, turn, reference = puck_reference(speed, spin)
    # The classic result: neither motion dies first (the ratio v / ωR settles to a constant).
    ratio = reference.y[0, -5:] / (reference.y[1, -5:] * RADIUS)
    assert np.ptp(ratio) < 1e-3 * ratio.mean()
    sliding = slide(PUCK, mass=MASS, inertia=INERTIA, twist0=[speed, 0.0, spin], duration=5.0)
    assert sliding.stopped == pytest.approx(stop, rel=1e-6)
    np.testing.assert_allclose(sliding.poses[-1], [distance, 0.0, turn], rtol=1e-6, atol=1e-12)
    before = np.flatnonzero(sliding.t < 0.9 * stop)[-1]
    vx, vy, w = sliding.twists[before]
    angle = sliding.poses[before, 2]
    world = np.array([[np.cos(angle), -np.sin(angle)], [np.sin(angle), np.cos(angle)]]) @ [vx, vy]
    assert world[0] > 0.0 and w > 0.0 and abs(world[1]) < 1e-9 * world[0]  # both still going


def test_a_sliding_body_stays_at_rest_once_it_stops():
    sliding = slide(PUCK, mass=MASS, inertia=INERTIA, twist0=[0.3, -0.1, 5.0], pose0=(0.1, 0.2, 1.0),
                    duration=2.0)  # fmt: skip
    after = sliding.t > sliding.stopped
    assert after.any()
    np.testing.assert_array_equal(sliding.twists[after], 0.0)
    np.testing.assert_array_equal(
        sliding.poses[after], np.tile(sliding.poses[-1], (after.sum(), 1))
    )


def test_slide_needs_a_forward_map_and_a_moving_body_or_a_load():
    with pytest.raises(InvalidArgumentError, match="forward map"):
        slide(Cone.from_limit_surface(PUCK), mass=MASS, inertia=INERTIA, twist0=[1, 0, 0],
              duration=1.0)  # fmt: skip
    with pytest.raises(InvalidArgumentError, match="nonzero"):
        slide(PUCK, mass=MASS, inertia=INERTIA, twist0=[0, 0, 0], duration=1.0)
    with pytest.raises(InvalidArgumentError, match="load"):
        slide(PUCK, mass=MASS, inertia=INERTIA, twist0=[0, 0, 0], load=[1, 0, 0], duration=1.0)
    with pytest.raises(InvalidArgumentError, match="frictionless"):
        slide(LimitSurface(pressure.disk(RADIUS), mu=0.0), mass=MASS, inertia=INERTIA,
              twist0=[1, 0, 0], duration=1.0)  # fmt: skip
    with pytest.raises(InvalidArgumentError, match="samples must be an integer from 1 to"):
        slide(  # (it never ended)
            PUCK, mass=MASS, inertia=INERTIA, twist0=[1, 0, 0], duration=1.0, samples=10**8
        )


# -- applied loads ------------------------------------------------------------------------------

FRICTION = MU * MASS * GRAVITY  # largest friction force of the puck [N]
RHO = 2 * RADIUS / 3  # the Table 2 ellipsoid's characteristic length of a uniform disk [m]
MASSES = np.array([MASS, MASS, INERTIA])


def uniform_disk(u):
    """``(|f|, |m| / R)`` per unit mu N of a uniform disk rotating about a point at ``u R`` from
    its centre (DESIGN.md §4, scipy's elliptic integrals of parameter ``k²``); the mpmath
    reference near the centre, where these forms cancel."""
    if u < 1e-2:
        return disk_force_moment("uniform", u)
    if u == 1.0:
        return 8 / (3 * np.pi), 8 / (9 * np.pi)
    if u < 1.0:
        e, k = ellipe(u * u), ellipk(u * u)
        return (4 / (3 * np.pi * u) * ((1 + u * u) * e - (1 - u * u) * k),
                4 / (9 * np.pi) * (2 * (2 - u * u) * e - (1 - u * u) * k))  # fmt: skip
    e, k = ellipe(1 / (u * u)), ellipk(1 / (u * u))
    return (4 / (3 * np.pi) * ((1 + u * u) * e - (u * u - 1) * k),
            4 / (9 * np.pi) * (2 * u * (2 - u * u) * e + (u * u - 1) * (2 * u * u - 3) / u * k))  # fmt: skip


def disk_friction(twist):
    """``(h(V), ∇h(V))`` of the puck from the closed forms: rotation about the centre of
    rotation ``c``, ``h = |w| mu N (R m + |c| f)`` and the load ``sign(w) mu N (f ĉ⊥, R m)``."""
    vx, vy, w = twist
    if w == 0.0:
        speed = np.hypot(vx, vy)
        return FRICTION * speed, FRICTION * np.array([vx / speed, vy / speed, 0.0])
    cor = np.array([-vy / w, vx / w])
    distance = np.hypot(*cor)
    ex, ey = cor / distance if distance > 0.0 else (1.0, 0.0)
    force, moment = uniform_disk(distance / RADIUS)
    ccw = FRICTION * np.array([force * ey, -force * ex, RADIUS * moment])
    return abs(w) * FRICTION * (RADIUS * moment + distance * force), np.sign(w) * ccw


def ellipsoid_friction(twist):
    """``(h(V), ∇h(V))`` of the Table 2 ellipsoid ``(f / mu N)² + (m / (mu N rho))² = 1``."""
    stretched = np.array([twist[0], twist[1], RHO * RHO * twist[2]])
    size = np.sqrt(twist[0] ** 2 + twist[1] ** 2 + (RHO * twist[2]) ** 2)
    return FRICTION * size, FRICTION * stretched / size


def starting_reference(friction, load):
    """``argmin 1/2 a^T M a - L·a + h(a)`` by BFGS on the closed forms (0 if the load is held)."""

    def objective(a):
        h, gradient = friction(a) if np.any(a) else (0.0, np.zeros(3))
        return 0.5 * a @ (MASSES * a) - load @ a + h, MASSES * a - load + gradient

    start = load / MASSES
    if objective(start)[0] >= 0.0 and objective(1e-6 * start)[0] >= 0.0:
        return np.zeros(3)
    solution = minimize(objective, start, jac=True, method="BFGS", options={"gtol": 1e-13})
    return solution.x


def body_reference(friction, load, twist0, duration, times):
    """Poses and twists at ``times`` from an integration in the body frame:
    ``m (v' + w × v) = f - f_F``, ``I w' = m - m_F``, from rest along the BFGS minimiser."""
    scale = max(np.linalg.norm(twist0[:2]), FRICTION / MASS * duration)

    def rate(t, state):
        twist = state[3:]
        if np.any(twist):
            acceleration = (load - friction(twist)[1]) / MASSES
        else:
            acceleration = starting_reference(friction, load)
        vx, vy, w = twist
        c, s = np.cos(state[2]), np.sin(state[2])
        return [c * vx - s * vy, s * vx + c * vy, w, acceleration[0] + w * vy,
                acceleration[1] - w * vx, acceleration[2]]  # fmt: skip

    def stops(t, state):
        return np.hypot(np.hypot(*state[3:5]), state[5] * np.sqrt(INERTIA / MASS)) - 1e-9 * scale

    stops.terminal, stops.direction = True, -1
    state = np.concatenate([[0.0, 0.0, 0.0], twist0])
    solution = solve_ivp(rate, (0.0, duration), state, events=stops, dense_output=True,
                         rtol=1e-11, atol=1e-13)  # fmt: skip
    stop = solution.t_events[0][0] if solution.t_events[0].size else None
    states = np.array([solution.sol(min(t, solution.t[-1])) for t in times])
    if stop is not None:
        states[np.asarray(times) >= stop, 3:] = 0.0
    return states[:, :3], states[:, 3:], stop


@pytest.mark.parametrize(
    "surface", [PUCK, Ellipsoid.from_limit_surface(PUCK)], ids=["exact", "ellipsoid"]
)
def test_a_push_the_support_holds_decelerates_a_sliding_body_as_newton_says_and_it_stays(surface):
    # Pure translation along +x pushed forward by fx < mu m g: m v' = fx - mu m g until it stops.
    speed, push = 0.6, 0.4 * FRICTION
    sliding = slide(surface, mass=MASS, inertia=INERTIA, twist0=[speed, 0.0, 0.0],
                    load=lambda t, pose: [push, 0.0, 0.0], duration=0.5, samples=50)  # fmt: skip
    deceleration = (FRICTION - push) / MASS
    stop = speed / deceleration
    assert sliding.stopped == pytest.approx(stop, rel=1e-8)
    assert sliding.stops == (sliding.stopped,)
    moving = sliding.t < stop
    np.testing.assert_allclose(sliding.twists[moving, 0], speed - deceleration * sliding.t[moving],
                               rtol=0.0, atol=1e-8 * speed)  # fmt: skip
    np.testing.assert_allclose(sliding.poses[~moving], np.tile([speed * stop / 2, 0.0, 0.0],
                               ((~moving).sum(), 1)), rtol=0.0, atol=1e-9)  # fmt: skip
    np.testing.assert_array_equal(sliding.twists[~moving], 0.0)


@pytest.mark.parametrize(
    ("surface", "friction"),
    [(PUCK, disk_friction), (Ellipsoid.from_limit_surface(PUCK), ellipsoid_friction)],
    ids=["exact", "ellipsoid"],
)
@pytest.mark.parametrize("load", [[0.55, 0.3, 0.004], [0.8, -0.3, 0.01], [0.0, 0.1, 0.02]])
def test_a_body_at_rest_starts_along_the_minimiser_of_the_convex_problem(surface, friction, load):
    load = np.array(load)
    expected = starting_reference(friction, load)
    found = start_acceleration(surface, load, mass=MASS, inertia=INERTIA)
    assert np.any(expected)  # every load here lies outside the surface
    # Norm-wise in the metric of the masses (rotation counted at the radius of gyration).
    error = np.linalg.norm(np.sqrt(MASSES) * (found - expected))
    assert error <= 1e-8 * np.linalg.norm(np.sqrt(MASSES) * expected)


def test_a_load_the_support_holds_leaves_a_body_at_rest():
    load = [0.5 * FRICTION, 0.0, 0.3 * FRICTION * RHO]
    assert not np.any(start_acceleration(PUCK, load, mass=MASS, inertia=INERTIA))
    assert not np.any(starting_reference(disk_friction, np.array(load)))
    sliding = slide(PUCK, mass=MASS, inertia=INERTIA, twist0=[0, 0, 0], load=lambda t, p: load,
                    duration=0.2, samples=10)  # fmt: skip
    assert sliding.stopped == 0.0 and sliding.stops == ()
    np.testing.assert_array_equal(sliding.poses, 0.0)


@pytest.mark.parametrize(
    ("surface", "friction"),
    [(PUCK, disk_friction), (Ellipsoid.from_limit_surface(PUCK), ellipsoid_friction)],
    ids=["exact", "ellipsoid"],
)
@pytest.mark.parametrize(
    ("twist0", "load", "held"),
    [([0.5, 0.0, 20.0], [0.2, 0.1, 0.003], True), ([0.0, 0.0, 0.0], [0.8, 0.3, 0.01], False)],
    ids=["spinning-puck-held-load", "from-rest-load-outside"],
)
def test_a_loaded_puck_follows_an_independent_integration_of_the_closed_forms(
    surface, friction, twist0, load, held
):
    duration = 0.6
    sliding = slide(surface, mass=MASS, inertia=INERTIA, twist0=twist0,
                    load=lambda t, pose: load, duration=duration, samples=30)  # fmt: skip
    poses, twists, stop = body_reference(friction, np.array(load), np.array(twist0), duration,
                                         sliding.t)  # fmt: skip
    if held:  # it stops within the run and stays
        assert sliding.stopped == pytest.approx(stop, rel=1e-9)
    else:
        assert stop is None and sliding.stopped is None and sliding.starts == (0.0,)
    np.testing.assert_allclose(sliding.poses[:, :2], poses[:, :2], rtol=0.0, atol=1e-9)
    np.testing.assert_allclose(sliding.poses[:, 2], poses[:, 2], rtol=0.0, atol=1e-7)
    np.testing.assert_allclose(sliding.twists, twists, rtol=1e-7, atol=1e-7)


def test_a_swinging_push_slides_the_puck_in_steps_stick_slip_as_the_closed_form_says():
    # fx = F sin(W t), F = 1.5 mu m g, along x: the puck rests while |fx| <= mu m g, else
    # m v' = fx - sign mu m g, in closed form between the instants found by root finding.
    amplitude, rate, duration = 1.5 * FRICTION, 10.0, 1.5
    sliding = slide(PUCK, mass=MASS, inertia=INERTIA, twist0=[0, 0, 0],
                    load=lambda t, pose: [amplitude * np.sin(rate * t), 0.0, 0.0],
                    duration=duration, samples=60)  # fmt: skip
    lag = np.arcsin(FRICTION / amplitude)
    stops, start, x0, phase = [], lag / rate, 0.0, []
    for k in range(5):
        sign = (-1) ** k
        begin, begin_x = start, x0

        def velocity(t, begin=begin, sign=sign):
            return (amplitude * (np.cos(rate * begin) - np.cos(rate * t)) / rate
                    - sign * FRICTION * (t - begin)) / MASS  # fmt: skip

        def position(t, begin=begin, begin_x=begin_x, sign=sign):
            swing = (t - begin) * np.cos(rate * begin) - (
                np.sin(rate * t) - np.sin(rate * begin)
            ) / rate
            return (
                begin_x + (amplitude * swing / rate - sign * FRICTION * (t - begin) ** 2 / 2) / MASS
            )

        stop = brentq(velocity, begin + 1e-6, begin + np.pi / rate, xtol=1e-15)
        assert abs(amplitude * np.sin(rate * stop)) < FRICTION  # held where it stops
        stops.append(stop)
        phase.append((begin, stop, position))
        x0 = position(stop)
        start = (lag + (k + 1) * np.pi) / rate
        assert start > stop

    def expected_x(t):
        x = 0.0
        for begin, stop, position in phase:
            if t >= begin:
                x = position(min(t, stop))
        return x

    # The integration's absolute tolerance (1e-10 of the run's speed scale per step) leaves
    # the velocity within ~1e-8 m/s, so the stops within a few 1e-8 s.
    assert sliding.stops == pytest.approx([t for t in stops if t < duration], abs=1e-8)
    assert sliding.starts == pytest.approx([b for b, _, _ in phase if b < duration], abs=1e-12)
    assert sliding.stopped is None  # moving again at the end
    np.testing.assert_allclose(sliding.poses[:, 0], [expected_x(t) for t in sliding.t], rtol=0.0,
                               atol=1e-9)  # fmt: skip
    np.testing.assert_allclose(sliding.poses[:, 1:], 0.0, rtol=0.0, atol=1e-12)


# -- runs that stop before the first sample, loads on the surface ---------------------------------

RECT = LimitSurface(pressure.rectangle(0.09, 0.06), mu=0.3, normal_force=0.5 * 9.81)


@pytest.mark.parametrize(("duration", "samples"), [(100.0, 200), (1e5, 200), (1.0, 2), (1.0, 1)])
def test_a_body_that_stops_before_the_first_sample_stops_where_newton_says(duration, samples):
    # Pure translation on a rectangle: m v' = -mu N, stop at v0 m / (mu N), after v0² m / 2 mu N.
    deceleration = 0.3 * 9.81
    sliding = slide(RECT, mass=0.5, inertia=1e-3, twist0=[1.0, 0.0, 0.0], duration=duration,
                    samples=samples)  # fmt: skip
    assert sliding.t[1] == sliding.stopped < duration / samples
    assert sliding.stopped == pytest.approx(1.0 / deceleration, rel=1e-3)
    np.testing.assert_allclose(sliding.poses[-1], [0.5 / deceleration, 0.0, 0.0], rtol=0.0,
                               atol=1e-7)  # fmt: skip
    assert sliding.t[-1] == duration and len(sliding.t) == samples + 2
    np.testing.assert_array_equal(sliding.twists[1:], 0.0)


def test_a_push_of_exactly_mu_n_leaves_a_body_at_rest_and_a_larger_one_slides_it():
    surface = LimitSurface(pressure.rectangle(0.09, 0.06), mu=0.3, normal_force=4.9)
    limit = 0.3 * 4.9
    assert surface.safety_factor([limit, 0.0, 0.0]) < 1.0  # rounding puts it just outside
    held = slide(surface, mass=0.5, inertia=1e-3, twist0=[0, 0, 0], duration=1.0,
                 load=lambda t, pose: [limit, 0.0, 0.0])  # fmt: skip
    assert held.stopped == 0.0 and held.starts == ()
    np.testing.assert_array_equal(held.poses, 0.0)
    push = 1.001 * limit
    moved = slide(surface, mass=0.5, inertia=1e-3, twist0=[0, 0, 0], duration=1.0,
                  load=lambda t, pose: [push, 0.0, 0.0])  # fmt: skip
    assert moved.starts == (0.0,) and moved.stopped is None
    np.testing.assert_allclose(moved.poses[-1], [(push - limit) / 0.5 / 2, 0.0, 0.0], rtol=1e-6,
                               atol=1e-12)  # fmt: skip


def test_a_push_just_above_mu_n_slides_as_newton_says_through_the_stiff_integration():
    """A push 1e-6 above the limit: the explicit integration is stiff there (steps of the
    friction's time scale over the small net force; it ran for minutes), the implicit one that
    takes over finds x = ΔF t² / 2m."""
    surface = LimitSurface(pressure.rectangle(0.09, 0.06), mu=0.3, normal_force=4.9)
    push = (1 + 1e-6) * 0.3 * 4.9
    moved = slide(surface, mass=0.5, inertia=1e-3, twist0=[0, 0, 0], duration=1.0,
                  load=lambda t, pose: [push, 0.0, 0.0])  # fmt: skip
    expected = (push - 0.3 * 4.9) / 0.5 / 2
    np.testing.assert_allclose(moved.poses[-1], [expected, 0.0, 0.0], rtol=1e-4, atol=1e-15)
