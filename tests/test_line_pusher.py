"""Flat pushers: the face's contact points against brute-force sampling of the outline, two-point
steps against nonnegative least squares over the friction cones' edge wrenches, the frictionless
step against the convex minimum-dissipation program (cvxpy), Lynch & Mason's stable-pushing
condition for a symmetric part, and trajectories that rotate onto the face and ride it."""

import math

import cvxpy as cp
import numpy as np
import pytest
from scipy.optimize import brentq, nnls

from fixplan import Contact, ContactSetSurface, LimitSurface, pressure
from fixplan.errors import InvalidArgumentError
from fixplan.models import Cone, Ellipsoid, Exact
from fixplan.motion import LinePusher, Outline, line_push_step, push

SUPPORT = LimitSurface(pressure.rectangle(0.1, 0.06), mu=0.4, normal_force=5.0)
ELLIPSOID = Ellipsoid.from_limit_surface(SUPPORT)
BLOCK = Outline.rectangle(0.1, 0.06)
SURFACES = {"ellipsoid": ELLIPSOID, "exact": SUPPORT}


def jacobian(point):
    """Velocity of the part point ``point`` per twist (vx, vy, w)."""
    return np.array([[1.0, 0.0, -point[1]], [0.0, 1.0, point[0]]])


def translation_load(surface, velocity):
    """The load on the surface that sustains the translation ``velocity``: for the ellipsoid
    L^T A L = N² the point whose normal A L is parallel to (v, 0); for the exact surface its
    forward map."""
    twist = np.array([velocity[0], velocity[1], 0.0])
    if isinstance(surface, Ellipsoid):
        load = np.linalg.solve(surface.load_matrix, twist)
        return load * surface.normal_force / math.sqrt(load @ surface.load_matrix @ load)
    return surface.load(twist)


def in_cone(wrenches, load):
    """Whether ``load`` is a nonnegative combination of the columns of ``wrenches`` (NNLS)."""
    weights, residual = nnls(wrenches, load)
    return residual <= 1e-9 * np.linalg.norm(load), weights


def edges(normal, mu):
    tangent = np.array([-normal[1], normal[0]])
    return [(normal + side * mu * tangent) / math.hypot(1.0, mu) for side in (1, -1)]


def world_vertices(shape, pose):
    c, s = math.cos(pose[2]), math.sin(pose[2])
    return shape.vertices @ np.array([[c, s], [-s, c]]) + pose[:2]


# -- the face's contact points ---------------------------------------------------------------------

L_SHAPE = Outline.polygon([[0, 0], [0.08, 0], [0.08, 0.02], [0.03, 0.02], [0.03, 0.06], [0, 0.06]])


@pytest.mark.parametrize("shape", [BLOCK, L_SHAPE], ids=["block", "L"])
def test_the_face_touches_the_lowest_points_of_the_outline_within_its_strip(shape):
    # Brute force: 4,001 points along every edge, kept where they lie within the strip.
    rng = np.random.default_rng(5)
    following = np.roll(shape.vertices, -1, axis=0)
    fractions = np.linspace(0.0, 1.0, 4001)[:, None, None]
    boundary = (shape.vertices + fractions * (following - shape.vertices)).reshape(-1, 2)
    for _ in range(40):
        angle = rng.uniform(0, 2 * np.pi)
        normal = np.array([math.cos(angle), math.sin(angle)])
        tangent = np.array([-normal[1], normal[0]])
        centre = rng.uniform(-0.05, 0.1, 2) - 0.12 * normal
        half = rng.uniform(0.005, 0.06)
        found = shape.face_points(centre, normal, half)
        along, level = (boundary - centre) @ tangent, (boundary - centre) @ normal
        strip = np.abs(along) <= half
        if not strip.any():
            assert not len(found.keys)
            continue
        # Sampling resolves the lowest level to a 4000th of an edge times its slope.
        assert found.levels.min() == pytest.approx(level[strip].min(), abs=3e-5)
        assert found.levels.min() <= level[strip].min() + 1e-15
        np.testing.assert_allclose(found.along, (found.points - centre) @ tangent, atol=1e-15)
        assert np.all(np.abs(found.along) <= half * (1 + 1e-12))
        for key, normal_there in zip(found.keys, found.normals, strict=True):
            if key[0] == "vertex":
                np.testing.assert_allclose(normal_there, normal, atol=1e-15)
            else:  # an edge crossing the strip's side: the edge's inward normal
                edge = following[key[1]] - shape.vertices[key[1]]
                np.testing.assert_allclose(normal_there, [-edge[1], edge[0]] / np.linalg.norm(edge),
                                           atol=1e-15)  # fmt: skip


