r"""A compiled interior-point method for the small second-order cone programs of re-solves.

With ellipsoid or cone models, the planner's programs are, in Clarabel's form,

.. math:: \min q^T x \quad\text{s.t.}\quad A_E x = b_E,\quad h - G x \in K
          = \mathbb{R}_+^{l} \times \mathcal{Q}^{d_1} \times \dots

where every variable is a coordinate of a cone, scaled, or a few variables mix into a few
rows: ``G`` restricted to one *pivot* row per variable (``G_P``, :func:`pivot_rows`) is
invertible. With ellipsoid or cone models each row holds at most one entry (a normal force, a
friction force, a moment, a load multiple and its bounds; a row without one is a constant
coordinate, a given normal force) and ``G_P`` is diagonal; the osculating ellipsoids of exact
models (``‖R l‖ <= n``, ``R`` upper triangular) and their cuts (``p·l <= h``) mix the three
components of a friction load, and ``G_P`` is triangular in blocks of three. In the cone
coordinates ``s = h - G x``, ``x = G_P^{-1} (h_P - s_P)``, and the program is in standard form,
``min c^T s`` s.t. ``F s = f``, ``s`` in ``K``: the rows of ``A_E`` in ``s``, plus the link of
each further row ``t`` to the pivot rows, ``s_t - G_t G_P^{-1} s_P = h_t - G_t G_P^{-1} h_P``
(``s_t = h_t`` for a constant row). Its primal-dual interior-point method needs one ``p x p``
system per step, ``F W^2 F^T`` (``W`` the Nesterov-Todd scaling; ``p`` is six per load case and
one per further row), where Clarabel factorises the whole KKT system: about 8 of its
iterations of 20 µs each for one 8-contact case. (A round of the exact grasp of
``benchmarks/bench_realtime.py``, with two cut rows per contact, has ``p = 22``: 4 iterations
of about 40 µs from the last round's optimum.)

The method is the infeasible-start path-following method with Mehrotra's predictor and
corrector (as in CVXOPT's ``coneqp`` and SDPT3), compiled in one call. Small pivots of the
Cholesky factorisation of ``F W^2 F^T`` are replaced by a huge number (Wright's modified
Cholesky factorisation for interior-point methods: that direction is dropped), as the system
grows ill-conditioned near the optimum. Its stopping rule is Clarabel's: residuals and
duality gap below ``TOL_FEAS`` and ``TOL_GAP_*`` of the data's size.

A solve starts from the last optimum of the same cost, moved into the cones' interior as far
as the loads moved: those of a control loop change little between solves, and such starts save
a third of the iterations. It finds optima only: where the program looks infeasible or
unbounded, or the method makes no progress (``MAX_ITERATIONS``, a tiny step), it gives up and
the caller asks Clarabel, which also returns the certificates. The iterates of an infeasible
program run off along a ray that is nearly a certificate (``y`` with ``f'y > 0`` and ``F'y + z``
small beside it; an unbounded one's ``x``, likewise): where they do (``RAY_RTOL``) it gives up
at once, not after ``MAX_ITERATIONS`` from the warm start and again from the cold one.
"""

from __future__ import annotations

import numpy as np

from fixplan.planner.dual_simplex import INVERT
from fixplan.surface.point_kernel import compiled_scalar

