"""Support function of a finite set of weighted points, compiled with numba.

Used for discrete point supports (where it is exact and the limit surface has facets), for
quadrature rules of continuous fields, and for the far field of polygons.
"""

from __future__ import annotations

import contextlib
import math
import os
import sys
import types
from dataclasses import dataclass, field
from pathlib import Path

import numba
import numpy as np

from fixplan.surface.kernels import SupportKernel

#: A point whose speed is below this fraction of the twist's scale at that point is stationary
#: (the centre of rotation sits on it up to rounding): it carries no force in :func:`_evaluate`
#: (one point of the facet) instead of a unit force in the direction of rounding noise.
STATIONARY_RTOL = 1e-12

_JIT = {"fastmath": {"reassoc", "contract"}, "nogil": True, "error_model": "numpy"}


def point_terms(points, start, stop, eps2, vx, vy, w, with_hessian, out):  # pragma: no cover
    """Support value, gradient and (``with_hessian``) Hessian at one twist ``(vx, vy, w)`` of the
    points ``start`` to ``stop`` of the columns ``points`` ``(3, P)`` (``x``, ``y`` [m], weight;
    a range rather than a view: a view costs as much as the terms of a few points, in its
    reference counting), written to ``out`` ``(10,)``: ``h``, ``g`` (3), then ``H`` 00, 01, 02,
    11, 12, 22.

    With ``s = sqrt(|u|² + eps²)``, ``A = [[1, 0, -y], [0, 1, x]]`` and ``e = u / s``:
    ``ds/dV = Aᵀ e``, ``d²s/dV² = Aᵀ (I - e eᵀ) A / s``. The loops are free of branches (a
    stationary point is masked out by a zero weight) so that they vectorise.
    """
    base = abs(vx) + abs(vy)
    spin = abs(w)
    h = 0.0
    g0 = 0.0
    g1 = 0.0
    g2 = 0.0
    if not with_hessian:
        for i in range(start, stop):
            x = points[0, i]
            y = points[1, i]
            ux = vx - w * y
            uy = vy + w * x
            speed = math.sqrt(ux * ux + uy * uy + eps2)
            moving = speed > STATIONARY_RTOL * (base + spin * (abs(x) + abs(y)))
            c = points[2, i] / speed if moving else 0.0
            gx = c * ux
            gy = c * uy
            h += c * speed * speed
            g0 += gx
            g1 += gy
            g2 += x * gy - y * gx
        out[0] = h
        out[1] = g0
        out[2] = g1
        out[3] = g2
        return
    h00 = 0.0
    h01 = 0.0
    h02 = 0.0
    h11 = 0.0
    h12 = 0.0
    h22 = 0.0
    for i in range(start, stop):
        x = points[0, i]
        y = points[1, i]
        ux = vx - w * y
        uy = vy + w * x
        speed = math.sqrt(ux * ux + uy * uy + eps2)
        moving = speed > STATIONARY_RTOL * (base + spin * (abs(x) + abs(y)))
        inverse = 1.0 / speed if moving else 0.0
        c = points[2, i] * inverse
        gx = c * ux
        gy = c * uy
        h += c * speed * speed
        g0 += gx
        g1 += gy
        g2 += x * gy - y * gx
        # (I - e eᵀ) / s = [[uy² + eps², -ux uy], [-ux uy, ux² + eps²]] / s³; with r = x ux + y uy
        # its image under A is as below.
        q = c * inverse * inverse
        a = q * ux
        b = q * uy
        r = x * ux + y * uy
        qe = q * eps2
        h00 += b * uy + qe
        h01 -= a * uy
        h11 += a * ux + qe
        h02 -= b * r + qe * y
        h12 += a * r + qe * x
        h22 += q * r * r + qe * (x * x + y * y)
    out[0] = h
    out[1] = g0
    out[2] = g1
    out[3] = g2
    out[4] = h00
    out[5] = h01
    out[6] = h02
    out[7] = h11
    out[8] = h12
    out[9] = h22


def _evaluate(points, eps2, twists, out_h, out_loads):  # pragma: no cover - compiled
    count = points.shape[1]
    for k in numba.prange(twists.shape[0]):
        out = np.empty(10)
        _POINT_TERMS(points, 0, count, eps2, twists[k, 0], twists[k, 1], twists[k, 2], False, out)
        out_h[k] = out[0]
        out_loads[k, 0] = out[1]
        out_loads[k, 1] = out[2]
        out_loads[k, 2] = out[3]


def _newton_terms(points, eps2, twists, out_h, out_g, out_hess):  # pragma: no cover
    count = points.shape[1]
    for k in numba.prange(twists.shape[0]):
        out = np.empty(10)
        _POINT_TERMS(points, 0, count, eps2, twists[k, 0], twists[k, 1], twists[k, 2], True, out)
        out_h[k] = out[0]
        out_g[k, 0] = out[1]
        out_g[k, 1] = out[2]
        out_g[k, 2] = out[3]
        _UNPACK_HESSIAN(out, out_hess[k])


def unpack_hessian(terms, hess):  # pragma: no cover - compiled
    """The symmetric 3x3 ``hess`` from the six entries ``terms[4:10]`` of :func:`point_terms`."""
    hess[0, 0] = terms[4]
    hess[0, 1] = terms[5]
    hess[1, 0] = terms[5]
    hess[0, 2] = terms[6]
    hess[2, 0] = terms[6]
    hess[1, 1] = terms[7]
    hess[1, 2] = terms[8]
    hess[2, 1] = terms[8]
    hess[2, 2] = terms[9]


