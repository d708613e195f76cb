"""Pressure fields: constructors, quadrature, centre of pressure (paper eq. 2), poses, bad input."""

import dataclasses
import math

import numpy as np
import pytest

from fixplan import FixplanError, GeometryError, InvalidArgumentError, LimitSurface, pressure

R = 0.02  # disk radius [m]
S = 0.6  # inner radius / radius of the annulus
L_SHAPE = [[0.0, 0.0], [0.03, 0.0], [0.03, 0.01], [0.01, 0.01], [0.01, 0.025], [0.0, 0.025]]
GRID_X = [-0.015, -0.005, 0.005, 0.015]
GRID_Y = [-0.004, 0.0, 0.004]
GRID_VALUES = [[1.0, 2.0, 0.0, 1.0], [0.5, 3.0, 2.0, 1.0], [1.0, 0.0, 1.0, 4.0]]
POINTS_XY = [[0.0, 0.0], [0.04, 0.0], [0.01, 0.03], [-0.02, 0.01]]
POINTS_W = [1.0, 2.0, 0.5, 1.5]


def _bump(x, y):
    """A smooth positive pressure over the disk of radius R and the L shape."""
    return 1.0 + 10.0 * x + 400.0 * y * y


def _polygon_moments(vertices):
    """Area, centroid and central second moments <x²>, <y²> of a polygon (shoelace formulas)."""
    x, y = np.asarray(vertices, dtype=float).T
    xn, yn = np.roll(x, -1), np.roll(y, -1)
    cross = x * yn - xn * y
    area = cross.sum() / 2.0
    cx = ((x + xn) * cross).sum() / (6.0 * area)
    cy = ((y + yn) * cross).sum() / (6.0 * area)
    ixx = ((x * x + x * xn + xn * xn) * cross).sum() / (12.0 * area)
    iyy = ((y * y + y * yn + yn * yn) * cross).sum() / (12.0 * area)
    return area, np.array([cx, cy]), ixx - cx * cx, iyy - cy * cy


def _grid_moments():
    x, y = np.meshgrid(GRID_X, GRID_Y)
    values = np.asarray(GRID_VALUES)
    f = values / values.sum()
    cx, cy = (f * x).sum(), (f * y).sum()
    dx, dy = GRID_X[1] - GRID_X[0], GRID_Y[1] - GRID_Y[0]
    return (
        (f * ((x - cx) ** 2 + dx * dx / 12)).sum(),
        (f * ((y - cy) ** 2 + dy * dy / 12)).sum(),
    )


def _points_moments():
    xy, w = np.asarray(POINTS_XY), np.asarray(POINTS_W) / np.sum(POINTS_W)
    centre = w @ xy
    return w @ (xy[:, 0] - centre[0]) ** 2, w @ (xy[:, 1] - centre[1]) ** 2


_L_AREA, _L_CENTROID, _L_XX, _L_YY = _polygon_moments(L_SHAPE)

#: Every standard field with its exact central second moments (<x²>, <y²>) [m²].
SECOND_MOMENTS = {
    "uniform disk": (lambda: pressure.disk(R), (R * R / 4, R * R / 4)),
    # p ∝ (1 - r²/R²)^a gives <r²> = R²/(a + 2).
    "hertz disk": (lambda: pressure.disk(R, "hertz"), (R * R / 5, R * R / 5)),
    "parabolic disk": (lambda: pressure.disk(R, "parabolic"), (R * R / 6, R * R / 6)),
    "annulus": (
        lambda: pressure.disk(R, "annulus", inner_radius=S * R),
        ((1 + S * S) * R * R / 4, (1 + S * S) * R * R / 4),
    ),
    "ring": (lambda: pressure.disk(R, "ring"), (R * R / 2, R * R / 2)),
    "rectangle": (lambda: pressure.rectangle(0.05, 0.01), (0.05**2 / 12, 0.01**2 / 12)),
    "L-shaped polygon": (lambda: pressure.polygon(L_SHAPE), (_L_XX, _L_YY)),
    "tactile grid": (lambda: pressure.grid(GRID_X, GRID_Y, GRID_VALUES), _grid_moments()),
    "points": (lambda: pressure.points(POINTS_XY, POINTS_W), _points_moments()),
}

