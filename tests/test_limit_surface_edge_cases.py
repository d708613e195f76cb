"""Edge cases of the limit surface's input: empty batches, twists of extreme size, point
supports given twice, skewed weights, friction at one support point, ring-thin annuli."""

from __future__ import annotations

from fractions import Fraction

import numpy as np
import pytest
from conftest import random_twists

from fixplan import InvalidArgumentError, LimitSurface, pressure

#: Twist sizes far beyond where the kernels' squared speeds underflow or overflow (1e±154).
EXTREME_SCALES = [1e-300, 1e-200, 1e-160, 1e160, 1e200, 1e300]

#: Powers of two among them: the twists scale exactly, and so must the answers.
EXACT_SCALES = [2.0**-1000, 2.0**-530, 2.0**530, 2.0**1000]


def test_an_empty_batch_of_loads_gives_empty_answers(surface):
    empty = np.zeros((0, 3))
    for ls in (surface, LimitSurface.combine([surface, surface])):
        assert ls.safety_factor(empty).shape == (0,)
        assert ls.contains(empty).shape == (0,)
        assert ls.contains(empty).dtype == bool
        assert ls.motion(empty).shape == (0, 3)
        motions, safety = ls.motion_and_safety_factor(empty)
        assert motions.shape == (0, 3) and safety.shape == (0,)
        assert ls.support(empty).shape == (0,)
        assert ls.load(empty).shape == (0, 3)


@pytest.mark.parametrize(
    "field",
    [
        pressure.points([[0.0, 0.0], [0.01, 0.0]]),
        pressure.rectangle(0.02, 0.01),
        pressure.disk(0.01, "annulus", inner_radius=0.005),
        pressure.grid([0.0, 0.001], [0.0, 0.001], [[1.0, 2.0], [3.0, 4.0]]),
    ],
    ids=["points", "rectangle", "annulus", "grid"],
)
def test_a_frictionless_surface_answers_an_empty_batch_too(field):
    ls = LimitSurface(field, mu=0.0)
    assert ls.safety_factor(np.zeros((0, 3))).shape == (0,)
    assert ls.motion(np.zeros((0, 3))).shape == (0, 3)


@pytest.mark.parametrize("scale", EXTREME_SCALES)
def test_twists_of_extreme_size_give_the_answers_of_their_direction(surface, rng, scale):
    twists = random_twists(surface, rng, 4)
    # h is homogeneous of degree 1 and its gradient, the load, of degree 0.
    np.testing.assert_allclose(
        surface.support(scale * twists) / scale, surface.support(twists), rtol=1e-13
    )
    expected = surface.load(twists)
    atol = 1e-13 * np.abs(expected).max()
    np.testing.assert_allclose(surface.load(scale * twists), expected, rtol=1e-13, atol=atol)


@pytest.mark.parametrize("scale", EXACT_SCALES)
def test_twists_scaled_by_a_power_of_two_give_exactly_scaled_answers(surface, rng, scale):
    twists = random_twists(surface, rng, 4)
    np.testing.assert_array_equal(surface.support(scale * twists), scale * surface.support(twists))
    np.testing.assert_array_equal(surface.load(scale * twists), surface.load(twists))
    # The Hessian is homogeneous of degree -1.
    np.testing.assert_array_equal(
        surface.support_hessian(scale * twists), surface.support_hessian(twists) / scale
    )


def test_a_subnormal_twist_gives_the_load_of_its_direction():
    ls = LimitSurface(pressure.points([[0.0, 0.0], [0.01, 0.0]]), mu=0.5)
    np.testing.assert_allclose(ls.load([1e-320, 0.0, 0.0]), [0.5, 0.0, 0.0], atol=1e-16)
    assert ls.support([1e-320, 0.0, 0.0]) == pytest.approx(5e-321, rel=1e-2)


