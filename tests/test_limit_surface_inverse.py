"""The inverse map and the rest of the LimitSurface API: motion, safety factor, facets of point
supports, containment, curves, samples, Minkowski sums (combine), shapes and bad input.

Requirements proven here: ``motion`` inverts ``load`` (angle below 1e-8 rad away from facets,
safety factor of a load on the surface equal to 1 within 1e-9); loads on a facet of a point
support move by rotation about that point and their safety factor is exact; the safety factor of
*any* load is certified by the independent references (``s L`` is the reference load of the
returned motion); every other method keeps its documented contract.
"""

import math

import numpy as np
import pytest
import reference as ref
from conftest import normalised, random_twists

from fixplan import FixplanError, InvalidArgumentError, LimitSurface, pressure

MOTION_ATOL = 1e-8  # rad
SAFETY_RTOL = 1e-9
#: Facets are exact: only rounding is allowed.
FACET_RTOL = 1e-12


def _angles(surface, motions, twists):
    return ref.angle_between(normalised(surface, motions), normalised(surface, twists))


# -- motion inverts load -------------------------------------------------------------------


def test_motion_inverts_load_for_random_twists(surface, rng):
    twists = random_twists(surface, rng, 40)
    motions, safety = surface.motion_and_safety_factor(surface.load(twists))
    assert np.max(_angles(surface, motions, twists)) <= MOTION_ATOL
    assert np.max(np.abs(safety - 1.0)) <= SAFETY_RTOL


def test_motion_inverts_load_for_translations_and_rotations_about_the_origin(surface):
    twists = np.array(
        [[1.0, 0.0, 0.0], [-0.6, 0.8, 0.0], [0.0, 0.0, 1.0], [0.0, 0.0, -3.0], [0.2, 0.1, 0.0]]
    )
    loads = surface.load(twists)
    motions, safety = surface.motion_and_safety_factor(loads)
    assert np.max(np.abs(safety - 1.0)) <= SAFETY_RTOL
    # Normality: the motion's support plane touches the load. For two supports this is all that
    # holds for a rotation about their centre: every COR on the line through them (the facets of
    # both points included) gives a normal at that load.
    power = np.einsum("ij,ij->i", loads, motions)
    assert np.allclose(power, surface.support(motions), rtol=SAFETY_RTOL, atol=0)
    if len(getattr(surface.field, "xy", ())) != 2:
        assert np.max(_angles(surface, motions, twists)) <= MOTION_ATOL


def test_motion_is_a_unit_twist_in_normalised_coordinates(surface, rng):
    loads = surface.load(random_twists(surface, rng, 10)) * 0.7
    norms = np.linalg.norm(normalised(surface, surface.motion(loads)), axis=1)
    assert np.allclose(norms, 1.0, rtol=0, atol=1e-14)


def test_safety_factor_scales_inversely_with_the_load(surface, rng):
    loads = surface.load(random_twists(surface, rng, 8))
    for factor in (0.25, 3.0):
        assert np.allclose(surface.safety_factor(factor * loads), 1.0 / factor, rtol=SAFETY_RTOL)
        motions = surface.motion(factor * loads)
        assert np.max(_angles(surface, motions, surface.motion(loads))) <= MOTION_ATOL


def test_contains_tells_held_loads_from_sliding_ones(surface, rng):
    loads = surface.load(random_twists(surface, rng, 5))
    for factor, held in [(0.5, True), (1 - 1e-6, True), (1.0, True), (1 + 1e-6, False), (2, False)]:
        assert np.all(surface.contains(factor * loads) == held)


def test_zero_load_is_held_with_infinite_safety_and_no_motion(surface):
    assert surface.safety_factor([0.0, 0.0, 0.0]) == math.inf
    assert surface.contains([0.0, 0.0, 0.0]) is True
    assert np.all(np.isnan(surface.motion([0.0, 0.0, 0.0])))
    translation = surface.load([0.0, 1.0, 0.0])
    batch = surface.safety_factor([[0.0, 0.0, 0.0], translation / 2])
    assert batch[0] == math.inf
    assert batch[1] == pytest.approx(2.0, rel=SAFETY_RTOL)


