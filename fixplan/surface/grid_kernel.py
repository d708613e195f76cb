r"""Closed-form support function of a tactile grid (piecewise-uniform cells), node by node.

Over a cell ``[x₀, x₁] × [y₀, y₁]`` of uniform pressure ``p`` the moment function
``M(c) = ∫ p |x - c| dA`` is ``p [G(X₁, Y₁) - G(X₀, Y₁) - G(X₁, Y₀) + G(X₀, Y₀)]`` with
``X = x - c_x``, ``Y = y - c_y`` and ``G`` the antiderivative with ``∂²G/∂X∂Y = R``
(``R = sqrt(X² + Y²)``, ``A = asinh(Y/|X|)``, ``B = asinh(X/|Y|)``):

.. math::

   G = \tfrac13 X Y R + \tfrac16 X^3 A + \tfrac16 Y^3 B,\qquad
   G_X = \tfrac12 (Y R + X^2 A),\quad G_Y = \tfrac12 (X R + Y^2 B),

   G_{XX} = X A,\qquad G_{XY} = R,\qquad G_{YY} = Y B.

Cells share corners, so the whole grid is one sum over the corners (nodes) of the lattice, each
with the mixed second difference ``κ`` of the cell pressures around it (the cells up-right and
down-left minus the other two; zero inside a uniform region, and wherever the pressure is a
function of x plus one of y; such corners are left out):
``M = Σ κ G``, ``∇M = -Σ κ (G_X, G_Y)``, ``∇²M = Σ κ [[G_XX, G_XY], [G_XY, G_YY]]``. Each node
costs one square root and two logarithms; the edge sums of
:mod:`~fixplan.surface.polygon_kernel` cost two square roots and two ``asinh`` per lattice edge,
and a grid has about twice as many edges as nodes. The support function and its Hessian follow
from ``M`` as there, and far centres of rotation (where the terms, of size ``R³``, cancel) go to
a point rule of the cells as there: on a large grid, that of blocks of cells
(:func:`block_rule`), which needs a fraction of the points of a Gauss rule per cell.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.polynomial.legendre import leggauss

from fixplan.surface.point_kernel import compiled_scalar
from fixplan.surface.polygon_kernel import _SUPPORT_TERMS
from fixplan.surface.vector_log import _LOGS

#: Below this fraction of ``R``, ``|X|`` (or ``|Y|``) is taken as zero in ``asinh(Y/|X|)``: the
#: terms carrying it (``X A``, ``X² A``, ``X³ A``) are then below ``1e-28 R`` and the quotient
#: cannot overflow.
_ON_AXIS = 1e-30

#: The far rule of :func:`block_rule`: blocks of ``floor(n / BLOCKS_PER_SIDE)`` (at least 1) of
#: the ``n`` cells along each axis of the loaded cells' bounding box, with ``BLOCK_NODES²`` points
#: each. Far centres of rotation are at least 4 patch sizes away, 80 or more half-blocks where
#: ``n >= BLOCKS_PER_SIDE``: there the rule matches a Gauss rule of 6 x 6 points per cell to
#: rounding (tests/test_grid_kernel.py), as one of 3 x 3 points per cell does.
BLOCKS_PER_SIDE = 20
BLOCK_NODES = 6


def node_terms(nodes, vx, vy, w, with_hessian, out):  # pragma: no cover - compiled
    """Support value, load and (``with_hessian``) Hessian at one twist ``(vx, vy, w)`` with
    ``w != 0``, written to ``out`` ``(10,)`` as :func:`~fixplan.surface.point_kernel.point_terms`
    does. ``nodes`` ``(3, N)`` holds the nodes' x, y [m] and mixed differences ``κ`` [1/m²].

    Three vectorised passes: the arguments of the two logarithms per node, their logarithms
    (:mod:`~fixplan.surface.vector_log`), the sums."""
    cx = -vy / w
    cy = vx / w
    n = nodes.shape[1]
    logs = np.empty(2 * n)
    by_x, by_y = logs[:n], logs[n:]  # log((|Y| + R)/|X|) and log((|X| + R)/|Y|)
    for i in range(n):
        x = nodes[0, i] - cx
        y = nodes[1, i] - cy
        ax = abs(x)
        ay = abs(y)
        r = math.sqrt(x * x + y * y)
        over_x = (ay + r) / ax  # (divided whatever the test says: the loop stays vectorised)
        over_y = (ax + r) / ay
        by_x[i] = over_x if ax > _ON_AXIS * r else 1.0
        by_y[i] = over_y if ay > _ON_AXIS * r else 1.0
    _LOGS(logs, np.empty(2 * n, dtype=np.int64))
    moment = 0.0
    gx = 0.0  # ∇M
    gy = 0.0
    m00 = 0.0  # ∇²M
    m01 = 0.0
    m11 = 0.0
    for i in range(n):
        k = nodes[2, i]
        x = nodes[0, i] - cx
        y = nodes[1, i] - cy
        r = math.sqrt(x * x + y * y)
        xa = x * by_x[i]  # X asinh(Y/|X|)
        xa = -xa if y < 0.0 else xa
        yb = y * by_y[i]  # Y asinh(X/|Y|)
        yb = -yb if x < 0.0 else yb
        moment += k * (x * y * r * (1.0 / 3.0) + (x * x * xa + y * y * yb) * (1.0 / 6.0))
        gx -= k * 0.5 * (y * r + x * xa)
        gy -= k * 0.5 * (x * r + y * yb)
        if with_hessian:
            m00 += k * xa
            m01 += k * r
            m11 += k * yb
    _SUPPORT_TERMS(moment, gx, gy, m00, m01, m11, vx, vy, w, with_hessian, out)


_NODE_TERMS = compiled_scalar(node_terms)


def grid_nodes(
    corner_x: np.ndarray, corner_y: np.ndarray, pressure: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Nodes ``(N, 2)`` [m] and their mixed differences ``κ`` ``(N,)`` [1/m²] of cells with
    ``pressure`` ``(ny, nx)`` [1/m²] between the corners ``corner_x`` ``(nx + 1,)`` and
    ``corner_y`` ``(ny + 1,)``; nodes with ``κ = 0`` are left out."""
    padded = np.pad(pressure, 1)  # a ring of empty cells around the grid
    kappa = padded[1:, 1:] + padded[:-1, :-1] - padded[1:, :-1] - padded[:-1, 1:]
    rows, columns = np.nonzero(kappa)
    return np.column_stack([corner_x[columns], corner_y[rows]]), kappa[rows, columns]