@pytest.mark.parametrize("copies", [2, 3, 100])
def test_points_given_twice_have_the_surface_of_the_merged_field(rng, copies):
    xy = [[0.0, 0.0]] * copies + [[0.01, 0.0], [0.0, 0.01]]
    repeated = LimitSurface(pressure.points(xy), mu=0.3, normal_force=2.0)
    merged = LimitSurface(
        pressure.points([[0.0, 0.0], [0.01, 0.0], [0.0, 0.01]], [copies, 1, 1]),
        mu=0.3,
        normal_force=2.0,
    )
    # Loads on the facet of the repeated point raised ConvergenceError on about half of these.
    loads = rng.normal(size=(400, 3)) * merged._units
    motions, safety = repeated.motion_and_safety_factor(loads)
    expected_motions, expected_safety = merged.motion_and_safety_factor(loads)
    np.testing.assert_allclose(safety, expected_safety, rtol=1e-12)
    np.testing.assert_allclose(motions, expected_motions, atol=1e-9)
    twists = random_twists(merged, rng, 20)
    np.testing.assert_allclose(repeated.support(twists), merged.support(twists), rtol=1e-14)


def test_combined_point_sets_sharing_a_point_have_the_surface_of_the_merged_field(rng):
    """Two point sets with a point in common, summed: that point is one support with the friction
    of both (each copy failed its facet test: the inverse map did not converge on 52 of 300
    loads)."""
    first = LimitSurface(pressure.points([[0, 0], [0.1, 0]], centered=False), mu=0.5,
                         normal_force=2.0)  # fmt: skip
    second = LimitSurface(pressure.points([[0, 0], [-0.1, 0.05]], centered=False), mu=0.5,
                          normal_force=2.0)  # fmt: skip
    combined = LimitSurface.combine([first, second])
    merged = LimitSurface(pressure.points([[0, 0], [0.1, 0], [-0.1, 0.05]], [2, 1, 1],
                                          centered=False), mu=0.5, normal_force=4.0)  # fmt: skip
    np.testing.assert_array_equal(combined.point_supports[0], merged.point_supports[0])
    np.testing.assert_allclose(combined.point_supports[1], merged.point_supports[1], rtol=1e-15)
    loads = rng.normal(size=(300, 3)) * merged._units
    motions, safety = combined.motion_and_safety_factor(loads)
    expected_motions, expected_safety = merged.motion_and_safety_factor(loads)
    np.testing.assert_allclose(safety, expected_safety, rtol=1e-12)
    np.testing.assert_allclose(motions, expected_motions, atol=1e-9)


def test_friction_at_a_single_support_point_is_refused():
    field = pressure.points([[0.0, 0.0], [0.01, 0.0], [0.0, 0.01]])
    with pytest.raises(InvalidArgumentError, match="one support point only"):
        LimitSurface(field, mu=lambda x, y: np.where(x > 0.005, 0.5, 0.0))


def test_friction_at_two_of_three_support_points_is_that_of_those_two(rng):
    field = pressure.points([[0.0, 0.0], [0.01, 0.0], [0.0, 0.01]], centered=False)
    varying = LimitSurface(field, mu=lambda x, y: np.where(y > 0.005, 0.0, 0.5))
    pair = LimitSurface(
        pressure.points([[0.0, 0.0], [0.01, 0.0]], centered=False), mu=0.5, normal_force=2 / 3
    )
    loads = rng.normal(size=(50, 3)) * pair._units
    np.testing.assert_allclose(varying.safety_factor(loads), pair.safety_factor(loads), rtol=1e-12)
    on_surface = varying.load([1.0, 1e-12, 0.0])
    assert varying.safety_factor(on_surface) == pytest.approx(1.0, rel=1e-12)


def test_friction_skewed_beyond_the_weight_bound_is_refused():
    field = pressure.points([[0.0, 0.0], [0.01, 0.0], [0.0, 0.01]])
    with pytest.raises(InvalidArgumentError, match="1e-10"):
        LimitSurface(field, mu=lambda x, y: np.where(x > 0.005, 1.0, 1e-12))


def test_points_weighted_at_the_bound_have_a_consistent_inverse_map(rng):
    ratio = pressure.MIN_WEIGHT_RATIO
    field = pressure.points([[0.0, 0.0], [0.01, 0.0], [0.0, 0.01]], [1.0, ratio, ratio])
    ls = LimitSurface(field, mu=0.3)
    loads = ls.load(random_twists(ls, rng, 300))
    np.testing.assert_allclose(ls.safety_factor(loads), 1.0, atol=1e-13)


