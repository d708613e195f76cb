"""FunctionKernel's analytic Hessians against the closed forms, against central differences of
its gradient and against the laws every support function's Hessian obeys; and the inverse map
that Newton runs on them, on a field whose rules' gradient does not match its exact Hessian.

The closed forms are independent: the edge sums of a uniform polygon
(:class:`~fixplan.surface.closed_form.EdgeSumKernel`) and the disk kernels
(:class:`~fixplan.surface.disk_kernel.DiskKernel`), each with its own analytic Hessian.
"""

from __future__ import annotations

import numpy as np
import pytest
from polygon_cells import edge_sum_kernel
from reference import central_differences, rotation

from fixplan import LimitSurface, pressure
from fixplan.surface.disk_kernel import DiskKernel
from fixplan.surface.function_kernel import FunctionKernel
from fixplan.surface.kernels import SupportKernel

CLOSED_FORM_RTOL = 1e-9  # relative to the largest entry (measured: 3e-14 disk, 8e-12 rectangle)
#: A ring's Hessian with the centre of rotation 1e-9 and 1e-7 radii off it (measured: 1.2e-7,
#: the closed form within 3e-9 of a 30-digit quadrature): near ``c`` the circle's rule maps its
#: arc so that ``h`` and the loads are entire in the sinh variable ``τ``, but the Hessian's
#: ``ê êᵀ`` has poles at ``τ = ±iπ/2``, which its Gauss panels of width 4 resolve to about 1e-7.
#: (The Hessian only steers Newton; the answers are fixed by the gradient.)
RING_RTOL = 1e-6
DIFFERENCE_RTOL = 1e-6  # against central differences of the rules' gradient (steps of 1e-5)
STEP = 1e-5

A, B = 0.5, 0.05  # a 1 m x 0.1 m rectangle
RECTANGLE = np.array([[-A, -B], [A, -B], [A, B], [-A, B]])
RECTANGLE_CORS = [(0.0, 0.0), (0.31, 0.012), (0.2, B), (A, B), (0.2, B + 1e-7), (0.8, 0.3),
                  (3.0, 2.0)]  # fmt: skip
RADIUS = 0.02
DISK_CORS = [0.0, 0.45, 1.0 - 1e-9, 1.0 + 1e-7, 1.7, 9.0]  # distances in radii


def twists_about(cors) -> np.ndarray:
    """Rotations both ways about each centre, and a translation."""
    rows = [rotation(np.asarray(c), spin) for c in cors for spin in (1.0, -2.5)]
    return np.vstack([*rows, [0.3, -0.4, 0.0]])


def disk_cors() -> list:
    return [u * RADIUS * np.array([np.cos(1.1), np.sin(1.1)]) for u in DISK_CORS]


def largest_error(hessians, reference) -> float:
    scale = np.max(np.abs(reference), axis=(1, 2))
    return float(np.max(np.max(np.abs(hessians - reference), axis=(1, 2)) / scale))


def test_a_uniform_rectangle_has_the_hessians_of_its_edge_sums():
    kernel = FunctionKernel((("polygon", RECTANGLE, 1.0),))
    twists = twists_about(RECTANGLE_CORS)
    exact = edge_sum_kernel([(RECTANGLE, 1.0)]).hessian(twists)
    assert largest_error(kernel.hessian(twists), exact) < CLOSED_FORM_RTOL


@pytest.mark.parametrize("profile", ["uniform", "hertz", "ring"])
def test_disks_and_a_ring_have_the_hessians_of_their_closed_forms(profile):
    regions = (("circle" if profile == "ring" else "disk", RADIUS, 1.0),)
    hertz = lambda x, y: np.sqrt(np.clip(1.0 - (x * x + y * y) / RADIUS**2, 0.0, None))  # noqa: E731
    kernel = FunctionKernel(regions, pressure=hertz if profile == "hertz" else None)
    twists = twists_about(disk_cors())
    exact = DiskKernel(RADIUS, profile).hessian(twists)
    tolerance = RING_RTOL if profile == "ring" else CLOSED_FORM_RTOL
    assert largest_error(kernel.hessian(twists), exact) < tolerance