def block_rule(
    corner_x: np.ndarray, corner_y: np.ndarray, pressure: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Points ``(n, 2)`` [m] and weights ``(n,)`` integrating the cells' ``pressure``
    ``(ny, nx)`` [1/m²] (uniform cells between the corners ``corner_x`` ``(nx + 1,)`` and
    ``corner_y`` ``(ny + 1,)``) times any polynomial of degree below :data:`BLOCK_NODES` in
    each coordinate over each block of cells exactly: smooth integrands, such as speeds about
    a far centre of rotation, to the accuracy of the polynomials that interpolate them there.

    The loaded cells' bounding box (whose size, not the grid's, sets the far-field switch) is
    cut into blocks of ``floor(n / BLOCKS_PER_SIDE)`` cells (at least 1) along each of its axes
    of ``n`` cells (the last padded with empty cells); a loaded block gets the Gauss-Legendre nodes
    ``x_k``, ``y_l`` of its sides and the weights ``∫ p L_k(x) L_l(y) dA`` (``L`` the Lagrange
    polynomials of the nodes), cell by cell in closed form. Weights may be slightly negative;
    they sum to the total force."""
    rows, columns = np.flatnonzero(pressure.any(axis=1)), np.flatnonzero(pressure.any(axis=0))
    pressure = pressure[rows[0] : rows[-1] + 1, columns[0] : columns[-1] + 1]
    corner_x, corner_y = corner_x[columns[0] : columns[-1] + 2], corner_y[rows[0] : rows[-1] + 2]
    ny, nx = pressure.shape
    (xs, across_x), (ys, across_y) = (
        _block_nodes(corner, cells) for corner, cells in ((corner_x, nx), (corner_y, ny))
    )
    by, bx = across_y.shape[0], across_x.shape[0]
    blocks = np.zeros((ys.shape[0] * by, xs.shape[0] * bx))
    blocks[:ny, :nx] = pressure
    blocks = blocks.reshape(ys.shape[0], by, xs.shape[0], bx)
    weights = np.einsum("ak,IaJb,bl->IkJl", across_y, blocks, across_x, optimize=True)
    loaded = np.broadcast_to(
        (blocks != 0.0).any(axis=(1, 3))[:, None, :, None], weights.shape
    )  # fmt: skip
    x = np.broadcast_to(xs[None, None, :, :], weights.shape)
    y = np.broadcast_to(ys[:, :, None, None], weights.shape)
    return np.column_stack([x[loaded], y[loaded]]), weights[loaded]


def _block_nodes(corners: np.ndarray, cells: int) -> tuple[np.ndarray, np.ndarray]:
    """Along one axis of ``cells`` uniform cells between ``corners``: the nodes ``(B, m)`` [m]
    of its ``B`` blocks of ``b`` cells, and ``∫ L_k`` over each cell of a block ``(b, m)`` [m]."""
    per_block = max(cells // BLOCKS_PER_SIDE, 1)
    count = -(-cells // per_block)
    width = (corners[-1] - corners[0]) / cells
    half = 0.5 * per_block * width
    nodes, gauss = leggauss(BLOCK_NODES)
    centres = corners[0] + half * (1.0 + 2.0 * np.arange(count))
    # The basis is of degree BLOCK_NODES - 1: the same Gauss rule on each cell is exact.
    edges = np.linspace(-1.0, 1.0, per_block + 1)
    middles, halves = (edges[1:] + edges[:-1]) / 2.0, (edges[1:] - edges[:-1]) / 2.0
    t = middles[:, None] + halves[:, None] * nodes[None, :]  # (b, q) in block units
    basis = np.ones((*t.shape, BLOCK_NODES))
    for k in range(BLOCK_NODES):
        for j in range(BLOCK_NODES):
            if j != k:
                basis[:, :, k] *= (t - nodes[j]) / (nodes[k] - nodes[j])
    integrals = np.einsum("cq,cqk->ck", halves[:, None] * gauss[None, :], basis) * half
    return centres[:, None] + half * nodes[None, :], integrals
