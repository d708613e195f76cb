r"""Closed-form support functions of piecewise-uniform polygonal pressure (polygons, grids).

The moment function ``M(c) = ∫ q |x - c| dA`` of a region with uniform ``q`` is a sum over its
directed boundary edges of signed triangles with apex at ``c``. For an edge with unit direction
``ê``, outward normal ``n``, signed distance ``d = n·(a - c)`` of its line and coordinates
``t = ê·(x - c)`` along it (``r = sqrt(d² + t²)``):

.. math::

   T(c) = \frac{d}{6}\Big[t r + d^2 \operatorname{asinh}\frac{t}{|d|}\Big]_{t_a}^{t_b},\qquad
   \int_\triangle \hat u \, dA = \frac{d}{2}\Big[d\,n \operatorname{asinh}\frac{t}{|d|}
   + ê\, r\Big]_{t_a}^{t_b},

with ``∇M = -∫ û dA``. This is exact for any centre of rotation; for far centres (and pure
translation) the terms cancel, so there a Gauss rule on the patch, exact to machine precision
because the integrand is analytic there, takes over.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from fixplan.surface.kernels import SupportKernel
from fixplan.surface.point_kernel import PointSetKernel
from fixplan.tolerances import FAR_FIELD_RADII


def _edge_terms(starts, ends, weights, centers):
    """``M`` ``(K,)`` and ``∫ q û dA`` ``(K, 2)`` at ``centers`` ``(K, 2)``."""
    direction = ends - starts
    length = np.hypot(direction[:, 0], direction[:, 1])
    ex, ey = direction[:, 0] / length, direction[:, 1] / length
    nx, ny = ey, -ex
    ax = starts[None, :, 0] - centers[:, 0, None]
    ay = starts[None, :, 1] - centers[:, 1, None]
    bx = ends[None, :, 0] - centers[:, 0, None]
    by = ends[None, :, 1] - centers[:, 1, None]
    d = nx * ax + ny * ay
    ta = ex * ax + ey * ay
    tb = ex * bx + ey * by
    ra, rb = np.hypot(d, ta), np.hypot(d, tb)
    absd = np.abs(d)
    safe = np.where(absd > 0.0, absd, 1.0)
    asinh_diff = np.where(absd > 0.0, np.arcsinh(tb / safe) - np.arcsinh(ta / safe), 0.0)
    moment = (d / 6.0) * (tb * rb - ta * ra + d * d * asinh_diff)
    u_integral_n = 0.5 * d * d * asinh_diff
    u_integral_e = 0.5 * d * (rb - ra)
    moment_sum = moment @ weights
    ux = (u_integral_n * nx + u_integral_e * ex) @ weights
    uy = (u_integral_n * ny + u_integral_e * ey) @ weights
    return moment_sum, np.column_stack([ux, uy])


@dataclass(frozen=True, slots=True)
class EdgeSumKernel(SupportKernel):
    """Unit-friction support function of piecewise-uniform pressure given by weighted edges.

    ``starts``/``ends`` ``(E, 2)`` [m] are directed boundary edges (region on their left),
    ``weights`` ``(E,)`` the pressure [1/m²] of the region they bound (normalised to unit total
    force), and ``far`` a Gauss rule of the same field for far centres of rotation.
    """

    starts: np.ndarray
    ends: np.ndarray
    weights: np.ndarray
    far: PointSetKernel

    @property
    def size(self) -> float:
        return self.far.size

    def evaluate(self, twists):
        vx, vy, w = twists[:, 0], twists[:, 1], twists[:, 2]
        far = np.abs(w) * FAR_FIELD_RADII * self.size <= np.hypot(vx, vy)
        h = np.empty(len(twists))
        loads = np.empty((len(twists), 3))
        if np.any(far):
            h[far], loads[far] = self.far.evaluate(twists[far])
        near = ~far
        if np.any(near):
            wn = w[near]
            centers = np.column_stack([-vy[near] / wn, vx[near] / wn])
            moment, u_integral = _edge_terms(self.starts, self.ends, self.weights, centers)
            grad = -u_integral  # ∇M(c)
            sign = np.sign(wn)
            h[near] = np.abs(wn) * moment
            loads[near, 0] = sign * grad[:, 1]
            loads[near, 1] = -sign * grad[:, 0]
            loads[near, 2] = sign * (moment - np.einsum("ij,ij->i", centers, grad))
        return h, loads


def polygon_edges(vertices: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Directed edges (starts, ends) of a counter-clockwise polygon."""
    return vertices, np.roll(vertices, -1, axis=0)
