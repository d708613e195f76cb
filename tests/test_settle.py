"""Quasi-static pivoting: a rod turning in a pinch of two soft fingers stops where the closed-form
limit curve of a uniform disk says; a part on two point supports pivots about one of them."""

import math

import numpy as np
import pytest
from reference import disk_force_moment
from scipy.optimize import brentq

from fixplan import LimitSurface, pressure
from fixplan.errors import InvalidArgumentError, ModelError
from fixplan.models import Cone, Ellipsoid
from fixplan.motion import settle
from fixplan.motion.pivoting import INSIDE, SLID_OUT, TURNED

# Two uniform soft finger pads of radius a, each pressed with N, pinch a rod at the origin: the
# rod slides over both pads alike, so the pinch's limit surface is that of one pad with 2N.
RADIUS, PRESS, MU, GRAVITY = 0.01, 5.0, 0.5, 9.81
PINCH = LimitSurface(pressure.disk(RADIUS), mu=MU, normal_force=2 * PRESS)
GRIP = 2 * MU * PRESS  # largest friction force of the pinch [N]


def gravity(mass, lever):
    """The rod's weight at ``lever`` from the pinch along the rod, about the pinch (the rod
    horizontal at θ = 0)."""
    weight = mass * GRAVITY
    return lambda pose: np.array([0.0, -weight, -weight * lever * math.cos(pose[2])])


def exact_stop(mass, lever):
    """Where the rod stops, from the closed-form limit curve of a uniform disk at 2N: the centre
    of rotation at u a along the rod gives the force mu 2N f(u) and the moment mu 2N a m(u);
    the weight fixes u (f grows from 0 to 1), the moment then fixes cos θ. The rod droops:
    θ < 0."""
    weight = mass * GRAVITY
    u = brentq(lambda u: disk_force_moment("uniform", u)[0] - weight / GRIP, 1e-9, 1e6,
               xtol=1e-15, rtol=1e-15)  # fmt: skip
    moment = GRIP * RADIUS * disk_force_moment("uniform", u)[1]
    return -math.acos(moment / (weight * lever))


@pytest.mark.parametrize(("mass", "lever"), [(0.3, 0.05), (0.1, 0.2)])
def test_a_rod_in_a_pinch_of_soft_disks_stops_where_the_closed_form_limit_curve_says(mass, lever):
    settling = settle(PINCH, gravity(mass, lever), (0.0, 0.0, 0.0))
    assert settling.stopped and settling.reason == INSIDE
    assert settling.pose[2] == pytest.approx(exact_stop(mass, lever), abs=1e-9)
    assert settling.safety_factors[-1] == pytest.approx(1.0, abs=1e-9)
    assert np.all(settling.safety_factors[:-1] < 1.0)
    assert np.all(np.diff(settling.poses[:, 2]) < 0.0)  # it droops all the way
    assert np.all(np.diff(settling.distance) > 0.0)


@pytest.mark.parametrize(("mass", "lever"), [(0.3, 0.05), (0.5, 0.02)])
def test_the_ellipsoid_model_stops_the_rod_where_its_ellipse_meets_the_load(mass, lever):
    # Table 2 ellipsoid of a uniform disk: (f / mu 2N)^2 + (m / (mu 2N rho))^2 = 1, rho = 2a/3.
    weight, rho = mass * GRAVITY, 2 * RADIUS / 3
    expected = -math.acos(GRIP * rho * math.sqrt(1 - (weight / GRIP) ** 2) / (weight * lever))
    settling = settle(Ellipsoid.from_limit_surface(PINCH), gravity(mass, lever), (0.0, 0.0, 0.0))
    assert settling.stopped
    assert settling.pose[2] == pytest.approx(expected, abs=1e-9)


def test_a_part_on_two_point_supports_pivots_about_one_of_them_until_the_load_is_held():
    # Points at (±b, 0) carrying mu N / 2 each. Rotation about (b, 0) drags the other point
    # along -y, so its friction force is (0, -mu N / 2) and the facet is the set of loads
    # (f1x, f1y - mu N/2, b f1y + b mu N/2) with |f1| <= mu N/2: a load (0, -F, m) lies on it
    # when m = b (mu N - F). The moment falls as the part turns: m0 - k θ.
    b, mu, normal, force, m0, k = 0.02, 0.4, 10.0, 2.0, 0.2, 0.5
    feet = LimitSurface(pressure.points([(b, 0.0), (-b, 0.0)]), mu=mu, normal_force=normal)
    settling = settle(feet, lambda pose: np.array([0.0, -force, m0 - k * pose[2]]), (0, 0, 0))
    stop = (m0 - b * (mu * normal - force)) / k
    assert settling.stopped
    assert settling.pose[2] == pytest.approx(stop, abs=1e-12)
    # The whole path is a rotation about the support point (b, 0).
    angle = settling.poses[:, 2]
    pivoted = np.column_stack([b - b * np.cos(angle), -b * np.sin(angle)])
    np.testing.assert_allclose(settling.poses[:, :2], pivoted, rtol=0.0, atol=1e-12)


def test_a_load_already_inside_stops_at_once():
    settling = settle(PINCH, gravity(0.05, 0.01), (0.001, 0.002, 0.3))
    assert settling.stopped and settling.reason == INSIDE
    np.testing.assert_array_equal(settling.poses, [[0.001, 0.002, 0.3]])
    np.testing.assert_array_equal(settling.distance, [0.0])
    assert settling.safety_factors[0] > 1.0


def test_a_rod_heavier_than_the_grip_slides_out():
    # The weight alone exceeds 2 mu N: no pose holds it. The rod droops towards vertical (the
    # moment vanishes there) and slides down through the pinch.
    mass = 1.2 * GRIP / GRAVITY
    settling = settle(PINCH, gravity(mass, 0.05), (0.0, 0.0, 0.0), max_distance=0.01)
    assert not settling.stopped and settling.reason == SLID_OUT
    assert settling.distance[-1] == pytest.approx(0.01, rel=1e-12)
    assert np.all(settling.safety_factors < 1.0)
    assert np.all(np.diff(settling.poses[:, 2]) < 0.0) and settling.pose[2] > -math.pi / 2
    assert np.all(np.diff(settling.poses[:, 1]) < 0.0)  # sliding down


def test_a_rod_that_would_turn_past_max_angle_is_reported_so():
    settling = settle(PINCH, gravity(0.3, 0.05), (0.0, 0.0, 0.0), max_angle=0.5)
    assert not settling.stopped and settling.reason == TURNED
    assert settling.pose[2] == pytest.approx(-0.5, abs=1e-12)
    assert settling.safety_factors[-1] < 1.0


def test_settle_rejects_what_has_no_quasi_static_motion():
    with pytest.raises(InvalidArgumentError, match="frictionless"):
        settle(LimitSurface(pressure.disk(RADIUS), mu=0.0), gravity(0.3, 0.05), (0, 0, 0))
    with pytest.raises(InvalidArgumentError, match="load_of_pose"):
        settle(PINCH, [0.0, -1.0, 0.0], (0, 0, 0))
    with pytest.raises(InvalidArgumentError, match="limit-surface interface"):
        settle(object(), gravity(0.3, 0.05), (0, 0, 0))
    with pytest.raises(InvalidArgumentError, match="max_angle"):
        settle(PINCH, gravity(0.3, 0.05), (0, 0, 0), max_angle=0.0)
    with pytest.raises(ModelError, match="no motion map"):
        settle(Cone.from_limit_surface(PINCH), gravity(0.3, 0.05), (0, 0, 0))
