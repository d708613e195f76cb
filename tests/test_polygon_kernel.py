"""The compiled polygon kernel's analytic Hessian against central differences of its exact
gradient and against an independent polar quadrature.

Reference: with ``u(x) = v + w J x`` the Hessian of ``h(V) = ∫ q |u(x)| dA`` is
``∫ q Aᵀ (I - ûûᵀ) A / |u| dA`` (``A = [[1, 0, -y], [0, 1, x]]``). About the centre of rotation
``c`` the vector ``Aᵀ ŝ`` (``ŝ`` the unit direction of ``x - c``) is
``g(θ) = (cos θ, sin θ, c_x sin θ - c_y cos θ)``, independent of the radius, and ``|u| = |w| r``,
so in polar coordinates about ``c``

    ∇²h = (1 / |w|) ∫ g(θ) g(θ)ᵀ L(θ) dθ,    L(θ) = ∫_0^∞ q(c + r ŝ) dr,

where ``L`` is the pressure-weighted length of the ray from ``c`` inside the region: the sum over
the boundary edges it crosses of ``± q r`` (+ leaving, - entering). ``L`` is smooth between the
directions of the vertices; Gauss-Legendre rules on subintervals graded towards the ends of each
piece integrate it.
"""

from __future__ import annotations

import numpy as np
import pytest
from polygon_cells import edge_sum_kernel
from reference import central_differences, rotation

from fixplan.surface.geometry import signed_area
from fixplan.surface.polygon_kernel import polygon_edges

#: Analytic Hessian vs the polar quadrature (relative to its largest entry): the 99-gon with its
#: centre far away differs by 1.6e-13 on a Xeon at 2.8 GHz, below 1e-13 on the machines before.
QUADRATURE_RTOL = 3e-13
DIFFERENCE_RTOL = 1e-7  # analytic Hessian vs central differences of the gradient
STEP = 1e-5  # relative step of the central differences
GAUSS_NODES, GAUSS_WEIGHTS = np.polynomial.legendre.leggauss(16)

RECTANGLE = np.array([[-0.1, -0.01], [0.1, -0.01], [0.1, 0.01], [-0.1, 0.01]])
ANGLES = 2 * np.pi * np.arange(99) / 99
ELLIPSE_99 = np.column_stack([0.1 * np.cos(ANGLES), 0.03 * np.sin(ANGLES)])
L_SHAPE = np.array([[0, 0], [2, 0], [2, 1], [1, 1], [1, 2], [0, 2]], dtype=float) * 0.01 - 0.006
ARROW = np.array([[0.0, -0.02], [0.03, 0.0], [0.0, 0.02], [0.01, 0.0]]) - [0.01, 0.0]


def grid_cells():
    """A 3 x 3 tactile grid of 4 mm cells with one cell unloaded, as (square, pressure)."""
    values = [[1.0, 2.0, 0.5], [0.0, 3.0, 1.5], [0.7, 1.0, 2.5]]
    cells = []
    for i, row in enumerate(values):
        for j, value in enumerate(row):
            if value > 0.0:
                x0, y0 = 0.004 * j - 0.006, 0.004 * i - 0.006
                square = np.array([[x0, y0], [x0 + 0.004, y0], [x0 + 0.004, y0 + 0.004],
                                   [x0, y0 + 0.004]])  # fmt: skip
                cells.append((square, value))
    return cells


SHAPES = {
    "rectangle 10:1": [(RECTANGLE, 1.0)],
    "99-gon ellipse": [(ELLIPSE_99, 1.0)],
    "L shape": [(L_SHAPE, 1.0)],
    "arrow head": [(ARROW, 1.0)],
    "tactile grid": grid_cells(),
}


def centres(cells):
    """Centres of rotation: inside, near and on an edge, at a vertex, outside, far away."""
    vertices = np.vstack([v for v, _ in cells])
    a, b = cells[0][0][0], cells[0][0][1]
    middle = 0.5 * (a + b)
    inward = np.array([-(b - a)[1], (b - a)[0]]) / np.linalg.norm(b - a)
    size = np.max(np.linalg.norm(vertices, axis=1))
    return {
        "inside": middle + 0.2 * size * inward,
        "just inside an edge": middle + 1e-6 * size * inward,
        "just outside an edge": middle - 1e-6 * size * inward,
        "on an edge": middle,
        "at a vertex": a,
        "outside": middle - 0.7 * size * inward,
        "far": 10.0 * size * np.array([0.6, 0.8]),
    }