#: Below this many (point, twist) pairs a call runs on one thread: waking the thread pool costs
#: more than the work, and far more when the other cores are busy.
PARALLEL_MIN_WORK = 200_000


def user_cache_dir() -> Path:
    """The per-user folder of fixplan's compiled kernels.

    ``NUMBA_CACHE_DIR`` when it is set; otherwise ``fixplan/numba`` in the platform's cache
    folder (``$XDG_CACHE_HOME`` or ``~/.cache`` on Linux, ``~/Library/Caches`` on macOS,
    ``%LOCALAPPDATA%`` on Windows).
    """
    if numba.config.CACHE_DIR:
        return Path(numba.config.CACHE_DIR)
    if sys.platform == "win32":
        base = os.environ.get("LOCALAPPDATA") or Path.home() / "AppData" / "Local"
    elif sys.platform == "darwin":
        base = Path.home() / "Library" / "Caches"
    else:
        base = os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache"
    return Path(base) / "fixplan" / "numba"


def _writable_cache_dir() -> Path | None:
    """:func:`user_cache_dir`, created if needed; ``None`` if it cannot be written."""
    folder = user_cache_dir()
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError:
        return None
    return folder if os.access(folder, os.W_OK) else None


@contextlib.contextmanager
def _cached_in(folder: Path | None):
    """Kernels decorated in this block cache their machine code in ``folder`` (if not ``None``).

    numba's default puts the cache next to the module: inside an installed package it outlives
    ``pip uninstall``, and the leftover folder then shadows a later (editable) install as a
    namespace package. numba picks the cache folder when a function is decorated, so setting
    its ``CACHE_DIR`` only meanwhile leaves other numba users alone.
    """
    previous = numba.config.CACHE_DIR
    numba.config.CACHE_DIR = previous if folder is None else os.fspath(folder)
    try:
        yield
    finally:
        numba.config.CACHE_DIR = previous


def _compiled(function):
    """A function compiled twice: (serial, parallel), cached in :func:`user_cache_dir` (not
    cached at all when that folder cannot be written).

    The serial variant is compiled from a renamed copy: numba's on-disk cache is keyed by the
    function's name, and two variants of one function would load each other's machine code.
    """
    serial = types.FunctionType(
        function.__code__, function.__globals__, f"{function.__name__}_serial"
    )
    serial.__qualname__ = f"{function.__qualname__}_serial"
    folder = _writable_cache_dir()
    options = {**_JIT, "cache": folder is not None}
    with _cached_in(folder):
        return (
            numba.njit(parallel=False, **options)(serial),
            numba.njit(parallel=True, **options)(function),
        )


def compiled_scalar(function, *, inline: bool = False):
    """``function`` compiled once, serial, cached like :func:`_compiled`: a building block that
    compiled loops call per twist. With ``inline``, compiled loops that call it compile its body
    into theirs (no call: small functions called in tight loops)."""
    folder = _writable_cache_dir()
    with _cached_in(folder):
        options = {**_JIT, "cache": folder is not None, "inline": "always" if inline else "never"}
        return numba.njit(**options)(function)


_POINT_TERMS = compiled_scalar(point_terms)
_UNPACK_HESSIAN = compiled_scalar(unpack_hessian)
_EVALUATE = _compiled(_evaluate)
_NEWTON_TERMS = _compiled(_newton_terms)


def _pick(variants, twists: int, points: int):
    return variants[twists > 1 and twists * points >= PARALLEL_MIN_WORK]


@dataclass(frozen=True, slots=True)
class PointSetKernel(SupportKernel):
    """Points ``(n, 2)`` [m] with friction weights ``(n,)`` (summing to the total friction).

    ``discrete`` marks true point supports, whose stationary points give the surface facets.
    ``smoothing`` [m/s per unit twist] replaces each speed ``|u|`` by ``sqrt(|u|² + smoothing²)``
    (a smooth, slightly larger support function, for the inverse map's continuation).
    """

    points: np.ndarray
    weights: np.ndarray
    discrete: bool = False
    smoothing: float = 0.0
    #: ``(3, n)``: the points' x, y [m] and weights, as the compiled terms read them.
    columns: np.ndarray = field(init=False, repr=False)

    def __post_init__(self):
        points = np.asarray(self.points, dtype=float)
        object.__setattr__(self, "weights", np.ascontiguousarray(self.weights, dtype=float))
        columns = np.vstack([points[:, 0], points[:, 1], self.weights])
        object.__setattr__(self, "columns", columns)

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
        _pick(_EVALUATE, len(twists), len(self.weights))(
            self.columns, self.smoothing**2, twists, h, loads
        )
        return h, loads

    def newton_terms(self, twists):
        twists = np.ascontiguousarray(twists, dtype=float)
        h = np.empty(len(twists))
        g = np.empty((len(twists), 3))
        hess = np.empty((len(twists), 3, 3))
        _pick(_NEWTON_TERMS, len(twists), len(self.weights))(
            self.columns, self.smoothing**2, twists, h, g, hess
        )
        return h, g, hess

    def hessian(self, twists):
        return self.newton_terms(twists)[2]

    def smoothed(self, smoothing: float) -> PointSetKernel:
        return PointSetKernel(self.points, self.weights, self.discrete, smoothing)


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
