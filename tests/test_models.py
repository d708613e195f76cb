"""Model-specific analytic cases of fixplan.models (paper §4.2, Table 2, eq. 11)."""

import math

import cvxpy as cp
import numpy as np
import pytest

from fixplan import LimitSurface, pressure
from fixplan.errors import FixplanError, InvalidArgumentError, ModelError
from fixplan.models import (
    Cone,
    Ellipsoid,
    Exact,
    FacetedEllipsoid,
    FittedEllipsoid,
    PointCone,
    PointPyramid,
    Pyramid,
)
from fixplan.models.compare import compare

MU, N = 0.5, 4.0
RADIUS = 0.01
#: Three unequally loaded points: the load at maximum moment has a force (tilted models).
SKEWED_POINTS = ([[0.0, 0.0], [0.04, 0.0], [0.0, 0.02]], [1, 2, 3])
TRIANGLE = [[0.0, 0.05], [-0.0433, -0.025], [0.0433, -0.025]]


@pytest.fixture(scope="module")
def disk():
    return LimitSurface(pressure.disk(RADIUS), mu=MU, normal_force=N)


@pytest.fixture(scope="module")
def skewed():
    return LimitSurface(pressure.points(*SKEWED_POINTS), mu=MU, normal_force=N)


# -- Ellipsoid (Table 2) ----------------------------------------------------------------------


def test_ellipsoid_takes_max_force_and_max_moment_from_the_surface(disk):
    model = Ellipsoid.from_limit_surface(disk)
    assert model.mu == pytest.approx(MU, rel=1e-14)
    assert model.rho == pytest.approx(2 * RADIUS / 3, rel=1e-12)
    assert model.tilt == (0.0, 0.0)
    assert model.max_force == pytest.approx(disk.max_force, rel=1e-14)
    assert model.max_moment == pytest.approx(disk.max_moment, rel=1e-12)


def test_normalised_ellipsoid_is_the_unit_sphere(disk):
    model = Ellipsoid.from_limit_surface(disk)
    units = np.array([disk.max_force, disk.max_force, disk.max_moment])
    directions = np.random.default_rng(0).normal(size=(100, 3))
    directions /= np.linalg.norm(directions, axis=1, keepdims=True)
    np.testing.assert_allclose(model.safety_factor(directions * units), 1.0, rtol=1e-14)


@pytest.mark.parametrize(("f", "m"), [(0.3, 0.01), (1.5, 0.002), (0.01, 0.03)])
def test_ellipsoid_motion_ratio_is_lambda_squared_f_over_m(disk, f, m):
    # Table 2, step 5: |v| / w = lambda² f / m, v parallel to the applied force.
    model = Ellipsoid.from_limit_surface(disk)
    angle = 0.7
    load = np.array([f * math.cos(angle), f * math.sin(angle), m])
    vx, vy, w = model.motion(load)
    lam = model.rho
    assert math.hypot(vx, vy) / w == pytest.approx(lam**2 * f / m, rel=1e-12)
    assert math.atan2(vy, vx) == pytest.approx(angle, abs=1e-12)
    # Normalised (step 3): |v| / w = lambda f' / m'.
    f_n, m_n = f / disk.max_force, m / disk.max_moment
    assert math.hypot(vx, vy) / w == pytest.approx(lam * f_n / m_n, rel=1e-12)


def test_tilted_ellipsoid_touches_the_surface_at_its_load_at_maximum_moment(skewed):
    apex = skewed.load_at_cor((0.0, 0.0))
    model = Ellipsoid.from_limit_surface(skewed)
    assert np.hypot(*model.tilt) > 0.05
    assert model.tilt == pytest.approx(apex[:2] / skewed.max_force, rel=1e-12)
    assert model.safety_factor(apex) == pytest.approx(1.0, rel=1e-12)
    # Its tangent plane there is horizontal, as on the exact surface: pure rotation.
    np.testing.assert_allclose(model.motion(apex), [0.0, 0.0, 1.0 / model.rho], atol=1e-12)
    rotation = [0.0, 0.0, 1.0 / skewed.characteristic_length]
    np.testing.assert_allclose(skewed.motion(apex), rotation, atol=1e-9)
    # And it keeps the exact circle of pure translation.
    circle = np.array([[1.0, 0.0, 0.0], [0.6, -0.8, 0.0]]) * skewed.max_force
    np.testing.assert_allclose(model.safety_factor(circle), 1.0, rtol=1e-14)
    untilted = Ellipsoid.from_limit_surface(skewed, tilted=False)
    assert untilted.tilt == (0.0, 0.0)
    assert untilted.safety_factor(apex) < 1.0