L_SHAPE = 0.01 * np.array([[0, 0], [4, 0], [4, 1], [1, 1], [1, 3], [0, 3]]) - 0.01
SMOOTH_FIELDS = {
    "L shape, varying pressure and friction": FunctionKernel(
        (("polygon", L_SHAPE, 1.0),),
        pressure=lambda x, y: 1.0 + 20.0 * x + 300.0 * y * y,
        friction=lambda x, y: 0.5 - 5.0 * x * y,
    ),
    "disk, tilted pressure": FunctionKernel(
        (("disk", RADIUS, 1.0),), pressure=lambda x, y: 1.0 + 30.0 * x
    ),
    "annulus of two disks": FunctionKernel((("disk", RADIUS, 1.0), ("disk", 0.6 * RADIUS, -1.0))),
}


@pytest.mark.parametrize("name", SMOOTH_FIELDS)
def test_smooth_fields_obey_the_hessian_laws_and_match_differences_of_the_gradient(name):
    kernel = SMOOTH_FIELDS[name]
    rng = np.random.default_rng(3)
    twists = rng.normal(size=(12, 3)) * [1.0, 1.0, 1.0 / kernel.size]
    twists[:6, 2] *= 20.0  # centres of rotation on and next to the patch
    h, g, hessians = kernel.newton_terms(twists)
    evaluated = kernel.evaluate(twists)
    np.testing.assert_allclose(h, evaluated[0], rtol=1e-14)
    np.testing.assert_allclose(g, evaluated[1], rtol=1e-12, atol=1e-14 * np.abs(g).max())
    scale = np.max(np.abs(hessians), axis=(1, 2))
    np.testing.assert_array_equal(hessians, hessians.transpose(0, 2, 1))
    # Homogeneous of degree 1: H V = 0; convex: H >= 0.
    assert np.max(np.abs(np.einsum("kij,kj->ki", hessians, twists)).max(axis=1) / (
        scale * np.linalg.norm(twists * [1, 1, kernel.size], axis=1))) < 1e-12  # fmt: skip
    assert np.min(np.linalg.eigvalsh(hessians) / scale[:, None]) > -1e-12
    differences = np.array([central_differences(kernel, twist, STEP) for twist in twists])
    assert largest_error(hessians, differences) < DIFFERENCE_RTOL


def test_a_query_whose_rules_are_noisier_than_their_hessian_ends_at_the_noise():
    """With p = exp(-(x/a)²) on a rectangle 4a long and a centre of rotation outside it, the
    rules' gradient is within 3e-7 of the fixed rule's, and its derivative 1.2 % off the exact
    Hessian in one entry:
    Newton on the exact Hessian stalled with a decrement of 4e-12 of h and took steps of 1e-12
    for 100 iterations (about 4,000 evaluations). It now stops there, and its answer is the one
    that Newton on differences of the rules' gradient finds, to that noise."""
    field = pressure.from_function(
        pressure.rectangle(0.04, 0.01), lambda x, y: np.exp(-((x / 0.01) ** 2))
    )
    surface = LimitSurface(field, mu=0.5, normal_force=10.0)
    assert isinstance(surface._kernel, FunctionKernel)
    load = surface.load(np.array([0.03644802, 1.90801459, -31.94578014])) * 1.2
    counted = {"evaluations": 0}
    evaluate = FunctionKernel.evaluate
    terms = FunctionKernel.newton_terms

    def counting(method):
        def call(self, twists):
            counted["evaluations"] += 1
            return method(self, twists)

        return call

    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(FunctionKernel, "evaluate", counting(evaluate))
        patch.setattr(FunctionKernel, "newton_terms", counting(terms))
        motion, safety = surface.motion_and_safety_factor(load)
    assert counted["evaluations"] < 40
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(FunctionKernel, "newton_terms", SupportKernel.newton_terms)
        patch.setattr(FunctionKernel, "hessian", SupportKernel.hessian)
        by_differences, reference = surface.motion_and_safety_factor(load)
    assert safety == pytest.approx(reference, rel=1e-9)
    inside = surface.load(np.array([0.01, 0.02, 1.0])) * 0.5
    batched = surface.safety_factor(np.vstack([load, inside]))  # (the batched Newton loop)
    np.testing.assert_allclose(batched, [safety, 2.0], rtol=1e-9)
    assert safety == pytest.approx(1.0 / 1.2, rel=1e-6)  # the load is 1.2 times a surface point
    units = [1.0, 1.0, surface.characteristic_length]
    a, b = motion * units, by_differences * units
    assert np.arccos(min(a @ b / np.linalg.norm(a) / np.linalg.norm(b), 1.0)) < 1e-4
