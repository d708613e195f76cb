"""Kernels summed in closed form near the patch: polygon edges and tactile-grid corners.

Both sum terms of size ``R³`` (``R`` the distance to the centre of rotation) to a moment
function of size ``R`` times the patch area, so far centres of rotation (and pure translations)
go to a point rule of the same field (``far``: a Gauss rule, or on a large grid one of blocks of
cells), beyond
:data:`~fixplan.tolerances.FAR_FIELD_RADII` sizes of the patch. The terms come from
:mod:`~fixplan.surface.polygon_kernel` (edges) and :mod:`~fixplan.surface.grid_kernel`
(corners).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numba
import numpy as np

from fixplan.surface.grid_kernel import _NODE_TERMS
from fixplan.surface.kernels import SupportKernel
from fixplan.surface.point_kernel import (
    _UNPACK_HESSIAN,
    PointSetKernel,
    _compiled,
    _pick,
    compiled_scalar,
)
from fixplan.surface.polygon_kernel import _EDGE_TERMS
from fixplan.tolerances import FAR_FIELD_RADII

#: Kinds of closed-form tables (numbered as :mod:`~fixplan.surface.compiled_inverse` numbers
#: its kernels): polygon edges ``(7, E)`` and grid corners ``(3, N)``.
EDGES = 1
NODES = 3


def near_terms(kind, table, vx, vy, w, with_hessian, out):  # pragma: no cover - compiled
    """Support value, load and (``with_hessian``) Hessian at one twist with ``w != 0`` from the
    closed-form ``table`` of ``kind``, written to ``out`` ``(10,)``."""
    if kind == EDGES:
        _EDGE_TERMS(table, vx, vy, w, with_hessian, out)
    else:
        _NODE_TERMS(table, vx, vy, w, with_hessian, out)


_NEAR_TERMS = compiled_scalar(near_terms)


def _near_sums(  # pragma: no cover - compiled
    kind, table, reach, twists, with_hessian, out_h, out_g, out_hess, out_far
):
    """Support values ``out_h``, loads ``out_g`` and, ``with_hessian``, Hessians ``out_hess`` of
    the twists whose centre of rotation lies within ``reach`` [m] (:func:`near_terms`);
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
        _NEAR_TERMS(kind, table, vx, vy, w, with_hessian, out)
        out_h[k] = out[0]
        out_g[k, 0] = out[1]
        out_g[k, 1] = out[2]
        out_g[k, 2] = out[3]
        if with_hessian:
            _UNPACK_HESSIAN(out, out_hess[k])
    return far_count


_NEAR_SUMS = _compiled(_near_sums)


class ClosedFormKernel(SupportKernel):
    """A kernel summed in closed form over a table (``_table``, of the kind ``_KIND``, read by
    :func:`near_terms`) for centres of rotation within
    :data:`~fixplan.tolerances.FAR_FIELD_RADII` sizes, and by the point rule ``far`` of the same
    field beyond (and for pure translations), where the closed-form terms cancel. Subclasses
    declare the fields ``_table`` and ``_size`` (set by :meth:`_store` on construction), the
    cost ``_TERM_WORK`` of one of their terms in points summed, and ``far``."""

    __slots__ = ()

    def _store(self, columns) -> None:
        """Keep the table of ``columns`` (arrays ``(n,)`` or ``(n, k)``, one row per term) and
        the far rule's size, computed once (a grid kernel then keeps its farthest node's)."""
        object.__setattr__(self, "_table", np.ascontiguousarray(np.column_stack(columns).T))
        object.__setattr__(self, "_size", self.far.size)

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
        far_count = _pick(_NEAR_SUMS, count, self.work)(
            self._KIND,
            self._table,
            FAR_FIELD_RADII * self.size,
            twists,
            with_hessian,
            h,
            g,
            hess,
            far,
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
    x and y and the weights (:func:`~fixplan.surface.polygon_kernel.edge_terms`).
    """

    starts: np.ndarray
    ends: np.ndarray
    weights: np.ndarray
    far: PointSetKernel
    _table: np.ndarray = field(init=False, repr=False)
    _size: float = field(init=False, repr=False)
    _KIND = EDGES
    _TERM_WORK = 12  # 106 ns per edge against 8.6 ns per point, Hessians included

    def __post_init__(self):
        starts = np.asarray(self.starts, dtype=float)
        ends = np.asarray(self.ends, dtype=float)
        direction = ends - starts
        length = np.hypot(direction[:, 0], direction[:, 1])
        self._store(
            (starts, ends, direction / length[:, None], np.asarray(self.weights, dtype=float))
        )


@dataclass(frozen=True, slots=True)
class GridKernel(ClosedFormKernel):
    """Unit-friction support function of a grid of uniform cells given by its nodes.

    ``nodes`` ``(N, 2)`` [m] are corners of the cell lattice with mixed pressure differences
    ``kappa`` ``(N,)`` [1/m²] (:func:`~fixplan.surface.grid_kernel.grid_nodes`; pressures
    normalised to unit total force), and ``far`` a point rule of the cells for far centres of
    rotation. Its :attr:`table` ``(3, N)`` holds the nodes' x, y and ``κ``
    (:func:`~fixplan.surface.grid_kernel.node_terms`); its size is that of its farthest node,
    the farthest corner of a loaded cell (the far rule's points may lie in empty cells).
    """

    nodes: np.ndarray
    kappa: np.ndarray
    far: PointSetKernel
    _table: np.ndarray = field(init=False, repr=False)
    _size: float = field(init=False, repr=False)
    _KIND = NODES
    _TERM_WORK = 3  # 8.4-12 ns per node against 2.9-4.2 ns per point, Hessians included

    def __post_init__(self):
        nodes = np.asarray(self.nodes, dtype=float)
        self._store((nodes, np.asarray(self.kappa, dtype=float)))
        object.__setattr__(self, "_size", float(np.max(np.hypot(nodes[:, 0], nodes[:, 1]))))
