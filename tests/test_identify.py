"""Fitted limit surfaces (issue 11 §2, §4, §5) on synthetic pairs from exact surfaces.

References are independent of the fitting code: the exact limit surface (closed forms and
quadrature), the paper's Table 2 ellipsoid, closed forms of the sphere-shaped quartic, numeric
Hessians by central differences and polynomial identities evaluated in plain Python.
"""

import json
import math
from functools import cache

import numpy as np
import pytest

from fixplan import LimitSurface, pressure
from fixplan.errors import InvalidArgumentError
from fixplan.models import Ellipsoid
from fixplan.motion import (
    Fit,
    FittedQuartic,
    Outline,
    PointPusher,
    assess,
    ellipsoid_from_matrix,
    fit,
    push,
    push_step,
    synthetic,
)
from fixplan.motion.fitted_quartic import MONOMIALS, monomials, sos_convexity_maps
from fixplan.surface.sphere import fibonacci_sphere

DISK = LimitSurface(pressure.disk(0.05), mu=0.5, normal_force=10.0)
#: The paper's Fig. 5 rectangle (10:1).
RECTANGLE = LimitSurface(pressure.rectangle(0.1, 0.01), mu=0.25, normal_force=200.0)
THREE_POINTS = LimitSurface(
    pressure.points([[0.05, 0.0], [-0.025, 0.0433], [-0.025, -0.0433]], [1.0, 1.0, 1.0]),
    mu=0.5,
    normal_force=10.0,
)
SURFACES = {"disk": DISK, "rectangle": RECTANGLE, "three points": THREE_POINTS}


def sphere_quartic(rho=0.02, normal_force=3.0, radius=2.0):
    """``H = (|x| / radius)^4``: the level set is the sphere of ``radius`` [N] in ``x``."""
    coefficients = np.zeros(15)
    coefficients[:3] = 1.0
    coefficients[9:12] = 2.0
    return FittedQuartic(coefficients=coefficients / radius**4, rho=rho, normal_force=normal_force)


def skewed_quartic():
    """A strictly SOS-convex quartic: ``|L x|^4 + 0.3 (x^4 + y^4 + z^4)`` (SOS-convexity is kept
    by linear maps and sums, and holds for ``|x|^4`` and separable quartics)."""
    stretch = np.array([[1.0, 0.3, -0.2], [0.0, 0.8, 0.4], [0.1, 0.0, 1.5]])
    points = np.random.default_rng(5).standard_normal((60, 3))
    values = np.sum((points @ stretch.T) ** 2, axis=1) ** 2 + 0.3 * np.sum(points**4, axis=1)
    coefficients = np.linalg.lstsq(monomials(points), values, rcond=None)[0]
    return FittedQuartic(coefficients=coefficients, rho=0.05, normal_force=2.0)


def angle(a, b, rho):
    """Angles [rad] between twists ``a`` and ``b`` as ``(vx, vy, rho w)`` (accurate near 0)."""
    a, b = np.atleast_2d(a) * [1.0, 1.0, rho], np.atleast_2d(b) * [1.0, 1.0, rho]
    return np.arctan2(np.linalg.norm(np.cross(a, b), axis=1), np.sum(a * b, axis=1))


@cache
def fitted(name, model, count=800, noise=False):
    """A fit of ``count`` pairs of a catalogue surface, half held out."""
    surface = SURFACES[name]
    noise = {"noise_force": 0.05, "noise_angle": math.radians(5.0)} if noise else {}
    loads, twists = synthetic(surface, count, seed=1, **noise)
    return fit(loads, twists, model=model, normal_force=surface.normal_force, holdout=0.5)


# -- synthetic pairs ----------------------------------------------------------------------------


def test_noise_free_synthetic_pairs_lie_on_the_exact_surface_along_its_normals():
    loads, twists = synthetic(RECTANGLE, 300, seed=4)
    np.testing.assert_allclose(RECTANGLE.safety_factor(loads), 1.0, rtol=1e-9)
    assert np.max(angle(RECTANGLE.motion(loads), twists, RECTANGLE.characteristic_length)) < 1e-7
    assert np.allclose(np.linalg.norm(twists * [1, 1, RECTANGLE.characteristic_length], axis=1), 1)


