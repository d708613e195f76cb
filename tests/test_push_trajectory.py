"""Pushing trajectories: straight pushes, contact made within a step, second-order convergence
of the SE(2) midpoint integration, round parts and callable paths."""

import re

import numpy as np
import pytest

from fixplan import Contact, ContactSetSurface, LimitSurface, pressure
from fixplan.errors import GeometryError, InvalidArgumentError
from fixplan.models import Ellipsoid
from fixplan.motion import LinePusher, Outline, PointPusher, push

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


@pytest.mark.parametrize("radius", [0.0, 0.01])
def test_a_round_pusher_never_ends_a_step_inside_the_part(radius):
    """Pushed off-centre with 10 steps of 1 cm, the box turns by almost 1 rad: each step's
    error left the pusher up to 6e-5 m inside it (falling to second order with the steps); the
    part is now moved out along the outline's normal by any overlap, so the pusher stays
    outside to rounding, and the final pose still converges to second order (errors against
    640 steps: 1.3e-4 and 1.8e-4 at 40 steps, 15 times less at 160)."""
    pusher = PointPusher(([-0.051 - radius, 0.02], [0.05, 0.0]), mu=0.3, radius=radius)
    poses = {}
    for steps in (10, 40, 160, 640):
        moved = push(SUPPORT, pusher, shape=BLOCK, duration=2.0, steps=steps)
        for pose, centre in zip(moved.poses, moved.pusher_positions, strict=True):
            turn = np.array([[np.cos(pose[2]), np.sin(pose[2])],
                             [-np.sin(pose[2]), np.cos(pose[2])]])  # fmt: skip
            assert BLOCK.nearest(turn @ (centre - pose[:2]))[2] - radius >= -1e-16
        poses[steps] = moved.poses[-1]
    assert poses[10][2] < -0.9
    errors = [np.abs(poses[steps] - poses[640]).max() for steps in (40, 160)]
    assert errors[0] < 2e-4 and errors[0] / errors[1] > 14


def test_a_round_pusher_wedging_into_a_notch_is_refused_with_time_and_place():
    """A 10 mm pusher driven into a V-notch of a box touches both its faces: its single contact
    does not model that (moved out of one face it went into the other, the part zig-zagging
    step by step; before any put-back it went 11 mm into the part)."""
    notched = Outline.polygon([[-0.05, -0.03], [0.05, -0.03], [0.05, 0.03], [-0.05, 0.03],
                               [-0.05, 0.012], [-0.03, 0.0], [-0.05, -0.012]])  # fmt: skip
    pusher = PointPusher(([-0.07, 0.004], [0.05, 0.003]), mu=0.3, radius=0.01)
    with pytest.raises(GeometryError, match=r"at t = 0\.45 s .* wedges into a notch"):
        push(SUPPORT, pusher, shape=notched, duration=2.0, steps=40)


def test_a_part_on_a_set_of_point_contacts_is_pushed_as_on_their_points():
    """A ContactSetSurface of point contacts is pushed on the LimitSurface of its points (the
    same surface, compiled): 100 steps took 1.46 s of conic solves and ended within 4e-8 m and
    rad of this."""
    places, forces = [[-0.04, -0.02], [0.04, -0.02], [0.0, 0.03]], [1.5, 2.0, 1.4]
    contacts = [
        Contact(name=f"p{i}", role="support", position=np.array([x, y, 0.0]),
                normal=np.array([0.0, 0.0, 1.0]), mu=0.3, model="point-cone")
        for i, (x, y) in enumerate(places)
    ]  # fmt: skip
    surface = ContactSetSurface(contacts, forces)
    pusher = PointPusher(([-0.06, 0.01], [0.02, 0.0]), mu=0.2, radius=0.005)
    shape = Outline.rectangle(0.1, 0.08)
    moved = push(surface, pusher, shape=shape, duration=2.0, steps=100)
    on_points = push(surface.as_limit_surface(), pusher, shape=shape, duration=2.0, steps=100)
    np.testing.assert_array_equal(moved.poses, on_points.poses)
    assert moved.poses[-1][0] > 0.03


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