def test_batch_and_single_queries_agree(rng):
    surface = LimitSurface(pressure.rectangle(0.05, 0.01), mu=0.5, normal_force=2.0)
    twists = random_twists(surface, rng, 2000)
    loads = surface.load(twists)
    assert loads.shape == (2000, 3)
    motions, safety = surface.motion_and_safety_factor(loads)
    assert motions.shape == (2000, 3)
    assert safety.shape == (2000,)
    assert np.max(_angles(surface, motions, twists)) <= MOTION_ATOL
    assert np.max(np.abs(safety - 1.0)) <= SAFETY_RTOL
    for k in (0, 777, 1999):
        assert np.allclose(surface.load(twists[k]), loads[k], rtol=1e-15)
        assert surface.safety_factor(loads[k]) == pytest.approx(safety[k], rel=1e-14)
        assert isinstance(surface.safety_factor(loads[k]), float)
        assert isinstance(surface.support(twists[k]), float)
        assert isinstance(surface.contains(loads[k]), bool)


# -- the safety factor of any load, certified by the references ------------------------------

#: Surfaces with closed-form references: (surface, reference(twist) -> (h, load), size [m]).
CERTIFIED = {
    "uniform disk": (
        lambda: LimitSurface(pressure.disk(0.01), mu=0.5, normal_force=10.0),
        lambda t: ref.closed_form("uniform", t, radius=0.01, mu=0.5, normal_force=10.0),
        0.01,
    ),
    "annulus": (
        lambda: LimitSurface(
            pressure.disk(0.02, "annulus", inner_radius=0.012), mu=0.4, normal_force=5.0
        ),
        lambda t: ref.closed_form(
            "annulus", t, radius=0.02, inner_ratio=0.6, mu=0.4, normal_force=5.0
        ),
        0.02,
    ),
    "ring": (
        lambda: LimitSurface(pressure.disk(0.015, "ring"), mu=0.6, normal_force=3.0),
        lambda t: ref.closed_form("ring", t, radius=0.015, mu=0.6, normal_force=3.0),
        0.015,
    ),
    "rotated shifted rectangle": (
        lambda: LimitSurface(
            pressure.rectangle(0.05, 0.02).rotated(0.4).shifted(0.03, -0.01),
            mu=0.6,
            normal_force=8.0,
        ),
        lambda t: ref.closed_form(
            "rectangle",
            t,
            length=0.05,
            width=0.02,
            angle=0.4,
            offset=(0.03, -0.01),
            mu=0.6,
            normal_force=8.0,
        ),
        0.03,
    ),
    "two fingertips": (
        lambda: LimitSurface.combine(
            [
                LimitSurface(pressure.disk(0.005).shifted(0.03, 0.0), mu=0.5, normal_force=4.0),
                LimitSurface(pressure.rectangle(0.02, 0.01).shifted(-0.03, 0.01), mu=0.3),
            ]
        ),
        lambda t: tuple(
            a + b
            for a, b in zip(
                ref.closed_form(
                    "uniform", t, radius=0.005, offset=(0.03, 0.0), mu=0.5, normal_force=4.0
                ),
                ref.closed_form(
                    "rectangle", t, length=0.02, width=0.01, offset=(-0.03, 0.01), mu=0.3
                ),
                strict=True,
            )
        ),
        0.04,
    ),
}


@pytest.mark.parametrize("name", sorted(CERTIFIED))
def test_safety_factor_and_motion_of_any_load_are_certified_by_the_reference(name, rng):
    """``s L`` must be the reference load of the returned motion: then ``s L`` lies on the
    surface with that motion as its normal, so ``s`` is the safety factor (DESIGN.md §2)."""
    build, reference_of, size = CERTIFIED[name]
    surface = build()
    units = np.array([surface.max_force, surface.max_force, surface.max_moment])
    loads = rng.normal(size=(12, 3)) * units * rng.uniform(0.1, 3.0, size=(12, 1))
    motions, safety = surface.motion_and_safety_factor(loads)
    for load, motion, s in zip(loads, motions, safety, strict=True):
        h_ref, load_ref = reference_of(motion)
        assert ref.relative_error(s * load, load_ref, size) <= SAFETY_RTOL
        assert s * (load @ motion) == pytest.approx(h_ref, rel=SAFETY_RTOL)