#: Fields of every kind, including moved ones and a pressure function.
ALL_FIELDS = {
    **{name: build for name, (build, _) in SECOND_MOMENTS.items()},
    "rotated shifted rectangle": lambda: (
        pressure.rectangle(0.05, 0.01).rotated(0.7).shifted(0.1, -0.02)
    ),
    "pressure function on a disk": lambda: pressure.from_function(pressure.disk(R), _bump),
    "pressure function on a polygon": lambda: pressure.from_function(
        pressure.polygon(L_SHAPE, centered=False), _bump
    ),
}


@pytest.mark.parametrize("name", sorted(ALL_FIELDS))
def test_quadrature_weights_are_positive_and_sum_to_one(name):
    points, weights = ALL_FIELDS[name]().quadrature()
    assert points.shape == (len(weights), 2)
    assert np.all(weights > 0.0)
    assert weights.sum() == pytest.approx(1.0, abs=1e-14)


@pytest.mark.parametrize("name", sorted(ALL_FIELDS))
def test_quadrature_arrays_are_read_only(name):
    points, weights = ALL_FIELDS[name]().quadrature()
    with pytest.raises(ValueError, match="read-only"):
        points[0, 0] = 1.0
    with pytest.raises(ValueError, match="read-only"):
        weights[0] = 1.0


@pytest.mark.parametrize("name", sorted(SECOND_MOMENTS))
def test_quadrature_integrates_second_moments_exactly(name):
    build, (xx, yy) = SECOND_MOMENTS[name]
    points, weights = build().quadrature()
    centre = weights @ points
    assert weights @ (points[:, 0] - centre[0]) ** 2 == pytest.approx(xx, rel=1e-12)
    assert weights @ (points[:, 1] - centre[1]) ** 2 == pytest.approx(yy, rel=1e-12)


@pytest.mark.parametrize("name", sorted(SECOND_MOMENTS))
def test_standard_fields_are_centred_on_their_centre_of_pressure(name):
    field = SECOND_MOMENTS[name][0]()
    assert np.allclose(field.center_of_pressure(), 0.0, atol=1e-15)
    assert np.allclose(field.center_of_pressure(mu=0.3), 0.0, atol=1e-15)


def test_polygon_is_moved_so_that_its_centroid_is_the_origin():
    field = pressure.polygon(L_SHAPE)
    assert np.allclose(field.vertices, np.asarray(L_SHAPE) - _L_CENTROID, atol=1e-15)
    assert field.area == pytest.approx(_L_AREA, rel=1e-14)


def test_polygon_keeps_its_coordinates_when_not_centered():
    field = pressure.polygon(L_SHAPE, centered=False)
    assert np.allclose(field.vertices, L_SHAPE)
    assert np.allclose(field.center_of_pressure(), _L_CENTROID, rtol=1e-13)


@pytest.mark.parametrize("offset", [1.0, 500.0, -999.0])
def test_a_small_polygon_far_from_the_origin_keeps_its_area_and_centroid(offset):
    # A 2 x 1 µm rectangle: shoelace sums about the origin lost its area to cancellation at
    # 500 m ("degenerate: its area is zero"); about its first vertex only the rounding of its
    # coordinates (ulp 1.1e-13 m at 500 m) remains.
    corners = np.array([[0.0, 0.0], [2e-6, 0.0], [2e-6, 1e-6], [0.0, 1e-6]]) + offset
    field = pressure.polygon(corners, centered=False)
    rounding = 4.0 * np.spacing(abs(offset)) / 1e-6
    assert field.area == pytest.approx(2e-12, rel=rounding)
    # (The centre of pressure is a quadrature's weighted sum of points at |offset|: 12 ulp.)
    np.testing.assert_allclose(field.center_of_pressure(), offset + np.array([1e-6, 0.5e-6]),
                               rtol=0.0, atol=16.0 * np.spacing(abs(offset)))  # fmt: skip