def test_the_thinnest_annulus_converges_where_a_thinner_one_failed():
    ratio = pressure.MAX_ANNULUS_RATIO
    ls = LimitSurface(pressure.disk(1.0, "annulus", inner_radius=ratio), mu=1.0)
    load = np.array([-0.626210056672238, -0.32431460793888456, 0.7089645505908386])
    motion, safety = ls.motion_and_safety_factor(load)
    assert ls.safety_factor(ls.load(motion)) == pytest.approx(1.0, abs=2e-12)
    assert np.dot(ls.load(motion), load) == pytest.approx(
        np.linalg.norm(ls.load(motion)) * np.linalg.norm(load), rel=1e-12
    )
    assert safety > 0.0


@pytest.mark.parametrize("ratio", [0.5, 0.9, 0.99, pressure.MAX_ANNULUS_RATIO])
def test_annulus_max_moment_is_the_exact_ratio_of_cubes_to_squares(ratio):
    radius = 0.01
    inner = ratio * radius
    ls = LimitSurface(pressure.disk(radius, "annulus", inner_radius=inner), mu=1.0)
    big, small = Fraction(radius), Fraction(inner)
    exact = float(Fraction(2, 3) * (big**3 - small**3) / (big**2 - small**2))
    assert ls.max_moment == pytest.approx(exact, rel=1e-13)


@pytest.mark.parametrize(("mu", "normal_force", "named"), [(0.5, 1e-200, "normal_force"),
                                                           (1e-120, 1.0, "mu \\* normal_force")])  # fmt: skip
def test_friction_forces_where_the_arithmetic_underflows_are_refused(mu, normal_force, named):
    """(A surface of 1e-200 N gave NaN safety factors; 1e-100 N is still exact, scaled.)"""
    with pytest.raises(InvalidArgumentError, match=f"{named} = .* below 1e-100 N"):
        LimitSurface(pressure.disk(0.01), mu=mu, normal_force=normal_force)
    tiny, unit = (LimitSurface(pressure.disk(0.01), mu=1.0, normal_force=f) for f in (1e-100, 1.0))
    load = np.array([0.15, 0.1, 0.001])
    assert tiny.safety_factor(1e-100 * load) == pytest.approx(unit.safety_factor(load), rel=1e-12)
    np.testing.assert_allclose(tiny.motion(1e-100 * load), unit.motion(load), rtol=1e-12)


@pytest.mark.parametrize(
    "field",
    [pressure.disk(0.01), pressure.rectangle(0.02, 0.01), pressure.points([[0, 0], [0.01, 0], [0, 0.01]]),
     pressure.from_function(pressure.disk(0.01), lambda x, y: 1.0 + 50.0 * x)],
    ids=["disk", "rectangle", "points", "function"],
)  # fmt: skip
def test_the_inverse_map_is_homogeneous_for_loads_of_any_finite_size(field):
    # Loads of 1e308 N gave NaN (ZeroDivisionError for function fields), 5e-324 N NaN motions.
    surface = LimitSurface(field, mu=0.3, normal_force=20.0)
    load = np.array([1.0, 0.7, 0.02])
    motion, safety = surface.motion_and_safety_factor(load)
    for scale in (1e308 / 1.01, 1e200, 1e-300):
        scaled_motion, scaled_safety = surface.motion_and_safety_factor(scale * load)
        assert scaled_safety * scale == pytest.approx(safety, rel=1e-14)
        np.testing.assert_allclose(scaled_motion, motion, atol=1e-13)
    tiny = np.array([5e-324, 0.0, 0.0])  # (its safety factor is beyond the floats)
    batch = np.vstack([1e308 * np.ones(3), load, tiny, np.zeros(3)])
    safeties = surface.safety_factor(batch)
    assert np.isfinite(safeties[0]) and safeties[0] > 0.0
    assert safeties[1] == pytest.approx(safety, rel=1e-14)
    assert safeties[2] == np.inf and safeties[3] == np.inf
    np.testing.assert_allclose(surface.motion(tiny), surface.motion([1.0, 0.0, 0.0]), atol=1e-13)