# -- point supports: facets ------------------------------------------------------------------

FIVE_XY = np.array([[0.0, 0.0], [0.05, 0.01], [0.02, 0.06], [-0.03, 0.03], [0.01, -0.04]])
FIVE_W = np.array([1.0, 2.0, 0.7, 1.3, 0.5])
SHIFT = np.array([0.02, 0.01])


def _rising_friction(x, y):
    return 0.4 + 3.0 * x + 2.0 * y


def _point_sets():
    """name: (surface, points in the contact frame, their weights, mu, normal force)."""
    triangle = 0.05 * np.array([[0.0, 1.0], [-math.sqrt(0.75), -0.5], [math.sqrt(0.75), -0.5]])
    turned = np.array([[math.cos(1.1), -math.sin(1.1)], [math.sin(1.1), math.cos(1.1)]])
    return {
        "three points (paper Fig. 6)": (
            LimitSurface(pressure.points(triangle), mu=0.5, normal_force=30.0),
            triangle,
            np.ones(3),
            0.5,
            30.0,
        ),
        "two points": (
            LimitSurface(pressure.points(FIVE_XY[:2], [3.0, 1.0], centered=False), mu=0.35),
            FIVE_XY[:2],
            np.array([3.0, 1.0]),
            0.35,
            1.0,
        ),
        "five shifted points": (
            LimitSurface(
                pressure.points(FIVE_XY, FIVE_W, centered=False).shifted(*SHIFT),
                mu=0.45,
                normal_force=7.0,
            ),
            FIVE_XY + SHIFT,
            FIVE_W,
            0.45,
            7.0,
        ),
        "five points with varying mu": (
            LimitSurface(
                pressure.points(FIVE_XY, FIVE_W, centered=False).shifted(*SHIFT),
                mu=_rising_friction,
                normal_force=7.0,
            ),
            FIVE_XY + SHIFT,
            FIVE_W,
            _rising_friction,
            7.0,
        ),
        "five rotated points": (
            LimitSurface(
                pressure.points(FIVE_XY, FIVE_W, centered=False).rotated(1.1),
                mu=0.45,
                normal_force=7.0,
            ),
            FIVE_XY @ turned.T,
            FIVE_W,
            0.45,
            7.0,
        ),
    }


POINT_SETS = _point_sets()


def _limit(xy, weights, mu, normal_force, k):
    """Friction limit [N] of support point ``k``."""
    friction = mu(*xy[k]) if callable(mu) else mu
    return friction * normal_force * weights[k] / np.sum(weights)


def _facet_loads(xy, weights, mu, normal_force, carried):
    """Loads on the facet of every support point and the facet twists.

    ``carried`` lists (fraction of the point's friction limit, direction [rad]) of the force
    the stationary point carries; each point gets them turned by its index.
    """
    loads, twists = [], []
    for k in range(len(xy)):
        limit = _limit(xy, weights, mu, normal_force, k)
        for fraction, angle in carried:
            force = fraction * limit * np.array([math.cos(angle + k), math.sin(angle + k)])
            loads.append(ref.facet_load(xy, weights, k, force, mu=mu, normal_force=normal_force))
            twists.append(ref.twist_about(xy[k]))
    return np.array(loads), np.array(twists)


@pytest.mark.parametrize("name", sorted(POINT_SETS))
def test_load_on_a_facet_moves_by_rotation_about_its_support_point(name):
    surface, xy, weights, mu, normal_force = POINT_SETS[name]
    loads, twists = _facet_loads(
        xy, weights, mu, normal_force, [(0.0, 0.0), (0.5, 2.0), (0.999, 4.0)]
    )
    loads, twists = np.concatenate([loads, -loads]), np.concatenate([twists, -twists])
    motions, safety = surface.motion_and_safety_factor(loads)
    assert np.max(_angles(surface, motions, twists)) <= FACET_RTOL
    assert np.max(np.abs(safety - 1.0)) <= FACET_RTOL
    scaled = surface.safety_factor(
        np.concatenate([0.5 * loads[: len(xy)], 4.0 * loads[-len(xy) :]])
    )
    assert np.allclose(scaled, np.repeat([2.0, 0.25], len(xy)), rtol=FACET_RTOL)