def test_clockwise_polygon_gives_the_same_field_as_counter_clockwise():
    ccw = pressure.polygon(L_SHAPE)
    cw = pressure.polygon(L_SHAPE[::-1])
    assert cw.area == pytest.approx(ccw.area, rel=1e-14)
    assert np.allclose(cw.center_of_pressure(), 0.0, atol=1e-15)
    assert sorted(map(tuple, np.round(cw.vertices, 15))) == sorted(
        map(tuple, np.round(ccw.vertices, 15))
    )


def test_rectangle_has_its_long_side_along_x():
    field = pressure.rectangle(0.05, 0.01)
    assert np.ptp(field.vertices[:, 0]) == pytest.approx(0.05)
    assert np.ptp(field.vertices[:, 1]) == pytest.approx(0.01)
    assert field.area == pytest.approx(0.05 * 0.01, rel=1e-14)


def test_points_are_normalised_and_zero_weights_dropped():
    field = pressure.points([[0.0, 0.0], [1.0, 0.0], [5.0, 5.0]], [1.0, 3.0, 0.0], centered=False)
    assert np.allclose(field.xy, [[0.0, 0.0], [1.0, 0.0]])
    assert np.allclose(field.weights, [0.25, 0.75])
    assert np.allclose(field.center_of_pressure(), [0.75, 0.0])


def test_points_given_twice_are_one_support_carrying_both_weights():
    field = pressure.points([[0, 0], [0.01, 0], [0, 0], [-0.0, 0.01], [0, 0.01]], [1, 2, 3, 4, 5])
    merged = pressure.points([[0, 0], [0.01, 0], [0, 0.01]], [4, 2, 9])
    np.testing.assert_array_equal(field.xy, merged.xy)
    np.testing.assert_allclose(field.weights, merged.weights, rtol=1e-15)


def test_point_weights_down_to_the_bound_are_accepted():
    field = pressure.points([[0, 0], [0.01, 0]], [1, pressure.MIN_WEIGHT_RATIO])
    assert field.weights[1] == pytest.approx(pressure.MIN_WEIGHT_RATIO, rel=1e-9)


def test_annulus_up_to_the_bound_is_accepted():
    field = pressure.disk(1.0, "annulus", inner_radius=pressure.MAX_ANNULUS_RATIO)
    assert field.inner_radius == pressure.MAX_ANNULUS_RATIO


def test_points_default_to_equal_weights_and_are_centred():
    field = pressure.points([[0.0, 0.0], [3.0, 0.0], [0.0, 3.0]])
    assert np.allclose(field.weights, 1.0 / 3.0)
    assert np.allclose(field.xy, [[-1.0, -1.0], [2.0, -1.0], [-1.0, 2.0]])