#: Stopping tolerances by Clarabel's names, and its defaults: primal and dual residuals
#: relative to the data's size, and the duality gap absolute and relative to the objective.
TOLERANCES = {"tol_feas": 1e-8, "tol_gap_abs": 1e-8, "tol_gap_rel": 1e-8}
#: Iterations before the method gives up (the planner's re-solves take 5-7).
MAX_ITERATIONS = 50
#: Fraction of the largest step to the cones' boundary taken.
STEP_FRACTION = 0.99
#: A solve starts from the last optimum of the same cost, each cone's part moved inside by a
#: fraction of its largest entry: the relative residual of ``F s = f`` at that optimum (how far
#: the loads moved), clipped to ``[WARM_SHIFT, SHIFT_MAX]``; from Mehrotra's start where that
#: fails. Along ``bench_realtime.py``'s path (loads that change little) the bare re-solves and
#: the analysis programs took 5.8 and 5.9 iterations, against 9.4 and 10.9 from Mehrotra's
#: start; with loads drawn at random (``bench_planner.milling_loads``) the grasp's bare re-solve
#: took 521–539 µs against 588 µs with Clarabel (a fixed shift of 1e-3: 676 µs, of 1e-1: 543 µs,
#: and 6.7 and 8.6 iterations along the path).
WARM_SHIFT, SHIFT_MAX = 1e-3, 1e-1
#: The iterates give up as a ray where ``|F'y + z| <= RAY_RTOL f'y`` (infeasible) or ``|F x| <=
#: RAY_RTOL (-c'x)`` (unbounded), largest entries: a feasible point would then need entries of
#: about ``1 / RAY_RTOL`` of the program's unit. On unholdable re-solves of the ellipsoid grasp
#: it gave up after 6-9 iterations, where it ran 50 from the warm start and 38 more from
#: Mehrotra's (to a tiny step) before.
RAY_RTOL = 1e-6
#: A Cholesky pivot below this fraction of its diagonal entry is replaced by ``HUGE_PIVOT``.
PIVOT_RTOL, HUGE_PIVOT = 1e-30, 1e128


class ConeInteriorPoint:
    """Solves ``min q'x`` s.t. ``A x + s = b``, ``s`` in ``equalities`` zero rows,
    ``nonnegative`` rows and second-order cones of ``dimensions``, for ``A`` (dense, nonzero
    only where ``pattern`` is) whose cone rows have a pivot row for every variable
    (:meth:`fits`). ``settings`` may set :data:`TOLERANCES` (other Clarabel settings are
    ignored)."""

    def __init__(
        self,
        equalities: int,
        nonnegative: int,
        dimensions,
        pattern: np.ndarray,
        settings: dict | None = None,
    ):
        settings = settings or {}
        self._tolerances = tuple(float(settings.get(k, v)) for k, v in TOLERANCES.items())
        self._zero = int(equalities)
        self._nonneg = int(nonnegative)
        self._dimensions = np.asarray(dimensions, dtype=np.int64).reshape(-1)
        #: The cone row whose coordinate stands for each variable (:func:`pivot_rows`), and
        #: whether those rows hold one entry each (their block of ``G`` is diagonal).
        cone = np.asarray(pattern)[self._zero :] != 0.0
        self._pivot_row = pivot_rows(cone, self._nonneg)
        if self._pivot_row is None:
            raise ValueError("the pattern does not fit the method (see ConeInteriorPoint.fits)")
        self._diagonal = bool(np.all(cone[self._pivot_row].sum(axis=1) == 1))
        #: The standard form's last optimum ``(s, y, z)`` by cost ``q``: the next solve of that
        #: cost starts there.
        self._optima: dict[bytes, tuple[np.ndarray, np.ndarray, np.ndarray]] = {}
        #: Iterations of the last solve.
        self.iterations = 0

    @staticmethod
    def fits(equalities: int, nonnegative: int, pattern: np.ndarray) -> bool:
        """Whether each variable of ``pattern`` (``A`` or its nonzero pattern) can stand for a
        cone row of its own (:func:`pivot_rows`)."""
        cone = np.asarray(pattern)[equalities:] != 0.0
        return pivot_rows(cone, nonnegative) is not None

    def solve(
        self, q: np.ndarray, a: np.ndarray, b: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray] | None:
        """The optimal ``x`` ``(n,)`` and multipliers ``z`` ``(rows,)`` (``q + A^T z = 0``,
        ``z`` in the dual cones: Clarabel's signs), or ``None`` where the method gave up."""
        rows, n = a.shape
        x, z = np.empty(n), np.empty(rows)
        key = q.tobytes()
        kept = self._optima.pop(key, None)
        for warm in (True, False) if kept is not None else (False,):
            m = rows - self._zero
            start = kept if warm else (np.empty(m), np.empty(self._zero + m - n), np.empty(m))
            status, self.iterations = _SOLVE(
                q, a, b, self._zero, self._nonneg, self._dimensions, self._pivot_row,
                self._diagonal, x, z, *start, warm, *self._tolerances, MAX_ITERATIONS,
                STEP_FRACTION, WARM_SHIFT, SHIFT_MAX, RAY_RTOL,
            )  # fmt: skip
            if status == 0:
                if len(self._optima) >= 8:
                    self._optima.clear()
                self._optima[key] = start
                return x, z
            if status == 2:  # a ray: no start finds an optimum
                break
        return None