def test_ellipsoid_from_limits_equals_the_one_from_the_surface(skewed):
    apex = skewed.load_at_cor((0.0, 0.0))
    built = Ellipsoid.from_limits(
        max_force=skewed.max_force,
        max_moment=skewed.max_moment,
        normal_force=N,
        apex_force=apex[:2],
    )
    reference = Ellipsoid.from_limit_surface(skewed)
    assert built.mu == pytest.approx(reference.mu) and built.rho == pytest.approx(reference.rho)
    assert built.tilt == pytest.approx(reference.tilt, rel=1e-12)


def test_ellipsoid_cvxpy_form_is_one_second_order_cone(disk):
    model = Ellipsoid.from_limit_surface(disk)
    (constraint,) = model.constraints(cp.Variable(3), cp.Parameter(nonneg=True))
    assert isinstance(constraint, cp.constraints.SOC)


@pytest.mark.parametrize("kind", [Ellipsoid, FittedEllipsoid])
def test_the_load_matrix_is_the_ellipsoid_in_loads_about_the_frame_origin(kind, skewed):
    # The skewed field's ellipsoid is tilted and centred off the origin: L^T A L must still be
    # the squared gauge at unit normal force, and A L the model's motion.
    model = kind.from_limit_surface(skewed)
    loads = np.random.default_rng(3).normal(size=(20, 3)) * [1.0, 1.0, 0.02]
    quadratic = np.einsum("ki,ij,kj->k", loads, model.load_matrix, loads)
    np.testing.assert_allclose(model.safety_factor(loads, normal_force=1.0), quadratic**-0.5,
                               rtol=1e-12)  # fmt: skip
    normals = loads @ model.load_matrix
    motions = model.motion(loads)
    cosine = np.einsum("ki,ki->k", normals, motions) / np.linalg.norm(normals, axis=1)
    cosine /= np.linalg.norm(motions, axis=1)
    np.testing.assert_allclose(cosine, 1.0, atol=1e-12)


# -- FittedEllipsoid ---------------------------------------------------------------------------


@pytest.mark.parametrize(
    "field", [pressure.disk(RADIUS), pressure.rectangle(0.1, 0.01)], ids=["disk", "rectangle"]
)
def test_fitted_ellipsoid_is_closer_than_the_table_2_ellipsoid(field):
    ls = LimitSurface(field, mu=MU, normal_force=N)
    fitted = compare(FittedEllipsoid.from_limit_surface(ls, samples=400), ls, n=600)
    table2 = compare(Ellipsoid.from_limit_surface(ls), ls, n=600)
    assert fitted.mean_abs_error < 0.65 * table2.mean_abs_error
    assert max(fitted.max_overestimate, fitted.max_underestimate) < table2.max_overestimate


def test_fit_recovers_an_ellipsoid_from_loads_on_it():
    truth = Ellipsoid(mu=0.8, rho=0.02, tilt=(0.1, -0.05), normal_force=3.0)
    directions = np.random.default_rng(1).normal(size=(50, 3))
    loads = directions * np.array([truth.max_force, truth.max_force, truth.max_moment])
    loads *= truth.safety_factor(loads)[:, None]
    fitted = FittedEllipsoid.from_loads(loads, normal_force=3.0)
    probes = np.random.default_rng(2).normal(size=(200, 3)) * np.array([2.4, 2.4, 0.048])
    np.testing.assert_allclose(fitted.safety_factor(probes), truth.safety_factor(probes), 1e-5)
    assert fitted.fit_error < 1e-6
    assert fitted.mu == pytest.approx(np.sqrt(0.8**2 * (1 + 0.1**2 / 2 + 0.05**2 / 2)), 1e-5)


