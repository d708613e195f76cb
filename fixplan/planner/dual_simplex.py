r"""A warm-started simplex method for the small linear programs of pyramid models.

With pyramid friction models (and a linear objective) the planner's problems are linear
programs in Clarabel's form

.. math:: \min q^T x \quad\text{s.t.}\quad A_E x = b_E,\; A_I x \le b_I ,

of a few dozen variables, re-solved with new right-hand sides ``b`` (the loads and given forces
of a force objective; ``A`` and ``q`` stay). An interior-point method starts from scratch every
time (about 10 iterations); the dual simplex starts from the last optimal *basis*: ``n`` active
rows ``W`` (all equalities among them) with an invertible matrix ``B = A_W``, the vertex
``x = B^{-1} b_W`` and the multipliers ``z_W = -B^{-T} q``, optimal when the vertex satisfies
every row and the multipliers of the inequalities are nonnegative. Those multipliers do not
depend on ``b``, so the last basis stays dual feasible; each pivot brings the most violated row
in and takes out the row whose multiplier reaches 0 first, until the vertex is feasible: a few
pivots of ``O(n^2 + m n)`` each, compiled, without BLAS (whose threads cost more than these
small products when the machine is busy).

The first solve starts from an artificial basis that is dual feasible by construction: the
equality rows and, for every variable outside a set that makes the equality rows invertible, a
bound ``±x_i <= BOUND`` on the side that makes its multiplier nonnegative, for slightly
perturbed costs (``COST_PERTURBATION``: no ties), whose optimal basis then starts the program's
own costs. A solve that ends with an artificial bound in the basis (an unbounded
program or one beyond ``BOUND``), finds the program infeasible or unbounded, or exceeds
``MAX_PIVOTS_PER_ROW`` pivots per row returns ``None``: the caller then asks Clarabel, which
also gives the infeasibility certificates. A warm start that finds the program infeasible (a
violated row that no pivot can bring in: a dual ray) returns ``None`` at once, without the
artificial start (about 1.7 ms of an unholdable re-solve of the pyramid grasp of
``benchmarks/bench_realtime.py``, profiled).
"""

from __future__ import annotations

import numpy as np
import scipy.linalg

from fixplan.surface.point_kernel import compiled_scalar

#: The artificial bounds of the first basis: far beyond any force [N] or multiple a plan has.
BOUND = 1e9
#: A row is violated when it exceeds its right-hand side by more than this fraction of the
#: sizes of its terms (``|b_i| + |a_i| |x|``).
FEASIBILITY_RTOL = 1e-12
#: A multiplier may be this fraction of ``max |q|`` below 0 and still count as nonnegative.
OPTIMALITY_RTOL = 1e-10
#: Pivots allowed per row of the program before the solve gives up (cycling).
MAX_PIVOTS_PER_ROW = 4
#: A program whose ``A`` changes is left to Clarabel once more than this fraction of at least
#: ``WARM_TRIAL`` warm starts missed (each miss costs an artificial start).
MAX_MISS_RATE, WARM_TRIAL = 0.25, 8
#: The basis inverse is computed afresh after this many rank-one updates, and an optimum found
#: after at least ``CONFIRM_AFTER`` of them is confirmed on a fresh one.
REFACTOR_EVERY, CONFIRM_AFTER = 32, 8
#: A column update of the basis inverse whose Sherman-Morrison denominator ``1 + (B^-1 u)_c``
#: is this small (a nearly singular new basis) is left to a fresh inversion.
SHERMAN_MORRISON_MIN = 1e-6
#: The artificial start pivots on costs perturbed by up to this fraction of their largest entry
#: (see :meth:`DualSimplex._cold`): well above rounding, a tenth of ``OPTIMALITY_RTOL``.
COST_PERTURBATION = 1e-11
#: What the compiled pivots return for an infeasible program.
RAY = -2