def pivot_rows(cone: np.ndarray, nonnegative: int) -> np.ndarray | None:
    """The cone row whose coordinate stands for each variable of the pattern ``cone`` (rows
    ``(m, n)`` of ``G``, the first ``nonnegative`` of them nonnegative rows): distinct rows,
    found as a matching of variables to rows that takes rows of fewer entries first, then rows
    of second-order cones before nonnegative ones (a cut's row, as full as the ellipsoid's
    first, may be empty now), then earlier rows (where every row holds one entry, the block of
    ``G`` is diagonal). ``None`` where no such rows exist (a variable in no cone row, or fewer
    rows than variables among some variables' rows)."""
    m, n = cone.shape
    entries = [np.flatnonzero(row) for row in cone]
    order = sorted(range(m), key=lambda r: (len(entries[r]), r < nonnegative, r))
    row_of = np.full(n, -1, dtype=np.int64)

    def augment(r: int, seen: set) -> bool:
        for j in entries[r]:
            if j in seen:
                continue
            seen.add(j)
            if row_of[j] < 0 or augment(row_of[j], seen):
                row_of[j] = r
                return True
        return False

    for r in order:
        if len(entries[r]):
            augment(r, set())
    return None if np.any(row_of < 0) else row_of


def solve_standard_form(
    q, a, b, zero, nonneg, dimensions, pivot_row, diagonal, x_out, z_out, s, y, z, warm,
    tol_feas, tol_gap_abs, tol_gap_rel, max_iterations, step_fraction, warm_shift, shift_max,
    ray_rtol,
):  # fmt: skip  # pragma: no cover - compiled
    """Write the optimum of Clarabel's program into ``x_out`` and ``z_out``, and that of its
    standard form into ``s``, ``y`` and ``z`` (with ``warm``, the start); ``(0, iterations)``
    when solved, ``(2, iterations)`` where the iterates ran off along a ray (see
    :func:`standard_form`), else ``(1, iterations)`` (also where the pivot rows' block of ``G``
    is singular now)."""
    n = a.shape[1]
    m = a.shape[0] - zero
    blocks = nonneg + dimensions.shape[0]
    start = np.empty(blocks, dtype=np.int64)
    size = np.empty(blocks, dtype=np.int64)
    row = 0
    for k in range(blocks):
        start[k] = row
        size[k] = 1 if k < nonneg else dimensions[k - nonneg]
        row += size[k]
    # In s = h - G x, with P the pivot rows (one per variable) and M = G_P^-1, x = M (h_P - s_P).
    # So A_E x = b_E is F s = f with F[:, P] = -A_E M, f = b_E - A_E M h_P; q'x = c's + constant
    # with c_P = -M'q; a further cone row t is s_t - (G_t M) s_P = h_t - G_t M h_P.
    rows_of, columns_of, values_of = _block_inverse(a[zero:], pivot_row, diagonal)
    if rows_of.shape[0] == 0:
        return 1, 0
    h_p = np.empty(n)
    for j in range(n):
        h_p[j] = b[zero + pivot_row[j]]
    p = zero + m - n
    f_matrix = np.zeros((p, m))
    f = np.zeros(p)
    c = np.zeros(m)
    for e in range(zero):
        f[e] = b[e]
    for t in range(rows_of.shape[0]):
        j, k, value = rows_of[t], columns_of[t], values_of[t]
        r = pivot_row[k]
        c[r] -= q[j] * value
        for e in range(zero):
            f_matrix[e, r] -= a[e, j] * value
            f[e] -= a[e, j] * value * h_p[k]
    pivot = np.zeros(m, dtype=np.bool_)
    for j in range(n):
        pivot[pivot_row[j]] = True
    link = zero
    for t in range(m):
        if pivot[t]:
            continue
        f_matrix[link, t] = 1.0
        f[link] = b[zero + t]
        for u in range(rows_of.shape[0]):
            j, k, value = rows_of[u], columns_of[u], values_of[u]
            entry = a[zero + t, j] * value
            if entry != 0.0:
                f_matrix[link, pivot_row[k]] -= entry
                f[link] -= entry * h_p[k]
        link += 1
    status, iterations = _STANDARD(f_matrix, f, c, start, size, nonneg, s, y, z, warm, tol_feas,
                                   tol_gap_abs, tol_gap_rel, max_iterations, step_fraction,
                                   warm_shift, shift_max, ray_rtol)  # fmt: skip
    if status != 0:
        return status, iterations
    # Back: x from s; Clarabel's multipliers are -y on the equalities and z on the cones.
    x_out[:] = 0.0
    for t in range(rows_of.shape[0]):
        j, k = rows_of[t], columns_of[t]
        x_out[j] += values_of[t] * (h_p[k] - s[pivot_row[k]])
    for t in range(m):
        z_out[zero + t] = z[t]
    for e in range(zero):
        z_out[e] = -y[e]
    return 0, iterations