def test_fit_needs_loads_in_every_direction():
    with pytest.raises(InvalidArgumentError, match="at least 6 loads"):
        FittedEllipsoid.from_loads(np.ones((3, 3)), normal_force=1.0)
    flat = np.column_stack([np.cos(np.arange(8)), np.sin(np.arange(8)), np.cos(np.arange(8))])
    with pytest.raises(InvalidArgumentError, match="span all three"):
        FittedEllipsoid.from_loads(flat, normal_force=1.0)


def test_fitted_matrix_must_be_positive_definite():
    with pytest.raises(InvalidArgumentError, match="positive definite"):
        FittedEllipsoid(matrix=np.diag([1.0, 1.0, -1.0]), mu=1.0, rho=1.0)


# -- FacetedEllipsoid (Table 2, step 4) ----------------------------------------------------------


def test_facets_are_the_exact_planes_of_rotation_about_each_point():
    ls = LimitSurface(pressure.points(TRIANGLE), mu=MU, normal_force=N)
    model = FacetedEllipsoid.from_limit_surface(ls)
    assert len(model.points) == 3
    for x, y in model.points:
        twist = np.array([y, -x, 1.0])
        on_facet = ls.load(twist)  # the point itself carries no force
        assert ls.safety_factor(on_facet) == pytest.approx(1.0, rel=1e-9)
        assert model.safety_factor(on_facet) == pytest.approx(1.0, rel=1e-12)
        motion = model.motion(on_facet)
        np.testing.assert_allclose(motion / motion[2], twist, atol=1e-12)


def test_facets_only_remove_overestimated_loads():
    ls = LimitSurface(pressure.points(TRIANGLE), mu=MU, normal_force=N)
    faceted = FacetedEllipsoid.from_limit_surface(ls)
    plain = Ellipsoid.from_limit_surface(ls)
    loads = np.random.default_rng(3).normal(size=(500, 3)) * [2.0, 2.0, 0.1]
    s_faceted, s_plain = faceted.safety_factor(loads), plain.safety_factor(loads)
    assert np.all(s_faceted <= s_plain)
    cut = s_faceted < s_plain * (1 - 1e-9)
    assert cut.mean() > 0.2
    # The facet planes support the exact surface: they never cut into it, and they are
    # exact where the load meets the true facet.
    exact = ls.safety_factor(loads[cut])
    assert np.all(s_faceted[cut] >= exact * (1 - 1e-9))
    assert np.isclose(s_faceted[cut], exact, rtol=1e-9).mean() > 0.3
    accuracy = compare(faceted, ls, n=600)
    assert accuracy.max_overestimate < 0.5 * compare(plain, ls, n=600).max_overestimate


def test_faceted_ellipsoid_needs_support_points(disk):
    with pytest.raises(InvalidArgumentError, match="pass points="):
        FacetedEllipsoid.from_limit_surface(disk)


# -- Cone and Pyramid ----------------------------------------------------------------------------


def test_cone_section_is_the_straight_line_of_the_moment_force_plot(disk):
    curve = Cone.from_limit_surface(disk).curve("fy-m", 72, normalized=True)
    np.testing.assert_allclose(np.abs(curve[:, 1]) + np.abs(curve[:, 2]), 1.0, rtol=1e-13)


def test_tilted_cone_has_its_apex_at_the_load_at_maximum_moment(skewed):
    cone = Cone.from_limit_surface(skewed)
    apex = skewed.load_at_cor((0.0, 0.0))
    assert cone.safety_factor(apex) == pytest.approx(1.0, rel=1e-12)
    assert cone.safety_factor([0.0, 0.0, skewed.max_moment]) < 1.0
    # The circle of pure translation is on the cone.
    assert cone.safety_factor([0.0, skewed.max_force, 0.0]) == pytest.approx(1.0, rel=1e-14)


def _eq11_holds(load, max_force, max_moment):
    """The paper's eq. 11 written out: lambda = max_moment / max_force."""
    lam = max_moment / max_force
    bound = (max_force - abs(load[2]) / lam) / math.sqrt(2)
    return abs(load[0]) <= bound and abs(load[1]) <= bound and abs(load[2]) <= max_moment