class DualSimplex:
    """Warm-started simplex for ``min q·x`` s.t. ``A x = b`` on the first ``equalities`` rows
    and ``A x <= b`` on the rest (``A`` dense: small programs only).

    The optimal basis of each objective ``q`` is kept as the start of its next solve (with the
    ``A`` it was found for, which the caller must not modify afterwards). Where
    ``A`` changes (``changing``: the fixed-force objectives, whose task-load multiple multiplies
    the load), the kept basis is refactored with the new ``A``; it is a start only if it is
    still dual feasible (else the artificial start is), which small load changes (a control
    loop) keep and large ones do not: once more than ``MAX_MISS_RATE`` of at least
    ``WARM_TRIAL`` warm starts missed, the simplex stops trying for that objective (the caller's
    Clarabel is then faster).
    """

    def __init__(self, equalities: int, *, changing: bool = False):
        self._equalities = int(equalities)
        self._changing = changing
        #: By objective: the basis, its inverse, the A it inverts and the column updates of that
        #: inverse since it was last computed afresh (see :meth:`_refactored`).
        self._bases: dict[bytes, tuple[np.ndarray, np.ndarray, np.ndarray, int]] = {}
        self._record: dict[bytes, tuple[int, int]] = {}  # warm starts tried and missed
        #: The last matrix pivoted on, with its rows' 1- and 2-norms.
        self._row_sizes: tuple = (None, None, None)
        #: Pivots of the last solve.
        self.pivots = 0
        #: Whether the last pivots ended on a dual ray (the program is infeasible).
        self._ray = False

    def solve(
        self, a: np.ndarray, q: np.ndarray, b: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray] | None:
        """The optimal ``x`` ``(n,)`` and multipliers ``z`` ``(m,)`` (``q + A^T z = 0``,
        ``z >= 0`` on the inequalities, 0 off the active rows), or ``None`` (see the module)."""
        key = q.tobytes()
        tried, missed = self._record.get(key, (0, 0))
        if tried >= WARM_TRIAL and missed > MAX_MISS_RATE * tried:
            return None
        self.pivots = 0
        self._ray = False
        found = None
        updates = 0
        if key in self._bases:
            rows, inverse, inverted, updates = self._bases[key]
            rows, inverse = rows.copy(), inverse.copy()
            updates = self._refactored(a, inverted, rows, inverse, updates)
            if updates is not None:
                found = self._pivot(a, q, b, rows, inverse)
            if self._ray:  # (not a miss: no artificial start follows)
                return None
            if self._changing:
                self._record[key] = (tried + 1, missed + (found is None))
        if found is None:
            found, updates = self._cold(a, q, b), 0
        if found is None:
            return None
        x, z, rows, inverse = found
        if len(self._bases) >= 8 and key not in self._bases:
            self._bases.clear()
        self._bases[key] = (rows, inverse, a, updates)
        return x, z

    @staticmethod
    def _refactored(a, inverted, rows, inverse, updates) -> int | None:
        """Make ``inverse`` (that of ``inverted[rows]``) the inverse of ``a[rows]``; the column
        updates since it was computed afresh, or ``None`` for a singular basis.

        Where one column changed (the load column of a fixed-force objective, or of its scaled
        form), by the rank-one update of Sherman and Morrison in ``O(n^2)``, at most
        ``REFACTOR_EVERY`` times in a row; else by a fresh inversion in ``O(n^3)``."""
        if inverted is a:
            return updates
        changed = _UPDATE(
            a, inverted, rows, inverse, SHERMAN_MORRISON_MIN, updates < REFACTOR_EVERY
        )
        if changed == 0:
            return updates
        if changed == 1:
            return updates + 1
        return 0 if INVERT(a, rows, inverse) else None

    def _cold(self, a, q, b):
        """From the artificial basis (see :meth:`_artificial`) of the costs perturbed by
        ``COST_PERTURBATION``, whose optimal basis then starts the program's own costs.

        Dually degenerate programs (many multipliers exactly 0: a task-load multiple
        minimised to 0, whose cost has one entry) tie the ratio test at every pivot, and the
        ties, broken by rounding, stalled the unperturbed pivots past their limit (101 of the
        cold starts of 125 fresh planners of benchmarks/bench_planner.py's fixture; 6.6 ms
        each, then Clarabel); perturbed costs leave no ties. The basis found was optimal for
        the program's own costs in all 374 cold starts of those planners and of a check of
        fixture-321 (no further pivots); where it is not dual feasible for them, the solve
        fails (Clarabel then solves the program)."""
        size = max(float(np.abs(q).max(initial=0.0)), 1e-300)
        shift = np.random.default_rng(0).uniform(0.5, 1.0, q.size)  # (deterministic)
        found = self._artificial(a, q + COST_PERTURBATION * size * shift, b)
        if found is None:
            return None
        _, _, rows, inverse = found
        return self._pivot(a, q, b, rows, inverse)

    def _artificial(self, a, q, b):
        """From the artificial basis: ``a`` with the rows ``x_i <= BOUND`` (``m + i``) and
        ``-x_i <= BOUND`` (``m + n + i``) appended."""
        m, n = a.shape
        e = self._equalities
        equal = a[:e]
        if e:
            _, _, order = scipy.linalg.qr(equal, pivoting=True, mode="economic")
            pivots = np.sort(order[:e])
            square = equal[:, pivots]
            if np.linalg.matrix_rank(square) < e:
                return None  # dependent equalities
            reduced = q + equal.T @ np.linalg.solve(square.T, -q[pivots])
        else:
            pivots, reduced = np.zeros(0, dtype=np.intp), q
        free = np.setdiff1d(np.arange(n), pivots)
        rows = np.concatenate(
            [np.arange(e), np.where(reduced[free] >= 0.0, m + n + free, m + free)]
        )
        bounded = np.vstack([a, np.eye(n), -np.eye(n)])
        try:
            inverse = np.linalg.inv(bounded[rows])
        except np.linalg.LinAlgError:
            return None
        rows = rows.astype(np.intp)
        self.pivots = 0
        bounds = np.full(2 * n, BOUND)
        found = self._pivot(bounded, q, np.concatenate([b, bounds]), rows, inverse)
        if found is None or np.any(rows >= m):  # an artificial bound still holds the vertex
            return None
        x, z, rows, inverse = found
        return x, z[:m], rows, inverse

    def _pivot(self, a, q, b, rows, inverse):
        """Dual simplex pivots from the basis ``rows`` (updated in place, with ``inverse``):
        ``(x, z, rows, inverse)`` at the optimum, or ``None`` if they failed."""
        m, n = a.shape
        x, z = np.empty(n), np.zeros(m)
        measured, size, norm = self._row_sizes
        fresh = measured is not a  # (the same matrix object is never changed: see the class)
        if fresh:
            size, norm = np.empty(m), np.empty(m)
            self._row_sizes = (a, size, norm)
        limit = MAX_PIVOTS_PER_ROW * (m + n)
        pivots = _PIVOTS(a, b, q, self._equalities, rows, inverse, x, z, limit,
                            FEASIBILITY_RTOL, OPTIMALITY_RTOL, REFACTOR_EVERY,
                            CONFIRM_AFTER, size, norm, fresh)  # fmt: skip
        self._ray = pivots == RAY
        if pivots < 0:
            return None
        self.pivots += pivots
        return x, z, rows, inverse