def _block_inverse(g, pivot_row, diagonal):  # pragma: no cover - compiled
    """The nonzero entries ``(rows, columns, values)`` of ``G_P^-1``, ``G_P`` the rows
    ``pivot_row`` of ``g`` (its row ``j`` is row ``pivot_row[j]``, ``diagonal`` where each holds
    only entry ``j``); none where ``G_P`` is singular: an entry 0 on a diagonal one, else as
    the dual simplex's Gauss-Jordan elimination finds it
    (:func:`~fixplan.planner.dual_simplex.invert`)."""
    n = pivot_row.shape[0]
    if diagonal:
        rows = np.arange(n)
        values = np.empty(n)
        for j in range(n):
            entry = g[pivot_row[j], j]
            if entry == 0.0:
                return rows[:0], rows[:0], values[:0]
            values[j] = 1.0 / entry
        return rows, rows, values
    out = np.empty((n, n))
    if not INVERT(g, pivot_row, out):
        empty = np.zeros(0, dtype=np.int64)
        return empty, empty, np.zeros(0)
    count = 0
    for i in range(n):
        for k in range(n):
            count += out[i, k] != 0.0
    rows = np.empty(count, dtype=np.int64)
    columns = np.empty(count, dtype=np.int64)
    values = np.empty(count)
    count = 0
    for i in range(n):
        for k in range(n):
            if out[i, k] != 0.0:
                rows[count], columns[count], values[count] = i, k, out[i, k]
                count += 1
    return rows, columns, values


