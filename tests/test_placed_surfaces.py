"""Limit surfaces placed in another frame (``LimitSurface.placed``, mirrored poses) and the
exact form of a set of point contacts and exact patches on a plane
(``ContactSetSurface.as_limit_surface``), against the same patches built directly in the
other frame, closed forms of point contacts and the closed form of a part turning about a pin."""

import math

import numpy as np
import pytest

from fixplan import Contact, ContactSetSurface, LimitSurface, pressure
from fixplan.errors import InvalidArgumentError
from fixplan.models import Ellipsoid
from fixplan.motion import slide
from fixplan.surface.geometry import Pose, signed_area
from fixplan.surface.kernels import twist_to_local

RNG = np.random.default_rng(11)
#: A rectangular pad, off its frame's origin (so that a mirror moves it).
PAD = pressure.rectangle(0.03, 0.01).rotated(0.3).shifted(0.002, 0.004)


def random_pose(rng, mirrored):
    return Pose(angle=rng.uniform(-3, 3), offset=tuple(rng.normal(size=2) * 0.05),
                mirrored=mirrored)  # fmt: skip


@pytest.mark.parametrize("mirrors", [(False, False), (False, True), (True, False), (True, True)])
def test_poses_compose_and_move_local_points_as_the_twist_transform_says(mirrors):
    inner, outer = (random_pose(RNG, m) for m in mirrors)
    points = RNG.normal(size=(5, 2)) * 0.02
    np.testing.assert_allclose(
        inner.then(outer).apply(points), outer.apply(inner.apply(points)), rtol=0, atol=1e-16
    )
    # The velocity of a local point under a contact-frame twist, in local axes, against the
    # twist_to_local transform's local twist at that point.
    pose = inner.then(outer)
    twist = RNG.normal(size=3)
    placed = pose.apply(points)
    velocity = twist[:2] + twist[2] * np.stack([-placed[:, 1], placed[:, 0]], axis=1)
    local_velocity = velocity @ pose.rotation  # (R^T v for each row)
    vx, vy, w = twist_to_local(pose) @ twist
    expected = np.stack([vx - w * points[:, 1], vy + w * points[:, 0]], axis=1)
    np.testing.assert_allclose(local_velocity, expected, rtol=0, atol=1e-15)
    assert (w == -twist[2]) == pose.mirrored


def world_polygon(field, pose):
    """``field`` (a polygon) with its frame placed by ``pose``, built as a field of that frame."""
    vertices = pose.apply(field.pose.apply(field.vertices))
    return pressure.polygon(vertices if signed_area(vertices) > 0 else vertices[::-1],
                            centered=False)  # fmt: skip


@pytest.mark.parametrize("mirrored", [False, True])
def test_a_placed_surface_is_the_patch_built_in_the_other_frame(mirrored):
    """Supports, loads, safety factors and motions of a rotated, shifted rectangle placed by a
    (mirrored) pose at twice its normal force: those of the same rectangle built in the other
    frame, to 1e-12; the placed kernel stays compiled (one pose, composed)."""
    pose = random_pose(RNG, mirrored)
    placed = LimitSurface(PAD, mu=0.4, normal_force=3.0).placed(pose, normal_force=6.0)
    direct = LimitSurface(world_polygon(PAD, pose), mu=0.4, normal_force=6.0)
    twists = RNG.normal(size=(100, 3)) * [1.0, 1.0, 30.0]
    np.testing.assert_allclose(placed.support(twists), direct.support(twists), rtol=1e-12)
    np.testing.assert_allclose(placed.load(twists), direct.load(twists), rtol=0, atol=1e-12)
    loads = RNG.normal(size=(100, 3)) * [1.0, 1.0, 0.05]
    motion, safety = placed.motion_and_safety_factor(loads)
    expected_motion, expected_safety = direct.motion_and_safety_factor(loads)
    np.testing.assert_allclose(safety, expected_safety, rtol=1e-12)
    np.testing.assert_allclose(motion, expected_motion, rtol=0, atol=1e-10)
    assert placed.normal_force == 6.0 and placed.mu == 0.4 and placed.field is None
    assert placed._compiled is not None and "placed" in repr(placed)


def test_placed_point_supports_move_their_facets():
    """Point supports placed by a mirrored pose: the points moved, their friction scaled with
    the force, and a load on a facet (the twist turning about a point) found exactly."""
    field = pressure.points([[0.0, 0.0], [0.03, 0.01], [0.01, 0.04]], [1.0, 2.0, 1.0])
    pose = Pose(angle=0.4, offset=(0.1, -0.2), mirrored=True)
    placed = LimitSurface(field, mu=0.5, normal_force=2.0).placed(pose, normal_force=4.0)
    points, friction = placed.point_supports
    np.testing.assert_allclose(points, pose.apply(field.xy), rtol=0, atol=1e-16)
    np.testing.assert_allclose(friction, 0.5 * 4.0 * field.weights, rtol=1e-15)
    # Turning about the first point: the others' friction is the load, the facet holds it.
    x, y = points[0]
    twist = np.array([y, -x, 1.0])
    load = placed.load(twist)
    motion, safety = placed.motion_and_safety_factor(load)
    assert safety == pytest.approx(1.0, rel=1e-12)
    np.testing.assert_allclose(motion / motion[2], twist, rtol=0, atol=1e-9)


