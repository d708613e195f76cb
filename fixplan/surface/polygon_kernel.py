r"""Closed-form support functions of piecewise-uniform polygonal pressure (polygons, grids).

The moment function ``M(c) = ∫ q |x - c| dA`` of a region with uniform ``q`` is a sum over its
directed boundary edges of signed triangles with apex at ``c``. For an edge with unit direction
``ê``, outward normal ``n``, signed distance ``d = n·(a - c)`` of its line and coordinates
``t = ê·(x - c)`` along it (``r = sqrt(d² + t²)``, ``A = asinh(t/|d|)``):

.. math::

   T(c) = \frac{d}{6}\Big[t r + d^2 A\Big]_{t_a}^{t_b},\qquad
   \int_\triangle \hat u \, dA = \frac{d}{2}\Big[d A\, n + r\, ê\Big]_{t_a}^{t_b},

with ``∇M = -∫ û dA``. Differentiating the second form (``∂d/∂c = -n``, ``∂t/∂c = -ê``) gives
the Hessian ``∇²M = ∫ (I - û ûᵀ)/|x - c| dA`` edge by edge,

.. math::

   \frac12\Big[\big(2 d A - \tfrac{d t}{r}\big) n n^T
   + \big(\tfrac{d^2}{r} + \tfrac{r}{2}\big)(n ê^T + ê n^T)
   + \tfrac{d t}{r}\, ê ê^T\Big]_{t_a}^{t_b}

(its antisymmetric part ``[r] (ê nᵀ - n êᵀ)/2`` telescopes to zero around every closed boundary
and is left out; the trace is ``∫ dA/|x - c| = d [A]``). With ``c = (-v_y, v_x)/w`` the support
function is ``h = |w| M(c)`` and its Hessian ``Pᵀ ∇²M P / |w|``, ``P = [[0, -1, -c_x],
[1, 0, -c_y]]``. This is exact for any centre of rotation; for far centres (and pure
translation) the terms cancel, so there a Gauss rule on the patch, exact to machine precision
because the integrand is analytic there, takes over. The sums over edges are compiled with
numba, like the point kernel, and summed per twist by :mod:`~fixplan.surface.closed_form`.
"""

from __future__ import annotations

import math

import numpy as np

from fixplan.surface.point_kernel import compiled_scalar


def support_terms(  # pragma: no cover - compiled
    moment, gx, gy, m00, m01, m11, vx, vy, w, with_hessian, out
):
    """Write to ``out`` ``(10,)``, as :func:`~fixplan.surface.point_kernel.point_terms` does,
    the support value, load and (``with_hessian``) Hessian at the twist ``(vx, vy, w)``
    (``w != 0``) from the moment function ``M`` at its centre of rotation, its gradient
    ``(gx, gy)`` and Hessian ``[[m00, m01], [m01, m11]]`` (see the module)."""
    cx = -vy / w
    cy = vx / w
    sign = 1.0 if w > 0.0 else -1.0
    out[0] = abs(w) * moment
    out[1] = sign * gy
    out[2] = -sign * gx
    out[3] = sign * (moment - cx * gx - cy * gy)
    if with_hessian:
        s = 1.0 / abs(w)
        out[4] = s * m11
        out[5] = -s * m01
        out[6] = -s * (m01 * cx + m11 * cy)
        out[7] = s * m00
        out[8] = s * (m00 * cx + m01 * cy)
        out[9] = s * (m00 * cx * cx + 2.0 * m01 * cx * cy + m11 * cy * cy)


_SUPPORT_TERMS = compiled_scalar(support_terms)


def edge_terms(edges, vx, vy, w, with_hessian, out):  # pragma: no cover - compiled
    """Support value, load and (``with_hessian``) Hessian at one twist ``(vx, vy, w)`` with
    ``w != 0``, written to ``out`` ``(10,)`` as :func:`~fixplan.surface.point_kernel.point_terms`
    does. ``edges`` ``(7, E)`` holds the starts' x and y, the ends' x and y, the unit
    directions' x and y and the weights."""
    cx = -vy / w
    cy = vx / w
    moment = 0.0
    ux = 0.0  # ∫ q û dA = -∇M
    uy = 0.0
    m00 = 0.0  # ∇²M
    m01 = 0.0
    m11 = 0.0
    for i in range(edges.shape[1]):
        q = edges[6, i]
        dx = edges[4, i]
        dy = edges[5, i]
        nx = dy
        ny = -dx
        ax = edges[0, i] - cx
        ay = edges[1, i] - cy
        d = nx * ax + ny * ay
        ta = dx * ax + dy * ay
        tb = dx * (edges[2, i] - cx) + dy * (edges[3, i] - cy)
        ra = math.sqrt(d * d + ta * ta)
        rb = math.sqrt(d * d + tb * tb)
        absd = abs(d)
        asinh_diff = math.asinh(tb / absd) - math.asinh(ta / absd) if absd > 0.0 else 0.0
        moment += q * (d / 6.0) * (tb * rb - ta * ra + d * d * asinh_diff)
        u_n = q * 0.5 * d * d * asinh_diff
        u_e = q * 0.5 * d * (rb - ra)
        ux += u_n * nx + u_e * dx
        uy += u_n * ny + u_e * dy
        if with_hessian:
            # t/r and 1/r vanish with d at the vertex itself (r = 0): |d t/r|, d²/r <= |d|.
            inv_ra = 1.0 / ra if ra > 0.0 else 0.0
            inv_rb = 1.0 / rb if rb > 0.0 else 0.0
            c_ee = d * (tb * inv_rb - ta * inv_ra)
            c_nn = 2.0 * d * asinh_diff - c_ee
            c_ne = d * d * (inv_rb - inv_ra) + 0.5 * (rb - ra)
            m00 += 0.5 * q * (c_nn * nx * nx + 2.0 * c_ne * nx * dx + c_ee * dx * dx)
            m01 += 0.5 * q * (c_nn * nx * ny + c_ne * (nx * dy + dx * ny) + c_ee * dx * dy)
            m11 += 0.5 * q * (c_nn * ny * ny + 2.0 * c_ne * ny * dy + c_ee * dy * dy)
    _SUPPORT_TERMS(moment, -ux, -uy, m00, m01, m11, vx, vy, w, with_hessian, out)


_EDGE_TERMS = compiled_scalar(edge_terms)


def polygon_edges(vertices: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Directed edges (starts, ends) of a counter-clockwise polygon."""
    return vertices, np.roll(vertices, -1, axis=0)