def test_grid_centre_of_pressure_is_the_value_weighted_mean_of_its_cell_centres():
    # Worked by hand from GRID_VALUES: value-weighted means of the cell centres (total 16.5),
    # then the pose (a rotation by 0.4 rad about (0.001, 0.002) and a shift).
    field = pressure.grid(GRID_X, GRID_Y, GRID_VALUES, centered=False)
    values = np.asarray(GRID_VALUES)
    local = np.array([values.sum(axis=0) @ GRID_X, values.sum(axis=1) @ GRID_Y]) / values.sum()
    assert field.center_of_pressure() == pytest.approx(local, rel=1e-14, abs=1e-18)
    posed = field.rotated(0.4, about=(0.001, 0.002)).shifted(0.01, -0.003)
    c, s = math.cos(0.4), math.sin(0.4)
    turned = np.array([[c, -s], [s, c]]) @ (local - [0.001, 0.002]) + [0.011, -0.001]
    assert posed.center_of_pressure() == pytest.approx(turned, rel=1e-14, abs=1e-18)
    assert posed.center_of_pressure(mu=0.4) == pytest.approx(turned, rel=1e-14, abs=1e-18)
    # A position-dependent mu weighs the cells by mu p, by quadrature: here mu = 1 + 20 x, linear
    # over each cell, so its mean over a cell is its value at the centre, and <x mu p> needs the
    # cell's second moment dx²/12 as well.
    dx = GRID_X[1] - GRID_X[0]
    xx, yy = np.meshgrid(GRID_X, GRID_Y)
    weight = values * (1 + 20 * xx)
    x_mean = (np.sum(values * (xx * (1 + 20 * xx) + 20 * dx**2 / 12))) / weight.sum()
    y_mean = np.sum(weight * yy) / weight.sum()
    found = field.center_of_pressure(mu=lambda x, y: 1 + 20 * x)
    assert found == pytest.approx([x_mean, y_mean], rel=1e-13)


def test_grid_quadrature_weights_follow_the_cell_values():
    field = pressure.grid(GRID_X, GRID_Y, GRID_VALUES, centered=False)
    points, weights = field.quadrature()
    dx, dy = GRID_X[1] - GRID_X[0], GRID_Y[1] - GRID_Y[0]
    values = np.asarray(GRID_VALUES)
    for j, y in enumerate(GRID_Y):
        for i, x in enumerate(GRID_X):
            inside = (np.abs(points[:, 0] - x) < dx / 2) & (np.abs(points[:, 1] - y) < dy / 2)
            assert weights[inside].sum() == pytest.approx(values[j, i] / values.sum(), abs=1e-15)


def test_pressure_function_weights_follow_the_function():
    # <x> over the disk with p = 1 + 10 x + 400 y²: ∫x p dA / ∫p dA = 10 R⁴π/4 / (πR² + 100πR⁴).
    field = pressure.from_function(pressure.disk(R), _bump)
    expected = 10.0 * R**4 / 4.0 / (R * R + 100.0 * R**4)
    assert field.center_of_pressure() == pytest.approx([expected, 0.0], rel=1e-13, abs=1e-17)


def test_pressure_function_keeps_the_origin_of_its_shape():
    shape = pressure.polygon(L_SHAPE, centered=False).shifted(0.1, 0.2)
    field = pressure.from_function(shape, lambda x, y: np.ones_like(x))
    assert np.allclose(field.center, [0.1, 0.2])
    assert np.allclose(field.center_of_pressure(), _L_CENTROID + [0.1, 0.2], rtol=1e-13)


def test_friction_weighted_centre_of_pressure_follows_eq_2():
    # Uniform disk, mu = 1 + x/R: x_c = ∫ x (1 + x/R) dA / ∫ (1 + x/R) dA = R/4.
    field = pressure.disk(R)
    cop = field.center_of_pressure(mu=lambda x, y: 1.0 + x / R)
    assert cop == pytest.approx([R / 4.0, 0.0], rel=1e-13, abs=1e-17)


def test_friction_weighted_centre_of_pressure_of_points_is_exact():
    field = pressure.points(POINTS_XY, POINTS_W, centered=False)
    mu = lambda x, y: 0.5 + 10.0 * x + 5.0 * y  # noqa: E731
    xy, w = np.asarray(POINTS_XY), np.asarray(POINTS_W)
    weight = w * mu(xy[:, 0], xy[:, 1])
    assert field.center_of_pressure(mu=mu) == pytest.approx(weight @ xy / weight.sum(), rel=1e-14)


def test_friction_weighted_centre_of_pressure_uses_contact_coordinates():
    # A disk moved to (0.1, 0): mu = x gives x_c = ∫ x² / ∫ x = (0.01 + R²/4) / 0.1.
    field = pressure.disk(R).shifted(0.1, 0.0)
    cop = field.center_of_pressure(mu=lambda x, y: x)
    assert cop == pytest.approx([(0.01 + R * R / 4.0) / 0.1, 0.0], rel=1e-13, abs=1e-17)