def test_placed_surfaces_keep_friction_that_varies_and_none():
    """A patch whose mu varies over it, placed: the same patch built in the other frame with
    mu moved with it (``mu`` is then ``None``); a frictionless one stays frictionless, its
    shape placed."""
    disk = pressure.disk(0.02).shifted(0.005, 0.0)
    pose = Pose(angle=1.0, offset=(0.03, 0.02), mirrored=True)

    def mu(x, y):
        return 0.3 + 5.0 * x + 2.0 * y

    def world_mu(x, y):  # (the local coordinates of a point of the other frame)
        local = (np.stack([x - pose.offset[0], y - pose.offset[1]], axis=-1)) @ pose.rotation
        return mu(local[..., 0], local[..., 1])

    placed = LimitSurface(disk, mu=mu, normal_force=2.0).placed(pose)
    world_disk = pressure.disk(0.02).shifted(*pose.apply(np.array([[0.005, 0.0]]))[0])
    direct = LimitSurface(world_disk, mu=world_mu, normal_force=2.0)
    twists = RNG.normal(size=(20, 3)) * [1.0, 1.0, 30.0]
    np.testing.assert_allclose(placed.support(twists), direct.support(twists), rtol=1e-9)
    assert placed.mu is None
    still = LimitSurface(disk, mu=0.0, normal_force=2.0).placed(pose, normal_force=3.0)
    assert still.frictionless and still.support([1.0, 0.0, 0.0]) == 0.0
    shape = LimitSurface(disk, mu=1.0, normal_force=3.0).placed(pose)
    np.testing.assert_allclose(still.friction_shape.support(twists), shape.support(twists),
                               rtol=1e-14)  # fmt: skip
    with pytest.raises(InvalidArgumentError, match="pose must be a Pose"):
        placed.placed((0.0, 0.0))
    with pytest.raises(InvalidArgumentError, match="below"):
        LimitSurface(disk, mu=0.3, normal_force=2.0).placed(pose, normal_force=1e-200)


def mixed_contacts():
    """A pad below (exact, its x axis turned), a pin below, a pad clamped from above (normal
    ``-z``: its frame mirrored in the plane) and a frictionless locator at the side."""
    return [
        Contact(name="pad", role="support", position=[0.02, 0.01, 0.0], normal=[0, 0, 1],
                mu=0.4, model="exact", patch=PAD, axis=[math.cos(0.5), math.sin(0.5), 0.0]),
        Contact(name="pin", role="support", position=[-0.03, 0.0, 0.0], normal=[0, 0, 1],
                mu=0.3, model="point-cone"),
        Contact(name="top", role="clamp", position=[0.0, -0.02, 0.01], normal=[0, 0, -1],
                mu=0.5, model="exact", patch=PAD, axis=[1.0, 0.0, 0.0]),
        Contact(name="side", role="locator", position=[0.05, 0.0, 0.005], normal=[-1, 0, 0],
                mu=0.0, model="point-cone"),
    ]  # fmt: skip


def test_a_set_of_points_and_exact_patches_is_their_exact_surface():
    """The exact form of a pin and two exact pads (one from above) is the sum of the pads built
    in the part's frame and the pin's closed form, to 1e-13; the set's queries are its."""
    contacts = mixed_contacts()
    surface = ContactSetSurface(contacts, [3.0, 2.0, 4.0, 5.0])
    exact = surface.as_limit_surface()
    pads = [
        LimitSurface(world_polygon(PAD, Pose(angle=0.5, offset=(0.02, 0.01))), mu=0.4,
                     normal_force=3.0),
        LimitSurface(world_polygon(PAD, Pose(offset=(0.0, -0.02), mirrored=True)), mu=0.5,
                     normal_force=4.0),
    ]  # fmt: skip
    pin = np.array([-0.03, 0.0])
    for twist in RNG.normal(size=(30, 3)) * [1.0, 1.0, 30.0]:
        speed = twist[:2] + twist[2] * np.array([-pin[1], pin[0]])
        expected = sum(pad.support(twist) for pad in pads) + 0.3 * 2.0 * np.linalg.norm(speed)
        assert exact.support(twist) == pytest.approx(expected, rel=1e-13)
        assert surface.support(twist) == exact.support(twist)
    np.testing.assert_array_equal(exact.point_supports[0], [pin])
    load = np.array([0.5, -0.3, 0.01])
    motion, safety = surface.motion_and_safety_factor(load)
    assert safety == exact.safety_factor(load)
    np.testing.assert_allclose(motion, exact.motion(load) / np.linalg.norm(exact.motion(load)))