def dual_pivots(a, b, q, equalities, rows, inverse, x, z, limit, feasibility, optimality,
                refactor, confirm, size, norm, fresh):  # fmt: skip  # pragma: no cover - compiled
    """Dual simplex pivots from the dual feasible basis ``rows`` (with ``inverse``, both
    updated in place) until its vertex ``x`` is feasible; ``z`` gets the multipliers. Returns
    the number of pivots, :data:`RAY` for an infeasible program (a violated row that no row can
    leave for), or -1 (too many pivots, multipliers < 0, a singular basis). ``size`` and
    ``norm`` ``(m,)`` hold the rows' 1- and 2-norms (computed here when ``fresh``)."""
    m, n = a.shape
    if fresh:
        for i in range(m):
            size[i], norm[i] = 0.0, 0.0
            for j in range(n):
                size[i] += abs(a[i, j])
                norm[i] += a[i, j] * a[i, j]
            norm[i] = np.sqrt(norm[i])
    q_size = 0.0
    for j in range(n):
        q_size = max(q_size, abs(q[j]))
    active = np.zeros(m, dtype=np.bool_)
    for k in range(n):
        active[rows[k]] = True
    # (The products with B^-1 run along its rows, contiguous in memory, so that they vectorise:
    # a third less time than along its columns on the solves of a check of fixture-321.)
    z_rows, d, b_rows = np.empty(n), np.empty(n), np.empty(n)
    pivots, since = 0, 0
    while True:
        for k in range(n):
            b_rows[k] = b[rows[k]]
        x_size = 0.0
        for j in range(n):
            total = 0.0
            for k in range(n):
                total += inverse[j, k] * b_rows[k]
            x[j] = total
            x_size = max(x_size, abs(total))
        entering, worst = -1, 0.0
        for i in range(equalities, m):
            if active[i]:
                continue
            excess = -b[i]
            for j in range(n):
                excess += a[i, j] * x[j]
            if excess > feasibility * (abs(b[i]) + size[i] * x_size) and excess > worst * norm[i]:
                entering, worst = i, excess / norm[i]
        z_rows[:] = 0.0  # z_W = -B^-T q, row by row of B^-1
        for j in range(n):
            q_j = q[j]
            for k in range(n):
                z_rows[k] -= inverse[j, k] * q_j
        if pivots == 0 and since == 0:  # a start that is not dual feasible: no dual simplex
            for k in range(n):
                if rows[k] >= equalities and z_rows[k] < -optimality * q_size:
                    return -1
        if entering < 0:
            if since >= confirm:  # confirm on a fresh inverse
                if not INVERT(a, rows, inverse):
                    return -1
                since = 0
                continue
            for k in range(n):
                if rows[k] >= equalities and z_rows[k] < -optimality * q_size:
                    return -1
            z[:] = 0.0
            for k in range(n):
                z[rows[k]] = z_rows[k]
            return pivots
        if pivots >= limit:
            return -1
        # Multipliers along the entering row: z_W(t) = z_W - t d, with d = B^-T a_j.
        d[:] = 0.0
        for j in range(n):
            a_j = a[entering, j]
            for k in range(n):
                d[k] += inverse[j, k] * a_j
        d_size = 0.0
        for k in range(n):
            d_size = max(d_size, abs(d[k]))
        leaving, ratio, best = -1, np.inf, 0.0
        for k in range(n):
            if rows[k] < equalities or d[k] <= 1e-9 * d_size:
                continue
            t = max(z_rows[k], 0.0) / d[k]
            if t < ratio * (1.0 - 1e-12) or (t <= ratio * (1.0 + 1e-12) and d[k] > best):
                leaving, ratio, best = k, t, d[k]
        if leaving < 0:
            return RAY  # no row can leave: the program is infeasible
        # Row k of B becomes a_j: B^-1 - B^-1 e_k (a_j^T B^-1 - e_k^T) / d_k.
        pivot = d[leaving]
        d[leaving] -= 1.0
        for j in range(n):
            factor = inverse[j, leaving] / pivot
            if factor != 0.0:
                for k in range(n):
                    inverse[j, k] -= factor * d[k]
        active[rows[leaving]] = False
        active[entering] = True
        rows[leaving] = entering
        pivots += 1
        since += 1
        if since >= refactor:
            if not INVERT(a, rows, inverse):
                return -1
            since = 0