def _uniform_disk_limits(u: float) -> tuple[float, float]:
    """``(|f| / (mu N), |m| / (mu N R))`` of a uniform disk sliding about a centre of rotation
    ``u R`` from its centre (DESIGN.md §4, complete elliptic integrals of modulus k)."""
    from scipy.special import ellipe, ellipk

    if u <= 1.0:
        e, k = ellipe(u * u), ellipk(u * u)
        force = 4 / (3 * np.pi * u) * ((1 + u * u) * e - (1 - u * u) * k)
        moment = 4 / (9 * np.pi) * (2 * (2 - u * u) * e - (1 - u * u) * k)
    else:
        e, k = ellipe(1 / (u * u)), ellipk(1 / (u * u))
        force = 4 / (3 * np.pi) * ((1 + u * u) * e - (u * u - 1) * k)
        moment = 4 / (9 * np.pi) * (2 * u * (2 - u * u) * e + (u * u - 1) * (2 * u * u - 3) / u * k)
    return force, moment


def _frictionless_face_push(radius, start, speed, start_time, end_time):
    """Independent integration of a square part on a uniform disk pushed on its left face (normal
    +x in the part frame) by a frictionless point moving along world +x: the load is
    F (1, 0, -cy); by symmetry the centre of rotation is (0, y_r) with |m|/|f| = |cy| from the
    closed-form limit curves, the twist (w y_r, 0, w), scaled so that the contact point keeps the
    pusher's speed along the face normal."""
    from scipy.integrate import solve_ivp
    from scipy.optimize import brentq

    def twist(pose, t):
        c, s = np.cos(pose[2]), np.sin(pose[2])
        pusher = np.array([start[0] + speed * t, start[1]])
        local = np.array([[c, s], [-s, c]]) @ (pusher - pose[:2])
        along_normal = c * speed  # the pusher's velocity along the face normal, part frame
        lever = local[1]
        if abs(lever) < 1e-12 * radius:
            return np.array([along_normal, 0.0, 0.0])

        def gap(log_u):
            force, moment = _uniform_disk_limits(np.exp(log_u))
            return radius * moment / force - abs(lever)

        u = np.exp(brentq(gap, -6.0, 6.0, xtol=1e-14))
        y_r = -np.sign(lever) * u * radius  # the part turns away from the pushed side
        w = along_normal / (y_r - lever)
        return np.array([w * y_r, 0.0, w])

    def rate(t, pose):
        body = twist(pose, t)
        c, s = np.cos(pose[2]), np.sin(pose[2])
        return [c * body[0] - s * body[1], s * body[0] + c * body[1], body[2]]

    solution = solve_ivp(rate, (start_time, end_time), [0.0, 0.0, 0.0], rtol=1e-11, atol=1e-13)
    return solution.y[:, -1]


def test_a_frictionless_face_push_on_a_uniform_disk_matches_an_independent_integration():
    # A 80 mm square on a uniform disk of radius 40 mm, pushed 15 mm off centre along x by a
    # frictionless point: the part turns clockwise, the contact first slides towards the middle
    # of the face, then the part turns away (a frictionless point push on a face is unstable).
    # Compared while the contact stays on the face, with a lever of at least a few millimetres
    # (where the closed forms are well conditioned).
    radius, start, speed, end = 0.04, (-0.1, 0.015), 0.05, 2.8
    support = LimitSurface(pressure.disk(radius), mu=0.5, normal_force=2.0)
    pusher = PointPusher((list(start), [speed, 0.0]), mu=0.0)
    shape = Outline.rectangle(0.08, 0.08)
    trajectory = push(support, pusher, shape=shape, duration=end, steps=800)  # error ~1e-6
    expected = _frictionless_face_push(radius, start, speed, (0.1 - 0.04) / speed, end)
    np.testing.assert_allclose(trajectory.poses[-1], expected, atol=2e-6)
    assert expected[2] < -0.5  # it turned clockwise
    levers = []
    for t, pose in zip(trajectory.t, trajectory.poses, strict=True):
        c, s = np.cos(pose[2]), np.sin(pose[2])
        levers.append(np.array([-s, c]) @ (np.array([start[0] + speed * t, start[1]]) - pose[:2]))
    assert (
        min(levers) < 0.4 * 0.015 and max(np.abs(levers)) < 0.04
    )  # towards the middle; on the face


