"""FunctionKernel against closed forms and an independent adaptive reference quadrature.

The reference works in polar coordinates about the centre of rotation ``c`` with the domain
boundary in closed form: rectangles by inclusion-exclusion of the four rectangles with a corner
at ``c``, disks by the chord through ``c`` in each direction, circles by their arc. The radial
integrals of the polynomial fields used here are exact with Gauss-Legendre; the angular ones use
SciPy's adaptive ``quad_vec`` split where the integrand kinks.
"""

from __future__ import annotations

import itertools

import numpy as np
import pytest
from polygon_cells import edge_sum_kernel
from scipy.integrate import quad_vec

from fixplan.surface.disk_kernel import DiskKernel
from fixplan.surface.function_kernel import FunctionKernel

SMOOTH = 1e-9  # relative accuracy required for smooth fields
HERTZ = 1e-7  # ... and for the Hertz profile (square-root edge)
REFERENCE_RTOL = 1e-13

RHO_NODES, RHO_WEIGHTS = np.polynomial.legendre.leggauss(12)


def relative_errors(result, reference):
    """Largest relative errors of the support values and of the loads (vector norm)."""
    (h, loads), (h_ref, loads_ref) = result, reference
    h_err = np.max(np.abs(h - h_ref) / np.abs(h_ref))
    load_err = np.max(np.linalg.norm(loads - loads_ref, axis=1) / np.linalg.norm(loads_ref, axis=1))
    return h_err, load_err


def rotation_about(c, spin=1.0):
    """Twist ``(1, 3)`` of rotation at rate ``spin`` [rad/s] about the point ``c`` [m]."""
    return spin * np.array([[c[1], -c[0], 1.0]])


def polar_sums(f, c, directions, rho_max):
    """Radial integrals ``∫ f (ρ, -e_y, e_x, x·ê) ρ dρ`` from ``c`` to ``rho_max`` along unit
    ``directions`` ``(M, 2)``: the ``h`` and load terms of counter-clockwise rotation about ``c``."""
    s = 0.5 * (RHO_NODES + 1.0)
    rho = rho_max[:, None] * s
    points = c + rho[..., None] * directions[:, None, :]
    weight = f(points[..., 0], points[..., 1]) * rho * rho_max[:, None] * 0.5 * RHO_WEIGHTS
    ex, ey = directions[:, 0, None], directions[:, 1, None]
    arm = points[..., 0] * ex + points[..., 1] * ey
    terms = np.stack([weight * rho, -weight * ey, weight * ex, weight * arm])
    return terms.sum(axis=2).T


def angular_integral(integrand, lo, hi, points=()):
    """Adaptive integral of a vector function of the angle over ``[lo, hi]``."""
    cuts = sorted({lo, hi, *(p for p in points if lo < p < hi)})
    total = np.zeros(4)
    for a, b in itertools.pairwise(cuts):
        value, _ = quad_vec(integrand, a, b, epsabs=1e-17, epsrel=REFERENCE_RTOL, limit=2000)
        total += value
    return total


def corner_rectangle(f, c, a, b):
    """Oriented integral over ``[cx, cx + a] x [cy, cy + b]``: four terms (see polar_sums)."""
    if a == 0.0 or b == 0.0:
        return np.zeros(4)
    sx, sy = np.sign(a), np.sign(b)
    diagonal = np.arctan2(abs(b), abs(a))

    def integrand(theta, limit):
        theta = np.atleast_1d(theta)
        directions = np.column_stack([sx * np.cos(theta), sy * np.sin(theta)])
        return polar_sums(f, c, directions, limit(theta))[0]

    lower = angular_integral(lambda t: integrand(t, lambda t: abs(a) / np.cos(t)), 0.0, diagonal)
    upper = angular_integral(
        lambda t: integrand(t, lambda t: abs(b) / np.sin(t)), diagonal, 0.5 * np.pi
    )
    return sx * sy * (lower + upper)


def rectangles_reference(rectangles, c, p, mu):
    """Reference ``h`` and load of rotation about ``c`` for weighted rectangles
    ``(x0, x1, y0, y1, weight)`` (inclusion-exclusion of corner rectangles at ``c``)."""

    def f(x, y):
        return p(x, y) * mu(x, y)

    total = np.zeros(4)
    force = 0.0
    for x0, x1, y0, y1, weight in rectangles:
        for xi, sx in ((x1, 1.0), (x0, -1.0)):
            for yj, sy in ((y1, 1.0), (y0, -1.0)):
                total += weight * sx * sy * corner_rectangle(f, c, xi - c[0], yj - c[1])
        gx, gy = np.meshgrid(
            x0 + (x1 - x0) * 0.5 * (RHO_NODES + 1.0), y0 + (y1 - y0) * 0.5 * (RHO_NODES + 1.0)
        )
        area_weights = np.outer(RHO_WEIGHTS, RHO_WEIGHTS) * (x1 - x0) * (y1 - y0) / 4.0
        force += weight * np.sum(area_weights * p(gx, gy))
    total /= force
    return total[:1], total[None, 1:]