def test_synthetic_noise_has_the_stated_size():
    # Same seed: the same twists and noise draws, scaled. Force noise per component of
    # (fx, fy, m / rho) has standard deviation noise_force |x|; the twist angle's rms is noise_angle.
    clean_loads, clean_twists = synthetic(DISK, 4000, seed=2)
    loads, twists = synthetic(DISK, 4000, noise_force=0.05, noise_angle=0.1, seed=2)
    scale = [1.0, 1.0, 1.0 / DISK.characteristic_length]
    relative = (loads - clean_loads) * scale / np.linalg.norm(clean_loads * scale, axis=1)[:, None]
    assert np.std(relative) == pytest.approx(0.05, rel=0.03)
    turned = angle(twists, clean_twists, DISK.characteristic_length)
    assert np.sqrt(np.mean(turned**2)) == pytest.approx(0.1, rel=0.03)


# -- the quartic surface ------------------------------------------------------------------------


def test_monomial_names_match_their_exponents():
    point = np.array([1.3, -0.7, 2.1])
    names = {"x": point[0], "y": point[1], "z": point[2]}
    expected = [eval(name.replace("^", "**"), {}, names) for name in MONOMIALS]
    np.testing.assert_allclose(monomials(point[None, :])[0], expected, rtol=1e-14)


def test_the_sphere_quartic_has_the_closed_forms_of_a_sphere():
    # Level set |x| = 2 N, x = (fx, fy, m / rho): h(V) = 2 |(vx, vy, rho w)|, load along it.
    quartic, rho = sphere_quartic(), 0.02
    twists = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.3, -0.4, 20.0]])
    u = twists * [1.0, 1.0, rho]
    np.testing.assert_allclose(quartic.support(twists), 2.0 * np.linalg.norm(u, axis=1), rtol=1e-12)
    expected = 2.0 * u / np.linalg.norm(u, axis=1)[:, None] * [1.0, 1.0, rho]
    np.testing.assert_allclose(quartic.load(twists), expected, rtol=1e-10, atol=1e-14)
    assert quartic.max_force == pytest.approx(2.0, rel=1e-12)
    assert quartic.max_moment == pytest.approx(2.0 * rho, rel=1e-12)
    assert quartic.mu == pytest.approx(2.0 / 3.0, rel=1e-12)
    assert quartic.safety_factor([1.0, 0.0, 0.0]) == pytest.approx(2.0, rel=1e-14)
    # x = (0, 1, 0.5): the normal (0, 1, 0.5) as (vx, vy, rho w) of unit norm.
    expected = np.array([0.0, 1.0, 0.5 / rho]) / math.sqrt(1.25)
    np.testing.assert_allclose(quartic.motion([0.0, 1.0, 0.01]), expected, rtol=1e-14)


def test_the_quartic_forward_and_inverse_maps_agree_and_are_dual():
    quartic = skewed_quartic()
    twists = fibonacci_sphere(200) * [1.0, 1.0, 30.0]
    loads = quartic.load(twists)
    np.testing.assert_allclose(quartic.safety_factor(loads), 1.0, rtol=1e-12)
    assert np.max(angle(quartic.motion(loads), twists, quartic.rho)) < 1e-9
    np.testing.assert_allclose(quartic.support(twists), np.sum(twists * loads, axis=1), rtol=1e-12)
    # Support function: no load on the surface does more work than h(V).
    work = quartic.sample(2000) @ twists.T
    assert np.all(work <= quartic.support(twists)[None, :] * (1 + 1e-12))


def test_the_quartic_curve_and_sample_lie_on_the_surface():
    quartic = skewed_quartic()
    for loads in (quartic.curve("fx-m", 90), quartic.curve("fx-fy", 90), quartic.sample(300)):
        np.testing.assert_allclose(quartic.level(loads), 1.0, rtol=1e-12)
    section = quartic.curve("fy-m", 8, normalized=True)
    assert np.all(section[:, 0] == 0.0)
    assert quartic.contains(0.999 * quartic.sample(5)).all()
    assert not quartic.contains(1.001 * quartic.sample(5)).any()