def test_a_face_touches_a_disk_at_its_lowest_point_in_the_strip():
    disk = Outline.disk(0.03)
    # The strip covers the disk's lowest point: it touches there, along the face normal.
    found = disk.face_points([-0.05, 0.01], [1.0, 0.0], 0.02)
    np.testing.assert_allclose(found.points, [[-0.03, 0.0]], atol=1e-15)
    np.testing.assert_allclose(found.normals, [[1.0, 0.0]], atol=1e-15)
    # Beside it: where the face's end meets the circle, y = 0.01 + 0.005, along the radius.
    found = disk.face_points([-0.05, 0.015 + 0.005], [1.0, 0.0], 0.005)
    x = -math.sqrt(0.03**2 - 0.015**2)
    np.testing.assert_allclose(found.points, [[x, 0.015]], atol=1e-15)
    np.testing.assert_allclose(found.normals, [[-x / 0.03, -0.015 / 0.03]], atol=1e-15)
    assert not len(disk.face_points([-0.05, 0.1], [1.0, 0.0], 0.02).keys)


# -- two-point steps ---------------------------------------------------------------------------------

FACE = [[-0.05, -0.03], [-0.05, 0.03]]  # the block's left edge, touched along +x
TWO_POINT_CASES = {
    "sticking": (FACE, [1.0, 0.0], [0.05, 0.01], 0.5),
    "sticking-offset": ([[-0.05, -0.03], [-0.05, 0.005]], [1.0, 0.0], [0.05, -0.004], 0.3),
    "sliding-left": (FACE, [1.0, 0.0], [0.05, 0.04], 0.3),
    "sliding-right": (FACE, [1.0, 0.0], [0.04, -0.05], 0.2),
    "turned-face": ([[0.02, 0.03], [-0.02, 0.03]], [0.0, -1.0], [0.01, -0.05], 0.5),
    "rotating-off": ([[-0.05, 0.01], [-0.05, 0.03]], [1.0, 0.0], [0.05, 0.0], 0.8),
}


def reference_two_point_step(surface, contacts, normal, velocity, mu):
    """Mode and translation of a two-point contact, from the cones of edge wrenches: sticking
    when the load of the pusher's translation lies in the cone of all four; else the
    translation at the pusher's normal speed whose load's force lies on one cone edge (a root
    in its tangential speed), consistent when its load lies in the cone of that edge at both
    points; else ``None`` (the part rotates off)."""
    normal, velocity = np.asarray(normal, float), np.asarray(velocity, float)
    tangent = np.array([-normal[1], normal[0]])
    points = [np.asarray(c, float) for c in contacts]
    cone = np.column_stack([jacobian(c).T @ e for c in points for e in edges(normal, mu)])
    load = translation_load(surface, velocity)
    if in_cone(cone, load)[0]:
        return "sticking", velocity, load
    if in_cone(np.column_stack(edges(normal, mu)), load[:2])[0]:
        return None, None, None  # the force is in the cone, its line misses the segment
    push, own = velocity @ normal, velocity @ tangent
    side = 1 if load[:2] @ tangent > 0 else -1
    edge = edges(normal, mu)[0 if side > 0 else 1]

    def off_edge(s):
        force = translation_load(surface, push * normal + s * tangent)[:2]
        return force[0] * edge[1] - force[1] * edge[0]  # cross(force, edge)

    bracket = (own - 1e3 * push, own) if side > 0 else (own, own + 1e3 * push)
    s = brentq(off_edge, *bracket, xtol=1e-16, rtol=1e-15)
    moving = push * normal + s * tangent
    load = translation_load(surface, moving)
    if in_cone(np.column_stack([jacobian(c).T @ edge for c in points]), load)[0]:
        return ("sliding-left" if side > 0 else "sliding-right"), moving, load
    return None, None, None