def disk_reference(radius, c, p, mu):
    """Reference for a disk about the origin: rays from ``c`` to the circle in closed form."""

    def f(x, y):
        return p(x, y) * mu(x, y)

    dist = float(np.hypot(*c))
    toward = np.arctan2(-c[1], -c[0]) if dist > 0.0 else 0.0
    if dist < radius:
        g2 = (radius - dist) * (radius + dist)

        def integrand(psi):
            psi = np.atleast_1d(psi)
            along = dist * np.cos(psi)  # c·ê, ψ the angle of the ray from ĉ
            root = np.sqrt(along * along + g2)
            reach = np.where(along <= 0.0, root - along, g2 / (root + along))
            directions = np.column_stack(
                [np.cos(psi + toward + np.pi), np.sin(psi + toward + np.pi)]
            )
            return polar_sums(f, c, directions, reach)[0]

        total = angular_integral(integrand, -np.pi, np.pi, points=(-0.5 * np.pi, 0.0, 0.5 * np.pi))
    else:  # lines of the tangent cone, sin ψ = (R/D) sin φ
        kappa = radius / dist

        def chord(phi, end):  # from c to the far (end = 1) or near (end = -1) side
            phi = np.atleast_1d(phi)
            sin_psi = kappa * np.sin(phi)
            cos_psi = np.sqrt(1.0 - sin_psi * sin_psi)
            half = radius * np.cos(phi)
            reach = dist * cos_psi + end * half
            directions = np.column_stack(
                [
                    np.cos(toward) * cos_psi - np.sin(toward) * sin_psi,
                    np.sin(toward) * cos_psi + np.cos(toward) * sin_psi,
                ]
            )
            jacobian = kappa * np.cos(phi) / cos_psi
            return polar_sums(f, c, directions, reach)[0] * jacobian

        total = angular_integral(lambda t: chord(t, 1.0), -0.5 * np.pi, 0.5 * np.pi)
        total -= angular_integral(lambda t: chord(t, -1.0), -0.5 * np.pi, 0.5 * np.pi)
    r, t = np.meshgrid(radius * 0.5 * (RHO_NODES + 1.0), np.linspace(0, 2 * np.pi, 65)[:-1])
    force = np.sum(p(r * np.cos(t), r * np.sin(t)) * r * RHO_WEIGHTS[None, :]) * radius * np.pi / 64
    result = total / force
    return result[:1], result[None, 1:]


def circle_reference(radius, c, mu):
    """Reference for a unit line density on a circle about the origin (1D, kink split)."""

    def integrand(psi):
        point = radius * np.array([np.cos(psi), np.sin(psi)])
        rel = point - c
        rho = np.hypot(*rel)
        unit = rel / rho
        weight = mu(point[0], point[1]) * radius
        return weight * np.array([rho, -unit[1], unit[0], point @ unit])

    toward = float(np.arctan2(c[1], c[0]))
    total = angular_integral(integrand, toward, toward + 2 * np.pi, points=(toward + np.pi,))
    result = total / (2 * np.pi * radius)
    return result[:1], result[None, 1:]


def one(x, y):
    return np.ones_like(x)


def hertz(x, y):
    return np.sqrt(np.clip(1.0 - x * x - y * y, 0.0, None))


# Uniform rectangle 1 m x 0.1 m (EdgeSumKernel is exact for it).
A, B = 0.5, 0.05
RECTANGLE = np.array([[-A, -B], [A, -B], [A, B], [-A, B]])
RECTANGLE_CORS = {
    "centre": (0.0, 0.0),
    "inside": (0.31, 0.012),
    "on an edge": (0.2, B),
    "at a vertex": (A, B),
    "just inside an edge": (0.2, B - 1e-9),
    "just outside an edge": (0.2, B + 1e-7),
    "outside": (0.8, 0.3),
    "far": (3.0, 2.0),
}


