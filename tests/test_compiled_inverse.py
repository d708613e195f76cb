"""The compiled inverse map gives the answers of the NumPy path it replaces (damped Newton, facet
tests and continuation in ``fixplan.surface.inverse``) for every kind of load: from twists,
random directions and sizes, on and next to facets (both sides of a kink), near pure moments,
far outside and deep inside; for point supports, polygons, posed polygons and tactile grids."""

from __future__ import annotations

import math

import numpy as np
import pytest
from conftest import SURFACES as SHARED_SURFACES

from fixplan import ConvergenceError, pressure
from fixplan.surface.compiled_inverse import compile_kernel, not_converged
from fixplan.surface.disk_kernel import DiskKernel
from fixplan.surface.inverse import solve
from fixplan.surface.kernels import PosedKernel, SumKernel
from fixplan.surface.limit_surface import COMPILED_SUPPORT_MAX_TWISTS, LimitSurface
from fixplan.surface.point_kernel import PointSetKernel

SAFETY_RTOL = 1e-12  # both run Newton to 1e-12 on the twist: s agrees to about its square
MOTION_RAD = 1e-9  # ... and the motions to about that angle

rng0 = np.random.default_rng(11)
CLOUD = rng0.uniform(-0.05, 0.05, size=(300, 2))
#: The field of benchmarks/bench_limit_surface.py: next to its facets Newton's decrement stalls
#: on the way into a kink and the compiled path stops there early (STALLED_DECREMENT).
DENSE_CLOUD = np.random.default_rng(1).uniform(-0.05, 0.05, size=(4096, 2))

#: The shared surfaces the compiled path covers (points, polygons, grids, disks), and more.
SURFACES = {
    name: SHARED_SURFACES[name]
    for name in (
        "three points",
        "rectangle 10:1",
        "rotated shifted rectangle",
        "tactile grid",
        "uniform disk",
        "hertz disk",
        "parabolic disk",
        "annulus",
        "ring",
    )
} | {
    "shifted Hertz disk": lambda: LimitSurface(
        pressure.disk(0.005, "hertz").shifted(0.01, -0.004), mu=0.5, normal_force=3.0
    ),
    "300 weighted points": lambda: LimitSurface(
        pressure.points(CLOUD, rng0.uniform(0.2, 2.0, len(CLOUD))), mu=0.4, normal_force=80.0
    ),
    "4,096 points": lambda: LimitSurface(pressure.points(DENSE_CLOUD), mu=0.5, normal_force=100.0),
    "shifted points": lambda: LimitSurface(
        pressure.points([[0.0, 0.0], [0.04, 0.01], [0.01, 0.03]], [2.0, 1.0, 1.5]).shifted(
            0.02, -0.01
        ),
        mu=0.7,
        normal_force=5.0,
    ),
}


def numpy_path(surface, loads):
    """Safety factors and SI twists of nonzero ``loads`` by the NumPy path, normalised as
    ``LimitSurface`` does."""
    units = np.array([surface.max_force, surface.max_force, surface.max_moment])
    size = np.max(np.abs(loads / units), axis=1)
    result = solve(surface._kernel, surface._scale, loads / size[:, None], units)
    return result.safety_factor / size, result.twist


def distributions(surface, rng):
    """name: loads ``(n, 3)`` of each distribution of the benchmark."""
    rho = surface.characteristic_length
    twists = rng.normal(size=(12, 3)) * [1.0, 1.0, 1.0 / rho]
    directions = rng.normal(size=(12, 3)) * [1.0, 1.0, rho]
    loads = {
        "from twists": surface.load(twists),
        "random directions and sizes": directions
        * surface.max_force
        * rng.uniform(0.01, 100.0, (12, 1)),
        "near pure moment": surface.load([0.0, 0.0, 1.0]) + directions * 1e-7 * surface.max_force,
        "far outside": surface.load(twists) * 1e6,
        "deep inside": surface.load(twists) * 1e-6,
    }
    points = surface._kernel.facets[0]
    if len(points):
        k = rng.integers(0, len(points), 12)
        offsets = rng.normal(size=(12, 2)) * 1e-7 * rho
        near = surface.load_at_cor(points[k] + offsets) * rng.uniform(0.5, 1.5, (12, 1))
        on = surface.load_at_cor(points[k]) * rng.uniform(0.5, 1.5, (12, 1))
        loads["next to facets"] = np.concatenate([near, -near])
        loads["on facets"] = on
    return loads


CASES = [(name, kind) for name in SURFACES for kind in ("single", "batch")]