def standard_form(
    f_matrix, f, c, start, size, nonneg, x, y, z, warm,
    tol_feas, tol_gap_abs, tol_gap_rel, max_iterations, step_fraction, warm_shift, shift_max,
    ray_rtol,
):  # fmt: skip  # pragma: no cover - compiled
    """``min c'x`` s.t. ``F x = f``, ``x`` in the cones (dual: ``max f'y`` s.t.
    ``F'y + z = c``, ``z`` in the cones): the optimum into ``x``, ``y``, ``z``; ``(0,
    iterations)`` when solved, ``(2, iterations)`` where the iterates run off along a ray
    (``|F'y + z| <= ray_rtol f'y``: infeasible; ``|F x| <= ray_rtol (-c'x)``: unbounded), else
    ``(1, iterations)``. With ``warm``, from the ``x``, ``y`` and ``z`` given, each cone's part
    moved inside by a fraction of the largest entry: the relative residual of ``F x = f``
    there, clipped to ``[warm_shift, shift_max]``."""
    p, m = f_matrix.shape
    blocks = start.shape[0]
    degree = float(blocks)
    normal = np.empty((p, p))  # F W^2 F'
    chol = np.empty((p, p))
    if warm:
        moved = 0.0  # how far the last optimum is from F x = f now
        for i in range(p):
            total = f[i]
            for r in range(m):
                total -= f_matrix[i, r] * x[r]
            moved = max(moved, abs(total))
        fraction = min(max(moved / max(_largest(f), 1e-300), warm_shift), shift_max)
        shift_x = fraction * max(_largest(x), 1e-12)
        shift_z = fraction * max(_largest(z), 1e-12)
        for k in range(blocks):
            x[start[k]] += shift_x
            z[start[k]] += shift_z
    else:
        _mehrotra_start(f_matrix, f, c, normal, chol, start, size, nonneg, x, y, z)
    scale_f = _largest(f)
    scale_c = _largest(c)
    r_p = np.empty(p)
    r_d = np.empty(m)
    beta = np.ones(blocks)
    v = np.zeros(m)
    lam = np.zeros(m)
    scaled = np.empty((p, m))  # W F'
    dx = np.empty(m)
    dy = np.empty(p)
    dz = np.empty(m)
    jordan = np.empty(m)
    target = np.empty(m)
    work = np.empty(m)
    for iteration in range(max_iterations):
        _product(f_matrix, x, f, -1.0, r_p)
        _transposed_product(f_matrix, y, c, -1.0, r_d)
        for r in range(m):
            r_d[r] -= z[r]
        primal, dual, gap = 0.0, 0.0, 0.0
        for r in range(m):
            primal += c[r] * x[r]
            gap += x[r] * z[r]
        for i in range(p):
            dual += f[i] * y[i]
        primal_ok = _largest(r_p) <= tol_feas * max(1.0, scale_f + _largest(x))
        dual_ok = _largest(r_d) <= tol_feas * max(1.0, scale_c + _largest(z) + _largest(y))
        bound = tol_gap_abs + tol_gap_rel * min(abs(primal), abs(dual))
        if primal_ok and dual_ok and gap <= bound and abs(primal - dual) <= bound:
            return 0, iteration
        if _ray(f, r_p, primal, c, r_d, dual, ray_rtol):
            return 2, iteration
        mu = gap / degree
        if not _scaling(x, z, start, size, nonneg, beta, v, lam):
            return 1, iteration
        # F W^2 F' = (W F')' (W F').
        for i in range(p):
            for r in range(m):
                scaled[i, r] = f_matrix[i, r]
            _apply_scaling(scaled[i], start, size, nonneg, beta, v, False)
        _gram(scaled, normal)
        _modified_cholesky(normal, chol)
        # Predictor: lambda o (W^-1 dx + W dz) = -lambda o lambda, lambda \ d = -lambda.
        for r in range(m):
            jordan[r] = -lam[r]
        _direction(f_matrix, chol, start, size, nonneg, beta, v, r_p, r_d, jordan, dx, dy, dz,
                   work)  # fmt: skip
        step = min(1.0, _step(x, dx, start, size, nonneg), _step(z, dz, start, size, nonneg))
        after = 0.0
        for r in range(m):
            after += (x[r] + step * dx[r]) * (z[r] + step * dz[r])
        sigma = min(1.0, max(0.0, after / gap)) ** 3 if gap > 0.0 else 0.0
        # Corrector: d = -lambda o lambda - (W^-1 dx_a) o (W dz_a) + sigma mu e.
        _apply_scaling(dx, start, size, nonneg, beta, v, True)
        _apply_scaling(dz, start, size, nonneg, beta, v, False)
        _jordan_product(dx, dz, start, size, work)
        _jordan_product(lam, lam, start, size, target)
        for r in range(m):
            target[r] = -target[r] - work[r]
        for k in range(blocks):
            target[start[k]] += sigma * mu
        _jordan_solve(lam, target, start, size, jordan)
        _direction(f_matrix, chol, start, size, nonneg, beta, v, r_p, r_d, jordan, dx, dy, dz,
                   work)  # fmt: skip
        step = min(_step(x, dx, start, size, nonneg), _step(z, dz, start, size, nonneg))
        step = min(1.0, step_fraction * step)
        if step < 1e-10:
            return 1, iteration
        for r in range(m):
            x[r] += step * dx[r]
            z[r] += step * dz[r]
        for i in range(p):
            y[i] += step * dy[i]
    return 1, max_iterations


def _ray(f, r_p, primal, c, r_d, dual, ray_rtol):  # pragma: no cover - compiled
    """Whether ``y`` or ``x`` nearly certifies infeasibility or unboundedness: ``F'y + z = c -
    r_d`` small beside ``f'y > 0`` (``dual``), or ``F x = f - r_p`` beside ``-c'x > 0``
    (``primal``), largest entries."""
    if dual > 0.0:
        largest = 0.0
        for r in range(c.shape[0]):
            largest = max(largest, abs(c[r] - r_d[r]))
        if largest <= ray_rtol * dual:
            return True
    if primal < 0.0:
        largest = 0.0
        for i in range(f.shape[0]):
            largest = max(largest, abs(f[i] - r_p[i]))
        if largest <= -ray_rtol * primal:
            return True
    return False


