"""The disk kernels' analytic Hessians (uniform, Hertz, parabolic, ring, annulus) against central
differences of their exact gradients and against an independent polar quadrature.

Reference: as in ``test_polygon_kernel``, about the centre of rotation ``c`` of a twist spinning
at rate ``w``

    ∇²h = (1 / |w|) ∫ g(θ) g(θ)ᵀ L(θ) dθ,    g(θ) = (cos θ, sin θ, c_x sin θ - c_y cos θ),

with ``L(θ) = ∫ p(c + r ŝ) dr`` the pressure integrated along the ray from ``c`` in direction
``ŝ = (cos θ, sin θ)``. The ray meets the circle ``|x| = R`` at ``r± = -b ± sqrt(b² - |c|² +
R²)``, ``b = c·ŝ``, and ``1 - |c + r ŝ|²/R² = (r₊ - r)(r - r₋)/R²``: with ``r = r₋ + (r₊ -
r₋)(1 - cos φ)/2`` every profile's ray integral is smooth in ``φ``. Outside the disk the rays fill
the cone ``θ = θ_c + asin((R/|c|) sin ψ)``, ``|ψ| <= π/2``, in which the integrand is smooth in
``ψ``; inside, ``L`` is smooth and periodic in ``θ``.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from reference import central_differences, rotation

from fixplan.surface.disk_kernel import AnnulusKernel, DiskKernel
from fixplan.surface.kernels import SupportKernel

RADIUS = 0.01
DIFFERENCE_RTOL = 1e-7  # analytic Hessian vs central differences of the gradient
STEP = 1e-5  # relative step of the central differences
QUADRATURE_RTOL = 1e-10  # analytic Hessian vs the polar quadrature (relative to its largest entry)
PHI_NODES, PHI_WEIGHTS = np.polynomial.legendre.leggauss(40)
PSI_NODES, PSI_WEIGHTS = np.polynomial.legendre.leggauss(200)

#: Pressure ``p(ρ²/R²)`` per unit total force on a disk of radius ``R``, of the profiles with
#: area density.
PRESSURE = {
    "uniform": lambda s: np.ones_like(s) / (math.pi * RADIUS**2),
    "hertz": lambda s: 1.5 * np.sqrt(np.clip(1.0 - s, 0.0, None)) / (math.pi * RADIUS**2),
    "parabolic": lambda s: 2.0 * np.clip(1.0 - s, 0.0, None) / (math.pi * RADIUS**2),
}


def ray_integral(profile, c, theta):
    """``L(θ)`` of the module docstring for directions ``theta`` ``(n,)``."""
    sx, sy = np.cos(theta), np.sin(theta)
    b = c[0] * sx + c[1] * sy
    disc = np.sqrt(np.clip(b * b - c @ c + RADIUS**2, 0.0, None))
    low, high = -b - disc, -b + disc
    start = np.maximum(low, 0.0)
    # φ from the start of the ray inside the disk to its exit.
    width = np.where(high > low, high - low, 1.0)
    phi0 = np.arccos(np.clip(1.0 - 2.0 * (start - low) / width, -1.0, 1.0))
    phi = phi0[:, None] + 0.5 * (math.pi - phi0)[:, None] * (PHI_NODES[None, :] + 1.0)
    weight = 0.5 * (math.pi - phi0)[:, None] * PHI_WEIGHTS[None, :]
    r = low[:, None] + 0.5 * width[:, None] * (1.0 - np.cos(phi))
    s = ((c[0] + r * sx[:, None]) ** 2 + (c[1] + r * sy[:, None]) ** 2) / RADIUS**2
    dr = 0.5 * width[:, None] * np.sin(phi)
    values = np.sum(weight * PRESSURE[profile](s) * dr, axis=1)
    return np.where(high > start, values, 0.0)


def polar_hessian(profile, c):
    """∇²h of rotation at unit rate about ``c`` by the polar quadrature of the module doc."""
    distance = math.hypot(*c)
    if distance < RADIUS:
        theta = 2.0 * math.pi * np.arange(400) / 400
        dtheta = np.full(400, 2.0 * math.pi / 400)
    else:
        psi = 0.5 * math.pi * PSI_NODES
        ratio = RADIUS / distance
        theta = math.atan2(-c[1], -c[0]) + np.arcsin(ratio * np.sin(psi))
        jacobian = ratio * np.cos(psi) / np.sqrt(1.0 - (ratio * np.sin(psi)) ** 2)
        dtheta = 0.5 * math.pi * PSI_WEIGHTS * jacobian
    length = ray_integral(profile, np.asarray(c), theta)
    g = np.column_stack([np.cos(theta), np.sin(theta), c[0] * np.sin(theta) - c[1] * np.cos(theta)])
    return np.einsum("n,ni,nj->ij", dtheta * length, g, g)


#: Centres of rotation in units of the radius: centre, inside, near the rim, outside, far.
CENTRES = [(0.0, 0.0), (0.2, -0.1), (0.45, 0.6), (0.0, 0.97), (1.03, 0.0), (-1.5, 1.1), (6.0, 8.0)]


@pytest.mark.parametrize("profile", PRESSURE)
@pytest.mark.parametrize("centre", CENTRES)
def test_the_disk_hessian_is_the_polar_quadrature_of_the_integral(profile, centre):
    kernel = DiskKernel(RADIUS, profile)
    c = RADIUS * np.asarray(centre)
    reference = polar_hessian(profile, c)
    scale = np.max(np.abs(reference))
    for spin in (1.0, -2.5):  # ∇²h is homogeneous of degree -1 in the twist
        hessian = kernel.hessian(rotation(c, spin)[None, :])[0]
        np.testing.assert_allclose(hessian, reference / abs(spin), rtol=0.0,
                                   atol=QUADRATURE_RTOL * scale / abs(spin))  # fmt: skip


KERNELS = {
    "uniform": DiskKernel(RADIUS, "uniform"),
    "hertz": DiskKernel(RADIUS, "hertz"),
    "parabolic": DiskKernel(RADIUS, "parabolic"),
    "ring": DiskKernel(RADIUS, "ring"),
    "annulus": AnnulusKernel(RADIUS, 0.6 * RADIUS),
}


def twists_near_and_far(rng):
    """Random twists, pure translations and rotations, and centres of rotation on both sides of
    the parabolic series' switch (u = 0.3) and near (not on) the rim."""
    u = np.array([0.0, 0.1, 0.29, 0.31, 0.6, 0.95, 1.05, 2.0, 5.0, 40.0])
    angle = rng.uniform(0.0, 2.0 * math.pi, len(u))
    cors = RADIUS * u[:, None] * np.column_stack([np.cos(angle), np.sin(angle)])
    spins = rng.choice([-1.7, 0.8], len(u))
    return np.vstack([
        rng.normal(size=(20, 3)) * [1.0, 1.0, 3.0 / RADIUS],
        [[1.0, 0.0, 0.0], [0.3, -0.8, 0.0], [0.0, 0.0, 2.0], [0.0, 0.0, -1.0]],
        [rotation(c, s) for c, s in zip(cors, spins, strict=True)],
    ])  # fmt: skip