@pytest.mark.parametrize("where", RECTANGLE_CORS)
def test_uniform_rectangle_matches_the_exact_edge_sum_and_the_reference(where):
    kernel = FunctionKernel((("polygon", RECTANGLE, 1.0),))
    c = np.array(RECTANGLE_CORS[where])
    twists = np.vstack([rotation_about(c), rotation_about(c, -2.5)])
    result = kernel.evaluate(twists)
    assert (
        max(relative_errors(result, edge_sum_kernel([(RECTANGLE, 1.0)]).evaluate(twists))) < SMOOTH
    )
    h_ref, loads_ref = rectangles_reference([(-A, A, -B, B, 1.0)], c, one, one)
    assert max(relative_errors((result[0][:1], result[1][:1]), (h_ref, loads_ref))) < SMOOTH


def test_pure_translation_gives_the_speed_and_the_moment_of_the_force():
    kernel = FunctionKernel((("polygon", RECTANGLE, 1.0),), friction=lambda x, y: 0.5 + x)
    h, loads = kernel.evaluate(np.array([[0.3, -0.4, 0.0]]))
    # Mean friction 0.5 and mean of mu x = <x²> = A²/3 over the rectangle; v̂ = (0.6, -0.8).
    np.testing.assert_allclose(h, [0.25], rtol=1e-14)
    np.testing.assert_allclose(loads[0], [0.3, -0.4, -0.8 * A * A / 3.0], rtol=1e-13)


# Non-convex L-shape with smooth pressure and friction: [0, 2] x [0, 1] and [0, 1] x [1, 2],
# shifted so that the origin is inside.
SHIFT = np.array([0.6, 0.7])
L_SHAPE = np.array([[0, 0], [2, 0], [2, 1], [1, 1], [1, 2], [0, 2]], dtype=float) - SHIFT
L_RECTANGLES = [(0.0, 2.0, 0.0, 1.0, 1.0), (0.0, 1.0, 1.0, 2.0, 1.0)]
L_CORS = {
    "inside": (0.3, 0.2),
    "at the reflex vertex": (1.0, 1.0),
    "on an edge": (1.5, 0.0),
    "just inside an edge": (0.5, 2.0 - 1e-8),
    "just outside an edge": (1.5, -1e-7),
    "in the notch": (1.4, 1.3),
    "outside": (3.5, -1.0),
    "far": (12.0, 9.0),
}


def l_pressure(x, y):
    return 1.0 + 0.5 * x + y * y


def l_friction(x, y):
    return 0.3 + 0.1 * x


@pytest.mark.parametrize("where", L_CORS)
def test_l_shape_with_smooth_pressure_and_friction_matches_the_reference(where):
    kernel = FunctionKernel((("polygon", L_SHAPE, 1.0),), pressure=l_pressure, friction=l_friction)
    c = np.array(L_CORS[where]) - SHIFT

    def shifted(f):
        return lambda x, y: f(x - SHIFT[0], y - SHIFT[1])

    reference = rectangles_reference(
        L_RECTANGLES, c + SHIFT, shifted(l_pressure), shifted(l_friction)
    )
    # The reference is about the shifted frame: move its moment back to the kernel's origin.
    h_ref, loads_ref = reference
    loads_ref = loads_ref.copy()
    loads_ref[0, 2] -= SHIFT[0] * loads_ref[0, 1] - SHIFT[1] * loads_ref[0, 0]
    assert max(relative_errors(kernel.evaluate(rotation_about(c)), (h_ref, loads_ref))) < SMOOTH


# A 3 x 3 tactile grid of 4 mm cells with measured pressures (weights), p = None.
CELL = 0.004
GRID_VALUES = np.array([[0.0, 1.0, 0.5], [2.0, 3.0, 1.5], [0.2, 1.2, 0.7]])
GRID_CELLS = [
    (np.array([[x, y], [x + CELL, y], [x + CELL, y + CELL], [x, y + CELL]]), GRID_VALUES[j, i])
    for j, y in enumerate((-1.5 * CELL, -0.5 * CELL, 0.5 * CELL))
    for i, x in enumerate((-1.5 * CELL, -0.5 * CELL, 0.5 * CELL))
]
GRID_CORS = {
    "in the centre cell": (0.0003, -0.0007),
    "on a shared corner": (0.5 * CELL, 0.5 * CELL),
    "on a shared edge": (-0.5 * CELL, 0.0011),
    "in an empty cell": (-CELL, -CELL),
    "just outside the grid": (1.5 * CELL + 1e-10, 0.0002),
    "outside": (4 * CELL, 2 * CELL),
    "far": (40 * CELL, -30 * CELL),
}