@pytest.mark.parametrize("name", sorted(POINT_SETS))
def test_load_on_the_rim_of_a_facet_has_safety_factor_one(name):
    surface, xy, weights, mu, normal_force = POINT_SETS[name]
    loads, _ = _facet_loads(xy, weights, mu, normal_force, [(1.0, 0.4), (1.0, 2.5), (1.0, 5.0)])
    assert np.allclose(surface.safety_factor(loads), 1.0, rtol=FACET_RTOL)


def test_facets_of_a_combined_surface_are_those_of_its_point_supports():
    disk = LimitSurface(pressure.disk(0.005).shifted(0.04, 0.0), mu=0.5, normal_force=5.0)
    xy = np.array([[-0.03, 0.02], [-0.03, -0.02]])
    points = LimitSurface(pressure.points(xy, centered=False), mu=0.3, normal_force=8.0)
    surface = LimitSurface.combine([disk, points])
    for k in range(2):
        twist = ref.twist_about(xy[k])
        _, disk_load = ref.closed_form(
            "uniform", twist, radius=0.005, offset=(0.04, 0.0), mu=0.5, normal_force=5.0
        )
        for carried in ([0.0, 0.0], [0.5, 0.9], [-1.1, 0.3]):
            facet = disk_load + ref.facet_load(xy, [1, 1], k, carried, mu=0.3, normal_force=8.0)
            motion, safety = surface.motion_and_safety_factor(facet)
            assert safety == pytest.approx(1.0, rel=FACET_RTOL)
            assert _angles(surface, motion, twist) <= FACET_RTOL


@pytest.mark.parametrize("distance", [1e-2, 1e-3, 1e-4])
@pytest.mark.parametrize("name", sorted(POINT_SETS))
def test_loads_near_but_off_a_facet_are_not_taken_for_facet_loads(name, distance):
    """CORs at ``distance`` patch sizes from a support point: the load is on the surface next
    to the facet, so its safety factor is 1 and its motion is the twist (not the facet's)."""
    surface, xy, _, _, _ = POINT_SETS[name]
    size = np.max(np.ptp(xy, axis=0))
    directions = [(math.cos(a), math.sin(a)) for a in np.linspace(0, 2 * math.pi, 8, endpoint=0)]
    twists = np.array(
        [ref.twist_about(p + distance * size * np.array(d)) for p in xy for d in directions]
    )
    motions, safety = surface.motion_and_safety_factor(surface.load(twists))
    assert np.max(np.abs(safety - 1.0)) <= SAFETY_RTOL
    assert np.max(_angles(surface, motions, twists)) <= MOTION_ATOL


def _certify_points(xy, weights, mu, normal_force, load, motion, safety):
    """Check that ``safety * load`` is carried by the points under ``motion``.

    Every moving point slides at its friction limit along its velocity; what is left must be a
    force at the stationary point (if any). Returns the index of the stationary point (or
    ``None``), the force it must carry over its limit (<= 1 when held) and the relative residual
    that no point can carry (0 up to rounding).
    """
    limits = np.array([_limit(xy, weights, mu, normal_force, k) for k in range(len(xy))])
    velocity = np.column_stack([motion[0] - motion[2] * xy[:, 1], motion[1] + motion[2] * xy[:, 0]])
    speed = np.hypot(velocity[:, 0], velocity[:, 1])
    scale = math.hypot(motion[0], motion[1]) + abs(motion[2]) * np.max(np.abs(xy))
    still = speed <= 1e-9 * scale
    forces = limits[:, None] * velocity / np.where(still, np.inf, speed)[:, None]
    moments = xy[:, 0] * forces[:, 1] - xy[:, 1] * forces[:, 0]
    residual = safety * load - np.array([forces[:, 0].sum(), forces[:, 1].sum(), moments.sum()])
    size = np.max(np.abs(xy))
    norm = np.linalg.norm(safety * load * [1, 1, 1 / size])
    if not np.any(still):
        return None, 0.0, np.linalg.norm(residual * [1, 1, 1 / size]) / norm
    k = int(np.flatnonzero(still)[0])
    fx, fy = residual[:2]
    moment_error = abs(residual[2] - (xy[k, 0] * fy - xy[k, 1] * fx)) / size / norm
    return k, math.hypot(fx, fy) / limits[k], moment_error