@pytest.mark.parametrize(("name", "how"), CASES)
def test_the_compiled_path_gives_the_answers_of_the_numpy_path(name, how):
    surface = SURFACES[name]()
    assert surface._compiled is not None
    rng = np.random.default_rng(5)
    for distribution, loads in distributions(surface, rng).items():
        expected_safety, expected_twists = numpy_path(surface, loads)
        if how == "single":
            pairs = [surface.motion_and_safety_factor(load) for load in loads]
            motions = np.array([m for m, _ in pairs])
            safety = np.array([s for _, s in pairs])
        else:
            motions, safety = surface.motion_and_safety_factor(loads)
        np.testing.assert_allclose(safety, expected_safety, rtol=SAFETY_RTOL, err_msg=distribution)
        assert np.max(angles(surface, motions, expected_twists)) <= MOTION_RAD, distribution


def angles(surface, twists, reference):
    """Angles [rad] between twists and reference twists, moments scaled by the surface's size."""
    rho = surface.characteristic_length
    a = twists * [1.0, 1.0, rho]
    b = reference * [1.0, 1.0, rho]
    return np.arctan2(np.linalg.norm(np.cross(a, b), axis=1), np.einsum("ij,ij->i", a, b))


@pytest.mark.parametrize("name", sorted(SURFACES))
def test_a_start_twist_moves_where_newton_starts_not_the_answer(name):
    # The planner's exact models start the inverse map from the ellipsoid normal of the last
    # solve; good, poor and useless starts (no positive work on the load) all give the answer.
    surface = SURFACES[name]()
    rng = np.random.default_rng(6)
    loads = np.concatenate(list(distributions(surface, rng).values()))
    expected_safety, expected_twists = numpy_path(surface, loads)
    units = np.array([surface.max_force, surface.max_force, surface.max_moment])
    rho = surface.characteristic_length
    noise = rng.normal(size=loads.shape) * [1.0, 1.0, 1.0 / rho]
    sizes = np.linalg.norm(expected_twists * [1.0, 1.0, rho], axis=1, keepdims=True)
    starts = {
        "the answers, scaled": expected_twists * rng.uniform(1e-3, 1e3, (len(loads), 1)),
        "the answers, 10 % off": expected_twists + 0.1 * sizes * noise,
        "the answers, reversed": -expected_twists,
        "zero": np.zeros_like(loads),
    }
    for what, start in starts.items():
        safety, twists = surface._compiled.solve(loads, units, surface._scale, start)
        np.testing.assert_allclose(safety, expected_safety, rtol=SAFETY_RTOL, err_msg=what)
        assert np.max(angles(surface, twists, expected_twists)) <= MOTION_RAD, what


#: The Hessians Newton hands over: computed at the answer, or (a full step in the quadratic
#: region ended the iteration) at the iterate before, a relative step of about 1e-6 away.
HANDED_OVER_RTOL = 2e-5


@pytest.mark.parametrize("name", sorted(SURFACES))
def test_newton_hands_over_the_hessians_at_its_answers(name):
    # The planner's osculating ellipsoids take the support's curvature at each answer from the
    # inverse map instead of evaluating it again; facets and kinks (no Hessian from Newton)
    # are evaluated at their twists.
    surface = SURFACES[name]()
    rng = np.random.default_rng(9)
    found = distributions(surface, rng)
    loads = np.concatenate(list(found.values()))
    units = np.array([surface.max_force, surface.max_force, surface.max_moment])
    handed = np.empty((len(loads), 3, 3))
    safety, twists = surface._compiled.solve(loads, units, surface._scale, None, handed)
    expected_safety, expected_twists = surface._compiled.solve(loads, units, surface._scale)
    np.testing.assert_array_equal(safety, expected_safety)
    np.testing.assert_array_equal(twists, expected_twists)
    # Newton's own answers carry their Hessians (point supports: those off the kinks).
    from_twists = np.isnan(handed[: len(found["from twists"]), 0, 0])
    assert not from_twists.all() if surface.has_facets else not from_twists.any()
    if "on facets" in found:
        assert np.isnan(handed[-len(found["on facets"]) :]).all()
    reference = surface._trusted_hessians(twists)
    safety, twists, hessians = surface._trusted_inverse_and_hessians(loads)
    np.testing.assert_array_equal(twists, expected_twists)
    size = np.abs(reference).max(axis=(1, 2))
    gap = np.abs(hessians - reference).max(axis=(1, 2)) / size
    assert gap.max() <= HANDED_OVER_RTOL
    missing = np.isnan(handed[:, 0, 0])
    np.testing.assert_array_equal(hessians[missing], reference[missing])


