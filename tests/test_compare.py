"""The paper's accuracy claims (§2.4, §4.2, Figs. 3 and 5), reproduced with numbers.

Every number asserted here was computed by fixplan.models.compare and, for the disks of Fig. 3,
checked against the closed forms of DESIGN.md §4, written out below independently of the
library. Radial errors are relative (``e = r_model / r_exact - 1``, ``e > 0`` unsafe); angles
are in radians.
"""

import math

import numpy as np
import pytest
from scipy.special import ellipe, ellipk

from fixplan import LimitSurface, pressure
from fixplan.errors import InvalidArgumentError
from fixplan.models import Cone, Ellipsoid, Exact, FittedEllipsoid, PointCone, PointPyramid, Pyramid
from fixplan.models.compare import Accuracy, accuracy_table, compare, load_directions, radial_errors
from fixplan.tolerances import UNSAFE_RTOL

MU, N, R = 0.5, 2.0, 0.01

#: Tolerance on the asserted numbers: they are maxima over deterministic direction sets, so
#: they reproduce to rounding; 1e-6 absolute leaves room for the solvers' last digits.
NUMBER_ATOL = 1e-6


def _surface(field):
    return LimitSurface(field, mu=MU, normal_force=N)


# -- closed forms of DESIGN.md §4 (per unit mu N; moments per unit mu N R) ---------------------


def _uniform_disk(u):
    """Force and moment of a uniform disk for a centre of rotation at distance u R."""
    if u < 1.0:
        e, k = ellipe(u * u), ellipk(u * u)
        force = 4 / (3 * math.pi * u) * ((1 + u * u) * e - (1 - u * u) * k)
        moment = 4 / (9 * math.pi) * (2 * (2 - u * u) * e - (1 - u * u) * k)
    else:
        e, k = ellipe(1 / u**2), ellipk(1 / u**2)
        force = 4 / (3 * math.pi) * ((1 + u * u) * e - (u * u - 1) * k)
        moment = (
            4 / (9 * math.pi) * (2 * u * (2 - u * u) * e + (u * u - 1) * (2 * u * u - 3) / u * k)
        )
    return force, moment


def _hertz_disk(u):
    """Hertz disk, valid for u <= 1 (where its largest gap to the ellipse lies)."""
    return 3 * math.pi / 32 * u * (4 - u * u), 3 * math.pi / 16 * (1 - u * u + 3 * u**4 / 8)


def _annulus(u, s=0.9):
    """Uniform annulus: the disk of radius R minus the disk of radius sR, weighted by area."""
    outer_f, outer_m = _uniform_disk(u)
    inner_f, inner_m = _uniform_disk(u / s)
    weight = s * s
    return (outer_f - weight * inner_f) / (1 - weight), (outer_m - weight * s * inner_m) / (
        1 - weight
    )


def _closed_form_gap(curve, u_max):
    """Largest relative radial gap between the unit circle and the normalised limit curve."""
    u = np.linspace(1e-4, u_max, 6001)
    u = u[np.abs(u - 1.0) > 1e-9]
    u = u[np.abs(u - 0.9) > 1e-9]  # the inner disk's rim for the annulus
    points = np.array([curve(x) for x in u])
    max_moment = curve(1e-6)[1]  # exact to O(u²)
    radius = np.hypot(points[:, 0], points[:, 1] / max_moment)
    return float(np.max(1.0 / radius - 1.0))


# -- Fig. 3: the ellipse lies close to the normalised limit curves of three disks --------------

FIG3 = [
    # profile, field, largest gap (ellipse outside the curve), closed form, range of u
    ("hertz", pressure.disk(R, "hertz"), 0.063830, _hertz_disk, 1.0),
    ("uniform", pressure.disk(R), 0.070429, _uniform_disk, 6.0),
    ("annulus s=0.9", pressure.disk(R, "annulus", inner_radius=0.9 * R), 0.110100, _annulus, 6.0),
]


@pytest.mark.parametrize(("name", "field", "gap", "curve", "u_max"), FIG3, ids=[c[0] for c in FIG3])
def test_ellipse_lies_close_to_the_normalised_limit_curves_of_fig_3(name, field, gap, curve, u_max):
    ls = _surface(field)
    accuracy = compare(Ellipsoid.from_limit_surface(ls), ls, n=720, plane="fy-m")
    assert accuracy.max_overestimate == pytest.approx(gap, abs=2e-6)
    # The ellipse lies outside every curve (it never underestimates) ...
    assert accuracy.max_underestimate <= 1e-12
    assert accuracy.unsafe_fraction > 0.98
    # ... and the same gap follows from the closed forms, independently of fixplan.
    assert _closed_form_gap(curve, u_max) == pytest.approx(gap, abs=2e-6)


def test_fig_3_gap_grows_as_pressure_moves_to_the_rim():
    gaps = [
        compare(
            Ellipsoid.from_limit_surface(_surface(c[1])), _surface(c[1]), n=720, plane="fy-m"
        ).max_overestimate
        for c in FIG3
    ]
    assert gaps == sorted(gaps)
    assert gaps[-1] < 0.111