def _mehrotra_start(
    f_matrix, f, c, normal, chol, start, size, nonneg, x, y, z
):  # pragma: no cover - compiled
    """Mehrotra's start: ``x = F'(FF')^-1 f``, ``y = (FF')^-1 F c``, ``z = c - F'y``, both
    moved into their cones (``normal`` and ``chol``: work arrays ``p x p``)."""
    p, m = f_matrix.shape
    _gram(f_matrix, normal)
    _modified_cholesky(normal, chol)
    t = f.copy()
    _cholesky_solve(chol, t)
    _transposed_product(f_matrix, t, np.zeros(m), 1.0, x)
    _product(f_matrix, c, np.zeros(p), 1.0, y)
    _cholesky_solve(chol, y)
    _transposed_product(f_matrix, y, c, -1.0, z)
    _into_cones(x, start, size, nonneg)
    _into_cones(z, start, size, nonneg)


def _direction(f_matrix, chol, start, size, nonneg, beta, v, r_p, r_d, jordan, dx, dy, dz,
               work):  # fmt: skip  # pragma: no cover - compiled
    """The Newton direction of ``F dx = r_p``, ``F'dy + dz = r_d`` and ``W^-1 dx + W dz =
    jordan``: ``F W^2 F' dy = r_p - F W jordan + F W^2 r_d``, ``dz = r_d - F'dy``,
    ``dx = W (jordan - W dz)``."""
    m = f_matrix.shape[1]
    for r in range(m):  # W^2 r_d - W jordan = W (W r_d - jordan)
        work[r] = r_d[r]
    _apply_scaling(work, start, size, nonneg, beta, v, False)
    for r in range(m):
        work[r] -= jordan[r]
    _apply_scaling(work, start, size, nonneg, beta, v, False)
    _product(f_matrix, work, r_p, 1.0, dy)
    _cholesky_solve(chol, dy)
    _transposed_product(f_matrix, dy, r_d, -1.0, dz)
    for r in range(m):
        dx[r] = dz[r]
    _apply_scaling(dx, start, size, nonneg, beta, v, False)
    for r in range(m):
        dx[r] = jordan[r] - dx[r]
    _apply_scaling(dx, start, size, nonneg, beta, v, False)


def _product(f_matrix, v, base, sign, out):  # pragma: no cover - compiled
    """``out = base + sign F v``."""
    for i in range(f_matrix.shape[0]):
        total = 0.0
        for r in range(f_matrix.shape[1]):
            total += f_matrix[i, r] * v[r]
        out[i] = base[i] + sign * total


def _transposed_product(f_matrix, v, base, sign, out):  # pragma: no cover - compiled
    """``out = base + sign F' v``."""
    for r in range(f_matrix.shape[1]):
        total = 0.0
        for i in range(f_matrix.shape[0]):
            total += f_matrix[i, r] * v[i]
        out[r] = base[r] + sign * total


def _gram(rows, out):  # pragma: no cover - compiled
    """``out = rows rows'``."""
    for i in range(rows.shape[0]):
        for k in range(i + 1):
            total = 0.0
            for r in range(rows.shape[1]):
                total += rows[i, r] * rows[k, r]
            out[i, k] = total
            out[k, i] = total


def _modified_cholesky(matrix, out):  # pragma: no cover - compiled
    """Lower Cholesky factor of ``matrix``; a pivot below ``PIVOT_RTOL`` of its diagonal entry
    (a direction the scaling made numerically dependent) becomes ``HUGE_PIVOT``, which drops it
    from the solves."""
    n = matrix.shape[0]
    for j in range(n):
        total = matrix[j, j]
        for t in range(j):
            total -= out[j, t] * out[j, t]
        if total <= PIVOT_RTOL * abs(matrix[j, j]):
            total = HUGE_PIVOT
        pivot = np.sqrt(total)
        out[j, j] = pivot
        for i in range(j + 1, n):
            total = matrix[i, j]
            for t in range(j):
                total -= out[i, t] * out[j, t]
            out[i, j] = total / pivot
        for i in range(j):
            out[i, j] = 0.0