@pytest.mark.parametrize("name", SURFACES)
@pytest.mark.parametrize("case", TWO_POINT_CASES)
def test_two_point_steps_agree_with_the_cones_of_edge_wrenches(name, case):
    surface = SURFACES[name]
    contacts, normal, velocity, mu = TWO_POINT_CASES[case]
    mode, moving, load = reference_two_point_step(surface, contacts, normal, velocity, mu)
    assert (mode or "rotating-off") == case.removesuffix("-offset").replace("turned-face",
                                                                             "sticking")  # fmt: skip
    step, bearing = line_push_step(surface, contacts=contacts, normal=normal, velocity=velocity,
                                   mu=mu)  # fmt: skip
    n = np.asarray(normal, float)
    if mode is None:
        # Rotating off: one end bears the push and the other moves away from the face.
        assert len(bearing) == 1 and step.mode != "separated"
        other = next(c for c in contacts if not np.allclose(c, bearing[0]))
        assert n @ jacobian(bearing[0]) @ step.twist == pytest.approx(n @ velocity, rel=1e-9)
        assert n @ jacobian(other) @ step.twist > n @ velocity
        return
    assert step.mode == mode and len(bearing) == 2
    assert surface.safety_factor(step.load) == pytest.approx(1.0, rel=1e-9)  # on the surface
    np.testing.assert_allclose(step.twist, [moving[0], moving[1], 0.0], rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(step.load, load, rtol=1e-9, atol=1e-12 * np.abs(load).max())
    np.testing.assert_allclose(step.force, load[:2], rtol=1e-9)
    tangent = np.array([-n[1], n[0]])
    assert step.slip == pytest.approx(tangent @ (np.asarray(velocity) - moving), abs=1e-12)


def test_a_part_rotating_off_one_end_of_the_face_is_pushed_at_that_end_alone():
    # The segment lies above the centre of friction: pushed along +x the part turns clockwise
    # about its lower end, lifting the upper one. A sticking single-point push on the ellipsoid
    # L^T A L = 1 has the closed form F ∝ (J A J^T)^-1 v, V = A J^T F.
    contacts, normal, velocity, mu = TWO_POINT_CASES["rotating-off"]
    a = ELLIPSOID.load_matrix
    lower = np.array(contacts[0])
    j = jacobian(lower)
    force = np.linalg.solve(j @ a @ j.T, velocity)
    twist = a @ j.T @ force
    assert abs(force[1]) <= mu * force[0]  # sticking at that end
    step, bearing = line_push_step(ELLIPSOID, contacts=contacts, normal=normal,
                                   velocity=velocity, mu=mu)  # fmt: skip
    np.testing.assert_allclose(bearing, [lower])
    assert step.mode == "sticking"
    np.testing.assert_allclose(step.twist, twist, rtol=1e-9)
    assert step.twist[2] < 0.0


@pytest.mark.parametrize(("velocity", "mu"), [([0.05, 0.01], 0.5), ([0.05, 0.04], 0.3)])
def test_a_contact_set_surface_gives_the_step_of_the_planar_surface_of_its_points(velocity, mu):
    # Three support points, as fixture contacts (a conic program per load) and as a planar
    # pressure field (closed forms): the same limit surface by two routes.
    xy = np.array([[0.03, 0.0], [-0.02, 0.025], [-0.02, -0.03]])
    forces = np.array([4.0, 8.0, 6.0])
    contacts = [Contact(name=f"p{k}", role="support", position=[x, y, 0], normal=[0, 0, 1],
                        mu=0.5, model="point-cone") for k, (x, y) in enumerate(xy)]  # fmt: skip
    fixture = ContactSetSurface(contacts, forces, ("fx", "fy", "mz"))
    planar = LimitSurface(pressure.points(xy, forces, centered=False), mu=0.5, normal_force=18.0)
    face = [[-0.04, -0.03], [-0.04, 0.03]]
    steps = [line_push_step(s, contacts=face, normal=[1, 0], velocity=velocity, mu=mu)[0]
             for s in (fixture, planar)]  # fmt: skip
    assert steps[0].mode == steps[1].mode != "separated"
    np.testing.assert_allclose(steps[0].twist, steps[1].twist, rtol=1e-6, atol=1e-9)
    np.testing.assert_allclose(steps[0].load, steps[1].load, rtol=1e-6, atol=1e-9)


# -- frictionless faces --------------------------------------------------------------------------------


def frictionless_reference(surface, contacts, normal, velocity):
    """min h(V) subject to both contact points moving at least with the pusher along the
    normal: the quasi-static twist of a frictionless face (convex; h(V) = sqrt(V^T A^-1 V) for
    the ellipsoid L^T A L <= 1)."""
    factor = np.linalg.cholesky(np.linalg.inv(surface.load_matrix)).T
    twist = cp.Variable(3)
    normal = np.asarray(normal, float)
    push = float(normal @ velocity)
    constraints = [normal @ jacobian(c) @ twist >= push for c in contacts]
    problem = cp.Problem(cp.Minimize(cp.norm(factor @ twist)), constraints)
    problem.solve(solver=cp.CLARABEL, tol_gap_abs=1e-12, tol_gap_rel=1e-12, tol_feas=1e-12)
    assert problem.status == cp.OPTIMAL
    return twist.value


@pytest.mark.parametrize(
    "contacts",
    [FACE, [[-0.05, -0.01], [-0.05, 0.03]], [[-0.05, 0.01], [-0.05, 0.03]],
     [[-0.05, -0.03], [-0.05, -0.02]]],
    ids=["whole-edge", "over-the-centre", "above-the-centre", "below-the-centre"],
)  # fmt: skip
def test_a_frictionless_face_step_is_the_minimum_dissipation_twist(contacts):
    velocity = [0.05, 0.02]
    expected = frictionless_reference(ELLIPSOID, contacts, [1.0, 0.0], velocity)
    step, bearing = line_push_step(ELLIPSOID, contacts=contacts, normal=[1.0, 0.0],
                                   velocity=velocity, mu=0.0)  # fmt: skip
    np.testing.assert_allclose(step.twist, expected, rtol=1e-6, atol=1e-8)
    spans_centre = min(c[1] for c in contacts) <= 0.0 <= max(c[1] for c in contacts)
    assert len(bearing) == (2 if spans_centre else 1)
    assert step.force[1] == pytest.approx(0.0, abs=1e-15) and step.force[0] > 0.0


@pytest.mark.parametrize("name", SURFACES)
@pytest.mark.parametrize("shape", [BLOCK, Outline.disk(0.03)], ids=["block", "disk"])
def test_a_frictionless_flat_pusher_translates_a_symmetric_part_along_its_normal(name, shape):
    # The face pushes along +x while moving obliquely; it reaches the part (left side at
    # x = -0.05 or -0.03) after 0.07 or 0.09 m along x, at 0.05 m/s.
    pusher = LinePusher(([-0.12, 0.0], [0.05, 0.015]), mu=0.0, width=0.2, normal=[1.0, 0.0])
    trajectory = push(SURFACES[name], pusher, shape=shape, duration=3.0, steps=30)
    left = -float(np.abs(shape.vertices).max(initial=shape.radius))
    np.testing.assert_allclose(trajectory.poses[-1], [0.15 - (0.12 + left), 0.0, 0.0], atol=1e-12)
    pressing = trajectory.contact_counts > 0
    assert set(trajectory.contact_counts[pressing]) == {2 if len(shape.vertices) else 1}


def test_a_narrow_face_off_the_centre_of_friction_turns_the_part_off_it():
    # The face meets only the top 20 mm of the block's 60 mm left edge: the push line misses
    # the centre, so the part rotates off the face about the segment's lower end (clockwise)
    # and is then pushed at that end by the face's corner, without passing through the face.
    pusher = LinePusher(([-0.07, 0.02], [0.05, 0.0]), mu=0.3, width=0.02)
    trajectory = push(ELLIPSOID, pusher, shape=BLOCK, duration=1.0, steps=40)
    first = int(np.flatnonzero(trajectory.contact_counts)[0])
    assert trajectory.contact_counts[first] == 1 and trajectory.twists[first][2] < 0.0
    assert trajectory.poses[-1][2] < -0.05
    np.testing.assert_allclose(trajectory.contact_points[first], [-0.05, 0.01], atol=1e-12)
    for t, pose in zip(trajectory.t, trajectory.poses, strict=True):
        levels = (world_vertices(BLOCK, pose) - pusher.position(t)) @ pusher.normal
        along = (world_vertices(BLOCK, pose) - pusher.position(t)) @ pusher.tangent
        assert levels[np.abs(along) <= 0.01].min(initial=np.inf) >= -1e-12


# -- Lynch & Mason's stable pushing ------------------------------------------------------------------


@pytest.mark.parametrize("segment", [(-0.03, 0.03), (-0.03, 0.0)], ids=["whole", "lower-half"])
@pytest.mark.parametrize("angle", [-0.7, -0.5, -0.3, -0.1, 0.0, 0.2, 0.45, 0.6, 0.75])
def test_a_flush_block_sticks_to_the_face_exactly_when_lynch_and_mason_say_it_does(segment, angle):
    # On the ellipsoid of a symmetric rectangle the load of a translation is its force along the
    # velocity through the centre (A diagonal with equal force entries). Stable pushing (the
    # composite friction cone holds it): the direction within the pusher's friction cone,
    # |angle| <= atan(mu), and its line through the centre crossing the contact segment on the
    # face x = -0.05, at y = -0.05 tan(angle). Every angle here is 0.02 rad or more from either
    # boundary.
    mu = 0.8
    crossing = -0.05 * math.tan(angle)
    stable = abs(angle) <= math.atan(mu) and segment[0] <= crossing <= segment[1]
    velocity = 0.05 * np.array([math.cos(angle), math.sin(angle)])
    contacts = [[-0.05, segment[0]], [-0.05, segment[1]]]
    step, bearing = line_push_step(ELLIPSOID, contacts=contacts, normal=[1.0, 0.0],
                                   velocity=velocity, mu=mu)  # fmt: skip
    assert (step.mode == "sticking" and len(bearing) == 2) == stable
    if stable:
        np.testing.assert_allclose(step.twist, [*velocity, 0.0], rtol=1e-12, atol=1e-15)


def test_a_stably_pushed_block_moves_rigidly_with_the_face():
    # Angle 0.3 rad: within the friction cone (atan 0.8 = 0.67) and crossing the whole edge at
    # y = -0.0155: the block, flush from the start, keeps its offset to the face.
    velocity = 0.05 * np.array([math.cos(0.3), math.sin(0.3)])
    pusher = LinePusher(([-0.05, 0.0], velocity), mu=0.8, width=0.1, normal=[1.0, 0.0])
    trajectory = push(ELLIPSOID, pusher, shape=BLOCK, duration=2.0, steps=10)
    assert set(trajectory.modes) == {"sticking"} and set(trajectory.contact_counts) == {2}
    np.testing.assert_allclose(trajectory.poses[:, :2] - trajectory.pusher_positions,
                               np.tile([0.05, 0.0], (11, 1)), atol=1e-15)  # fmt: skip
    np.testing.assert_allclose(trajectory.poses[:, 2], 0.0, atol=1e-15)
    assert trajectory.line_contact_travel() == 0.0


# -- rotating onto the face ------------------------------------------------------------------------


def penetration(trajectory):
    """The deepest any vertex lies behind the face line over the trajectory [m] (0: none)."""
    pusher = trajectory.pusher
    deepest = 0.0
    for t, pose in zip(trajectory.t, trajectory.poses, strict=True):
        offsets = world_vertices(trajectory.shape, pose) - pusher.position(t)
        within = np.abs(offsets @ pusher.tangent) <= pusher.width / 2
        deepest = min(deepest, (offsets @ pusher.normal)[within].min(initial=0.0))
    return -deepest


@pytest.mark.parametrize("name", SURFACES)
def test_a_tilted_block_rotates_onto_a_wide_face_and_then_translates_with_it(name):
    # The block, turned 0.3 rad, is met at its lower left corner; it turns clockwise onto the
    # face (a new contact within a step, found by bisection), then rides flush: sticking, both
    # points pressing, moving with the face. Its edge is then parallel to the face: angle 0 to
    # the bisection's tolerance (a level difference of 2.5e-11 m over the 60 mm edge).
    pusher = LinePusher(([-0.12, 0.0], [0.05, 0.0]), mu=0.3, width=0.2)
    trajectory = push(SURFACES[name], pusher, shape=BLOCK, pose=(0.0, 0.0, 0.3), duration=3.0,
                      steps=60)  # fmt: skip
    assert abs(trajectory.poses[-1][2]) < 1e-9
    assert penetration(trajectory) < 1e-15
    flush = np.flatnonzero(trajectory.contact_counts == 2)
    assert len(flush) >= 10 and np.all(np.diff(flush) == 1) and flush[-1] == 59
    assert {trajectory.modes[k] for k in flush} == {"sticking"}
    moved = np.diff(trajectory.poses[flush[0] :], axis=0)
    np.testing.assert_allclose(moved, np.tile([0.0025, 0.0, 0.0], (len(moved), 1)), atol=1e-12)
    # The travel until flush: the part lay 0.07 m ahead of the face at its first corner.
    assert 0.07 < trajectory.line_contact_travel() < 0.15


def test_the_travel_until_flush_converges_with_the_step():
    # The first step starting flush comes at most one step's travel (0.05 m/s * dt) after the
    # instant the part turns flush, which the finer runs pin down.
    pusher = LinePusher(([-0.12, 0.0], [0.05, 0.0]), mu=0.3, width=0.2)
    travels = {n: push(ELLIPSOID, pusher, shape=BLOCK, pose=(0.0, 0.0, 0.3), duration=3.0,
                       steps=n).line_contact_travel() for n in (30, 120, 480)}  # fmt: skip
    for n in (30, 120):
        assert travels[480] - 1e-5 <= travels[n] <= travels[480] + 0.05 * 3.0 / n + 1e-5


def test_the_line_pusher_integration_converges_to_second_order():
    # Before the flush event (2.2 s) the error falls 4x per halving; through it (3.0 s) the
    # event's time inherits the error of the rotation before it, still at second order overall.
    pusher = LinePusher(([-0.12, 0.0], [0.05, 0.0]), mu=0.3, width=0.2)

    def final(duration, steps):
        return push(ELLIPSOID, pusher, shape=BLOCK, pose=(0.0, 0.0, 0.3), duration=duration,
                    steps=steps).poses[-1]  # fmt: skip

    reference = final(2.2, 400)
    errors = [np.abs(final(2.2, n) - reference).max() for n in (25, 50, 100)]
    assert errors[0] / errors[1] > 3.5 and errors[1] / errors[2] > 3.5
    reference = final(3.0, 800)
    errors = [np.abs(final(3.0, n) - reference).max() for n in (25, 200)]
    assert errors[0] / errors[1] > 8**1.8


# -- arguments ------------------------------------------------------------------------------------------


def test_bad_line_pusher_arguments_are_refused():
    path = ([-0.1, 0.0], [0.05, 0.0])
    for width in (0.0, -0.1, float("nan"), "wide"):
        with pytest.raises(InvalidArgumentError, match="width"):
            LinePusher(path, mu=0.3, width=width)
    with pytest.raises(InvalidArgumentError, match="mu"):
        LinePusher(path, mu=-0.1, width=0.1)
    with pytest.raises(InvalidArgumentError, match="normal"):
        LinePusher(path, mu=0.3, width=0.1, normal=[0.0, 0.0])
    with pytest.raises(InvalidArgumentError, match="normal"):
        LinePusher(path, mu=0.3, width=0.1, normal=[1.0, 0.0, 0.0])
    with pytest.raises(InvalidArgumentError, match="pass normal"):
        LinePusher(([0.0, 0.0], [0.0, 0.0]), mu=0.3, width=0.1)
    with pytest.raises(InvalidArgumentError, match="path"):
        LinePusher(3.0, mu=0.3, width=0.1)
    pusher = LinePusher(path, mu=0.3, width=0.1, normal=[2.0, 0.0])
    np.testing.assert_array_equal(pusher.normal, [1.0, 0.0])
    curve = LinePusher(lambda t: np.array([0.03 * t, 0.04 * t + t**2]), mu=0.3, width=0.1)
    np.testing.assert_allclose(curve.normal, [0.6, 0.8], rtol=1e-9)
    with pytest.raises(InvalidArgumentError, match="PointPusher or a LinePusher"):
        push(SUPPORT, "pusher", shape=BLOCK, duration=1.0, steps=5)
    with pytest.raises(InvalidArgumentError, match="forward map"):
        line_push_step(Cone.from_limit_surface(SUPPORT), contacts=FACE, normal=[1, 0],
                       velocity=[1, 0], mu=0.3)  # fmt: skip
    with pytest.raises(InvalidArgumentError, match="two points apart"):
        line_push_step(SUPPORT, contacts=[[-0.05, 0.0], [-0.05, 0.0]], normal=[1, 0],
                       velocity=[1, 0], mu=0.3)  # fmt: skip
    with pytest.raises(InvalidArgumentError, match="frictionless"):
        line_push_step(LimitSurface(pressure.disk(0.05), mu=0.0), contacts=FACE, normal=[1, 0],
                       velocity=[1, 0], mu=0.3)  # fmt: skip


def test_a_face_moving_away_leaves_the_part_at_rest():
    step, bearing = line_push_step(SUPPORT, contacts=FACE, normal=[1, 0], velocity=[-0.1, 0.2],
                                   mu=0.3)  # fmt: skip
    assert step.mode == "separated" and not len(bearing) and not np.any(step.twist)
    assert step.slip == 0.2


@pytest.mark.parametrize("velocity", [[1.0, 0.0], [1.0, 0.5], [1.0, -0.8]])
def test_the_exact_model_steps_like_its_limit_surface(velocity):
    model = Exact.from_limit_surface(SUPPORT)
    ours, _ = line_push_step(model, contacts=FACE, normal=[1, 0], velocity=velocity, mu=0.3)
    exact, _ = line_push_step(SUPPORT, contacts=FACE, normal=[1, 0], velocity=velocity, mu=0.3)
    assert ours.mode == exact.mode
    np.testing.assert_array_equal(ours.twist, exact.twist)