def test_square_pyramid_is_equation_11(disk):
    pyramid = Pyramid.from_limit_surface(disk)
    units = np.array([disk.max_force, disk.max_force, disk.max_moment])
    loads = np.random.default_rng(4).uniform(-1.0, 1.0, size=(2000, 3)) * units
    expected = [_eq11_holds(load, disk.max_force, disk.max_moment) for load in loads]
    np.testing.assert_array_equal(pyramid.contains(loads), expected)
    # Values: a pure force along x holds up to mu N / sqrt(2), along the diagonal up to mu N.
    assert pyramid.safety_factor([1.0, 0.0, 0.0]) == pytest.approx(MU * N / math.sqrt(2))
    diagonal = np.array([1.0, 1.0, 0.0]) / math.sqrt(2)
    assert pyramid.safety_factor(diagonal) == pytest.approx(MU * N)
    assert pyramid.safety_factor([0.0, 0.0, 1e-3]) == pytest.approx(disk.max_moment / 1e-3)


@pytest.mark.parametrize("facets", [3, 4, 7])
def test_pyramid_inequalities_match_its_safety_factor(disk, facets):
    pyramid = Pyramid.from_limit_surface(disk, facets=facets, inscribed=False)
    a, b = pyramid.inequalities(normal_force=2 * N)
    assert a.shape == (2 * facets, 3) and b.shape == (2 * facets,)
    loads = np.random.default_rng(5).normal(size=(500, 3)) * [2.0, 2.0, 0.02]
    held = np.all(loads @ a.T <= b, axis=1)
    safety = pyramid.safety_factor(loads, normal_force=2 * N)
    far = np.abs(safety - 1.0) > 1e-9
    np.testing.assert_array_equal(held[far], safety[far] >= 1.0)


def test_inscribed_pyramid_facets_sit_at_cos_pi_over_k(disk):
    for facets in (3, 4, 6, 12):
        inner = Pyramid.from_limit_surface(disk, facets=facets)
        outer = Pyramid.from_limit_surface(disk, facets=facets, inscribed=False)
        along_normal = [disk.max_force, 0.0, 0.0]
        assert inner.safety_factor(along_normal) == pytest.approx(math.cos(math.pi / facets))
        assert outer.safety_factor(along_normal) == pytest.approx(1.0)


def test_pyramid_is_solved_by_osqp_as_a_linear_program(disk):
    pyramid = Pyramid.from_limit_surface(disk, facets=8)
    load = cp.Parameter(3)
    fn = cp.Variable(nonneg=True)
    problem = cp.Problem(cp.Minimize(fn), pyramid.constraints(load, fn))
    assert problem.is_dcp(dpp=True)
    load.value = np.array([0.3, -0.2, 0.004])
    problem.solve(solver=cp.OSQP, eps_abs=1e-9, eps_rel=1e-9, max_iter=100000)
    expected = N / pyramid.safety_factor(load.value)
    assert fn.value == pytest.approx(expected, rel=1e-5)


def test_cone_and_pyramid_have_no_motion_map(disk):
    for model in (Cone.from_limit_surface(disk), Pyramid.from_limit_surface(disk)):
        assert not model.has_motion
        with pytest.raises(ModelError) as info:
            model.motion([0.1, 0.0, 0.0])
        assert isinstance(info.value, FixplanError) and isinstance(info.value, TypeError)


@pytest.mark.parametrize("facets", [2, 2.5, True])
def test_pyramid_needs_three_or_more_facets(facets):
    with pytest.raises(InvalidArgumentError, match="facets must be an integer >= 3"):
        Pyramid(mu=1.0, rho=0.01, facets=facets)


# -- Point contacts ------------------------------------------------------------------------------


def test_point_cone_is_the_coulomb_cone_and_bears_no_moment():
    cone = PointCone(mu=0.5, normal_force=2.0)
    assert cone.safety_factor([0.6, 0.8]) == pytest.approx(1.0)
    assert cone.safety_factor([0.6, 0.8, 0.0]) == pytest.approx(1.0)
    assert cone.safety_factor([0.6, 0.8, 1e-9]) == 0.0
    assert not cone.contains([0.0, 0.0, 1e-9])
    np.testing.assert_allclose(cone.motion([0.3, 0.4]), [0.6, 0.8])
    np.testing.assert_allclose(cone.motion([0.3, 0.4, 0.0]), [0.6, 0.8, 0.0])
    assert np.all(np.isnan(cone.motion([0.3, 0.4, 0.1])))