def test_a_point_pusher_trajectory_records_its_pusher_and_single_contacts():
    pusher = PointPusher(([-0.1, 0.0], [0.05, 0.0]), mu=0.3, radius=0.005)
    trajectory = push(SUPPORT, pusher, shape=BLOCK, duration=2.0, steps=40)
    assert trajectory.pusher is pusher and trajectory.shape is BLOCK
    np.testing.assert_allclose(trajectory.pusher_positions,
                               [[-0.1 + 0.05 * t, 0.0] for t in trajectory.t], atol=1e-15)  # fmt: skip
    touching = np.array([mode != "separated" for mode in trajectory.modes])
    np.testing.assert_array_equal(trajectory.contact_counts, touching.astype(int))
    assert trajectory.line_contact_travel() is None


def test_outline_distance_is_negative_exactly_inside_a_star_shaped_outline():
    # Inside or not by the winding number (the angle swept by the vertices seen from the point),
    # independent of the crossing-number test in the outline.
    angles = np.linspace(0.0, 2.0 * np.pi, 201)[:-1]
    radii = 0.05 * (1.0 + 0.4 * np.sin(7 * angles))
    vertices = np.column_stack([radii * np.cos(angles), radii * np.sin(angles)])
    star = Outline.polygon(vertices)
    for point in np.random.default_rng(3).uniform(-0.08, 0.08, (400, 2)):
        seen = np.arctan2(*(vertices - point)[:, ::-1].T)
        turns = np.diff(np.append(seen, seen[0]))
        winding = np.sum((turns + np.pi) % (2 * np.pi) - np.pi) / (2 * np.pi)
        assert (star.nearest(point)[2] < 0.0) == (abs(round(winding)) == 1)


@pytest.mark.parametrize(("start", "radius"), [([-0.06, 0.015], 0.1), ([-0.06, 0.015], 1000.0),
                                               ([-0.045, 0.03], 0.005), ([0.0, 0.0], 0.0)])  # fmt: skip
def test_a_pusher_that_starts_inside_the_part_is_refused_with_its_overlap(start, radius):
    box = Outline.rectangle(0.09, 0.06)
    table = LimitSurface(pressure.rectangle(0.09, 0.06), mu=0.3, normal_force=0.5 * 9.81)
    finger = PointPusher((start, [0.02, 0.0]), mu=0.25, radius=radius)
    with pytest.raises(GeometryError, match=f"radius {radius:g} m .* overlaps the part"):
        push(table, finger, shape=box, duration=1.0, steps=10)


def test_a_flat_pusher_that_starts_inside_the_part_is_refused():
    box = Outline.rectangle(0.09, 0.06)
    table = LimitSurface(pressure.rectangle(0.09, 0.06), mu=0.3, normal_force=0.5 * 9.81)
    face = LinePusher(([-0.04, 0.0], [0.02, 0.0]), mu=0.25, width=0.15)
    with pytest.raises(
        GeometryError, match=r"overlaps the part at pose \(0\.0, 0\.0, 0\.0\) by 0\.005 m"
    ):
        push(table, face, shape=box, duration=1.0, steps=10)


def test_a_round_pusher_allowed_to_start_inside_pushes_as_one_smaller_by_its_overlap():
    # A measured start: the cylinder's rim 2 mm into the box, its centre outside. The push is the
    # one of a pusher of radius 3 mm on the same path, which starts just touching.
    box = Outline.rectangle(0.09, 0.06)
    table = LimitSurface(pressure.rectangle(0.09, 0.06), mu=0.3, normal_force=0.5 * 9.81)
    path = ([-0.048, 0.012], [0.02, 0.003])
    measured = push(table, PointPusher(path, mu=0.25, radius=0.005), shape=box, duration=1.0,
                    steps=50, start_overlap=0.002)  # fmt: skip
    touching = push(table, PointPusher(path, mu=0.25, radius=0.003), shape=box, duration=1.0,
                    steps=50)  # fmt: skip
    assert measured.modes[0] != "separated" and measured.poses[-1][0] > 0.015
    np.testing.assert_allclose(measured.poses, touching.poses, rtol=0.0, atol=1e-15)


