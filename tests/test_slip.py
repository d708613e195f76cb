"""Slip-onset updates of a limit surface (issue 11 §1, §5): the scaled surface against exact
surfaces of scaled patches, and the estimator on synthetic onsets drawn from true surfaces that
it does not see (exact surfaces of other patch sizes and friction, and ellipsoids in closed
form), with force and twist noise."""

import math
import tracemalloc

import numpy as np
import pytest

from fixplan import LimitSurface, pressure
from fixplan.errors import InvalidArgumentError
from fixplan.models import Cone, Ellipsoid, FittedEllipsoid
from fixplan.motion import ScaledSurface, SlipEstimator, push_step, slide

MU, RADIUS = 0.5, 0.02
RECTANGLE = (0.1, 0.01)  # 10:1 [m]
SUPPORTS = np.array([[0.03, 0.0], [-0.02, 0.025], [-0.01, -0.03]])  # three points [m]

#: Relative force noise of the synthetic sensor in the convergence tests.
FORCE_NOISE = 0.03


def disk(scale=1.0, mu=MU):
    return LimitSurface(pressure.disk(scale * RADIUS), mu=mu)


def rectangle(scale=1.0, mu=MU):
    return LimitSurface(pressure.rectangle(scale * RECTANGLE[0], scale * RECTANGLE[1]), mu=mu)


def three_points(scale=1.0, mu=MU):
    # Equal weights: the centre of pressure is the centroid, kept fixed by the scaling.
    xy = SUPPORTS.mean(axis=0) + scale * (SUPPORTS - SUPPORTS.mean(axis=0))
    return LimitSurface(pressure.points(xy, centered=False), mu=mu)


SHAPES = {"disk": disk, "rectangle": rectangle, "three points": three_points}


def ellipsoid_loads(model, twists):
    """Loads of an ellipsoid ``L^T A L = 1`` at unit normal force whose normals are ``twists``:
    ``L = A^-1 V / sqrt(V^T A^-1 V)`` (Lagrange condition of max ``L·V`` on the ellipsoid)."""
    inverse = np.linalg.inv(model.load_matrix)
    stretched = twists @ inverse
    return stretched / np.sqrt(np.einsum("ij,ij->i", stretched, twists))[:, None]


def onsets(true, count, *, seed, noise=FORCE_NOISE, twist_noise=0.0):
    """Slip onsets on ``true``: loads of random twists at random normal forces, with relative
    force noise per component and twist noise in the normalised twist ``(vx, vy, rho w)``."""
    rng = np.random.default_rng(seed)
    ellipsoidal = isinstance(true, Ellipsoid | FittedEllipsoid)
    rho = true.rho if ellipsoidal else true.characteristic_length
    twists = rng.normal(size=(count, 3)) / np.array([1.0, 1.0, rho])
    unit = ellipsoid_loads(true, twists) if ellipsoidal else true.load(twists)
    normal_forces = rng.uniform(2.0, 20.0, count)
    loads = unit * normal_forces[:, None] * (1.0 + noise * rng.normal(size=(count, 3)))
    twists = twists / np.linalg.norm(twists * np.array([1.0, 1.0, rho]), axis=1, keepdims=True)
    twists = twists + twist_noise * rng.normal(size=(count, 3)) / np.array([1.0, 1.0, rho])
    return loads, normal_forces, twists


def feed(estimator, samples, *, twists=False):
    loads, normal_forces, measured = samples
    for k in range(len(loads)):
        estimator.update(loads[k], normal_forces[k], twist=measured[k] if twists else None)
    return estimator


def relative_error(value, truth):
    return abs(value / truth - 1.0)


# -- the scaled surface is the exact surface of the scaled patch --------------------------------