@pytest.mark.parametrize("facets", [3, 4, 8])
def test_point_pyramids_bracket_the_coulomb_cone(facets):
    cone = PointCone(mu=0.5)
    inner = PointPyramid(mu=0.5, facets=facets)
    outer = PointPyramid(mu=0.5, facets=facets, inscribed=False)
    angles = np.linspace(0.0, 2 * np.pi, 721)
    forces = np.column_stack([np.cos(angles), np.sin(angles)])
    s_inner, s_cone, s_outer = (m.safety_factor(forces) for m in (inner, cone, outer))
    assert np.all(s_inner <= s_cone + 1e-15) and np.all(s_cone <= s_outer + 1e-15)
    assert s_inner.min() == pytest.approx(0.5 * math.cos(math.pi / facets), rel=1e-12)
    assert s_outer.max() == pytest.approx(0.5 / math.cos(math.pi / facets), rel=1e-12)
    assert inner.conservative and not outer.conservative
    assert "inscribed" in repr(inner) and "circumscribed" in repr(outer)


def test_point_model_constraints_accept_forces_or_zero_moment_loads():
    cone = PointCone(mu=0.5)
    fn = cp.Parameter(nonneg=True, value=2.0)
    for width in (2, 3):
        load = cp.Variable(width)
        problem = cp.Problem(cp.Maximize(load[0] + load[1]), cone.constraints(load, fn))
        assert problem.is_dcp(dpp=True)
        problem.solve(solver=cp.CLARABEL)
        assert load.value[0] == pytest.approx(math.sqrt(0.5), rel=1e-7)
        if width == 3:
            assert abs(load.value[2]) < 1e-9


def test_point_models_built_from_a_surface_keep_its_friction(disk):
    assert PointCone.from_limit_surface(disk) == PointCone(mu=MU, normal_force=N)
    assert PointPyramid.from_limit_surface(disk, facets=6) == PointPyramid(
        mu=MU, facets=6, normal_force=N
    )


# -- Exact -------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    "ls",
    [
        LimitSurface(pressure.disk(0.01), mu=MU, normal_force=N),
        LimitSurface(pressure.rectangle(0.1, 0.01), mu=MU, normal_force=N),
        LimitSurface(pressure.points([[0.0, 0.0], [0.04, 0.0], [0.0, 0.02]], [1, 2, 3]), mu=MU),
        LimitSurface(pressure.points([[0, 0], [0.02, 0], [0, 0.02]]), mu=lambda x, y: 0.3 + 10 * x),
        LimitSurface.combine(
            [
                LimitSurface(pressure.disk(0.005).shifted(-0.03, 0.0), mu=0.4, normal_force=1.0),
                LimitSurface(pressure.disk(0.005).shifted(0.03, 0.0), mu=0.6, normal_force=3.0),
            ]
        ),
    ],
    ids=["disk", "rectangle", "points", "varying-mu", "combined"],
)
def test_exact_model_is_the_exact_surface(ls):
    model = Exact.from_limit_surface(ls)
    assert model.mu == pytest.approx(ls.max_force / ls.normal_force, rel=1e-15)
    units = np.array([ls.max_force, ls.max_force, ls.max_moment])
    loads = np.random.default_rng(6).normal(size=(50, 3)) * units
    np.testing.assert_allclose(model.safety_factor(loads), ls.safety_factor(loads), rtol=1e-12)
    motion = model.motion(loads)
    exact = ls.motion(loads)
    np.testing.assert_allclose(motion / np.linalg.norm(motion, axis=1, keepdims=True),
                               exact / np.linalg.norm(exact, axis=1, keepdims=True), atol=1e-12)  # fmt: skip