def test_a_flat_pusher_allowed_to_start_inside_pushes_as_one_set_back_by_its_overlap():
    box = Outline.rectangle(0.09, 0.06)
    table = LimitSurface(pressure.rectangle(0.09, 0.06), mu=0.3, normal_force=0.5 * 9.81)
    velocity = [0.02, 0.004]
    measured = push(table, LinePusher(([-0.043, 0.01], velocity), mu=0.25, width=0.04,
                                      normal=[1.0, 0.0]),
                    shape=box, duration=1.0, steps=20, start_overlap=0.002)  # fmt: skip
    touching = push(table, LinePusher(([-0.045, 0.01], velocity), mu=0.25, width=0.04,
                                      normal=[1.0, 0.0]),
                    shape=box, duration=1.0, steps=20)  # fmt: skip
    assert measured.poses[-1][0] > 0.015
    np.testing.assert_allclose(measured.poses, touching.poses, rtol=0.0, atol=1e-15)


@pytest.mark.parametrize(("start", "allowed", "refused"), [
    ([-0.048, 0.0], 0.001, "by 0.002 m at t = 0 (more than the start_overlap of 0.001 m)"),
    ([-0.04, 0.0], 1.0, "by 0.01 m at t = 0 (its centre inside the outline)"),
])  # fmt: skip
def test_a_round_pusher_deeper_than_allowed_or_with_its_centre_inside_is_refused(
    start, allowed, refused
):
    box = Outline.rectangle(0.09, 0.06)
    table = LimitSurface(pressure.rectangle(0.09, 0.06), mu=0.3, normal_force=0.5 * 9.81)
    finger = PointPusher((start, [0.02, 0.0]), mu=0.25, radius=0.005)
    with pytest.raises(GeometryError, match=re.escape(refused)):
        push(table, finger, shape=box, duration=1.0, steps=10, start_overlap=allowed)


@pytest.mark.parametrize("allowed", [-1e-3, np.nan, "1 mm"])
def test_a_start_overlap_that_is_no_length_is_refused(allowed):
    finger = PointPusher(([-0.1, 0.0], [0.02, 0.0]), mu=0.25)
    with pytest.raises(InvalidArgumentError, match="start_overlap"):
        push(SUPPORT, finger, shape=BLOCK, duration=1.0, steps=10, start_overlap=allowed)


@pytest.mark.parametrize("start", [[-0.045, 0.03], [-0.03, 0.03], [0.045, -0.03]])
def test_a_point_pusher_moving_along_an_edge_of_the_part_does_not_push_it(start):
    box = Outline.rectangle(0.09, 0.06)
    table = LimitSurface(pressure.rectangle(0.09, 0.06), mu=0.3, normal_force=0.5 * 9.81)
    finger = PointPusher((start, [0.02 if start[1] > 0 else -0.02, 0.0]), mu=0.25)
    pushed = push(table, finger, shape=box, duration=1.0, steps=50)
    assert set(pushed.modes) == {"separated"}
    np.testing.assert_array_equal(pushed.poses, 0.0)
    np.testing.assert_array_equal(pushed.forces, 0.0)


def test_a_point_pusher_at_a_corner_moving_into_the_part_pushes_it():
    box = Outline.rectangle(0.09, 0.06)
    table = LimitSurface(pressure.rectangle(0.09, 0.06), mu=0.3, normal_force=0.5 * 9.81)
    finger = PointPusher(([-0.045, 0.03], [0.02, -0.01]), mu=0.25)
    pushed = push(table, finger, shape=box, duration=1.0, steps=50)
    assert pushed.modes[0] != "separated" and pushed.poses[-1][0] > 0.0