@pytest.mark.parametrize("shape", SHAPES)
def test_a_scaled_surface_is_the_exact_surface_of_the_scaled_patch(shape):
    nominal, truth = SHAPES[shape](), SHAPES[shape](scale=1.7, mu=1.3 * MU)
    center = SUPPORTS.mean(axis=0) if shape == "three points" else (0.0, 0.0)
    scaled = ScaledSurface(nominal=nominal, friction_scale=1.3, length_scale=1.7, center=center)
    rng = np.random.default_rng(0)
    twists = rng.normal(size=(40, 3)) / np.array([1.0, 1.0, truth.characteristic_length])
    loads = truth.load(twists) * rng.uniform(0.5, 1.5, size=(40, 1))
    np.testing.assert_allclose(scaled.safety_factor(loads), truth.safety_factor(loads),
                               rtol=1e-9)  # fmt: skip
    np.testing.assert_allclose(scaled.motion(loads), truth.motion(loads), rtol=1e-7, atol=1e-9)
    np.testing.assert_allclose(scaled.load(twists), truth.load(twists), rtol=1e-10, atol=1e-14)
    np.testing.assert_allclose(scaled.support(twists), truth.support(twists), rtol=1e-12)
    for name in ("max_force", "max_moment", "characteristic_length"):
        assert getattr(scaled, name) == pytest.approx(getattr(truth, name), rel=1e-12)
    assert scaled.mu == pytest.approx(1.3 * MU, rel=1e-15)
    assert np.array_equal(scaled.contains(loads), truth.safety_factor(loads) >= 1.0 - 1e-9)


def test_a_patch_off_the_origin_is_scaled_about_its_centre():
    field = pressure.rectangle(*RECTANGLE).rotated(0.4).shifted(0.03, -0.02)
    scaled_field = pressure.rectangle(0.6 * RECTANGLE[0], 0.6 * RECTANGLE[1])
    truth = LimitSurface(scaled_field.rotated(0.4).shifted(0.03, -0.02), mu=0.8 * MU)
    scaled = ScaledSurface(nominal=LimitSurface(field, mu=MU), friction_scale=0.8,
                           length_scale=0.6, center=(0.03, -0.02))  # fmt: skip
    loads = truth.sample(50)
    np.testing.assert_allclose(scaled.safety_factor(loads), 1.0, rtol=1e-9)
    np.testing.assert_allclose(scaled.motion(loads), truth.motion(loads), rtol=1e-7, atol=1e-9)


# -- the estimator ---------------------------------------------------------------------------------


@pytest.mark.parametrize("shape", SHAPES)
def test_noise_free_onsets_on_the_nominal_leave_the_estimate_in_place(shape):
    # The only error left is the interpolation of the nominal's tabulated shape (radial error
    # at most about 1e-3, on the edges of the 10:1 rectangle; 6e-5 root-mean-square).
    nominal = SHAPES[shape]()
    estimator = feed(SlipEstimator(nominal), onsets(nominal, 200, seed=1, noise=0.0), twists=True)
    assert estimator.accepted == 200
    assert relative_error(estimator.mu, MU) < 5e-4
    assert relative_error(estimator.rho, SlipEstimator(nominal).rho) < 1e-3


@pytest.mark.parametrize("shape", SHAPES)
def test_the_estimate_converges_from_a_wrong_start(shape):
    # Start at twice the friction and 0.6 times the patch; onsets with 3 % force noise.
    true, nominal = SHAPES[shape](), SHAPES[shape](scale=0.6, mu=2.0 * MU)
    estimator = SlipEstimator(nominal, noise=FORCE_NOISE)
    assert relative_error(estimator.mu, MU) == pytest.approx(1.0)
    start = (estimator.mu_std, estimator.rho_std)
    feed(estimator, onsets(true, 400, seed=2))
    rho = SlipEstimator(true).rho
    assert relative_error(estimator.mu, MU) < 0.01
    assert relative_error(estimator.rho, rho) < 0.02
    # The stated uncertainty covers the error and has shrunk.
    assert abs(estimator.mu - MU) < 3.0 * estimator.mu_std
    assert abs(estimator.rho - rho) < 3.0 * estimator.rho_std
    assert estimator.mu_std < 0.05 * start[0] and estimator.rho_std < 0.05 * start[1]
    assert estimator.rejected == dict.fromkeys(estimator.rejected, 0)


def test_the_uncertainty_shrinks_as_one_over_the_root_of_the_sample_count():
    estimator, variances = SlipEstimator(disk()), []
    loads, normal_forces, _ = onsets(disk(), 1000, seed=3)
    for k in range(1000):
        estimator.update(loads[k], normal_forces[k])
        variances.append(np.diag(estimator.covariance))
    variances = np.array(variances)
    assert np.all(np.diff(variances, axis=0) <= 0.0)
    np.testing.assert_allclose(variances[999] / variances[99], 0.1, rtol=0.3)