@pytest.mark.parametrize("name", sorted(ALL_FIELDS))
def test_shifting_a_field_moves_its_points_and_centre_of_pressure(name):
    field = ALL_FIELDS[name]()
    moved = field.shifted(0.3, -0.1)
    points, weights = field.quadrature()
    moved_points, moved_weights = moved.quadrature()
    assert np.allclose(moved_points, points + [0.3, -0.1], rtol=0, atol=1e-15)
    assert np.array_equal(moved_weights, weights)
    assert np.allclose(moved.center_of_pressure(), field.center_of_pressure() + [0.3, -0.1])


@pytest.mark.parametrize("name", sorted(ALL_FIELDS))
@pytest.mark.parametrize(("angle", "about"), [(0.7, (0.0, 0.0)), (-2.0, (0.05, -0.03))])
def test_rotating_a_field_rotates_its_points_about_a_point(name, angle, about):
    field = ALL_FIELDS[name]()
    turned = field.rotated(angle, about=about)
    c, s = math.cos(angle), math.sin(angle)
    rotation = np.array([[c, -s], [s, c]])
    points, weights = field.quadrature()
    expected = (points - about) @ rotation.T + about
    turned_points, turned_weights = turned.quadrature()
    assert np.allclose(turned_points, expected, rtol=0, atol=1e-15)
    assert np.allclose(turned_weights, weights, rtol=1e-15)
    assert np.allclose(
        turned.center_of_pressure(),
        (field.center_of_pressure() - about) @ rotation.T + about,
        rtol=0,
        atol=1e-15,
    )


def test_moving_a_field_leaves_the_original_unchanged():
    field = pressure.rectangle(0.05, 0.01)
    before = field.quadrature()[0].copy()
    field.shifted(1.0, 1.0).rotated(1.0)
    assert np.array_equal(field.quadrature()[0], before)
    assert np.allclose(field.center, 0.0)


def test_a_full_turn_gives_back_the_same_points():
    field = pressure.polygon(L_SHAPE)
    turned = field.rotated(math.pi).rotated(math.pi)
    assert np.allclose(turned.quadrature()[0], field.quadrature()[0], rtol=0, atol=1e-15)


@pytest.mark.parametrize("name", sorted(ALL_FIELDS))
def test_fields_are_immutable(name):
    field = ALL_FIELDS[name]()
    with pytest.raises(dataclasses.FrozenInstanceError):
        field.pose = None


def test_only_point_sets_are_discrete():
    assert pressure.points(POINTS_XY).is_discrete
    assert not pressure.disk(R).is_discrete
    assert not pressure.grid(GRID_X, GRID_Y, GRID_VALUES).is_discrete