@pytest.mark.parametrize("name", sorted(POINT_SETS))
def test_random_loads_on_point_supports_have_a_friction_certificate(name, rng):
    """Loads in all directions, many on facets: ``s L`` must be carried by the sliding points at
    their limits plus the stationary point within its limit (the safety factor is then exact)."""
    surface, xy, weights, mu, normal_force = POINT_SETS[name]
    units = np.array([surface.max_force, surface.max_force, surface.max_moment])
    loads = rng.normal(size=(300, 3)) * units
    motions, safety = surface.motion_and_safety_factor(loads)
    on_facets = 0
    for load, motion, s in zip(loads, motions, safety, strict=True):
        point, carried, residual = _certify_points(xy, weights, mu, normal_force, load, motion, s)
        assert carried <= 1.0 + 1e-9
        assert residual <= SAFETY_RTOL
        on_facets += point is not None
    assert on_facets > 0  # the sample did reach facets


# -- curves and samples ----------------------------------------------------------------------

PLANES = {"fx-m": (0, 2), "fy-m": (1, 2), "fx-fy": (0, 1)}


@pytest.mark.parametrize("plane", sorted(PLANES))
def test_curve_points_lie_on_the_surface_evenly_spread_in_angle(surface, plane):
    n = 12
    normal = surface.curve(plane, n, normalized=True)
    units = np.array([surface.max_force, surface.max_force, surface.max_moment])
    assert normal.shape == (n, 3)
    first, second = PLANES[plane]
    assert np.all(normal[:, 3 - first - second] == 0.0)
    assert np.allclose(surface.safety_factor(normal * units), 1.0, rtol=SAFETY_RTOL)
    angles = np.arctan2(normal[:, second], normal[:, first]) % (2 * math.pi)
    assert np.allclose(angles, 2 * math.pi * np.arange(n) / n, rtol=0, atol=1e-12)


def test_normalized_curves_and_samples_are_divided_by_the_maximum_force_and_moment():
    surface = LimitSurface(pressure.rectangle(0.05, 0.01).shifted(0.01, 0.0), mu=0.4)
    units = np.array([surface.max_force, surface.max_force, surface.max_moment])
    for plane in PLANES:
        curve = surface.curve(plane, 10)
        assert np.allclose(surface.curve(plane, 10, normalized=True) * units, curve, rtol=1e-14)
    sample = surface.sample(50)
    assert np.allclose(surface.sample(50, normalized=True) * units, sample, rtol=1e-14)
    assert np.array_equal(sample, surface.sample(50))  # deterministic


def test_limit_curve_of_a_uniform_disk_follows_the_closed_form():
    """Paper Fig. 2: every point of the (fy, m) curve is the closed-form load of its motion."""
    surface = LimitSurface(pressure.disk(0.01), mu=0.5, normal_force=10.0)
    curve = surface.curve("fy-m", 72)
    for point, motion in zip(curve, surface.motion(curve), strict=True):
        _, load = ref.closed_form("uniform", motion, radius=0.01, mu=0.5, normal_force=10.0)
        assert ref.relative_error(point, load, 0.01) <= SAFETY_RTOL
        assert abs(motion[0]) <= 1e-12 * np.linalg.norm(motion[1:])  # COR on the x axis


@pytest.mark.parametrize("plane", ["fx-m", "fy-m"])
def test_limit_curves_of_a_long_rectangle_follow_the_closed_form(plane):
    """Paper Fig. 5: the two extreme cross sections of a 10:1 rectangle."""
    surface = LimitSurface(pressure.rectangle(0.1, 0.01), mu=0.25, normal_force=200.0)
    curve = surface.curve(plane, 36)
    for point, motion in zip(curve, surface.motion(curve), strict=True):
        _, load = ref.closed_form(
            "rectangle", motion, length=0.1, width=0.01, mu=0.25, normal_force=200.0
        )
        assert ref.relative_error(point, load, 0.05) <= SAFETY_RTOL