# -- Fig. 5: the 10:1 rectangle ---------------------------------------------------------------


@pytest.fixture(scope="module")
def rectangle():
    return _surface(pressure.rectangle(10 * R, R))


def test_fx_m_section_of_the_rectangle_bulges_outside_the_ellipse(rectangle):
    accuracy = compare(Ellipsoid.from_limit_surface(rectangle), rectangle, n=720, plane="fx-m")
    assert accuracy.max_overestimate <= UNSAFE_RTOL
    assert accuracy.max_underestimate == pytest.approx(0.039304, abs=NUMBER_ATOL)
    assert accuracy.mean_error == pytest.approx(-0.019208, abs=NUMBER_ATOL)


def test_fy_m_section_of_the_rectangle_is_flattened_inside_the_ellipse(rectangle):
    accuracy = compare(Ellipsoid.from_limit_surface(rectangle), rectangle, n=720, plane="fy-m")
    assert accuracy.max_overestimate == pytest.approx(0.150722, abs=NUMBER_ATOL)
    assert accuracy.max_underestimate <= 1e-12
    assert accuracy.mean_error == pytest.approx(0.086514, abs=NUMBER_ATOL)


def test_longer_rectangles_change_the_sections_little():
    # Paper §2.3: "further increases in the aspect ratio have little effect".
    gaps = []
    for ratio in (10, 20, 40):
        ls = _surface(pressure.rectangle(ratio * R, R))
        gaps.append(compare(Ellipsoid.from_limit_surface(ls), ls, n=720, plane="fy-m"))
    over = [g.max_overestimate for g in gaps]
    assert over == pytest.approx([0.150722, 0.153474, 0.154333], abs=NUMBER_ATOL)


def test_ellipsoid_is_not_conservative_on_the_rectangle(rectangle):
    accuracy = compare(Ellipsoid.from_limit_surface(rectangle), rectangle)
    assert not Ellipsoid.conservative
    assert accuracy.unsafe_fraction == pytest.approx(0.67, abs=1e-9)
    assert accuracy.max_overestimate == pytest.approx(0.150603, abs=NUMBER_ATOL)
    assert accuracy.max_underestimate == pytest.approx(0.039206, abs=NUMBER_ATOL)


SHAPES = {
    "uniform disk": pressure.disk(R),
    "hertz disk": pressure.disk(R, "hertz"),
    "parabolic disk": pressure.disk(R, "parabolic"),
    "annulus s=0.9": pressure.disk(R, "annulus", inner_radius=0.9 * R),
    "thin ring": pressure.disk(R, "ring"),
    "rectangle 10:1": pressure.rectangle(10 * R, R),
    "square": pressure.rectangle(R, R),
    "triangle": pressure.polygon([[0.0, 0.0], [3 * R, 0.0], [0.0, R]]),
    "tactile grid": pressure.grid([0.0, R, 2 * R], [0.0, R], [[1.0, 2.0, 0.5], [0.0, 3.0, 1.0]]),
    "three points": pressure.points([[0.0, 5 * R], [-4.33 * R, -2.5 * R], [4.33 * R, -2.5 * R]]),
    "skewed points": pressure.points([[0.0, 0.0], [4 * R, 0.0], [0.0, 2 * R]], [1, 2, 3]),
    # Frames whose origin is not the centre of pressure.
    "shifted hertz disk": pressure.disk(R, "hertz").shifted(1.5 * R, -0.7 * R),
    "off-centre points": pressure.points(
        [[0.0, 0.0], [4 * R, 0.0], [0.0, 2 * R]], [1, 2, 3], centered=False
    ),
}

CONSERVATIVE = {
    "cone": Cone.from_limit_surface,
    "pyramid k=4 (eq. 11)": Pyramid.from_limit_surface,
    "pyramid k=8": lambda ls: Pyramid.from_limit_surface(ls, facets=8),
}


@pytest.mark.parametrize("shape", list(SHAPES))
def test_cone_and_pyramids_are_conservative_for_every_shape_tested(shape):
    ls = _surface(SHAPES[shape])
    results = {name: compare(build(ls), ls, n=600) for name, build in CONSERVATIVE.items()}
    for name, accuracy in results.items():
        assert accuracy.max_overestimate <= UNSAFE_RTOL, name
        assert accuracy.unsafe_fraction == 0.0, name
    # The cost of safety: the square pyramid gives up more than the octagonal one, which gives
    # up more than the cone.
    means = [results[name].mean_error for name in ("pyramid k=4 (eq. 11)", "pyramid k=8", "cone")]
    assert means == sorted(means) and means[-1] < 0.0


def test_an_untilted_cone_is_unsafe_when_the_pressure_is_skewed():
    ls = _surface(SHAPES["skewed points"])
    accuracy = compare(Cone.from_limit_surface(ls, tilted=False), ls, n=600)
    assert accuracy.max_overestimate > 0.01


# -- the ellipse is good for slip tests, weaker for motion (paper §4.2) -------------------------


