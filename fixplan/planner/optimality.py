r"""Whether a given point of a conic program is feasible or optimal, checked to a tolerance.

The programs are those Clarabel solves,

.. math:: \min_x q^T x \quad\text{s.t.}\quad A x + s = b, \quad s \in \mathcal K,

with ``K`` the zero cone (equality rows), then the nonnegative orthant, then second-order cones
(``(t, u)`` with ``t >= ‖u‖``). Their dual is ``max -bᵀz`` subject to ``Aᵀz + q = 0`` and
``z ∈ K*`` (the same cones, but free on the equality rows). For every feasible ``x`` and dual
feasible ``z``, ``qᵀx >= -bᵀz`` (weak duality), so a feasible pair whose values meet is optimal:
``x`` attains the optimum and no point does better than ``-bᵀz``.

A point found without solving the program, carried from the solve of another
(:mod:`fixplan.planner.carried`), is checked here the way Clarabel checks its own iterates: each
residual against the largest of the terms it is made of (and 1), to ``CERTIFICATE_RTOL``. ``A``
is given as its values in a fixed compressed-column pattern (:class:`Pattern`), and the check is
one compiled pass over its entries (about 1 µs for a grasp of 8 contacts).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from fixplan.surface.point_kernel import compiled_scalar
from fixplan.tolerances import CERTIFICATE_RTOL


@dataclass(frozen=True)
class Pattern:
    """A program's rows and the compressed-column pattern of its ``A``: ``rows`` ``(nnz,)``
    and ``indptr`` ``(n + 1,)``; ``zero`` equality rows, then ``nonneg`` nonnegative rows, then
    second-order cones that start at rows ``heads`` with ``sizes`` rows each; ``row_count`` rows
    and ``column_count`` columns in all."""

    rows: np.ndarray
    indptr: np.ndarray
    zero: int
    nonneg: int
    heads: np.ndarray
    sizes: np.ndarray
    row_count: int
    column_count: int

    @classmethod
    def of(cls, rows, indptr, zero: int, nonneg: int, soc) -> Pattern:
        sizes = np.asarray(soc, dtype=np.intp).reshape(-1)
        heads = int(zero) + int(nonneg) + np.cumsum(sizes) - sizes
        indptr = np.asarray(indptr, dtype=np.intp)
        return cls(np.asarray(rows, dtype=np.intp), indptr, int(zero), int(nonneg),
                   heads.astype(np.intp), sizes, int(zero) + int(nonneg) + int(sizes.sum()),
                   indptr.size - 1)  # fmt: skip

    def residuals(self, q, values, b, x, z=None) -> tuple[float, float, float]:
        """``(primal, dual, gap)``, each relative to its terms: how far ``s = b - A x`` lies
        outside the cones; how far ``z`` lies outside the dual cones or from ``Aᵀz + q = 0``;
        the gap ``|qᵀx + bᵀz|`` (0 and 0 without ``z``). ``A`` has the ``values`` in this
        pattern."""
        z = _NO_MULTIPLIERS if z is None else z
        return RESIDUALS(q, values, self.rows, self.indptr, b, x, z, self.zero, self.nonneg,
                          self.heads, self.sizes)  # fmt: skip

    def feasible(self, values, b, x) -> bool:
        """Whether ``x`` satisfies ``A x + s = b`` with ``s`` in the cones, to
        ``CERTIFICATE_RTOL`` of the largest of ``|b|``, ``|A x|`` and 1."""
        return self.residuals(_NO_COST, values, b, x)[0] <= CERTIFICATE_RTOL

    def optimal(self, q, values, b, x, z) -> bool:
        """Whether ``x`` and the multipliers ``z`` are optimal, to ``CERTIFICATE_RTOL``: ``x``
        :meth:`feasible`; ``z`` in ``K*`` (against its largest entry) and ``Aᵀz + q = 0``
        (against the largest of ``|q|``, ``|Aᵀz|``); ``qᵀx = -bᵀz`` (against the larger)."""
        return max(self.residuals(q, values, b, x, z)) <= CERTIFICATE_RTOL


_NO_MULTIPLIERS = np.zeros(0)
_NO_COST = np.zeros(0)


def conic_residuals(
    q, values, rows, indptr, b, x, z, zero, nonneg, heads, sizes
):  # pragma: no cover - compiled
    """See :meth:`Pattern.residuals` (``z`` empty: no multipliers; ``q`` then unused)."""
    m, n = b.shape[0], x.shape[0]
    product = np.zeros(m)
    for j in range(n):
        for k in range(indptr[j], indptr[j + 1]):
            product[rows[k]] += values[k] * x[j]
    size, worst = 1.0, 0.0
    for i in range(m):
        size = max(size, abs(b[i]), abs(product[i]))
    for i in range(zero):
        worst = max(worst, abs(b[i] - product[i]))
    for i in range(zero, zero + nonneg):
        worst = max(worst, product[i] - b[i])
    for c in range(heads.shape[0]):
        head, squares = heads[c], 0.0
        for i in range(head + 1, head + sizes[c]):
            squares += (b[i] - product[i]) ** 2
        worst = max(worst, math.sqrt(squares) - (b[head] - product[head]))
    primal = worst / size
    if z.shape[0] == 0:
        return primal, 0.0, 0.0
    size, worst, value = 1.0, 0.0, 0.0
    for j in range(n):
        total = 0.0
        for k in range(indptr[j], indptr[j + 1]):
            total += values[k] * z[rows[k]]
        size = max(size, abs(q[j]), abs(total))
        worst = max(worst, abs(total + q[j]))
        value += q[j] * x[j]
    stationary = worst / size
    size, worst, bound = 1.0, 0.0, 0.0
    for i in range(m):
        size = max(size, abs(z[i]))
        bound -= b[i] * z[i]
    for i in range(zero, zero + nonneg):
        worst = max(worst, -z[i])
    for c in range(heads.shape[0]):
        head, squares = heads[c], 0.0
        for i in range(head + 1, head + sizes[c]):
            squares += z[i] * z[i]
        worst = max(worst, math.sqrt(squares) - z[head])
    gap = abs(value - bound) / max(1.0, abs(value), abs(bound))
    return primal, max(stationary, worst / size), gap


RESIDUALS = compiled_scalar(conic_residuals)
