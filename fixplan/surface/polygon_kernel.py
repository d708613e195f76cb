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
numba, like the point kernel.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numba
import numpy as np

from fixplan.surface.kernels import SupportKernel
from fixplan.surface.point_kernel import (
    _UNPACK_HESSIAN,
    PointSetKernel,
    _compiled,
    _pick,
    compiled_scalar,
)
from fixplan.tolerances import FAR_FIELD_RADII


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
    sign = 1.0 if w > 0.0 else -1.0
    gx = -ux
    gy = -uy
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


_EDGE_TERMS = compiled_scalar(edge_terms)


def _edge_sums(  # pragma: no cover - compiled
    edges, reach, twists, with_hessian, out_h, out_g, out_hess, out_far
):
    """Support values ``out_h``, loads ``out_g`` and, ``with_hessian``, Hessians ``out_hess`` of
    the twists whose centre of rotation lies within ``reach`` [m] (:func:`edge_terms`);
    ``out_far`` marks the others (their rows are left unset), whose number is returned."""
    far_count = 0
    for k in numba.prange(twists.shape[0]):
        vx, vy, w = twists[k, 0], twists[k, 1], twists[k, 2]
        far = abs(w) * reach <= math.sqrt(vx * vx + vy * vy)
        out_far[k] = far
        if far:
            far_count += 1
            continue
        out = np.empty(10)
        _EDGE_TERMS(edges, vx, vy, w, with_hessian, out)
        out_h[k] = out[0]
        out_g[k, 0] = out[1]
        out_g[k, 1] = out[2]
        out_g[k, 2] = out[3]
        if with_hessian:
            _UNPACK_HESSIAN(out, out_hess[k])
    return far_count


_EDGE_SUMS = _compiled(_edge_sums)


class ClosedFormKernel(SupportKernel):
    """A kernel summed in closed form over a table (``_table``, read by the compiled pair
    ``_NEAR_SUMS`` as :func:`_edge_sums` reads edges) for centres of rotation within
    :data:`~fixplan.tolerances.FAR_FIELD_RADII` sizes, and by the Gauss rule ``far`` of the same
    field beyond (and for pure translations), where the closed-form terms cancel. Subclasses set
    ``_table`` and ``_size`` (the far rule's, computed once) on construction, and the cost
    ``_TERM_WORK`` of one of their terms in points summed."""

    __slots__ = ()

    @property
    def size(self) -> float:
        return self._size

    @property
    def work(self) -> int:
        """Cost of one evaluation in points summed (it sets when a batch runs in parallel)."""
        return self._TERM_WORK * self._table.shape[1]

    @property
    def table(self) -> np.ndarray:
        """The table the compiled sums read (do not modify)."""
        return self._table

    def _sums(self, twists, with_hessian):
        twists = np.ascontiguousarray(twists, dtype=float)
        count = len(twists)
        h = np.empty(count)
        g = np.empty((count, 3))
        hess = np.empty((count if with_hessian else 0, 3, 3))
        far = np.empty(count, dtype=np.bool_)
        far_count = _pick(self._NEAR_SUMS, count, self.work)(
            self._table, FAR_FIELD_RADII * self.size, twists, with_hessian, h, g, hess, far
        )
        return twists, far if far_count else None, h, g, hess

    def evaluate(self, twists):
        twists, far, h, loads, _ = self._sums(twists, False)
        if far is not None:
            h[far], loads[far] = self.far.evaluate(twists[far])
        return h, loads

    def newton_terms(self, twists):
        twists, far, h, g, hess = self._sums(twists, True)
        if far is not None:
            h[far], g[far], hess[far] = self.far.newton_terms(twists[far])
        return h, g, hess

    def hessian(self, twists):
        return self.newton_terms(twists)[2]


@dataclass(frozen=True, slots=True)
class EdgeSumKernel(ClosedFormKernel):
    """Unit-friction support function of piecewise-uniform pressure given by weighted edges.

    ``starts``/``ends`` ``(E, 2)`` [m] are directed boundary edges (region on their left),
    ``weights`` ``(E,)`` the pressure [1/m²] of the region they bound (normalised to unit total
    force), and ``far`` a Gauss rule of the same field for far centres of rotation. Its
    :attr:`table` ``(7, E)`` holds the starts' x and y, the ends' x and y, the unit directions'
    x and y and the weights (:func:`edge_terms`).
    """

    starts: np.ndarray
    ends: np.ndarray
    weights: np.ndarray
    far: PointSetKernel
    _table: np.ndarray = field(init=False, repr=False)
    _size: float = field(init=False, repr=False)
    _NEAR_SUMS = _EDGE_SUMS
    _TERM_WORK = 12  # 106 ns per edge against 8.6 ns per point, Hessians included

    def __post_init__(self):
        starts = np.asarray(self.starts, dtype=float)
        ends = np.asarray(self.ends, dtype=float)
        direction = ends - starts
        length = np.hypot(direction[:, 0], direction[:, 1])
        columns = (starts, ends, direction / length[:, None], np.asarray(self.weights, dtype=float))
        object.__setattr__(self, "_table", np.ascontiguousarray(np.column_stack(columns).T))
        object.__setattr__(self, "_size", self.far.size)


def polygon_edges(vertices: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Directed edges (starts, ends) of a counter-clockwise polygon."""
    return vertices, np.roll(vertices, -1, axis=0)