@pytest.mark.parametrize("name", sorted(SURFACES))
def test_small_batches_of_the_support_function_give_the_numpy_kernels_values(name):
    # Up to COMPILED_SUPPORT_MAX_TWISTS twists the compiled kernel answers, one at a time.
    surface = SURFACES[name]()
    rng = np.random.default_rng(8)
    rho = surface.characteristic_length
    twists = rng.normal(size=(COMPILED_SUPPORT_MAX_TWISTS, 3)) * [1, 1, 1 / rho]
    twists[:3] = [[0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, -2.0, 0.0]]
    expected = surface._scale * surface._kernel.support(twists)
    np.testing.assert_allclose(surface.support(twists), expected, rtol=1e-13)
    assert surface.support(twists[5]) == pytest.approx(expected[5], rel=1e-13)
    assert surface.support([0.0, 0.0, 0.0]) == 0.0
    many = np.vstack([np.zeros(3), twists, twists])  # (more than compiled: the NumPy kernels)
    assert surface.support(many)[0] == 0.0
    np.testing.assert_allclose(surface.support(many)[1:], np.tile(expected, 2), rtol=1e-13)


def test_zero_loads_in_a_batch_are_held_with_no_motion():
    surface = SURFACES["three points"]()
    loads = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 0.0]])
    motions, safety = surface.motion_and_safety_factor(loads)
    assert safety[0] == math.inf and safety[2] == math.inf
    assert np.all(np.isnan(motions[[0, 2]]))
    assert np.all(np.isfinite(motions[1])) and math.isfinite(safety[1])


def test_kernels_with_a_part_without_a_compiled_form_keep_the_numpy_path():
    points = PointSetKernel(np.array([[0.0, 0.0], [0.01, 0.0]]), np.array([0.5, 0.5]), True)
    disk = DiskKernel(0.01, "uniform")
    pose = pressure.disk(0.01).shifted(0.01, 0.0).pose
    varying = LimitSurface(pressure.disk(0.01), mu=lambda x, y: 0.3 + 0.0 * x)._kernel
    assert compile_kernel(points.smoothed(1e-3)) is None
    assert compile_kernel(SumKernel((disk, varying), (1.0, 1.0))) is None
    for kernel in (points, disk, PosedKernel(disk, pose), PosedKernel(points, pose),
                   SumKernel((disk, points), (1.0, 2.0))):  # fmt: skip
        assert compile_kernel(kernel) is not None


def test_the_convergence_error_names_the_load_and_what_to_do():
    error = not_converged(np.array([1.0, 2.0, 3.0]), 0.01)
    assert isinstance(error, ConvergenceError)
    assert "[1.0, 2.0, 3.0]" in str(error) and "LimitSurface.combine" in str(error)


def test_the_terms_next_to_a_facet_are_its_points_taylor_expansion_and_the_kinks_own():
    """Where Newton leaves the kink of a support point (``_escape_kink``), its first terms are
    the other points' by Taylor's formula at the facet's twist plus the point's own: against a
    pass over the 4,096 points at twists 1e-7 to 1e-5 of the facet's away (relative steps
    ``d``), the value to 1e-11, the gradient to ``1e4 d²`` and the Hessian (the other points'
    taken at the facet) to ``1e3 d``, relative to their largest entries (seen: 2e-12,
    ``3900 d²`` and ``130 d``: points near the kink's curve steeply)."""
    from fixplan.surface import compiled_inverse as compiled

    surface = SURFACES["4,096 points"]()
    kernel = surface._compiled.parts
    rng = np.random.default_rng(5)
    for k in (17, 300, 2000):
        load = surface.load_at_cor(DENSE_CLOUD[k] + [3e-9, -2e-9])
        facet, rest, exact, estimate = np.empty(3), np.empty(10), np.empty(10), np.empty(10)
        compiled._facet(kernel, load, 1.0, k, facet, True, rest)
        hess = np.empty((3, 3))
        compiled._unpack(rest, hess)
        for size in (1e-7, 1e-6, 1e-5):
            twist = facet + size * np.linalg.norm(facet) * rng.normal(size=3) / math.sqrt(3.0)
            compiled._terms_near_facet(kernel, k, facet, rest, hess, twist, estimate)
            compiled._terms(kernel, 0.0, twist, True, np.empty(10), exact)
            assert estimate[0] == pytest.approx(exact[0], rel=1e-11)
            gradient, hessian = np.abs(exact[1:4]).max(), np.abs(exact[4:]).max()
            assert np.abs(estimate[1:4] - exact[1:4]).max() <= 1e4 * size**2 * gradient
            assert np.abs(estimate[4:] - exact[4:]).max() <= 1e3 * size * hessian
