"""Free sliding against an independent integration of the closed-form limit curves: the spinning
puck that stops sliding and turning at the same instant."""

import numpy as np
import pytest
from reference import disk_force_moment
from scipy.integrate import solve_ivp

from fixplan import LimitSurface, pressure
from fixplan.errors import InvalidArgumentError
from fixplan.models import Ellipsoid
from fixplan.motion.sliding import slide

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


def test_slide_needs_a_forward_map_and_a_moving_body():
    with pytest.raises(InvalidArgumentError, match="forward map"):
        slide(Ellipsoid.from_limit_surface(PUCK), mass=MASS, inertia=INERTIA, twist0=[1, 0, 0],
              duration=1.0)  # fmt: skip
    with pytest.raises(InvalidArgumentError, match="nonzero"):
        slide(PUCK, mass=MASS, inertia=INERTIA, twist0=[0, 0, 0], duration=1.0)