@pytest.mark.parametrize(
    ("shape", "radial", "angle", "mean_radial", "mean_angle"),
    [
        ("uniform disk", 0.070429, 0.152592, 0.039699, 0.090315),
        ("rectangle 10:1", 0.150603, 0.415961, 0.041163, 0.149965),
    ],
)
def test_ellipse_normal_error_exceeds_its_radial_error(
    shape, radial, angle, mean_radial, mean_angle
):
    ls = _surface(SHAPES[shape])
    accuracy = compare(Ellipsoid.from_limit_surface(ls), ls)
    assert accuracy.max_error == pytest.approx(radial, abs=NUMBER_ATOL)
    assert accuracy.mean_abs_error == pytest.approx(mean_radial, abs=NUMBER_ATOL)
    assert accuracy.max_motion_angle == pytest.approx(angle, abs=NUMBER_ATOL)
    assert accuracy.mean_motion_angle == pytest.approx(mean_angle, abs=NUMBER_ATOL)
    # The normal (sliding direction) is off by more than twice the radial (slip) error.
    assert accuracy.max_motion_angle > 2 * accuracy.max_overestimate
    assert accuracy.mean_motion_angle > 2 * accuracy.mean_abs_error


def test_fitted_ellipsoid_halves_the_mean_error_of_the_table_2_ellipsoid():
    ls = _surface(SHAPES["uniform disk"])
    fitted = compare(FittedEllipsoid.from_limit_surface(ls), ls)
    assert fitted.max_overestimate == pytest.approx(0.0292, abs=5e-4)
    assert fitted.max_underestimate == pytest.approx(0.0542, abs=5e-4)
    assert fitted.mean_abs_error == pytest.approx(0.0193, abs=5e-4)
    assert (
        fitted.mean_abs_error < 0.5 * compare(Ellipsoid.from_limit_surface(ls), ls).mean_abs_error
    )


def test_exact_model_has_no_error():
    ls = _surface(SHAPES["rectangle 10:1"])
    model = Exact.from_limit_surface(ls)
    accuracy = compare(model, ls, n=400)
    assert max(accuracy.max_overestimate, accuracy.max_underestimate) < 1e-12
    assert accuracy.max_motion_angle < 1e-9


# -- point contacts -------------------------------------------------------------------------------


def test_point_models_are_compared_in_the_force_plane():
    ls = _surface(SHAPES["hertz disk"])
    cone = compare(PointCone.from_limit_surface(ls), ls, n=360)
    assert cone.plane == "fx-fy"
    assert max(cone.max_overestimate, cone.max_underestimate) < 1e-12
    assert cone.max_motion_angle < 1e-6
    inner = compare(PointPyramid.from_limit_surface(ls), ls, n=360)
    outer = compare(PointPyramid.from_limit_surface(ls, inscribed=False), ls, n=360)
    assert inner.max_underestimate == pytest.approx(1 - math.cos(math.pi / 4), abs=1e-12)
    assert inner.max_overestimate <= 1e-12
    assert outer.max_overestimate == pytest.approx(1 / math.cos(math.pi / 4) - 1, abs=1e-12)
    with pytest.raises(InvalidArgumentError, match="point model bears no moment"):
        compare(PointCone.from_limit_surface(ls), ls, plane="fy-m")


# -- the API ---------------------------------------------------------------------------------------


def test_load_directions_are_unit_vectors_in_normalised_coordinates(rectangle):
    units = np.array([rectangle.max_force, rectangle.max_force, rectangle.max_moment])
    for plane in (None, "fx-m", "fy-m", "fx-fy"):
        loads = load_directions(rectangle, 50, plane=plane)
        np.testing.assert_allclose(np.linalg.norm(loads / units, axis=1), 1.0)
    with pytest.raises(InvalidArgumentError, match="plane must be one of"):
        load_directions(rectangle, 10, plane="m-fx")


def test_radial_errors_are_signed(rectangle):
    model = Ellipsoid.from_limit_surface(rectangle)
    loads = np.array([[1.0, 0.0, 0.0], [0.0, 0.5, 0.02], [0.5, 0.0, 0.02]])
    errors = radial_errors(model, rectangle, loads)
    assert errors[0] == pytest.approx(0.0, abs=1e-12)
    assert errors[1] > 0.05 and errors[2] < -0.01


def test_accuracy_table_is_markdown_with_one_row_per_case(rectangle):
    rows = {
        "ellipsoid": compare(Ellipsoid.from_limit_surface(rectangle), rectangle, n=100),
        "cone": compare(Cone.from_limit_surface(rectangle), rectangle, n=100),
    }
    table = accuracy_table(rows).splitlines()
    assert table[0].startswith("| case |") and len(table) == 4
    assert table[3].startswith("| cone |") and table[3].endswith("| - | - |")
    assert isinstance(rows["cone"], Accuracy) and rows["cone"].max_error < 0.0


def test_compare_rejects_what_is_not_a_model_or_a_surface(rectangle):
    with pytest.raises(InvalidArgumentError, match="must be a friction model"):
        compare(rectangle, rectangle)
    with pytest.raises(InvalidArgumentError, match="must be a LimitSurface"):
        compare(Cone.from_limit_surface(rectangle), pressure.disk(R))