@pytest.mark.parametrize("where", GRID_CORS)
def test_weighted_grid_matches_the_exact_edge_sum_and_the_reference(where):
    kernel = FunctionKernel(tuple(("polygon", v, w) for v, w in GRID_CELLS))
    c = np.array(GRID_CORS[where])
    twists = rotation_about(c, 3.0)
    result = kernel.evaluate(twists)
    assert max(relative_errors(result, edge_sum_kernel(GRID_CELLS).evaluate(twists))) < SMOOTH
    rectangles = [(v[0, 0], v[1, 0], v[0, 1], v[2, 1], w) for v, w in GRID_CELLS]
    h_ref, loads_ref = rectangles_reference(rectangles, c, one, one)
    assert max(relative_errors(result, (3.0 * h_ref, loads_ref))) < SMOOTH


RADIUS = 0.02
DISK_CORS = {
    "centre": 0.0,
    "inside": 0.45,
    "near the rim inside": 1.0 - 1e-9,
    "on the rim": 1.0,
    "just outside": 1.0 + 1e-7,
    "outside": 1.7,
    "far": 9.0,
}


def disk_centre(u):
    return u * RADIUS * np.array([np.cos(1.1), np.sin(1.1)])


@pytest.mark.parametrize("where", DISK_CORS)
@pytest.mark.parametrize("profile", ["uniform", "hertz"])
def test_disk_matches_the_closed_form(profile, where):
    pressure = None if profile == "uniform" else lambda x, y: hertz(x / RADIUS, y / RADIUS)
    kernel = FunctionKernel((("disk", RADIUS, 1.0),), pressure=pressure)
    c = disk_centre(DISK_CORS[where])
    twists = np.vstack([rotation_about(c), rotation_about(c, -0.4), [[0.02, -0.01, 0.0]]])
    tolerance = SMOOTH if profile == "uniform" else HERTZ
    exact = DiskKernel(RADIUS, profile).evaluate(twists)
    assert max(relative_errors(kernel.evaluate(twists), exact)) < tolerance


def disk_pressure(x, y):
    return 1.0 + 0.6 * x / RADIUS + 0.4 * (y / RADIUS) ** 2


def disk_friction(x, y):
    return 0.4 - 0.1 * (x * y) / RADIUS**2


@pytest.mark.parametrize("where", DISK_CORS)
def test_disk_with_smooth_pressure_and_friction_matches_the_reference(where):
    kernel = FunctionKernel(
        (("disk", RADIUS, 1.0),), pressure=disk_pressure, friction=disk_friction
    )
    c = disk_centre(DISK_CORS[where])
    reference = disk_reference(RADIUS, c, disk_pressure, disk_friction)
    assert max(relative_errors(kernel.evaluate(rotation_about(c)), reference)) < SMOOTH


@pytest.mark.parametrize("where", DISK_CORS)
def test_ring_with_constant_friction_matches_the_closed_form(where):
    kernel = FunctionKernel((("circle", RADIUS, 2.0),))
    c = disk_centre(DISK_CORS[where])
    twists = np.vstack([rotation_about(c), rotation_about(c, -3.0), [[0.0, 0.01, 0.0]]])
    exact = DiskKernel(RADIUS, "ring").evaluate(twists)
    assert max(relative_errors(kernel.evaluate(twists), exact)) < SMOOTH


@pytest.mark.parametrize("where", DISK_CORS)
def test_ring_with_varying_friction_matches_the_reference(where):
    def friction(x, y):
        return 0.5 + 0.2 * x / RADIUS - 0.1 * np.cos(3 * y / RADIUS)

    kernel = FunctionKernel((("circle", RADIUS, 1.0),), friction=friction)
    c = disk_centre(DISK_CORS[where])
    reference = circle_reference(RADIUS, c, friction)
    assert max(relative_errors(kernel.evaluate(rotation_about(c)), reference)) < SMOOTH


@pytest.mark.parametrize(
    ("regions", "pressure", "force", "size"),
    [
        ((("polygon", RECTANGLE, 2.0),), None, 2.0 * 4 * A * B, np.hypot(A, B)),
        (
            (("disk", RADIUS, 1.0),),
            lambda x, y: hertz(x / RADIUS, y / RADIUS),
            2 * np.pi / 3 * RADIUS**2,
            RADIUS,
        ),
        (
            (("circle", RADIUS, 3.0), ("polygon", RECTANGLE, 0.0)),
            None,
            6 * np.pi * RADIUS,
            np.hypot(A, B),
        ),
    ],
)
def test_normal_force_and_size_are_those_of_the_regions(regions, pressure, force, size):
    kernel = FunctionKernel(regions, pressure=pressure)
    assert kernel.normal_force == pytest.approx(force, rel=1e-14)
    assert kernel.size == pytest.approx(size, rel=1e-15)
