"""Pushing trajectories: straight pushes, contact made within a step, second-order convergence
of the SE(2) midpoint integration, round parts and callable paths."""

import numpy as np
import pytest

from fixplan import LimitSurface, pressure
from fixplan.errors import InvalidArgumentError
from fixplan.models import Ellipsoid
from fixplan.motion import Outline, PointPusher, push

SUPPORT = LimitSurface(pressure.rectangle(0.1, 0.06), mu=0.4, normal_force=5.0)
ELLIPSOID = Ellipsoid.from_limit_surface(SUPPORT)
BLOCK = Outline.rectangle(0.1, 0.06)


@pytest.mark.parametrize("surface", [SUPPORT, ELLIPSOID], ids=["exact", "ellipsoid"])
def test_a_push_through_the_centre_moves_the_part_straight_by_the_travel_after_contact(surface):
    # The pusher's rim reaches the block's face x = -0.05 after 0.045 m of its 0.1 m of travel.
    pusher = PointPusher(([-0.1, 0.0], [0.05, 0.0]), mu=0.3, radius=0.005)
    trajectory = push(surface, pusher, shape=BLOCK, duration=2.0, steps=40)
    np.testing.assert_allclose(trajectory.poses[-1], [0.055, 0.0, 0.0], atol=1e-12)
    assert trajectory.modes[:17] == ("separated",) * 17 and trajectory.modes[-1] == "sticking"
    assert np.all(np.isnan(trajectory.contact_points[:17]))
    # The contact point of a step is where it is at the step's start: the last begins at x = 0.0525.
    np.testing.assert_allclose(trajectory.contact_points[-1], [0.0525 - 0.05, 0.0], atol=1e-12)
    assert trajectory.forces[-1][0] > 0.0 and trajectory.forces[-1][1] == pytest.approx(0.0)


def test_the_midpoint_integration_converges_to_second_order():
    pusher = PointPusher(([-0.1, 0.015], [0.05, 0.0]), mu=0.3, radius=0.005)
    final = {n: push(ELLIPSOID, pusher, shape=BLOCK, duration=2.0, steps=n).poses[-1]
             for n in (40, 80, 160, 1280)}  # fmt: skip
    errors = [np.abs(final[n] - final[1280]).max() for n in (40, 80, 160)]
    assert errors[0] / errors[1] > 3.5 and errors[1] / errors[2] > 3.5
    assert errors[2] < 1e-5


def test_a_pusher_that_misses_the_part_leaves_it_at_rest():
    pusher = PointPusher(([-0.1, 0.2], [0.05, 0.0]), mu=0.3, radius=0.005)
    trajectory = push(SUPPORT, pusher, shape=BLOCK, pose=(0.01, 0.0, 0.3), duration=1.0, steps=10)
    np.testing.assert_array_equal(trajectory.poses, np.tile([0.01, 0.0, 0.3], (11, 1)))
    assert set(trajectory.modes) == {"separated"}


@pytest.mark.parametrize("offset", [0.0, 0.01, -0.02])
def test_a_frictionless_round_pusher_translates_a_disk_along_the_line_of_centres(offset):
    # On a round part the contact normal passes through its centre, the centre of pressure of
    # the disk support: a frictionless push never turns it.
    disk = LimitSurface(pressure.disk(0.04), mu=0.5, normal_force=3.0)
    pusher = PointPusher(([-0.08, offset], [0.02, 0.0]), mu=0.0, radius=0.01)
    trajectory = push(disk, pusher, shape=Outline.disk(0.04), duration=2.0, steps=50)
    assert np.abs(trajectory.poses[:, 2]).max() < 1e-12
    # The line of centres keeps the part's centre on it: the gap stays the sum of the radii.
    centres = trajectory.poses[:, :2]
    pusher_centres = np.array([pusher.position(t) for t in trajectory.t])
    touching = np.array([mode != "separated" for mode in trajectory.modes])
    gaps = np.linalg.norm(centres[1:] - pusher_centres[1:], axis=1)[touching]
    np.testing.assert_allclose(gaps, 0.05, rtol=1e-6)


def test_a_callable_path_gives_the_straight_path_trajectory():
    line = PointPusher(([-0.1, 0.015], [0.05, 0.0]), mu=0.3, radius=0.005)
    curve = PointPusher(lambda t: np.array([-0.1 + 0.05 * t, 0.015]), mu=0.3, radius=0.005)
    a = push(ELLIPSOID, line, shape=BLOCK, duration=2.0, steps=60)
    b = push(ELLIPSOID, curve, shape=BLOCK, duration=2.0, steps=60)
    np.testing.assert_allclose(a.poses, b.poses, atol=1e-8)


def test_bad_trajectory_arguments_are_refused():
    pusher = PointPusher(([-0.1, 0.0], [0.05, 0.0]), mu=0.3)
    with pytest.raises(InvalidArgumentError, match="steps"):
        push(SUPPORT, pusher, shape=BLOCK, duration=1.0, steps=0)
    with pytest.raises(InvalidArgumentError, match="shape"):
        push(SUPPORT, pusher, shape=[[0, 0], [1, 0], [0, 1]], duration=1.0, steps=5)
    with pytest.raises(InvalidArgumentError, match="path"):
        PointPusher(path=3.0, mu=0.3)