def graded_rule(low, high):
    """Gauss-Legendre nodes and weights on ``[low, high]`` split into subintervals that halve
    towards both ends (down to 1e-9 of the width): the ray length ``δ / sin α`` of an edge
    passing at a distance ``δ`` from ``c`` peaks at the ends of its piece."""
    halves = 0.5 ** np.arange(1, 31)
    cuts = np.unique(np.concatenate([[0.0, 1.0], halves, 1.0 - halves]))
    a, b = low + (high - low) * cuts[:-1], low + (high - low) * cuts[1:]
    nodes = 0.5 * (a + b)[:, None] + 0.5 * (b - a)[:, None] * GAUSS_NODES[None, :]
    weights = 0.5 * (b - a)[:, None] * GAUSS_WEIGHTS[None, :]
    return nodes.ravel(), weights.ravel()


def polar_hessian(cells, c):
    """∇²h of rotation at unit rate about ``c`` by the polar quadrature of the module docstring."""
    force = sum(pressure * signed_area(vertices) for vertices, pressure in cells)
    starts = np.vstack([polygon_edges(v)[0] for v, _ in cells])
    e = np.vstack([polygon_edges(v)[1] for v, _ in cells]) - starts
    weights = np.concatenate([np.full(len(v), q / force) for v, q in cells])
    offset = starts - c
    vertices = np.vstack([v for v, _ in cells])
    breaks = np.unique(np.arctan2(vertices[:, 1] - c[1], vertices[:, 0] - c[0]))
    cuts = np.concatenate([breaks, [breaks[0] + 2 * np.pi]])
    theta, dtheta = (
        np.concatenate(p) for p in zip(*map(graded_rule, cuts[:-1], cuts[1:]), strict=True)
    )
    sx, sy = np.cos(theta)[:, None], np.sin(theta)[:, None]
    across = sx * e[:, 1] - sy * e[:, 0]  # ŝ × e = |e| ŝ·n: > 0 where the ray leaves
    safe = np.where(across == 0.0, 1.0, across)
    r = (offset[:, 0] * e[:, 1] - offset[:, 1] * e[:, 0]) / safe
    t = (offset[:, 0] * sy - offset[:, 1] * sx) / safe
    hit = (across != 0.0) & (r > 0.0) & (t >= 0.0) & (t <= 1.0)
    length = np.sum(np.where(hit, np.sign(across) * weights * r, 0.0), axis=1)
    g = np.column_stack([sx[:, 0], sy[:, 0], c[0] * sy[:, 0] - c[1] * sx[:, 0]])
    return np.einsum("n,ni,nj->ij", dtheta * length, g, g)


CASES = [(shape, where) for shape in SHAPES for where in centres(SHAPES[shape])]


@pytest.mark.parametrize(("shape", "where"), CASES)
def test_the_hessian_is_the_polar_quadrature_of_the_integral(shape, where):
    cells = SHAPES[shape]
    kernel = edge_sum_kernel(cells)
    c = centres(cells)[where]
    reference = polar_hessian(cells, c)
    scale = np.max(np.abs(reference))
    for spin in (1.0, -2.5):  # ∇²h is homogeneous of degree -1 in the twist
        hessian = kernel.hessian(rotation(c, spin)[None, :])[0]
        np.testing.assert_allclose(hessian, reference / abs(spin), rtol=0.0,
                                   atol=QUADRATURE_RTOL * scale / abs(spin))  # fmt: skip


SMOOTH_CENTRES = ("inside", "outside", "far")


@pytest.mark.parametrize("shape", SHAPES)
def test_the_hessian_is_the_derivative_of_the_exact_gradient(shape):
    kernel = edge_sum_kernel(SHAPES[shape])
    rng = np.random.default_rng(7)
    size = kernel.size
    # Random twists (centres of rotation near and far), pure translations and the centres above.
    twists = np.vstack([
        rng.normal(size=(20, 3)) * [1.0, 1.0, 3.0 / size],
        [[1.0, 0.0, 0.0], [0.3, -0.8, 0.0]],
        [rotation(centres(SHAPES[shape])[w], 1.3) for w in SMOOTH_CENTRES],
    ])  # fmt: skip
    h, gradient, hessian = kernel.newton_terms(twists)
    reference_h, reference_gradient = kernel.evaluate(twists)
    np.testing.assert_allclose(h, reference_h, rtol=1e-14)
    np.testing.assert_allclose(gradient, reference_gradient, rtol=1e-14, atol=1e-14 * h.max())
    for twist, analytic in zip(twists, hessian, strict=True):
        reference = central_differences(kernel, twist, STEP)
        scale = np.max(np.abs(reference))
        np.testing.assert_allclose(analytic, reference, rtol=0.0, atol=DIFFERENCE_RTOL * scale)
        # h is homogeneous of degree one: the Hessian annuls the twist.
        np.testing.assert_allclose(
            analytic @ twist, 0.0, atol=1e-12 * scale * np.linalg.norm(twist)
        )