def _cholesky_solve(chol, rhs):  # pragma: no cover - compiled
    """``rhs = (L L')^-1 rhs``, in place."""
    n = chol.shape[0]
    for i in range(n):
        total = rhs[i]
        for t in range(i):
            total -= chol[i, t] * rhs[t]
        rhs[i] = total / chol[i, i]
    for i in range(n - 1, -1, -1):
        total = rhs[i]
        for t in range(i + 1, n):
            total -= chol[t, i] * rhs[t]
        rhs[i] = total / chol[i, i]


def _largest(values):  # pragma: no cover - compiled
    out = 0.0
    for value in values:
        out = max(out, abs(value))
    return out


def _into_cones(values, start, size, nonneg):  # pragma: no cover - compiled
    """Move ``values`` into the interior of the cones: add ``(1 + a) e`` where ``a`` is the
    least multiple of ``e`` that reaches the cones (when that is not clearly negative)."""
    reach = -np.inf
    norm = 0.0
    for k in range(start.shape[0]):
        first = start[k]
        if k < nonneg:
            reach = max(reach, -values[first])
        else:
            tail = 0.0
            for r in range(first + 1, first + size[k]):
                tail += values[r] * values[r]
            reach = max(reach, np.sqrt(tail) - values[first])
        for r in range(first, first + size[k]):
            norm += values[r] * values[r]
    if reach >= -1e-8 * max(np.sqrt(norm), 1.0):
        for k in range(start.shape[0]):
            values[start[k]] += 1.0 + reach


def _scaling(s, z, start, size, nonneg, beta, v, lam):  # pragma: no cover - compiled
    """The Nesterov-Todd scaling of ``s`` and ``z`` (``False`` if either left its cone)."""
    for k in range(start.shape[0]):
        first, dim = start[k], size[k]
        if k < nonneg:
            if s[first] <= 0.0 or z[first] <= 0.0:
                return False
            beta[k] = np.sqrt(s[first] / z[first])
            continue
        s_norm = _hyperbolic_norm(s, first, dim)
        z_norm = _hyperbolic_norm(z, first, dim)
        if s_norm <= 0.0 or z_norm <= 0.0:
            return False
        beta[k] = np.sqrt(np.sqrt(s_norm / z_norm))
        inner = 0.0
        for r in range(first, first + dim):
            inner += s[r] * z[r]
        gamma = np.sqrt(0.5 * (1.0 + inner / np.sqrt(s_norm * z_norm)))
        # w = (s/|s|_J + J z/|z|_J) / (2 gamma); v = (w + e) / sqrt(2 (w_0 + 1)).
        w0 = (s[first] / np.sqrt(s_norm) + z[first] / np.sqrt(z_norm)) / (2.0 * gamma)
        scale = 1.0 / np.sqrt(2.0 * (w0 + 1.0))
        v[first] = (w0 + 1.0) * scale
        for r in range(first + 1, first + dim):
            w = (s[r] / np.sqrt(s_norm) - z[r] / np.sqrt(z_norm)) / (2.0 * gamma)
            v[r] = w * scale
    lam[:] = z  # lambda = W z
    _apply_scaling(lam, start, size, nonneg, beta, v, False)
    return True


def _hyperbolic_norm(u, first, dim):  # pragma: no cover - compiled
    """``u_0^2 - |u_1|^2`` of the cone at ``first``, computed as a product of a sum and a
    difference (no cancellation near the boundary); 0 or less outside the interior."""
    tail = 0.0
    for r in range(first + 1, first + dim):
        tail += u[r] * u[r]
    tail = np.sqrt(tail)
    return (u[first] - tail) * (u[first] + tail) if u[first] > tail else 0.0