def test_the_sos_convexity_maps_equate_the_hessian_form_and_the_gram_form():
    # y^T ∇²H(x) y by central differences of H, and z^T Q z with z = (x_i y_j), against the
    # same bihomogeneous monomials times the maps.
    rng = np.random.default_rng(3)
    coefficient_map, gram_map = sos_convexity_maps()
    coefficients, gram = rng.standard_normal(15), rng.standard_normal((9, 9))
    for x, y in rng.standard_normal((5, 2, 3)):
        step = 1e-3

        def h(point):
            return monomials(point[None, :])[0] @ coefficients

        hessian_form = (h(x + step * y) - 2 * h(x) + h(x - step * y)) / step**2
        basis = _bihomogeneous_basis(x, y)
        assert basis @ coefficient_map @ coefficients == pytest.approx(hessian_form, rel=1e-5)
        z = np.outer(x, y).ravel()
        assert basis @ gram_map @ gram.ravel(order="F") == pytest.approx(z @ gram @ z, rel=1e-12)


def _bihomogeneous_basis(x, y):
    """The 36 monomials x^β y^γ (|β| = |γ| = 2) at ``(x, y)`` in the row order of the maps: a
    row's first Gram entry ``Q[a, b]`` names its monomial ``z_a z_b``."""
    _, gram_map = sos_convexity_maps()
    basis = np.zeros(gram_map.shape[0])
    for row in range(gram_map.shape[0]):
        entry = int(np.flatnonzero(gram_map[row])[0])
        (i, j), (p, q) = divmod(entry % 9, 3), divmod(entry // 9, 3)
        basis[row] = x[i] * x[p] * y[j] * y[q]
    return basis


def test_given_coefficients_load_by_name_or_in_order():
    quartic = skewed_quartic()
    named = dict(zip(MONOMIALS, quartic.coefficients.tolist(), strict=True))
    by_name = FittedQuartic.from_coefficients(named, rho=0.05, normal_force=2.0)
    by_order = FittedQuartic.from_coefficients(list(named.values()), rho=0.05, normal_force=2.0)
    loads = quartic.sample(50) * 1.3
    np.testing.assert_array_equal(by_name.level(loads), quartic.level(loads))
    np.testing.assert_array_equal(by_order.level(loads), quartic.level(loads))


@pytest.mark.parametrize(
    ("change", "message"),
    [
        (lambda c: c[:14], "shape"),
        (lambda c: np.where(np.arange(15) == 2, np.nan, c), "finite"),
        (lambda c: np.where(np.arange(15) == 2, -1.0, c), "unbounded"),
        (lambda c: c + np.where(np.arange(15) == 4, 3.0, 0.0), "not convex"),
    ],
)
def test_invalid_quartic_coefficients_are_refused(change, message):
    coefficients = sphere_quartic(radius=1.0).coefficients
    with pytest.raises(InvalidArgumentError, match=message):
        FittedQuartic(coefficients=change(coefficients), rho=0.02)


def test_unknown_or_missing_monomial_names_are_refused():
    with pytest.raises(InvalidArgumentError, match=r"unknown \['x\^5'\], missing \['x\^4'"):
        FittedQuartic.from_coefficients({"x^5": 1.0}, rho=0.02)


# -- fits of exact models -------------------------------------------------------------------------


@pytest.mark.parametrize("with_twists", [True, False])
def test_an_ellipsoid_fitted_to_an_exact_ellipsoid_recovers_it(with_twists):
    truth = ellipsoid_from_matrix(
        [[0.3, 0.05, -0.02], [0.05, 0.5, 0.03], [-0.02, 0.03, 0.8]], rho=0.04, normal_force=5.0
    )
    loads, twists = synthetic(truth, 200, seed=6)
    result = fit(loads, twists if with_twists else None, normal_force=5.0, holdout=0.0)
    np.testing.assert_allclose(result.surface.load_matrix, truth.load_matrix, rtol=1e-5)
    assert result.surface.fit_error < 1e-6


@pytest.mark.parametrize("size", [1e-300, 1e300])
def test_only_the_twists_directions_matter_at_any_size(size):
    """Twists 1e-300 (or 1e300) times as large give the same fit (the squares of their norms
    underflowed to 0 before: a NaN in the fit's data)."""
    truth = ellipsoid_from_matrix(
        [[0.3, 0.05, -0.02], [0.05, 0.5, 0.03], [-0.02, 0.03, 0.8]], rho=0.04, normal_force=5.0
    )
    loads, twists = synthetic(truth, 200, seed=6, noise_force=0.02)
    expected = fit(loads, twists, normal_force=5.0, holdout=0.0).surface.load_matrix
    found = fit(loads, twists * size, normal_force=5.0, holdout=0.0).surface.load_matrix
    np.testing.assert_allclose(found, expected, rtol=1e-9)


def test_noise_free_quartic_pairs_recover_the_quartic():
    truth = skewed_quartic()
    loads, twists = synthetic(truth, 300, seed=7)
    result = fit(loads, twists, model="quartic", normal_force=2.0, rho=truth.rho, holdout=0.0)
    np.testing.assert_allclose(result.surface.coefficients, truth.coefficients, rtol=2e-4,
                               atol=2e-4 * np.max(np.abs(truth.coefficients)))  # fmt: skip
    test_loads = truth.sample(500)
    np.testing.assert_allclose(result.surface.safety_factor(test_loads), 1.0, atol=1e-5)


@pytest.mark.parametrize("name", SURFACES)
def test_a_fitted_quartic_is_convex_by_its_numeric_hessian(name):
    # Central differences of H (not the analytic Hessian) at random points of noisy fits.
    quartic = fitted(name, "quartic", noise=True).surface
    points = np.random.default_rng(8).standard_normal((300, 3)) * [1.0, 1.0, quartic.rho]
    points *= np.asarray(quartic.safety_factor(points))[:, None]
    step = 1e-4 * np.array([1.0, 1.0, quartic.rho])
    for point in points:
        hessian = np.empty((3, 3))
        for i in range(3):
            for j in range(3):
                ei, ej = np.eye(3)[i] * step[i], np.eye(3)[j] * step[j]
                corners = [point + ei + ej, point + ei - ej, point - ei + ej, point - ei - ej]
                a, b, c, d = quartic.level(np.array(corners))
                hessian[i, j] = (a - b - c + d) / (4 * step[i] * step[j])
        eigenvalues = np.linalg.eigvalsh(0.5 * (hessian + hessian.T))
        assert eigenvalues[0] >= -1e-6 * eigenvalues[-1]


# -- accuracy of the fits (issue §5) ---------------------------------------------------------------


def test_an_ellipsoid_fitted_to_a_uniform_disk_lies_within_the_papers_ellipse_with_the_exact():
    # The exact disk surface lies inside the paper's ellipse (Table 2) by 0 to 6.6 % radially; a
    # fit to it is axisymmetric and lies in the same band (to 1 %), nearer the exact surface.
    result = fitted("disk", "ellipsoid")
    matrix = result.surface.matrix  # in normalised coordinates (fx, fy, m / rho) / (mu N)
    assert matrix[1, 1] == pytest.approx(matrix[0, 0], rel=0.01)
    assert np.max(np.abs(matrix[[0, 0, 1], [1, 2, 2]])) < 0.01 * matrix[0, 0]
    paper = Ellipsoid.from_limit_surface(DISK)
    directions = fibonacci_sphere(1000) * [5.0, 5.0, 5.0 * paper.rho]
    exact = DISK.safety_factor(directions) / paper.safety_factor(directions)
    ratio = result.surface.safety_factor(directions) / paper.safety_factor(directions)
    assert np.min(exact) > 1.0 - 0.066 and np.max(exact) <= 1.0 + 1e-12
    assert np.min(ratio) > np.min(exact) - 0.01 and np.max(ratio) < 1.01
    loads, _ = synthetic(DISK, 400, seed=9)
    assert assess(result.surface, loads).radial_median < assess(paper, loads).radial_median


@pytest.mark.parametrize("name", ["rectangle", "three points"])
def test_a_quartic_fit_beats_the_ellipsoid_on_held_out_pairs(name):
    # §5: held-out median radial error at most a third of the ellipsoid's, median motion error
    # at most half (400 fitted, 400 held-out noise-free pairs).
    quartic = fitted(name, "quartic").report.validation
    ellipsoid = fitted(name, "ellipsoid").report.validation
    assert quartic.samples == ellipsoid.samples == 400
    assert quartic.radial_median <= ellipsoid.radial_median / 3.0
    assert quartic.angle_median <= ellipsoid.angle_median / 2.0


@pytest.mark.parametrize("model", ["ellipsoid", "quartic"])
@pytest.mark.parametrize("name", SURFACES)
def test_mu_is_fitted_within_two_percent_from_noisy_pairs(name, model):
    # §5: 5 % force noise and 5° twist noise on 200 pairs.
    surface = SURFACES[name]
    loads, twists = synthetic(surface, 200, noise_force=0.05, noise_angle=math.radians(5), seed=0)
    result = fit(loads, twists, model=model, normal_force=surface.normal_force, holdout=0.0)
    assert result.surface.mu == pytest.approx(surface.max_force / surface.normal_force, rel=0.02)


def test_a_quartic_fitted_to_the_rectangle_pushes_like_the_exact_surface():
    # Each step's twist differs from the exact step's by no more than the fit's motion error at
    # the exact step's load (normality at the same load; sticking steps follow the pusher).
    quartic = fitted("rectangle", "quartic").surface
    rho = RECTANGLE.characteristic_length
    cases = [([-0.05, 0.0], [1, 0], [1, 0]), ([-0.03, -0.005], [0, 1], [0.2, 1]),
             ([0.045, -0.005], [0, 1], [0, 1]), ([0.0, -0.005], [0, 1], [0.5, 1])]  # fmt: skip
    for contact, normal, velocity in cases:
        exact = push_step(RECTANGLE, contact=contact, normal=normal, velocity=velocity, mu=0.3)
        step = push_step(quartic, contact=contact, normal=normal, velocity=velocity, mu=0.3)
        motion_error = angle(quartic.motion(exact.load), RECTANGLE.motion(exact.load), rho)[0]
        assert step.mode == exact.mode
        assert angle(step.twist, exact.twist, rho)[0] <= motion_error + 1e-3
    # A whole push: 50 mm of pusher travel, the fit's few-degree motion errors integrated.
    outline = Outline.polygon([[-0.05, -0.005], [0.05, -0.005], [0.05, 0.005], [-0.05, 0.005]])
    pusher = PointPusher(([0.02, -0.02], [0.0, 0.05]), mu=0.3)
    ends = [push(s, pusher, shape=outline, duration=1.0, steps=40).poses[-1]
            for s in (RECTANGLE, quartic)]  # fmt: skip
    assert np.hypot(*(ends[1][:2] - ends[0][:2])) < 0.05 * 0.05
    assert abs(ends[1][2] - ends[0][2]) < math.radians(5.0)


# -- reports, published fits, files -----------------------------------------------------------------


def test_the_report_states_the_fit_and_its_split():
    loads, twists = synthetic(DISK, 60, seed=10)
    report = fit(loads, twists, holdout=0.25, seed=3).report
    assert (report.model, report.twists, report.weight, report.solver) == (
        "ellipsoid", True, 1.0, "CLARABEL")  # fmt: skip
    assert (report.training.samples, report.validation.samples) == (45, 15)
    assert report.rho == pytest.approx(np.max(np.abs(loads[:, 2])) / np.max(
        np.hypot(loads[:, 0], loads[:, 1])))  # fmt: skip
    loads_only = fit(loads, holdout=0.0, rho=0.03).report
    assert (loads_only.twists, loads_only.weight, loads_only.validation) == (False, 0.0, None)
    assert loads_only.training.angle_mean is None and loads_only.rho == 0.03


def test_assess_measures_a_published_ellipsoid_against_its_own_pairs():
    # Pairs of the surface itself: no radial or angle error; 10 % larger loads: H = 1.21.
    published = ellipsoid_from_matrix(np.diag([0.2, 0.25, 1.5]), rho=0.06, normal_force=4.0)
    loads, twists = synthetic(published, 50, seed=11)
    errors = assess(published, loads, twists, rho=0.06)
    assert errors.radial_median < 1e-12 and errors.angle_mean < 1e-7
    bigger = assess(published, 1.1 * loads)
    assert bigger.level_rms == pytest.approx(0.21, rel=1e-12)
    assert bigger.radial_median == pytest.approx(1.0 - 1.0 / 1.1, rel=1e-12)


def test_a_published_matrix_becomes_the_same_ellipsoid():
    # Zhou's convention: x = (fx, fy, m / rho), H = x^T A x = 1.
    matrix, rho = np.array([[0.42, -0.03, -0.05], [-0.03, 0.44, 0.02], [-0.05, 0.02, 1.7]]), 0.06
    model = ellipsoid_from_matrix(matrix, rho=rho, normal_force=3.0)
    loads = np.random.default_rng(13).standard_normal((20, 3)) * [1.0, 1.0, rho]
    x = loads / [1.0, 1.0, rho]
    expected = np.einsum("ij,jk,ik->i", x, matrix, x) ** -0.5
    np.testing.assert_allclose(model.safety_factor(loads), expected, rtol=1e-12)
    scale = np.diag([1.0, 1.0, 1.0 / rho])
    inverse = np.linalg.inv(scale @ matrix @ scale)
    assert model.max_force == pytest.approx(math.sqrt((inverse[0, 0] + inverse[1, 1]) / 2))
    assert model.max_moment == pytest.approx(math.sqrt(inverse[2, 2]), rel=1e-12)


@pytest.mark.parametrize("model", ["ellipsoid", "quartic"])
def test_a_fit_saved_to_json_loads_back_the_same(model, tmp_path):
    result = fitted("three points", model)
    result.save(tmp_path / "fit.json")
    again = Fit.load(tmp_path / "fit.json")
    assert again.report == result.report
    loads = THREE_POINTS.sample(40)
    np.testing.assert_array_equal(again.surface.safety_factor(loads),
                                  result.surface.safety_factor(loads))  # fmt: skip
    np.testing.assert_array_equal(again.surface.motion(loads), result.surface.motion(loads))


def test_a_surface_of_given_coefficients_saves_without_a_report(tmp_path):
    Fit(surface=skewed_quartic()).save(tmp_path / "given.json")
    again = Fit.load(tmp_path / "given.json")
    assert again.report is None
    np.testing.assert_array_equal(again.surface.coefficients, skewed_quartic().coefficients)


@pytest.mark.parametrize(
    ("edit", "message"),
    [
        (lambda d: d.update(version=2), "'version' must be"),
        (lambda d: d.update(extra=1), "key 'extra' is not a key"),
        (lambda d: d["surface"].pop("rho"), "key 'surface.rho' is missing"),
        (lambda d: d["surface"].update(coefficients=[1.0, 2.0]), "key 'surface'.*shape"),
        (lambda d: d["report"]["training"].pop("samples"), "'report.training.samples'"),
        (lambda d: d.update(model="cone"), "'model' must be one of"),
    ],
)
def test_a_bad_fit_file_is_refused_naming_the_key(edit, message, tmp_path):
    path = tmp_path / "fit.json"
    fitted("disk", "quartic").save(path)
    document = json.loads(path.read_text())
    edit(document)
    path.write_text(json.dumps(document))
    with pytest.raises(InvalidArgumentError, match=message):
        Fit.load(path)


# -- validation ------------------------------------------------------------------------------------

GOOD_LOADS, GOOD_TWISTS = synthetic(DISK, 40, seed=12)


@pytest.mark.parametrize(
    ("arguments", "options", "message"),
    [
        ((GOOD_LOADS[:, :2],), {}, r"loads must have shape \(n, 3\)"),
        ((np.where(GOOD_LOADS[3, 1] == GOOD_LOADS, np.nan, GOOD_LOADS),), {}, "finite"),
        ((GOOD_LOADS, GOOD_TWISTS[:30]), {}, "twists must have the shape of loads"),
        ((GOOD_LOADS, np.where(np.arange(40)[:, None] == 5, 0.0, GOOD_TWISTS)), {},
         "twists row 5 is zero"),
        ((np.where(np.arange(40)[:, None] == 7, 0.0, GOOD_LOADS),), {}, "loads row 7 is zero"),
        ((GOOD_LOADS[:18],), {"model": "quartic"}, "at least 15 fitted pairs"),
        ((GOOD_LOADS[:6],), {}, "at least 6 fitted pairs"),
        ((GOOD_LOADS,), {"model": "cubic"}, "model must be one of"),
        ((GOOD_LOADS, GOOD_TWISTS), {"weight": 1e300}, "weight must be at most 10000"),
        ((GOOD_LOADS,), {"seed": -1}, "seed must be an integer >= 0"),
        ((GOOD_LOADS,), {"holdout": 1.0}, "holdout must be a fraction"),
        ((GOOD_LOADS,), {"weight": -1.0}, "weight must be >= 0"),
        ((GOOD_LOADS * [1.0, 1.0, 0.0],), {}, "every moment is zero"),
        ((GOOD_LOADS * [1.0, 0.0, 1.0],), {}, "lie in a plane"),
    ],
)  # fmt: skip
def test_invalid_fit_arguments_are_refused(arguments, options, message):
    with pytest.raises(InvalidArgumentError, match=message):
        fit(*arguments, **options)


def test_invalid_synthetic_arguments_are_refused():
    with pytest.raises(InvalidArgumentError, match="n must be a positive integer"):
        synthetic(DISK, 0)
    with pytest.raises(InvalidArgumentError, match="noise_angle must be >= 0"):
        synthetic(DISK, 5, noise_angle=-0.1)