@pytest.mark.parametrize("name", KERNELS)
def test_the_disk_hessian_is_the_derivative_of_the_exact_gradient(name):
    kernel = KERNELS[name]
    twists = twists_near_and_far(np.random.default_rng(3))
    h, gradient, hessian = kernel.newton_terms(twists)
    reference_h, reference_gradient = kernel.evaluate(twists)
    np.testing.assert_array_equal(h, reference_h)
    np.testing.assert_array_equal(gradient, reference_gradient)
    for twist, analytic in zip(twists, hessian, strict=True):
        reference = central_differences(kernel, twist, STEP)
        scale = np.max(np.abs(reference))
        np.testing.assert_allclose(analytic, reference, rtol=0.0, atol=DIFFERENCE_RTOL * scale)
        np.testing.assert_array_equal(analytic, analytic.T)
        # h is homogeneous of degree one: the Hessian annuls the twist.
        np.testing.assert_allclose(
            analytic @ twist, 0.0, atol=1e-12 * scale * np.linalg.norm(twist)
        )


def test_a_ring_rotating_about_one_of_its_points_gets_a_finite_hessian_from_differences():
    kernel = DiskKernel(RADIUS, "ring")
    twists = np.array([rotation([RADIUS, 0.0], 1.0), rotation([0.6 * RADIUS, 0.0], 1.0)])
    hessian = kernel.hessian(twists)
    assert np.all(np.isfinite(hessian))
    # The rim's row is the differences' (infinite curvature), the other the analytic one.
    np.testing.assert_array_equal(hessian[0], SupportKernel.hessian(kernel, twists[:1])[0])
    assert not np.array_equal(hessian[1], SupportKernel.hessian(kernel, twists[1:])[0])