def _inputs():
    disk = pressure.disk(R)
    return {
        # name: (call, exception class, words the message must contain)
        "negative radius": (lambda: pressure.disk(-1.0), InvalidArgumentError, ["radius", "> 0"]),
        "zero radius": (lambda: pressure.disk(0.0), InvalidArgumentError, ["radius", "> 0"]),
        "NaN radius": (lambda: pressure.disk(math.nan), InvalidArgumentError, ["radius", "finite"]),
        "infinite radius": (
            lambda: pressure.disk(math.inf),
            InvalidArgumentError,
            ["radius", "finite"],
        ),
        "unknown profile": (
            lambda: pressure.disk(R, "cone"),
            InvalidArgumentError,
            ["profile", "'hertz'", "'cone'"],
        ),
        "annulus without inner radius": (
            lambda: pressure.disk(R, "annulus"),
            InvalidArgumentError,
            ["inner_radius", "< radius"],
        ),
        "inner radius equal to radius": (
            lambda: pressure.disk(R, "annulus", inner_radius=R),
            InvalidArgumentError,
            ["inner_radius", "< radius"],
        ),
        "inner radius above radius": (
            lambda: pressure.disk(R, "annulus", inner_radius=2 * R),
            InvalidArgumentError,
            ["inner_radius", "< radius"],
        ),
        "negative inner radius": (
            lambda: pressure.disk(R, "annulus", inner_radius=-R / 2),
            InvalidArgumentError,
            ["inner_radius", "> 0"],
        ),
        "inner radius of a Hertz disk": (
            lambda: pressure.disk(R, "hertz", inner_radius=R / 2),
            InvalidArgumentError,
            ["inner_radius", "annulus"],
        ),
        "negative rectangle length": (
            lambda: pressure.rectangle(-0.01, 0.01),
            InvalidArgumentError,
            ["length", "> 0"],
        ),
        "NaN rectangle width": (
            lambda: pressure.rectangle(0.01, math.nan),
            InvalidArgumentError,
            ["width", "finite"],
        ),
        "self-intersecting polygon": (
            lambda: pressure.polygon([[0, 0], [2, 2], [2, 0], [0, 1]]),
            GeometryError,
            ["vertices", "self-intersecting"],
        ),
        "symmetric bowtie polygon": (
            lambda: pressure.polygon([[0, 0], [1, 1], [1, 0], [0, 1]]),
            GeometryError,
            ["vertices", "self-intersecting"],
        ),
        "collinear polygon": (
            lambda: pressure.polygon([[0, 0], [1, 0], [2, 0]]),
            GeometryError,
            ["vertices", "degenerate"],
        ),
        "polygon with two vertices": (
            lambda: pressure.polygon([[0, 0], [1, 0]]),
            GeometryError,
            ["vertices", "at least 3"],
        ),
        "polygon with a repeated vertex": (
            lambda: pressure.polygon([[0, 0], [1, 0], [1, 0], [0, 1]]),
            GeometryError,
            ["vertices", "repeated"],
        ),
        "NaN polygon vertex": (
            lambda: pressure.polygon([[0, 0], [1, math.nan], [0, 1]]),
            InvalidArgumentError,
            ["vertices", "finite"],
        ),
        "empty point set": (
            lambda: pressure.points(np.empty((0, 2))),
            InvalidArgumentError,
            ["xy", "two"],
        ),
        "empty point list": (lambda: pressure.points([]), InvalidArgumentError, ["xy", "(n, 2)"]),
        "single point": (lambda: pressure.points([[0, 0]]), GeometryError, ["two distinct"]),
        "coincident points": (
            lambda: pressure.points([[1, 1], [1, 1]]),
            GeometryError,
            ["two distinct"],
        ),
        "skewed point weights": (
            lambda: pressure.points([[0, 0], [0.01, 0], [0, 0.01]], [1e12, 1e-12, 1e-12]),
            InvalidArgumentError,
            ["weights", "1e-10", "0"],
        ),
        "a point weight of 1e-300": (
            lambda: pressure.points([[0, 0], [0.01, 0]], [1, 1e-300]),
            InvalidArgumentError,
            ["weights", "1e-10"],
        ),
        "annulus thinner than the bound": (
            lambda: pressure.disk(1.0, "annulus", inner_radius=0.9999),
            InvalidArgumentError,
            ["inner_radius", "0.999", "'ring'"],
        ),
        "NaN point": (
            lambda: pressure.points([[0, 0], [math.nan, 1]]),
            InvalidArgumentError,
            ["xy", "finite"],
        ),
        "negative point weight": (
            lambda: pressure.points([[0, 0], [1, 1]], [1, -1]),
            InvalidArgumentError,
            ["weights", ">= 0"],
        ),
        "all-zero point weights": (
            lambda: pressure.points([[0, 0], [1, 1]], [0, 0]),
            InvalidArgumentError,
            ["weights", "zero"],
        ),
        "too many point weights": (
            lambda: pressure.points([[0, 0], [1, 1]], [1, 1, 1]),
            InvalidArgumentError,
            ["weights", "shape"],
        ),
        "all-zero grid": (
            lambda: pressure.grid([0, 1], [0, 1], np.zeros((2, 2))),
            InvalidArgumentError,
            ["values", "zero"],
        ),
        "negative grid value": (
            lambda: pressure.grid([0, 1], [0, 1], [[1, -1], [1, 1]]),
            InvalidArgumentError,
            ["values", ">= 0"],
        ),
        "NaN grid value": (
            lambda: pressure.grid([0, 1], [0, 1], [[1, math.nan], [1, 1]]),
            InvalidArgumentError,
            ["values", "finite"],
        ),
        "unequal grid spacing": (
            lambda: pressure.grid([0, 1, 3], [0, 1], np.ones((2, 3))),
            InvalidArgumentError,
            ["x", "equally spaced"],
        ),
        "single grid column": (
            lambda: pressure.grid([0], [0, 1], np.ones((2, 1))),
            InvalidArgumentError,
            ["x", "at least two"],
        ),
        "disk below a nanometre": (
            lambda: pressure.disk(1e-300),
            InvalidArgumentError,
            ["radius", "at least 1e-09 m", "1e-300"],
        ),
        "polygon below a nanometre": (
            lambda: pressure.polygon([[0, 0], [1e-12, 0], [0, 1e-12]]),
            InvalidArgumentError,
            ["vertices' extent", "at least 1e-09 m"],
        ),
        "grid cells below a nanometre": (
            lambda: pressure.grid([0, 1e-11], [0, 0.01], np.ones((2, 2))),
            InvalidArgumentError,
            ["x: the cells' width must be at least 1e-09 m", "got 1e-11"],
        ),
        "grid of a needle's sides": (
            lambda: pressure.grid([0, 1e-8], [0, 0.01], np.ones((2, 2))),
            InvalidArgumentError,
            ["2e-08 m by 0.02 m", "above 100000"],
        ),
        "points closer than 1e-7 of their span": (
            lambda: pressure.points([[0, 0], [1e-12, 0], [0.01, 0], [0, 0.01]]),
            GeometryError,
            ["xy", "1e-12 m apart", "one point"],
        ),
        "points spanning less than a nanometre": (
            lambda: pressure.points([[0, 0], [1e-300, 0]]),
            GeometryError,
            ["xy: the loaded points' span must be at least 1e-09 m", "got 1e-300"],
        ),
        "rectangle beyond a kilometre": (
            lambda: pressure.rectangle(1e200, 1e200),
            GeometryError,
            ["length must be at most 1000 m", "1e+200"],
        ),
        "disk beyond a kilometre": (
            lambda: pressure.disk(1e10),
            GeometryError,
            ["radius must be at most 1000 m"],
        ),
        "polygon beyond a kilometre from the origin": (
            lambda: pressure.polygon([[1e200, 0], [1e200 + 1, 0], [1e200, 1]], centered=False),
            GeometryError,
            ["vertices must lie within 1000 m of the origin"],
        ),
        "points beyond a kilometre from the origin": (
            lambda: pressure.points([[1e5, 0], [1e5 + 1, 0]]),
            GeometryError,
            ["xy must lie within 1000 m of the origin", "100001.0"],
        ),
        "grid beyond a kilometre from the origin": (
            lambda: pressure.grid([0, 1], [1e4, 1e4 + 1], np.ones((2, 2))),
            GeometryError,
            ["y must lie within 1000 m of the origin"],
        ),
        "field shifted beyond a kilometre": (
            lambda: disk.shifted(0.0, 1e4),
            GeometryError,
            ["placed origin must lie within 1000 m", "10000.0"],
        ),
        "field rotated beyond a kilometre": (
            lambda: disk.rotated(1.0, about=(1e4, 0.0)),
            GeometryError,
            ["placed origin must lie within 1000 m"],
        ),
        "grid values of the wrong shape": (
            lambda: pressure.grid([0, 1], [0, 1], np.ones((3, 2))),
            InvalidArgumentError,
            ["values", "shape"],
        ),
        "pressure function on a Hertz disk": (
            lambda: pressure.from_function(pressure.disk(R, "hertz"), _bump),
            InvalidArgumentError,
            ["shape", "uniform"],
        ),
        "pressure that is not a function": (
            lambda: pressure.from_function(disk, 3.0),
            InvalidArgumentError,
            ["p", "function"],
        ),
        "all-zero pressure function": (
            lambda: pressure.from_function(disk, lambda x, y: 0.0 * x),
            InvalidArgumentError,
            ["p(x, y)", "zero"],
        ),
        "negative pressure function": (
            lambda: pressure.from_function(disk, lambda x, y: x),
            InvalidArgumentError,
            ["p(x, y)", ">= 0"],
        ),
        "NaN shift": (lambda: disk.shifted(math.nan, 0.0), InvalidArgumentError, ["dx", "finite"]),
        "infinite rotation": (
            lambda: disk.rotated(math.inf),
            InvalidArgumentError,
            ["angle", "finite"],
        ),
        "quadrature order zero": (
            lambda: disk.quadrature(0),
            InvalidArgumentError,
            ["order", ">= 1"],
        ),
        "negative friction function": (
            lambda: disk.center_of_pressure(mu=lambda x, y: x - 1.0),
            InvalidArgumentError,
            ["mu(x, y)", "from 0 to 100"],
        ),
        "friction function above the largest mu": (
            lambda: LimitSurface(disk, mu=lambda x, y: 1e300 + 0.0 * x),
            InvalidArgumentError,
            ["mu(x, y)", "from 0 to 100"],
        ),
        "friction function of the wrong shape": (
            lambda: LimitSurface(disk, mu=lambda x, y: np.ones(3)),
            InvalidArgumentError,
            ["mu(x, y) must return real numbers, one per point"],
        ),
        "pressure function of text": (
            lambda: LimitSurface(pressure.from_function(disk, lambda x, y: "high"), mu=0.3),
            InvalidArgumentError,
            ["p(x, y) must return real numbers"],
        ),
        "radius an integer beyond the floats": (
            lambda: pressure.disk(10**400),
            InvalidArgumentError,
            ["radius must be finite", "beyond 1e308"],
        ),
        "vertices with an integer beyond the floats": (
            lambda: pressure.polygon([[0, 0], [10**400, 0], [0, 1]]),
            InvalidArgumentError,
            ["vertices must be an array of finite real numbers"],
        ),
    }