@pytest.mark.parametrize(
    ("change", "forces"),
    [
        ({"top": {"model": "cone"}}, [3.0, 2.0, 4.0, 5.0]),  # (a cone: not smooth)
        ({"top": {"normal": [0.0, 0.1, -1.0]}}, [3.0, 2.0, 4.0, 5.0]),  # (not on the plane)
        ({}, [0.0, 2.0, 0.0, 5.0]),  # (one point alone: no torsional friction)
    ],
)
def test_other_sets_with_patches_have_no_exact_form(change, forces):
    contacts = [
        Contact(**{**{k: getattr(c, k) for k in ("name", "role", "position", "normal", "mu",
                                                  "model", "patch", "axis")},
                   **change.get(c.name, {})})
        for c in mixed_contacts()
    ]  # fmt: skip
    assert ContactSetSurface(contacts, forces).as_limit_surface() is None


#: The pin and the pad's place of the part turning about the pin.
PIN, PAD_AT = np.array([-0.03, 0.0]), np.array([0.02, 0.01])
#: The unit rotation about the pin, and the pad's own twist in it (the velocity at its place).
ABOUT_PIN = np.array([PIN[1], -PIN[0], 1.0])
AT_PAD = np.array([ABOUT_PIN[0] - PAD_AT[1], ABOUT_PIN[1] + PAD_AT[0], 1.0])


def _exact_pad_moment() -> float:
    """The exact pad's friction moment about the pin: the pad built where it lies."""
    pad = LimitSurface(world_polygon(PAD, Pose(offset=tuple(PAD_AT))), mu=0.4, normal_force=0.5)
    return float(pad.support(ABOUT_PIN))


def _ellipsoid_pad_moment() -> float:
    """The ellipsoid pad's: ``N sqrt(u^T A^-1 u)`` at its own twist ``u``."""
    matrix = Ellipsoid.from_limit_surface(LimitSurface(PAD, mu=0.4, normal_force=1.0)).load_matrix
    return float(0.5 * np.sqrt(AT_PAD @ np.linalg.solve(matrix, AT_PAD)))


@pytest.mark.parametrize(
    ("model", "moment"), [("exact", _exact_pad_moment), ("ellipsoid", _ellipsoid_pad_moment)]
)
def test_a_part_turning_about_a_pin_beside_a_pad_stops_as_the_closed_form_says(model, moment):
    """Turning about a strong pin, a part decelerates by the pad's friction moment about the
    pin, ``M = h_pad(V)`` at the unit rotation about it (the exact pad's, or its Ellipsoid
    model's): it stops at ``ω0 I_pin / M`` having turned ``ω0² I_pin / (2 M)``, its pin still.
    Before, each call of the forward map was a conic solve (and an exact pad its seed
    polytope): such runs ended in a ConvergenceError after 116 s (exact) and 151 s
    (ellipsoid)."""
    contacts = [
        Contact(name="pin", role="support", position=[*PIN, 0.0], normal=[0, 0, 1], mu=0.5,
                model="point-cone"),
        Contact(name="pad", role="support", position=[*PAD_AT, 0.0], normal=[0, 0, 1],
                mu=0.4, model=model, patch=PAD),
    ]  # fmt: skip
    surface = ContactSetSurface(contacts, [20.0, 0.5])
    assert surface.as_limit_surface() is not None
    mass, inertia, spin = 1.0, 1e-3, 3.0
    moved = slide(surface, mass=mass, inertia=inertia, twist0=spin * ABOUT_PIN, duration=1.0)
    turning_inertia = inertia + mass * PIN @ PIN
    assert [index for _, _, index in moved.pivots] == [0]
    # (It is put at rest where its speed falls below STOP_RTOL of the run's speed scale, the
    # 10.2 m/s its friction takes away in 1 s: 3.2e-7 rad/s at the radius of gyration, which
    # it loses in 1.2e-7 s; its angle stands still there to second order.)
    assert moved.stopped == pytest.approx(spin * turning_inertia / moment(), rel=2e-7)
    assert moved.poses[-1, 2] == pytest.approx(spin**2 * turning_inertia / (2 * moment()),
                                               rel=1e-12)  # fmt: skip
    angle = moved.poses[-1, 2]
    turn = np.array([[math.cos(angle), -math.sin(angle)], [math.sin(angle), math.cos(angle)]])
    np.testing.assert_allclose(moved.poses[-1, :2] + turn @ PIN, PIN, rtol=0, atol=1e-12)


