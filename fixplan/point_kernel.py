"""Support function of a finite set of weighted points, compiled with numba.

Used for discrete point supports (where it is exact and the limit surface has facets), for
quadrature rules of continuous fields, and for the far field of polygons.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numba
import numpy as np

from fixplan.kernels import SupportKernel

_JIT = {"cache": True, "fastmath": {"reassoc", "contract"}, "nogil": True}


def _evaluate(px, py, pw, twists, out_h, out_loads):  # pragma: no cover - compiled
    for k in numba.prange(twists.shape[0]):
        vx, vy, w = twists[k, 0], twists[k, 1], twists[k, 2]
        h = 0.0
        fx = 0.0
        fy = 0.0
        m = 0.0
        for i in range(px.shape[0]):
            ux = vx - w * py[i]
            uy = vy + w * px[i]
            speed = math.sqrt(ux * ux + uy * uy)
            if speed > 0.0:
                s = pw[i] / speed
                h += pw[i] * speed
                gx = s * ux
                gy = s * uy
                fx += gx
                fy += gy
                m += px[i] * gy - py[i] * gx
        out_h[k] = h
        out_loads[k, 0] = fx
        out_loads[k, 1] = fy
        out_loads[k, 2] = m


def _newton_terms(px, py, pw, twists, out_h, out_g, out_hess):  # pragma: no cover - compiled
    for k in numba.prange(twists.shape[0]):
        vx, vy, w = twists[k, 0], twists[k, 1], twists[k, 2]
        h = 0.0
        g0 = 0.0
        g1 = 0.0
        g2 = 0.0
        h00 = 0.0
        h01 = 0.0
        h02 = 0.0
        h11 = 0.0
        h12 = 0.0
        h22 = 0.0
        for i in range(px.shape[0]):
            x = px[i]
            y = py[i]
            ux = vx - w * y
            uy = vy + w * x
            speed = math.sqrt(ux * ux + uy * uy)
            if speed > 0.0:
                # d|u|/dV = A^T u/|u|, d²|u|/dV² = A^T (I - û û^T) A / |u|, A = [[1,0,-y],[0,1,x]].
                c = pw[i] / speed
                ex = ux / speed
                ey = uy / speed
                h += pw[i] * speed
                g0 += c * ux
                g1 += c * uy
                g2 += c * (x * uy - y * ux)
                # (I - û û^T) = t t^T with t = (-ey, ex): rank one.
                t0 = -ey
                t1 = ex
                t2 = -y * t0 + x * t1
                h00 += c * t0 * t0
                h01 += c * t0 * t1
                h02 += c * t0 * t2
                h11 += c * t1 * t1
                h12 += c * t1 * t2
                h22 += c * t2 * t2
        out_h[k] = h
        out_g[k, 0] = g0
        out_g[k, 1] = g1
        out_g[k, 2] = g2
        out_hess[k, 0, 0] = h00
        out_hess[k, 0, 1] = h01
        out_hess[k, 1, 0] = h01
        out_hess[k, 0, 2] = h02
        out_hess[k, 2, 0] = h02
        out_hess[k, 1, 1] = h11
        out_hess[k, 1, 2] = h12
        out_hess[k, 2, 1] = h12
        out_hess[k, 2, 2] = h22


#: Below this many (point, twist) pairs a call runs on one thread: waking the thread pool costs
#: more than the work, and far more when the other cores are busy.
PARALLEL_MIN_WORK = 200_000


def _compiled(function):
    """A function compiled twice: (serial, parallel)."""
    return numba.njit(parallel=False, **_JIT)(function), numba.njit(parallel=True, **_JIT)(function)


_EVALUATE = _compiled(_evaluate)
_NEWTON_TERMS = _compiled(_newton_terms)


def _pick(variants, twists: int, points: int):
    return variants[twists > 1 and twists * points >= PARALLEL_MIN_WORK]


@dataclass(frozen=True, slots=True)
class PointSetKernel(SupportKernel):
    """Points ``(n, 2)`` [m] with friction weights ``(n,)`` (summing to the total friction).

    ``discrete`` marks true point supports, whose stationary points give the surface facets.
    """

    points: np.ndarray
    weights: np.ndarray
    discrete: bool = False
    _x: np.ndarray = field(init=False, repr=False)
    _y: np.ndarray = field(init=False, repr=False)

    def __post_init__(self):
        points = np.asarray(self.points, dtype=float)
        object.__setattr__(self, "weights", np.ascontiguousarray(self.weights, dtype=float))
        object.__setattr__(self, "_x", np.ascontiguousarray(points[:, 0]))
        object.__setattr__(self, "_y", np.ascontiguousarray(points[:, 1]))

    @property
    def size(self) -> float:
        return float(np.max(np.hypot(self.points[:, 0], self.points[:, 1])))

    @property
    def facets(self):
        if not self.discrete:
            return super(PointSetKernel, self).facets
        return self.points, self.weights

    def evaluate(self, twists):
        twists = np.ascontiguousarray(twists, dtype=float)
        h = np.empty(len(twists))
        loads = np.empty((len(twists), 3))
        _pick(_EVALUATE, len(twists), len(self._x))(
            self._x, self._y, self.weights, twists, h, loads
        )
        return h, loads

    def newton_terms(self, twists):
        twists = np.ascontiguousarray(twists, dtype=float)
        h = np.empty(len(twists))
        g = np.empty((len(twists), 3))
        hess = np.empty((len(twists), 3, 3))
        _pick(_NEWTON_TERMS, len(twists), len(self._x))(
            self._x, self._y, self.weights, twists, h, g, hess
        )
        return h, g, hess

    def hessian(self, twists):
        return self.newton_terms(twists)[2]


def _slowest(px, py, pw, twists, out_index, out_speed):  # pragma: no cover - compiled
    count = out_index.shape[1]
    for k in numba.prange(twists.shape[0]):
        vx, vy, w = twists[k, 0], twists[k, 1], twists[k, 2]
        for j in range(count):
            out_speed[k, j] = np.inf
            out_index[k, j] = -1
        for i in range(px.shape[0]):
            ux = vx - w * py[i]
            uy = vy + w * px[i]
            speed = math.sqrt(ux * ux + uy * uy) * pw[i]
            if speed < out_speed[k, count - 1]:
                j = count - 1
                while j > 0 and speed < out_speed[k, j - 1]:
                    out_speed[k, j] = out_speed[k, j - 1]
                    out_index[k, j] = out_index[k, j - 1]
                    j -= 1
                out_speed[k, j] = speed
                out_index[k, j] = i


_SLOWEST = _compiled(_slowest)


def slowest_points(
    points: np.ndarray, weights: np.ndarray, twists: np.ndarray, count: int
) -> tuple[np.ndarray, np.ndarray]:
    """Indices ``(K, count)`` of the points with the least weighted speed under each twist,
    and those speeds ``|v_i| * weight_i``, slowest first."""
    count = min(count, len(points))
    index = np.empty((len(twists), count), dtype=np.int64)
    speed = np.empty((len(twists), count))
    _pick(_SLOWEST, len(twists), len(points))(
        np.ascontiguousarray(points[:, 0]),
        np.ascontiguousarray(points[:, 1]),
        np.ascontiguousarray(weights, dtype=float),
        np.ascontiguousarray(twists, dtype=float),
        index,
        speed,
    )
    return index, speed