BAD_INPUTS = _inputs()


@pytest.mark.parametrize("name", sorted(BAD_INPUTS))
def test_bad_input_raises_an_error_naming_the_argument_and_its_range(name):
    call, error, words = BAD_INPUTS[name]
    with pytest.raises(error) as caught:
        call()
    assert isinstance(caught.value, FixplanError)
    assert isinstance(caught.value, ValueError)
    message = str(caught.value)
    for word in words:
        assert word in message, f"{word!r} missing from {message!r}"


def test_measurable_weights_drop_an_engines_rim_that_points_refuses():
    """A rim of 1e-15 of the peak (a hydroelastic engine's outer polygons) is refused by
    ``points`` and dropped by ``measurable``; weights at the ratio stay."""
    xy, weights = [[0, 0], [0.01, 0], [0, 0.01]], [1.0, 1e-15, pressure.MIN_WEIGHT_RATIO]
    with pytest.raises(InvalidArgumentError, match="below 1e-10 of the largest"):
        pressure.points(xy, weights)
    np.testing.assert_array_equal(pressure.measurable(weights), [1.0, 0.0, 1e-10])
    np.testing.assert_array_equal(pressure.measurable([1.0, -1e-20]), [1.0, -1e-20])  # refused
    field = pressure.points(xy, pressure.measurable(weights), centered=False)
    np.testing.assert_allclose(field.xy, [[0, 0], [0, 0.01]])