def test_sample_points_lie_on_the_surface(surface):
    sample = surface.sample(30)
    assert sample.shape == (30, 3)
    assert np.allclose(surface.safety_factor(sample), 1.0, rtol=SAFETY_RTOL)


def test_sample_points_cover_every_direction(rng):
    surface = LimitSurface(pressure.rectangle(0.1, 0.01), mu=0.25, normal_force=200.0)
    sample = surface.sample(300)
    assert np.allclose(surface.safety_factor(sample), 1.0, rtol=SAFETY_RTOL)
    units = np.array([surface.max_force, surface.max_force, surface.max_moment])
    directions = sample / units
    directions /= np.linalg.norm(directions, axis=1, keepdims=True)
    probes = rng.normal(size=(200, 3))
    probes /= np.linalg.norm(probes, axis=1, keepdims=True)
    gaps = ref.angle_between(probes[:, None, :], directions[None, :, :]).min(axis=1)
    assert gaps.max() < 0.25  # rad; an even spread of 300 directions leaves gaps of about 0.12


# -- Minkowski sums ----------------------------------------------------------------------------


def _fingertips():
    return [
        LimitSurface(pressure.disk(0.005, "hertz").shifted(0.03, 0.0), mu=0.5, normal_force=4.0),
        LimitSurface(pressure.disk(0.005, "hertz").shifted(-0.03, 0.0), mu=0.5, normal_force=4.0),
        LimitSurface(pressure.rectangle(0.02, 0.01).rotated(0.3).shifted(0, 0.05), mu=0.2),
    ]


def test_combined_support_and_load_are_the_sums_of_the_parts(rng):
    parts = _fingertips()
    combined = LimitSurface.combine(parts)
    twists = random_twists(combined, rng, 50)
    assert np.allclose(combined.support(twists), sum(p.support(twists) for p in parts), rtol=1e-14)
    assert np.allclose(combined.load(twists), sum(p.load(twists) for p in parts), rtol=1e-13)
    assert combined.max_force == pytest.approx(sum(p.max_force for p in parts), rel=1e-14)
    assert combined.normal_force == pytest.approx(9.0)
    assert combined.parts == tuple(parts)
    assert combined.field is None
    assert combined.mu is None


def test_combined_surface_inverts_its_load(rng):
    combined = LimitSurface.combine(_fingertips())
    twists = random_twists(combined, rng, 40)
    motions, safety = combined.motion_and_safety_factor(combined.load(twists))
    assert np.max(_angles(combined, motions, twists)) <= MOTION_ATOL
    assert np.max(np.abs(safety - 1.0)) <= SAFETY_RTOL


def test_combining_one_surface_gives_the_same_surface(rng):
    single = LimitSurface(pressure.rectangle(0.05, 0.01), mu=0.5, normal_force=3.0)
    combined = LimitSurface.combine([single])
    twists = random_twists(single, rng, 20)
    assert np.allclose(combined.load(twists), single.load(twists), rtol=1e-15)
    loads = single.load(twists) * 0.8
    assert np.allclose(combined.safety_factor(loads), single.safety_factor(loads), rtol=1e-12)


def test_combining_combined_surfaces_is_associative(rng):
    a, b, c = _fingertips()
    left = LimitSurface.combine([LimitSurface.combine([a, b]), c])
    right = LimitSurface.combine([a, LimitSurface.combine([b, c])])
    twists = random_twists(left, rng, 20)
    assert np.allclose(left.load(twists), right.load(twists), rtol=1e-13)


# -- API: shapes, directions, bad input --------------------------------------------------------


def test_load_at_cor_is_the_load_of_the_rotation_about_it(rng):
    surface = LimitSurface(pressure.disk(0.01, "parabolic"), mu=0.5, normal_force=2.0)
    cors = rng.normal(size=(6, 2)) * 0.02
    twists = np.column_stack([cors[:, 1], -cors[:, 0], np.ones(6)])
    assert np.allclose(surface.load_at_cor(cors), surface.load(twists), rtol=1e-15)
    assert np.allclose(surface.load_at_cor(cors, ccw=False), -surface.load(twists), rtol=1e-15)
    assert surface.load_at_cor(cors[0]).shape == (3,)