def test_twists_separate_mu_from_rho_when_the_load_direction_does_not_change():
    # Every onset slides about the same centre of rotation: the loads alone fix only one
    # combination of log mu and log rho; the twists' elevations fix rho.
    true, nominal = rectangle(), rectangle(scale=0.6, mu=2.0 * MU)
    rng = np.random.default_rng(4)
    twist = np.array([0.3, -0.2, 1.0 / true.characteristic_length])
    normal_forces = rng.uniform(2.0, 20.0, 200)
    loads = true.load(twist) * normal_forces[:, None]
    loads = loads * (1.0 + FORCE_NOISE * rng.normal(size=(200, 3)))
    twists = twist * (1.0 + math.radians(3.0) * rng.normal(size=(200, 3)))
    samples = (loads, normal_forces, twists)
    with_twists = feed(SlipEstimator(nominal, twist_noise=math.radians(5.0)), samples, twists=True)
    without = feed(SlipEstimator(nominal), samples)
    rho = SlipEstimator(true).rho
    assert relative_error(with_twists.mu, MU) < 0.01
    assert relative_error(with_twists.rho, rho) < 0.01
    assert abs(with_twists.rho - rho) < 3.0 * with_twists.rho_std < 0.03 * rho
    assert relative_error(without.mu, MU) > 0.05 and relative_error(without.rho, rho) > 0.05
    assert without.rho_std > 0.05 * rho


@pytest.mark.parametrize("new_mu", [0.7, 0.35])
def test_forgetting_tracks_a_step_change_of_mu(new_mu):
    # 300 onsets at mu = 0.5, then 300 at new_mu. A drop puts the onsets inside the surface:
    # they are rejected until ageing widens the gate.
    before = onsets(disk(), 300, seed=5)
    after = onsets(disk(mu=new_mu), 300, seed=6)
    tracking, fixed = SlipEstimator(disk(), forgetting=0.95), SlipEstimator(disk())
    for estimator in (tracking, fixed):
        feed(estimator, before)
        assert relative_error(estimator.mu, MU) < 0.01
        feed(estimator, after)
    assert relative_error(tracking.mu, new_mu) < 0.02
    assert relative_error(fixed.mu, new_mu) > 0.15


def test_rejected_samples_are_counted_by_reason_and_leave_the_estimate_alone():
    estimator = feed(SlipEstimator(disk()), onsets(disk(), 100, seed=7))
    state = (estimator.mu, estimator.rho, estimator.covariance)
    inside = 0.5 * disk().load([1.0, 0.0, 0.0])
    bad = [
        ([math.nan, 0.1, 0.0], 1.0, None, "not finite"),
        ([0.3, 0.1, 0.0], math.inf, None, "not finite"),
        ([0.6, 0.0, 0.0], 1.0, [1.0, math.nan, 0.0], "not finite"),
        ([0.6, 0.0, 0.0], 0.0, None, "normal force"),
        ([0.6, 0.0, 0.0], -2.0, None, "normal force"),
        ([0.6, 0.0, 0.0], 1.0, [-1.0, 0.0, 0.0], "twist"),
        ([0.6, 0.0, 0.0], 1.0, [0.0, 0.0, 0.0], "twist"),
        (inside, 1.0, None, "inside"),
        ([0.0, 0.0, 0.0], 1.0, None, "inside"),
    ]
    for load, normal_force, twist, reason in bad:
        assert estimator.update(load, normal_force, twist=twist) == reason
    assert estimator.rejected == {"not finite": 3, "normal force": 2, "twist": 2, "inside": 2}
    assert estimator.accepted == 100
    assert (estimator.mu, estimator.rho) == state[:2]
    assert np.array_equal(estimator.covariance, state[2])
    assert estimator.update(disk().load([1.0, 0.0, 0.0]), 1.0) == "accepted"