def test_an_ellipsoid_surface_is_its_model_in_closed_form():
    """The surface of an Ellipsoid model's set (tilted: the pad's pressure is off its frame's
    origin) at 5 N: supports ``N sqrt(V^T A^-1 V)`` to 1e-14, safety factors the model's to
    1e-13, motions along the ellipsoid's normal ``A L`` (1e-10 rad in normalised coordinates,
    the inverse map's accuracy) and the Hessian the derivative of the load (central differences,
    1e-6)."""
    model = Ellipsoid.from_limit_surface(LimitSurface(PAD, mu=0.4, normal_force=1.0))
    matrix = model.load_matrix
    surface = LimitSurface.ellipsoid(matrix, normal_force=5.0)
    inverse = np.linalg.inv(matrix)
    twists = RNG.normal(size=(20, 3)) * [1.0, 1.0, 30.0]
    closed = 5.0 * np.sqrt(np.einsum("ki,ij,kj->k", twists, inverse, twists))
    np.testing.assert_allclose(surface.support(twists), closed, rtol=1e-14)
    loads = RNG.normal(size=(20, 3)) * [1.0, 1.0, 0.02]
    expected = [model.safety_factor(load, normal_force=5.0) for load in loads]
    np.testing.assert_allclose(surface.safety_factor(loads), expected, rtol=1e-13)
    units = surface.max_force * np.array([1.0, 1.0, surface.characteristic_length])
    motions, normals = surface.motion(loads) * units, loads @ matrix * units  # (normalised)
    sines = np.linalg.norm(np.cross(motions, normals), axis=1)
    assert np.all(
        sines <= 1e-10 * np.linalg.norm(motions, axis=1) * np.linalg.norm(normals, axis=1)
    )
    twist, step = twists[0], 1e-6 * np.linalg.norm(twists[0])
    numeric = np.column_stack([
        (surface.load(twist + step * e) - surface.load(twist - step * e)) / (2 * step)
        for e in np.eye(3)
    ])  # fmt: skip
    np.testing.assert_allclose(surface.support_hessian(twist), numeric, rtol=1e-6, atol=1e-9)
    assert "ellipsoid" in repr(surface)


@pytest.mark.parametrize(
    ("matrix", "message"),
    [
        (np.diag([1.0, 1.0, np.nan]), "finite"),
        (np.array([[1.0, 0.5, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]), "symmetric"),
        (np.diag([1.0, -1.0, 1.0]), "positive definite"),
    ],
)
def test_an_ellipsoid_surface_refuses_a_matrix_that_is_no_ellipsoid(matrix, message):
    with pytest.raises(InvalidArgumentError, match=message):
        LimitSurface.ellipsoid(matrix, normal_force=1.0)


def test_a_placed_tactile_grid_and_a_placed_sum_are_their_parts_built_in_the_other_frame():
    """A tactile grid placed by a mirrored pose is the grid with its rows flipped, turned and
    shifted as a field (1e-13; it stays compiled); a combined surface placed is the sum of its
    parts placed, its point supports moved with them."""
    rng = np.random.default_rng(3)
    x, y = np.linspace(-0.01, 0.01, 9), np.linspace(-0.006, 0.006, 7)
    values = rng.uniform(0.0, 1.0, (7, 9))
    pose = Pose(angle=0.8, offset=(0.05, -0.02), mirrored=True)
    grid = LimitSurface(pressure.grid(x, y, values, centered=False), mu=0.3, normal_force=2.0)
    placed = grid.placed(pose, normal_force=3.0)
    flipped = pressure.grid(x, -y[::-1], values[::-1], centered=False).rotated(0.8)
    direct = LimitSurface(flipped.shifted(0.05, -0.02), mu=0.3, normal_force=3.0)
    twists = rng.normal(size=(30, 3)) * [1.0, 1.0, 50.0]
    np.testing.assert_allclose(placed.support(twists), direct.support(twists), rtol=1e-13)
    loads = rng.normal(size=(30, 3)) * [1.0, 1.0, 0.01]
    np.testing.assert_allclose(placed.safety_factor(loads), direct.safety_factor(loads),
                               rtol=1e-13)  # fmt: skip
    assert placed._compiled is not None
    disk = LimitSurface(pressure.disk(0.01).shifted(0.01, 0.0), mu=0.4, normal_force=1.0)
    points = LimitSurface(pressure.points([[0.0, 0.02], [0.01, -0.02]]), mu=0.2, normal_force=2.0)
    summed = LimitSurface.combine([disk, points]).placed(pose)
    parts = disk.placed(pose).support(twists) + points.placed(pose).support(twists)
    np.testing.assert_allclose(summed.support(twists), parts, rtol=1e-14)
    np.testing.assert_allclose(summed.point_supports[0], pose.apply(points.point_supports[0]),
                               rtol=0, atol=1e-17)  # fmt: skip