def test_exact_model_cut_is_the_tangent_plane_at_the_load_and_holds_the_surface(disk):
    model = Exact.from_limit_surface(disk)
    units = np.array([MU, MU, MU * model.rho])  # the set per unit normal force
    loads = np.random.default_rng(8).normal(size=(40, 3)) * units
    planes, excess = model.cut(loads)
    safety = disk.safety_factor(loads * N)
    np.testing.assert_allclose(excess, 1.0 / safety - 1.0, rtol=1e-12)
    # The plane a · L <= 1 touches the surface at the load's ray ...
    touching = loads * safety[:, None]
    np.testing.assert_allclose(np.einsum("ij,ij->i", planes, touching), 1.0, rtol=1e-12)
    # ... and holds every load of the surface.
    surface = disk.sample(500) / N
    assert np.max(surface @ planes.T) <= 1.0 + 1e-12


def test_exact_model_of_point_supports_cuts_along_the_facets(skewed):
    # A load whose centre of rotation is a support point lies on a facet: the cut is the facet.
    model = Exact.from_limit_surface(skewed)
    xy = skewed.field.pose.apply(skewed.field.xy)[1]
    facet_twist = np.array([xy[1], -xy[0], 1.0])
    on_facet = skewed.load(facet_twist) / N
    planes, excess = model.cut(on_facet[None, :] * 1.5)
    assert excess[0] == pytest.approx(0.5, rel=1e-12)
    expected = facet_twist / (skewed.support(facet_twist) / N)
    np.testing.assert_allclose(planes[0], expected, rtol=1e-9)


def test_exact_model_constraints_state_an_outer_polytope_of_tangent_planes(disk):
    model = Exact.from_limit_surface(disk)
    assert 0.0 < model.constraint_error < 0.5
    load = cp.Parameter(3)
    fn = cp.Variable()
    problem = cp.Problem(cp.Minimize(fn), model.constraints(load, fn))
    assert problem.is_dcp(dpp=True)
    ratios = []
    for probe in disk.sample(60):
        load.value = probe
        problem.solve(solver=cp.CLARABEL)
        ratios.append(fn.value / N)  # probe is on the surface at N: the polytope needs less
    assert min(ratios) >= 1.0 / (1.0 + model.constraint_error) - 1e-7
    assert max(ratios) <= 1.0 + 1e-7


# -- frames whose origin is not the centre of pressure --------------------------------------------

OFFSET = (0.013, -0.021)  # [m]

MOVED_MODELS = {
    "ellipsoid": Ellipsoid.from_limit_surface,
    "fitted-ellipsoid": lambda ls: FittedEllipsoid.from_limit_surface(ls, samples=300),
    "faceted-ellipsoid": FacetedEllipsoid.from_limit_surface,
    "cone": Cone.from_limit_surface,
    "pyramid": lambda ls: Pyramid.from_limit_surface(ls, facets=5),
    "exact": Exact.from_limit_surface,
}


@pytest.mark.parametrize("name", list(MOVED_MODELS))
def test_models_of_a_shifted_patch_are_the_models_of_the_centred_patch_moved(skewed, name):
    # Shifting the patch by d adds d × f to every moment and moves the origin's velocity by
    # w × (dy, -dx): the model must describe the same physical contact.
    build = MOVED_MODELS[name]
    moved_ls = LimitSurface(pressure.points(*SKEWED_POINTS).shifted(*OFFSET), mu=MU, normal_force=N)
    centred, moved = build(skewed), build(moved_ls)
    dx, dy = OFFSET
    loads = np.random.default_rng(8).normal(size=(40, 3)) * [2.0, 2.0, 0.05]
    moved_loads = loads.copy()
    moved_loads[:, 2] += dx * loads[:, 1] - dy * loads[:, 0]
    rtol = 2e-3 if name == "fitted-ellipsoid" else 1e-9
    np.testing.assert_allclose(moved.safety_factor(moved_loads), centred.safety_factor(loads), rtol)
    if name in ("ellipsoid", "cone", "pyramid"):
        assert moved.center == pytest.approx(OFFSET, abs=1e-15)
        assert moved.rho == pytest.approx(centred.rho, rel=1e-12)
        assert moved.tilt == pytest.approx(centred.tilt, abs=1e-12)
    if moved.has_motion and name != "fitted-ellipsoid":
        twists = centred.motion(loads)
        expected = twists + np.column_stack(
            [dy * twists[:, 2], -dx * twists[:, 2], np.zeros(len(twists))]
        )
        predicted = moved.motion(moved_loads)
        # Same direction (Exact scales twists about the frame origin, like LimitSurface).
        scale = np.array([1.0, 1.0, centred.rho])
        unit = (predicted * scale) / np.linalg.norm(predicted * scale, axis=1, keepdims=True)
        ref = (expected * scale) / np.linalg.norm(expected * scale, axis=1, keepdims=True)
        np.testing.assert_allclose(unit, ref, atol=1e-7)