@pytest.mark.parametrize(
    ("arguments", "options"),
    [((disk(),), {"forgetting": 0.0}), ((disk(),), {"forgetting": 1.01}),
     ((disk(),), {"noise": 0.0}), ((disk(),), {"twist_noise": -1.0}),
     ((disk(),), {"prior_std": math.nan}), ((disk(),), {"resolution": 4}),
     ((disk(mu=0.0),), {}), ((Cone(mu=MU, rho=0.01),), {}),
     ((Ellipsoid(mu=0.0, rho=0.01),), {})],
)  # fmt: skip
def test_bad_estimator_options_are_rejected_with_a_message(arguments, options):
    with pytest.raises(InvalidArgumentError):
        SlipEstimator(*arguments, **options)


@pytest.mark.parametrize(("load", "twist"), [([1.0, 2.0], None), ("abc", None),
                                             ([1.0, 0.0, 0.0], [1.0, 0.0])])  # fmt: skip
def test_a_malformed_sample_raises_instead_of_counting(load, twist):
    with pytest.raises(InvalidArgumentError):
        SlipEstimator(disk()).update(load, 1.0, twist=twist)


def test_the_estimated_surface_agrees_with_the_true_surface():
    true = rectangle(scale=1.25, mu=0.4)
    estimator = feed(SlipEstimator(rectangle(), noise=FORCE_NOISE), onsets(true, 400, seed=8))
    surface = estimator.surface
    assert isinstance(surface, ScaledSurface)
    loads = true.sample(200) * 0.7
    bound = 3.0 * (estimator.mu_std / estimator.mu + estimator.rho_std / estimator.rho)
    ratio = surface.safety_factor(loads) / true.safety_factor(loads)
    assert np.max(np.abs(ratio - 1.0)) < bound < 0.03
    step = {"contact": [-0.05, 0.002], "normal": [1.0, 0.0], "velocity": [1.0, 0.2], "mu": 0.3}
    pushed, reference = push_step(surface, **step), push_step(true, **step)
    assert pushed.mode == reference.mode
    assert np.linalg.norm(pushed.twist - reference.twist) < 0.02 * np.linalg.norm(reference.twist)
    # Free sliding through the forward map: where the body comes to rest.
    sliding = {"mass": 1.0, "inertia": 1e-3, "twist0": [0.5, 0.1, 5.0], "duration": 0.3}
    rest, reference_rest = slide(surface, **sliding).poses[-1], slide(true, **sliding).poses[-1]
    np.testing.assert_allclose(rest, reference_rest, rtol=0.01)


TILTED = {"tilt": (0.1, -0.05), "center": (0.01, 0.004), "normal_force": 3.0}
FITTED_MATRIX = [[1.1, 0.1, 0.2], [0.1, 0.9, -0.1], [0.2, -0.1, 1.2]]


@pytest.mark.parametrize(
    ("model", "shape"),
    [(Ellipsoid, TILTED), (FittedEllipsoid, {"matrix": FITTED_MATRIX, "center": (-0.01, 0.0)})],
)
def test_an_ellipsoid_nominal_converges_to_the_true_ellipsoid(model, shape):
    true = model(mu=0.4, rho=0.012, **shape)
    nominal = model(mu=0.8, rho=0.007, **shape)
    samples = onsets(true, 400, seed=9, twist_noise=math.radians(5.0))
    estimator = feed(SlipEstimator(nominal, twist_noise=math.radians(5.0)), samples, twists=True)
    surface = estimator.surface
    assert isinstance(surface, model)
    for name, value in shape.items():
        assert np.array_equal(getattr(surface, name), value)
    assert surface.mu == pytest.approx(0.4, rel=0.01)
    assert surface.rho == pytest.approx(0.012, rel=0.01)


def test_an_update_keeps_no_memory_of_past_samples():
    """A recursive estimator: 50,000 more samples leave its memory as it was (a cost growing
    with the samples would keep them; even 8 bytes each would be 400 kB)."""
    estimator = SlipEstimator(disk(), forgetting=0.99)
    loads, normal_forces, _ = onsets(disk(), 2000, seed=10)
    samples = list(zip(loads.tolist(), normal_forces.tolist(), strict=True))

    def batch():
        for load, normal_force in samples:
            estimator.update(load, normal_force)

    batch()
    tracemalloc.start()
    try:
        batch()
        early, _ = tracemalloc.get_traced_memory()
        for _ in range(25):
            batch()
        late, _ = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    assert estimator.accepted + sum(estimator.rejected.values()) == 54_000
    assert late - early < 32_000