def _apply_scaling(u, start, size, nonneg, beta, v, inverse):  # pragma: no cover - compiled
    """``u`` times ``W`` (or ``W^-1`` with ``inverse``), in place. (One loop with no calls: an
    inlined helper taking the arrays cost two atomic reference counts per array and block.)"""
    for k in range(start.shape[0]):
        first, dim = start[k], size[k]
        if k < nonneg:
            u[first] = u[first] / beta[k] if inverse else u[first] * beta[k]
        elif inverse:  # (2 J v v' J - J) u / beta
            jvu = v[first] * u[first]
            for r in range(first + 1, first + dim):
                jvu -= v[r] * u[r]
            u[first] = (2.0 * v[first] * jvu - u[first]) / beta[k]
            for r in range(first + 1, first + dim):
                u[r] = (-2.0 * v[r] * jvu + u[r]) / beta[k]
        else:  # beta (2 v v' - J) u
            vu = 0.0
            for r in range(first, first + dim):
                vu += v[r] * u[r]
            u[first] = beta[k] * (2.0 * v[first] * vu - u[first])
            for r in range(first + 1, first + dim):
                u[r] = beta[k] * (2.0 * v[r] * vu + u[r])


def _jordan_product(a, b, start, size, out):  # pragma: no cover - compiled
    """``out = a o b``: ``(a'b, a_0 b_1 + b_0 a_1)`` on each cone, ``a b`` on rows."""
    for k in range(start.shape[0]):
        first, dim = start[k], size[k]
        inner = 0.0
        for r in range(first, first + dim):
            inner += a[r] * b[r]
        for r in range(first + 1, first + dim):
            out[r] = a[first] * b[r] + b[first] * a[r]
        out[first] = inner


def _jordan_solve(lam, d, start, size, out):  # pragma: no cover - compiled
    """``out = lambda \\ d``, the ``x`` of ``lambda o x = d``."""
    for k in range(start.shape[0]):
        first, dim = start[k], size[k]
        tail_inner, tail_norm = 0.0, 0.0
        for r in range(first + 1, first + dim):
            tail_inner += lam[r] * d[r]
            tail_norm += lam[r] * lam[r]
        head = (lam[first] * d[first] - tail_inner) / (lam[first] ** 2 - tail_norm)
        out[first] = head
        for r in range(first + 1, first + dim):
            out[r] = (d[r] - head * lam[r]) / lam[first]


def _step(u, d, start, size, nonneg):  # pragma: no cover - compiled
    """The largest ``t`` with ``u + t d`` in the cones (``inf`` if every ``t >= 0``)."""
    out = np.inf
    for k in range(start.shape[0]):
        first, dim = start[k], size[k]
        if k < nonneg:
            if d[first] < 0.0:
                out = min(out, -u[first] / d[first])
            continue
        # (u_0 + t d_0)^2 - |u_1 + t d_1|^2 = c + 2 b t + a t^2.
        c = _hyperbolic_norm(u, first, dim)
        a_term = d[first] * d[first]
        b_term = u[first] * d[first]
        for r in range(first + 1, first + dim):
            a_term -= d[r] * d[r]
            b_term -= u[r] * d[r]
        if a_term >= 0.0 and d[first] >= 0.0:
            continue
        root = np.sqrt(max(b_term * b_term - a_term * c, 0.0))
        out = min(out, c / (root - b_term)) if root - b_term > 0.0 else 0.0
    return out


# The helpers compiled before the solves that call them.
_largest = compiled_scalar(_largest, inline=True)
_into_cones = compiled_scalar(_into_cones)
_hyperbolic_norm = compiled_scalar(_hyperbolic_norm, inline=True)
_apply_scaling = compiled_scalar(_apply_scaling)
_scaling = compiled_scalar(_scaling)
_jordan_product = compiled_scalar(_jordan_product)
_jordan_solve = compiled_scalar(_jordan_solve)
_step = compiled_scalar(_step)
_ray = compiled_scalar(_ray)
_product = compiled_scalar(_product)
_transposed_product = compiled_scalar(_transposed_product)
_gram = compiled_scalar(_gram)
_modified_cholesky = compiled_scalar(_modified_cholesky)
_cholesky_solve = compiled_scalar(_cholesky_solve)
_mehrotra_start = compiled_scalar(_mehrotra_start)
_direction = compiled_scalar(_direction)
_block_inverse = compiled_scalar(_block_inverse)
_STANDARD = compiled_scalar(standard_form)
_SOLVE = compiled_scalar(solve_standard_form)
