"""The compiled disk terms (uniform, Hertz, parabolic, ring, annulus) against the NumPy/SciPy
closed forms of :class:`DiskKernel` and against the independent polar quadrature of
``test_disk_kernel_hessian``; their one-argument functions against ``scipy.special.hyp2f1``.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from reference import rotation
from scipy.special import hyp2f1
from test_disk_kernel_hessian import CENTRES, KERNELS, PRESSURE, RADIUS, polar_hessian
from test_disk_kernel_hessian import twists_near_and_far as shared_twists

from fixplan.surface.compiled_inverse import compile_kernel
from fixplan.surface.disk_compiled import _DISK_TERMS, PROFILES, jet

VALUE_RTOL = 1e-13  # h and the load, relative to their scale (both are closed forms to rounding)
HESSIAN_RTOL = 1e-10  # the Hessian against the quadrature (relative to its largest entry)
DERIVATIVE_RTOL = 1e-12  # the slopes against hyp2f1 (finite on the rim: c - a - b = c > 0)

#: ``c`` of ``F = ₂F₁(-1/2, -1/2; c; z)`` per profile (the function outside the disk).
OUTSIDE_C = {"uniform": 2.0, "hertz": 2.5, "parabolic": 3.0, "ring": 1.0}


def compiled_terms(kernel, twists):
    """``h``, loads ``(K, 3)`` and Hessians ``(K, 3, 3)`` of the compiled disk table."""
    tables = compile_kernel(kernel).parts[6]  # (one part: its table is the whole, 3 rows)
    table = np.ascontiguousarray(tables[:3])
    out = np.empty(10)
    h, loads, hessians = np.empty(len(twists)), np.empty((len(twists), 3)), []
    for k, (vx, vy, w) in enumerate(twists):
        _DISK_TERMS(table, vx, vy, w, True, out)
        h[k], loads[k] = out[0], out[1:4]
        a, b, c, d, e, f = out[4:]
        hessians.append([[a, b, c], [b, d, e], [c, e, f]])
    return h, loads, np.array(hessians)


def twists_near_and_far(rng):
    """The shared twists, and centres of rotation within 1e-12 to 1e-6 radii of the rim."""
    gap = np.array([-1e-6, -1e-9, -1e-12, 1e-12, 1e-9, 1e-6])
    angle = rng.uniform(0.0, 2.0 * math.pi, len(gap))
    cors = RADIUS * (1.0 + gap)[:, None] * np.column_stack([np.cos(angle), np.sin(angle)])
    rim = [rotation(c, s) for c, s in zip(cors, rng.choice([-1.7, 0.8], len(gap)), strict=True)]
    return np.vstack([shared_twists(rng), rim])


@pytest.mark.parametrize("name", KERNELS)
def test_compiled_disk_values_and_loads_are_the_closed_forms(name):
    kernel = KERNELS[name]
    twists = twists_near_and_far(np.random.default_rng(4))
    h, loads, _ = compiled_terms(kernel, twists)
    reference_h, reference_loads = kernel.evaluate(twists)
    np.testing.assert_allclose(h, reference_h, rtol=VALUE_RTOL)
    scale = np.abs(reference_loads[:, :2]).sum(axis=1) + np.abs(reference_loads[:, 2]) / RADIUS
    error = np.abs(loads - reference_loads) / scale[:, None] * [1.0, 1.0, 1.0 / RADIUS]
    assert np.max(error) <= VALUE_RTOL


@pytest.mark.parametrize("profile", PRESSURE)
@pytest.mark.parametrize("centre", CENTRES)
def test_compiled_disk_hessian_is_the_polar_quadrature_of_the_integral(profile, centre):
    c = RADIUS * np.asarray(centre)
    reference = polar_hessian(profile, c)
    scale = np.max(np.abs(reference))
    twists = np.array([rotation(c, spin) for spin in (1.0, -2.5)])
    _, _, hessians = compiled_terms(KERNELS[profile], twists)
    for spin, hessian in zip((1.0, -2.5), hessians, strict=True):
        np.testing.assert_allclose(hessian, reference / abs(spin), rtol=0.0,
                                   atol=HESSIAN_RTOL * scale / abs(spin))  # fmt: skip


@pytest.mark.parametrize("profile", PROFILES)
def test_the_outside_function_and_its_slopes_are_the_hypergeometric_series(profile):
    row = 2 * PROFILES.index(profile)
    c = OUTSIDE_C[profile]
    z = np.concatenate([np.linspace(0.0, 0.999, 1000), 1.0 - np.logspace(-15, -3, 40)])
    values = np.array([jet(row, x, 1.0 - x) for x in z])
    np.testing.assert_allclose(values[:, 0], hyp2f1(-0.5, -0.5, c, z), rtol=VALUE_RTOL)
    slope = hyp2f1(0.5, 0.5, c + 1.0, z) / (4.0 * c)
    np.testing.assert_allclose(values[:, 1], slope, rtol=DERIVATIVE_RTOL)