def _api_inputs():
    surface = LimitSurface(pressure.disk(0.01), mu=0.5)
    field = pressure.disk(0.01)
    return {
        "zero twist": (lambda: surface.load([0.0, 0.0, 0.0]), ["twist", "zero"]),
        "zero twist in a batch": (
            lambda: surface.load([[1.0, 0.0, 0.0], [0.0, 0.0, 0.0]]),
            ["twist[1]", "zero"],
        ),
        "twist of the wrong shape": (lambda: surface.load([[1.0, 2.0]]), ["twist", "(K, 3)"]),
        "NaN twist": (lambda: surface.support([math.nan, 0.0, 1.0]), ["twist", "finite"]),
        "COR of the wrong shape": (lambda: surface.load_at_cor([1.0, 2.0, 3.0]), ["cor"]),
        "infinite load": (lambda: surface.safety_factor([math.inf, 0, 1]), ["load", "finite"]),
        "load of the wrong shape": (lambda: surface.motion([1.0, 2.0]), ["load", "(K, 3)"]),
        "unknown plane": (lambda: surface.curve("xy"), ["plane", "fy-m"]),
        "no curve points": (lambda: surface.curve(n=0), ["n", "positive"]),
        "fractional sample size": (lambda: surface.sample(2.5), ["n", "positive"]),
        "negative mu": (lambda: LimitSurface(field, mu=-0.5), ["mu", ">= 0"]),
        "NaN mu": (lambda: LimitSurface(field, mu=math.nan), ["mu", "finite"]),
        "zero normal force": (
            lambda: LimitSurface(field, mu=0.5, normal_force=0.0),
            ["normal_force", "> 0"],
        ),
        "not a field": (lambda: LimitSurface("disk", mu=0.5), ["field", "pressure field"]),
        "negative friction function": (
            lambda: LimitSurface(pressure.points([[0, 0], [1, 0]]), mu=lambda x, y: x - 5.0),
            ["mu(x, y)", "from 0 to 100"],
        ),
        "combine nothing": (lambda: LimitSurface.combine([]), ["LimitSurface"]),
        "combine a non-surface": (lambda: LimitSurface.combine([field]), ["LimitSurface"]),
    }


API_INPUTS = _api_inputs()


@pytest.mark.parametrize("name", sorted(API_INPUTS))
def test_bad_api_input_raises_an_error_naming_the_argument(name):
    call, words = API_INPUTS[name]
    with pytest.raises(InvalidArgumentError) as caught:
        call()
    assert isinstance(caught.value, FixplanError)
    assert isinstance(caught.value, ValueError)
    for word in words:
        assert word in str(caught.value), f"{word!r} missing from {caught.value}"


def test_two_halves_combined_are_the_whole_rectangle():
    whole = LimitSurface(pressure.rectangle(0.04, 0.01), mu=0.5, normal_force=7.0)
    halves = LimitSurface.combine(
        [
            LimitSurface(pressure.rectangle(0.02, 0.01).shifted(x, 0.0), mu=0.5, normal_force=3.5)
            for x in (-0.01, 0.01)
        ]
    )
    loads = whole.sample(50)
    assert np.max(np.abs(halves.safety_factor(loads) - 1.0)) <= 1e-12


@pytest.mark.parametrize("aspect", [100, 1000])
def test_very_thin_rectangles_invert_near_translation_across_their_long_side(aspect):
    surface = LimitSurface(pressure.rectangle(1.0, 1.0 / aspect), mu=0.5, normal_force=7.0)
    twists = np.array([[0.01, 1.0, 0.2], [-0.02, -1.0, 0.5], [0.0, 1.0, -1.0]])
    motions, safety = surface.motion_and_safety_factor(surface.load(twists))
    assert np.max(np.abs(safety - 1.0)) <= 1e-9
    scale = np.array([1.0, 1.0, surface.characteristic_length])
    a, b = motions * scale, twists * scale
    sine = np.linalg.norm(np.cross(a, b), axis=1) / np.linalg.norm(a, axis=1)
    assert np.max(sine / np.linalg.norm(b, axis=1)) <= 1e-8