def test_cone_and_pyramid_stay_conservative_off_the_centre_of_pressure():
    # A linear pressure over a rectangle keeps the rectangle's centroid as origin.
    field = pressure.from_function(pressure.rectangle(0.02, 0.01), lambda x, y: 1.0 + 50.0 * x)
    ls = LimitSurface(field, mu=MU, normal_force=N)
    cone = Cone.from_limit_surface(ls)
    # Centre of pressure: x_c = ∫ x p dA / ∫ p dA = 50 L² / 12 for p = 1 + 50 x, length L.
    assert cone.center == pytest.approx((50.0 * 0.02**2 / 12, 0.0), rel=1e-6, abs=1e-12)
    for model in (cone, Pyramid.from_limit_surface(ls, facets=6)):
        accuracy = compare(model, ls, n=200)
        assert accuracy.max_overestimate <= 1e-9


def test_pyramid_inequalities_hold_off_the_centre_of_pressure(skewed):
    moved_ls = LimitSurface(pressure.points(*SKEWED_POINTS).shifted(*OFFSET), mu=MU, normal_force=N)
    pyramid = Pyramid.from_limit_surface(moved_ls, facets=6)
    a, b = pyramid.inequalities()
    loads = np.random.default_rng(9).normal(size=(500, 3)) * [1.0, 1.0, 0.05]
    safety = pyramid.safety_factor(loads)
    far = np.abs(safety - 1.0) > 1e-9
    np.testing.assert_array_equal(np.all(loads @ a.T <= b, axis=1)[far], safety[far] >= 1.0)


# -- construction checks -----------------------------------------------------------------------


def test_models_refuse_bad_parameters_naming_them(disk):
    with pytest.raises(InvalidArgumentError, match="mu must be >= 0"):
        Ellipsoid(mu=-0.1, rho=0.01)
    with pytest.raises(InvalidArgumentError, match="rho must be > 0"):
        Cone(mu=1.0, rho=-0.01)
    with pytest.raises(InvalidArgumentError, match="normal_force must be > 0"):
        Ellipsoid.from_limit_surface(disk).safety_factor([1.0, 0.0, 0.0], normal_force=0.0)
    with pytest.raises(InvalidArgumentError, match=r"ls must be a fixplan\.LimitSurface"):
        Cone.from_limit_surface(pressure.disk(0.01))
    with pytest.raises(InvalidArgumentError, match=r"ls must be a fixplan\.LimitSurface"):
        Exact.from_limit_surface(pressure.disk(0.01))
    with pytest.raises(InvalidArgumentError, match="only section is 'fx-fy'"):
        PointCone(mu=1.0).curve("fy-m")


def test_point_models_must_sit_at_the_centre_of_pressure():
    field = pressure.points(*SKEWED_POINTS, centered=False)
    ls = LimitSurface(field, mu=MU, normal_force=N)
    for build in (PointCone.from_limit_surface, PointPyramid.from_limit_surface):
        with pytest.raises(InvalidArgumentError, match="not its centre of pressure"):
            build(ls)


@pytest.mark.parametrize("build", [Cone.from_limit_surface, Pyramid.from_limit_surface])
def test_an_untilted_cone_of_skewed_pressure_is_not_flagged_conservative(build):
    # Skewed points: the load at maximum moment has a force, so the untilted apex (0, m_max)
    # lies outside the exact surface.
    ls = LimitSurface(pressure.points([[0, 0], [0.03, 0], [0, 0.01]], [1, 2, 3]), mu=0.5,
                      normal_force=7.0)  # fmt: skip
    untilted, tilted = build(ls, tilted=False), build(ls)
    assert tilted.conservative and not untilted.conservative
    assert "apex off the surface" in repr(untilted)
    apex = np.array([0.0, 0.0, untilted.max_moment])
    assert untilted.contains(apex) and not ls.contains(apex)