def invert(a, rows, inverse):  # pragma: no cover - compiled
    """``inverse`` = ``a[rows]^-1`` by Gauss-Jordan elimination with partial pivoting (no
    LAPACK: see the module); ``False`` if the basis is singular."""
    n = rows.shape[0]
    work = np.empty((n, 2 * n))
    for i in range(n):
        for j in range(n):
            work[i, j] = a[rows[i], j]
            work[i, n + j] = 1.0 if i == j else 0.0
    scale = 0.0
    for i in range(n):
        for j in range(n):
            scale = max(scale, abs(work[i, j]))
    for col in range(n):
        best, row = 0.0, -1
        for i in range(col, n):
            if abs(work[i, col]) > best:
                best, row = abs(work[i, col]), i
        if best <= 1e-14 * scale:
            return False
        if row != col:
            for j in range(2 * n):
                work[row, j], work[col, j] = work[col, j], work[row, j]
        pivot = work[col, col]
        for j in range(2 * n):
            work[col, j] /= pivot
        for i in range(n):
            factor = work[i, col]
            if i != col and factor != 0.0:
                for j in range(2 * n):
                    work[i, j] -= factor * work[col, j]
    for i in range(n):
        for j in range(n):
            inverse[i, j] = work[i, n + j]
    return True


def column_update(a, inverted, rows, inverse, smallest, allowed):  # pragma: no cover - compiled
    """Update ``inverse`` (that of ``inverted[rows]``) to that of ``a[rows]`` where the two
    differ in one column ``c`` (by ``u`` on the basis rows): ``B^-1 - B^-1 u (B^-1)_c /
    (1 + (B^-1 u)_c)``, if ``allowed`` and the denominator exceeds ``smallest``. Returns 0 (the
    same matrix), 1 (updated) or -1 (not: more columns changed, or not allowed, or too small)."""
    m, n = a.shape
    column = -1
    for i in range(m):  # (row by row: the matrices are C-ordered)
        for j in range(n):
            if a[i, j] != inverted[i, j] and j != column:
                if column >= 0:
                    return -1
                column = j
    if column < 0:
        return 0
    if not allowed:
        return -1
    shift = np.zeros(n)
    for j in range(n):
        total = 0.0
        for k in range(n):
            total += inverse[j, k] * (a[rows[k], column] - inverted[rows[k], column])
        shift[j] = total
    denominator = 1.0 + shift[column]
    if abs(denominator) <= smallest:
        return -1
    row = inverse[column] / denominator
    for j in range(n):
        factor = shift[j]
        if factor != 0.0:
            for k in range(n):
                inverse[j, k] -= factor * row[k]
    return 1


#: :func:`invert`, compiled (also the elimination of :mod:`fixplan.planner.cone_interior_point`).
INVERT = compiled_scalar(invert)
_UPDATE = compiled_scalar(column_update)
_PIVOTS = compiled_scalar(dual_pivots)
