r"""The inverse map compiled whole, for point sets, polygons, grids, disks, ellipsoids and sums.

One numba loop per load runs the method of :mod:`fixplan.surface.inverse`: damped Newton on the
plane ``L·V = 1`` from the ellipsoid's twist, then (point supports) the exact facet tests of the
slowest support points and, where Newton stalled at a kink that is not a facet, the smoothing
continuation. The iterates are those of the NumPy path to rounding; only the Python around each
iteration is gone (a few microseconds per query on a few points instead of half a millisecond),
and next to the kinks of point supports Newton stops sooner (:data:`STALLED_DECREMENT`): the
answers agree with the NumPy path's to rounding.

A kernel is passed as a tuple (its entries named by :data:`WHOLE` to :data:`TABLES`) of three
arrays and a few numbers: a table of its summed parts (one row each, its columns named by
:data:`KIND` to :data:`TRANSFORM`), the points' columns ``(3, P)`` (``x``, ``y`` [m] and
friction: point sets, and the far-field rules of polygons and grids) and the tables
``(TABLE_ROWS, T)``: the polygons' edge tables ``(7, E)`` (kind
:data:`~fixplan.surface.closed_form.EDGES`), the grids' node tables ``(3, N)`` (kind
:data:`~fixplan.surface.closed_form.NODES`), both with their far-field radius, and the disk
tables ``(3, D)`` (kind :data:`DISKS`), the shorter ones padded. A part is weighed by its weight
and sees the local twist ``T V`` of its transform ``T`` (where posed); its points and table are
the ranges of columns its row names. An ellipsoid is the unit ball (:data:`BALL`) through its
factor. The discrete point supports, the facets, are the first :data:`FACET_COUNT` points: one
part in the contact frame. A kernel of one part, unposed and of weight 1 (``whole``), is
evaluated with its arrays whole (:func:`_whole_terms`).

The per-twist terms come from :mod:`~fixplan.surface.point_kernel`,
:mod:`~fixplan.surface.polygon_kernel`, :mod:`~fixplan.surface.grid_kernel` and
:mod:`~fixplan.surface.disk_compiled`. numba keys its on-disk cache by each compiled function's
own file, so after editing those modules in a working copy, delete the cache folder
(:func:`~fixplan.surface.point_kernel.user_cache_dir`): the cached loops here would keep the old
terms. (Installing a new version replaces every file, which invalidates the whole cache.)
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numba
import numpy as np

from fixplan.errors import ConvergenceError, InvalidArgumentError
from fixplan.surface.closed_form import _NEAR_TERMS, ClosedFormKernel
from fixplan.surface.disk_compiled import _DISK_TERMS, PROFILES
from fixplan.surface.disk_kernel import AnnulusKernel, DiskKernel
from fixplan.surface.kernels import (
    EllipsoidKernel,
    PosedKernel,
    SumKernel,
    SupportKernel,
    twist_to_local,
)
from fixplan.surface.point_kernel import (
    _POINT_TERMS,
    PointSetKernel,
    _compiled,
    _pick,
    compiled_scalar,
)
from fixplan.tolerances import (
    FACET_RTOL,
    FAR_FIELD_RADII,
    INVERSE_GRADIENT_RTOL,
    INVERSE_MAX_ITERATIONS,
    INVERSE_RTOL,
)

#: Kinds of compiled parts: weighted points, polygon edges or grid nodes with a far-field
#: point rule, closed-form disks, or the unit ball (an ellipsoid through its transform).
POINTS = 0
DISKS = 2
BALL = 4
# EDGES = 1 and NODES = 3: see fixplan.surface.closed_form.

#: Where a kernel's entries sit in its tuple (see the module): whether it is one part, unposed,
#: of weight 1, that part's kind and far-field radius, the number of facets; the parts' table,
#: the points' columns and the tables. (Few arrays: each array of a tuple costs about 10 ns per
#: call between compiled functions that branch, in its reference counting, a tenth of a few
#: points' terms; so does each view made of an array, so ranges are passed instead.)
WHOLE, WHOLE_KIND, WHOLE_REACH, FACET_COUNT, PARTS, COLUMNS, TABLES = range(7)

#: Columns of a kernel's parts table: kind, first and end point, first and end table column,
#: weight, far-field radius, whether posed (1.0 or 0.0), then the transform (row by row).
KIND, POINT_START, POINT_STOP, TABLE_START, TABLE_STOP, WEIGHT, REACH, POSED, TRANSFORM = range(9)

#: Rows of the table of a kernel's parts: a polygon's edges have the most.
TABLE_ROWS = 7

#: Number of nearest support points whose facets are tested per query.
FACETS_TESTED = 3

#: Newton decrement (relative to h) below which full steps are taken without a line search:
#: there the iteration is quadratic and rounding would defeat the sufficient-decrease test.
QUADRATIC_REGION = 1e-12

#: A support point whose weighted speed is below this fraction of the support value (both of
#: the unit-friction kernel) sits on a possible kink.
NEAR_KINK = 1e-6

#: Kink handling of :func:`_newton`: none (smooth functions), stop where steps crawl into a
#: kink, or also stop at the first rejected full step and name the kink it crosses.
SMOOTH = 0
CRAWLS = 1
PROBES = 2

#: Smoothing speeds (relative to the translation speed of the twist) of the continuation that
#: takes over where Newton stalls at a kink.
SMOOTHING_STAGES = (1e-1, 1e-2, 1e-3, 1e-4, 1e-6, 1e-8, 1e-10, 1e-12)

#: With point supports, Newton stops at a kink where its decrement falls by less than
#: ``STALLED_DECREMENT`` in an iteration (it falls quadratically where ``h`` is smooth) and the
#: slowest support point's weighted speed is below ``STALLED_NEAR_KINK`` of ``h``: the iterates
#: are closing in on that point's kink, which is certified there (:func:`_certify_kink`) instead
#: of after a step across it. Near the facets of 4,096 points: 8.4 passes over the points per
#: query instead of 10.2; other loads unchanged (benchmarks/bench_limit_surface.py). At 1e-6 of
#: ``h`` a few loads stopped at a point whose kink was not the answer's.
STALLED_DECREMENT = 0.3
STALLED_NEAR_KINK = 1e-7

#: Newton leaves a kink (:func:`_escape_kink`) from a start this close to the facet's twist
#: (relative) with the terms estimated there (:func:`_terms_near_facet`) rather than evaluated:
#: next to the facets of 4,096 points (benchmarks/bench_limit_surface.py, starts about 1e-7
#: away) 5.2 passes over the points with Hessians per query instead of 6.2, the same answers
#: to 1.3e-15; the estimate's gradient is off by up to about ``4e3 d²`` at a distance ``d``.
NEAR_FACET = 1e-4

#: A Newton step damped below this fraction signals a kink: Newton stops there.
CRAWL = 1e-3

#: Most step halvings of the backtracking line search.
MAX_HALVINGS = 60

#: Sufficient decrease of the line search (Armijo constant).
_ARMIJO = 1e-4

#: The ridge added to the projected Hessian (relative to its trace) keeps it invertible.
RIDGE = 1e-14

#: Largest angle [rad] (normalised coordinates) between a start twist and its load's ray for
#: Newton to start from it: a start nearly parallel to the plane ``L·V = 1`` meets it far out
#: (10 times farther than the ellipsoid's twist at this angle, 84°).
START_MAX_ANGLE = math.acos(0.1)


def _terms(kernel, eps2, twist, with_hessian, local, out):  # pragma: no cover - compiled
    """Support value, gradient and (``with_hessian``) Hessian of the unit-friction ``kernel`` at
    the contact-frame ``twist`` (3,) [m/s, rad/s], in ``out`` (10,) as ``point_terms`` writes
    them (without the Hessian, ``out[4:]`` is left as it was); ``local`` (10,) is scratch.
    ``eps2`` [m²/s²] smooths the speeds of points. The parts' terms are summed, each at its
    local twist ``T V`` and weighed: ``g = w Tᵀ g_local``, ``H = w Tᵀ H_local T``."""
    if kernel[WHOLE]:
        _whole_terms(kernel, eps2, twist[0], twist[1], twist[2], with_hessian, out)
        return
    parts = kernel[PARTS]
    last = 10 if with_hessian else 4
    for i in range(last):
        out[i] = 0.0
    t = np.empty((3, 3))
    hl = np.empty((3, 3))
    for part in range(parts.shape[0]):
        posed = parts[part, POSED] != 0.0
        vx, vy, w = twist[0], twist[1], twist[2]
        if posed:
            for i in range(3):
                for j in range(3):
                    t[i, j] = parts[part, TRANSFORM + 3 * i + j]
            vx, vy, w = (
                t[0, 0] * twist[0] + t[0, 1] * twist[1] + t[0, 2] * twist[2],
                t[1, 0] * twist[0] + t[1, 1] * twist[1] + t[1, 2] * twist[2],
                t[2, 0] * twist[0] + t[2, 1] * twist[1] + t[2, 2] * twist[2],
            )
        _part_terms(kernel, part, eps2, vx, vy, w, with_hessian, local)
        weight = parts[part, WEIGHT]
        out[0] += weight * local[0]
        if not posed:
            for i in range(1, last):
                out[i] += weight * local[i]
            continue
        for i in range(3):
            out[1 + i] += weight * (t[0, i] * local[1] + t[1, i] * local[2] + t[2, i] * local[3])
        if not with_hessian:
            continue
        _unpack(local, hl)
        for slot, (i, j) in enumerate(((0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2))):
            total = 0.0
            for a in range(3):
                for b in range(3):
                    total += t[a, i] * hl[a, b] * t[b, j]
            out[4 + slot] += weight * total


def _whole_terms(kernel, eps2, vx, vy, w, with_hessian, out):  # pragma: no cover - compiled
    """:func:`_terms` of a kernel of one part, unposed and of weight 1 (its arrays whole)."""
    kind = kernel[WHOLE_KIND]
    if kind == DISKS or (kind != POINTS and abs(w) * kernel[WHOLE_REACH] > math.hypot(vx, vy)):
        _table_terms(kind, kernel[TABLES], vx, vy, w, with_hessian, out)
    else:
        columns = kernel[COLUMNS]
        _POINT_TERMS(columns, 0, columns.shape[1], eps2, vx, vy, w, with_hessian, out)


def _part_terms(kernel, part, eps2, vx, vy, w, with_hessian, out):  # pragma: no cover - compiled
    """:func:`_terms` of one ``part`` of the ``kernel`` at its local twist ``(vx, vy, w)``,
    unweighed."""
    parts = kernel[PARTS]
    kind = int(parts[part, KIND])
    if kind == BALL:
        _ball_terms(vx, vy, w, with_hessian, out)
        return
    if kind == DISKS or (kind != POINTS and abs(w) * parts[part, REACH] > math.hypot(vx, vy)):
        start, stop = int(parts[part, TABLE_START]), int(parts[part, TABLE_STOP])
        _table_terms(kind, kernel[TABLES][:, start:stop], vx, vy, w, with_hessian, out)
        return
    start, stop = int(parts[part, POINT_START]), int(parts[part, POINT_STOP])
    _POINT_TERMS(kernel[COLUMNS], start, stop, eps2, vx, vy, w, with_hessian, out)


def _table_terms(kind, table, vx, vy, w, with_hessian, out):  # pragma: no cover - compiled
    """The terms of a disk, polygon or grid ``table`` (rows beyond its own are padding)."""
    if kind == DISKS:
        _DISK_TERMS(table, vx, vy, w, with_hessian, out)
    else:
        _NEAR_TERMS(kind, table, vx, vy, w, with_hessian, out)


def _ball_terms(vx, vy, w, with_hessian, out):  # pragma: no cover - compiled
    """The terms of the unit ball's support ``h(u) = |u|`` at ``u = (vx, vy, w)``: ``g = u / h``,
    ``H = (I - g gᵀ) / h`` (an ellipsoid's, through its part's transform)."""
    h = math.sqrt(vx * vx + vy * vy + w * w)
    g0, g1, g2 = vx / h, vy / h, w / h
    out[0], out[1], out[2], out[3] = h, g0, g1, g2
    if with_hessian:
        out[4], out[5], out[6] = (1.0 - g0 * g0) / h, -g0 * g1 / h, -g0 * g2 / h
        out[7], out[8], out[9] = (1.0 - g1 * g1) / h, -g1 * g2 / h, (1.0 - g2 * g2) / h


def _unpack(terms, hess):  # pragma: no cover - compiled
    """The symmetric Hessian ``hess`` (3, 3) from ``terms[4:10]``."""
    hess[0, 0] = terms[4]
    hess[0, 1] = hess[1, 0] = terms[5]
    hess[0, 2] = hess[2, 0] = terms[6]
    hess[1, 1] = terms[7]
    hess[1, 2] = hess[2, 1] = terms[8]
    hess[2, 2] = terms[9]


def _projected(terms, b1, b2):  # pragma: no cover - compiled
    """``g·b1``, ``g·b2``, ``b1ᵀ H b1``, ``b1ᵀ H b2`` and ``b2ᵀ H b2`` of ``terms``."""
    h = np.empty((3, 3))
    _unpack(terms, h)
    g1 = terms[1] * b1[0] + terms[2] * b1[1] + terms[3] * b1[2]
    g2 = terms[1] * b2[0] + terms[2] * b2[1] + terms[3] * b2[2]
    h11 = 0.0
    h12 = 0.0
    h22 = 0.0
    for i in range(3):
        for j in range(3):
            h11 += b1[i] * h[i, j] * b1[j]
            h12 += b1[i] * h[i, j] * b2[j]
            h22 += b2[i] * h[i, j] * b2[j]
    return g1, g2, h11, h12, h22


def _newton_step(g1, g2, h11, h12, h22):  # pragma: no cover - compiled
    """Step ``(s1, s2)`` in plane coordinates and the Newton decrement ``gᵀ H⁻¹ g``; steepest
    descent where the Hessian is unusable (never at a smooth minimum)."""
    ridge = RIDGE * abs(h11 + h22) + 1e-300
    h11 += ridge
    h22 += ridge
    det = h11 * h22 - h12 * h12
    if det > 0.0:
        s1 = -(h22 * g1 - h12 * g2) / det
        s2 = -(h11 * g2 - h12 * g1) / det
        decrement = -(g1 * s1 + g2 * s2)
        if math.isfinite(decrement) and decrement >= 0.0:
            return s1, s2, decrement
    return -g1, -g2, g1 * g1 + g2 * g2


def _newton(kernel, eps2, twist, b1, b2, kinks, current, given=False):  # pragma: no cover
    """Damped Newton on the plane through ``twist`` spanned by ``b1``, ``b2`` [SI], in place on
    ``twist``. Returns whether it stalled (no descent, a crawl into a kink unless ``kinks`` is
    :data:`SMOOTH`, or the iteration limit), the support value at the final ``twist`` and,
    with ``kinks`` :data:`PROBES`, the support point whose kink the first rejected full step
    crosses (Newton stops there; else -1). ``current`` (10,) is left with the terms at the
    final ``twist``: its Hessian is that of the last iterate where a full step in the quadratic
    region ended the iteration (a relative change of the size of that step, about 1e-6).
    With :data:`PROBES` Newton also stops where its decrement stalls next to a kink
    (:data:`STALLED_DECREMENT`) and names that kink's support point. With ``given``,
    ``current`` holds the terms at ``twist`` already (estimated: they set the first step, never
    the answer; every later iterate's terms are evaluated)."""
    local = np.empty(10)
    new = np.empty(10)
    step = np.empty(3)
    trial = np.empty(3)
    if not given:
        _terms(kernel, eps2, twist, True, local, current)
    previous = np.inf
    for iteration in range(INVERSE_MAX_ITERATIONS):
        h = current[0]
        s1, s2, decrement = _newton_step(*_projected(current, b1, b2))
        if decrement <= INVERSE_RTOL**2 * h and not (given and iteration == 0):
            return False, h, -1
        if kinks == PROBES and decrement > STALLED_DECREMENT * previous:
            slowest, speed = _slowest_point(kernel, twist)
            if speed <= STALLED_NEAR_KINK * h:
                return True, h, slowest
        previous = decrement
        for i in range(3):
            step[i] = s1 * b1[i] + s2 * b2[i]
            trial[i] = twist[i] + step[i]
        if decrement <= QUADRATIC_REGION * h:
            # The full step is taken; it nearly always ends the iteration, which the decrement
            # at its gradient with this Hessian (a relative change of the size of the step)
            # shows without the cost of a new Hessian.
            _terms(kernel, eps2, trial, False, local, new)
            new[4:] = current[4:]
            if _newton_step(*_projected(new, b1, b2))[2] <= INVERSE_RTOL**2 * new[0]:
                twist[:] = trial
                current[:] = new
                return False, new[0], -1
        # The full step is tried with the terms of the next iteration: it is nearly always taken.
        _terms(kernel, eps2, trial, True, local, new)
        t = 1.0
        # Near the minimum the sufficient decrease is below rounding: full steps are taken.
        if decrement > QUADRATIC_REGION * h and new[0] > h - _ARMIJO * decrement:
            if kinks == PROBES:
                return True, h, _nearest_kink(kernel, twist, step)
            accepted = False
            for _ in range(MAX_HALVINGS - 1):
                t *= 0.5
                for i in range(3):
                    trial[i] = twist[i] + t * step[i]
                _terms(kernel, eps2, trial, False, local, new)
                if new[0] <= h - _ARMIJO * t * decrement:
                    accepted = True
                    break
            if not accepted:
                return True, h, -1
            _terms(kernel, eps2, trial, True, local, new)
        twist[:] = trial
        current[:] = new
        if kinks != SMOOTH and t < CRAWL:
            return True, current[0], -1
    return True, current[0], -1


def _slowest_point(kernel, twist):  # pragma: no cover - compiled
    """The support point with the least weighted speed under ``twist``, and that speed."""
    index = np.empty(1, dtype=np.int64)
    speed = np.empty(1)
    _slowest(kernel, twist, index, speed)
    return index[0], speed[0]


def _slowest(kernel, twist, index, speed):  # pragma: no cover - compiled
    """Indices ``index`` (n,) of the points with the least weighted speed under ``twist``, and
    those speeds ``|v_i| * weight_i`` in ``speed``, slowest first."""
    points = kernel[COLUMNS]
    count = index.shape[0]
    speed[:] = np.inf
    index[:] = -1
    for i in range(kernel[FACET_COUNT]):
        ux = twist[0] - twist[2] * points[1, i]
        uy = twist[1] + twist[2] * points[0, i]
        s = math.sqrt(ux * ux + uy * uy) * points[2, i]
        if s < speed[count - 1]:
            j = count - 1
            while j > 0 and s < speed[j - 1]:
                speed[j] = speed[j - 1]
                index[j] = index[j - 1]
                j -= 1
            speed[j] = s
            index[j] = i


def _facet(kernel, load, scale, k, twist, with_hessian, terms):  # pragma: no cover - compiled
    """The safety factor of ``load`` on the facet of support point ``k``; ``inf`` where the load
    does not lie on it (the force point ``k`` must carry to balance it is above its friction
    limit), NaN where the facet is parallel to the load. The facet's twist (on the plane
    ``L·V = 1``) is left in ``twist`` and the terms of the other points there in ``terms``."""
    points = kernel[COLUMNS]
    twist[0], twist[1], twist[2] = points[1, k], -points[0, k], 1.0
    power = load[0] * twist[0] + load[1] * twist[1] + load[2]
    if power == 0.0:
        return np.nan
    twist /= power
    local = np.empty(10)
    _terms(kernel, 0.0, twist, with_hessian, local, terms)
    s_k = scale * terms[0]
    carried = math.hypot(s_k * load[0] - scale * terms[1], s_k * load[1] - scale * terms[2])
    return s_k if carried <= scale * points[2, k] * (1.0 + FACET_RTOL) else np.inf


def _facets(kernel, load, scale, twist, safety):  # pragma: no cover - compiled
    """The safety factor on the facets of the slowest support points where ``load`` lies on
    one (``twist`` is then set to the facet's twist), else ``safety``; and whether it does."""
    count = min(FACETS_TESTED, kernel[FACET_COUNT])
    index = np.empty(count, dtype=np.int64)
    speed = np.empty(count)
    _slowest(kernel, twist, index, speed)
    facet = np.empty(3)
    terms = np.empty(10)
    on_facet = False
    for k in index:
        s_k = _facet(kernel, load, scale, k, facet, False, terms)
        if s_k <= safety * (1.0 + 1e-9):
            safety = s_k
            twist[:] = facet
            on_facet = True
    return safety, on_facet


def _nearest_kink(kernel, twist, step):  # pragma: no cover - compiled
    """The support point that comes nearest to standing still (least weighted speed) on the
    segment from ``twist`` to ``twist + step``: the kink a rejected Newton step crosses."""
    points = kernel[COLUMNS]
    best = np.inf
    nearest = 0
    for i in range(kernel[FACET_COUNT]):
        x, y, weight = points[0, i], points[1, i], points[2, i]
        ux = twist[0] - twist[2] * y
        uy = twist[1] + twist[2] * x
        dx = step[0] - step[2] * y
        dy = step[1] + step[2] * x
        t = min(max(-(ux * dx + uy * dy) / (dx * dx + dy * dy), 0.0), 1.0)
        ex = ux + t * dx
        ey = uy + t * dy
        speed = (ex * ex + ey * ey) * weight * weight
        if speed < best:
            best = speed
            nearest = i
    return nearest


def _certify_kink(kernel, load, scale, twist, b1, b2, k):  # pragma: no cover - compiled
    """The safety factor where ``load`` lies on the facet of support point ``k`` or where Newton
    converges next to its kink (:func:`_escape_kink`), with ``twist`` set to the motion; 0
    (``twist`` unchanged) otherwise. Either is a certificate: ``h`` is convex on the plane."""
    facet = np.empty(3)
    rest = np.empty(10)
    # (With the other points' Hessian, which the escape needs: one pass over the points.)
    s_k = _facet(kernel, load, scale, k, facet, True, rest)
    if s_k < np.inf:
        twist[:] = facet
        return s_k
    if math.isnan(s_k):
        return 0.0
    return scale * _escape_kink(kernel, twist, b1, b2, k, facet, rest)


def _escape_kink(kernel, twist, b1, b2, k, facet, rest):  # pragma: no cover - compiled
    r"""Newton's minimum next to the kink of support point ``k`` where the load is not on that
    point's facet (twist ``facet``, where the other points have the terms ``rest``); ``twist``
    is set to it. Returns its support value, or 0 (``twist`` unchanged) where Newton does not
    converge from the start below.

    On the plane, the speed of point ``k`` is ``u = M (α, β)`` (``M`` = ``[A b1, A b2]``,
    ``A = [[1, 0, -y_k], [0, 1, x_k]]``), zero at the facet's twist ``F``. With the gradient
    ``G`` and Hessian ``H`` of the other points at ``F`` (``g_u = M⁻ᵀ (G·b1, G·b2)``, larger
    than the weight ``w_k`` off the facet) the support along ``u = -r ĝ_u`` is
    ``h(F) - r |g_u| + w_k r + r² dᵀHd / 2``, least at ``r = (|g_u| - w_k) / dᵀHd``: a start
    on the smooth side of the kink, from which Newton converges quadratically.
    """
    points = kernel[COLUMNS]
    x, y, weight = points[0, k], points[1, k], points[2, k]
    m00 = b1[0] - b1[2] * y
    m10 = b1[1] + b1[2] * x
    m01 = b2[0] - b2[2] * y
    m11 = b2[1] + b2[2] * x
    det = m00 * m11 - m01 * m10
    g1 = rest[1] * b1[0] + rest[2] * b1[1] + rest[3] * b1[2]
    g2 = rest[1] * b2[0] + rest[2] * b2[1] + rest[3] * b2[2]
    gu0 = (m11 * g1 - m10 * g2) / det
    gu1 = (-m01 * g1 + m00 * g2) / det
    pull = math.hypot(gu0, gu1)
    if not pull > weight:
        return 0.0
    # Plane direction δ = M⁻¹ û with û = -g_u / |g_u|.
    d0 = -(m11 * gu0 - m01 * gu1) / (det * pull)
    d1 = -(-m10 * gu0 + m00 * gu1) / (det * pull)
    d = d0 * b1 + d1 * b2
    hess = np.empty((3, 3))
    _unpack(rest, hess)
    curvature = 0.0
    for i in range(3):
        for j in range(3):
            curvature += d[i] * hess[i, j] * d[j]
    if not (curvature > 0.0 and math.isfinite(curvature)):
        return 0.0
    distance = (pull - weight) / curvature
    start = facet + distance * d
    current = np.empty(10)
    near = distance * math.sqrt(d[0] ** 2 + d[1] ** 2 + d[2] ** 2) <= NEAR_FACET * math.sqrt(
        facet[0] ** 2 + facet[1] ** 2 + facet[2] ** 2
    )
    if near:
        _terms_near_facet(kernel, k, facet, rest, hess, start, current)
    stalled, h, _ = _newton(kernel, 0.0, start, b1, b2, CRAWLS, current, near)
    if stalled:
        return 0.0
    twist[:] = start
    return h


def _terms_near_facet(kernel, k, facet, rest, hess, twist, out):  # pragma: no cover
    """The terms (:func:`_terms`, with the Hessian) at ``twist``, next to the ``facet`` twist
    of support point ``k`` where the other points have the terms ``rest`` (``hess`` unpacked):
    theirs by Taylor's formula to second order (the third-order rest is of the size of the step
    cubed, which :func:`_escape_kink` takes at about 1e-7 of the twist near the facets of 4,096
    points), point ``k``'s exactly. Saves a pass over the points (one of about seven of such a
    query), as Newton's first step from ``twist`` needs these terms only."""
    step = np.empty(3)
    moved = np.zeros(3)
    for i in range(3):
        step[i] = twist[i] - facet[i]
    for i in range(3):
        for j in range(3):
            moved[i] += hess[i, j] * step[j]
    out[0] = rest[0] + (rest[1] + 0.5 * moved[0]) * step[0] + (rest[2] + 0.5 * moved[1]) * step[1]
    out[0] += (rest[3] + 0.5 * moved[2]) * step[2]
    for i in range(3):
        out[1 + i] = rest[1 + i] + moved[i]
    out[4:] = rest[4:]
    own = np.empty(10)
    _POINT_TERMS(kernel[COLUMNS], k, k + 1, 0.0, twist[0], twist[1], twist[2], True, own)
    for i in range(10):
        out[i] += own[i]


def _continuation(kernel, units, scale, twist, safety, b1, b2):  # pragma: no cover - compiled
    """Minimise ``h`` where Newton stalled at a kink that is not the minimum: speeds rounded off
    as ``sqrt(|u|² + eps²)``, ``eps`` reduced stage by stage to zero, each stage starting where
    the last ended. Keeps the result (``twist`` in place) only where it lowers ``h``; returns
    the safety factor."""
    start = twist.copy()
    terms = np.empty(10)
    for eta in SMOOTHING_STAGES:
        _newton(kernel, (eta / units[0]) ** 2, twist, b1, b2, SMOOTH, terms)
    found = scale * _newton(kernel, 0.0, twist, b1, b2, SMOOTH, terms)[1]
    if found < safety:
        return found
    twist[:] = start
    return safety


def _plane(load, units, twist, b1, b2):  # pragma: no cover - compiled
    """Start ``twist`` (the ellipsoid's, on ``L·V = 1``) and the plane's basis ``b1``, ``b2``
    (orthonormal in normalised coordinates, divided by ``units``)."""
    d = np.empty(3)
    for i in range(3):
        d[i] = load[i] / units[i]
    length = math.sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2])
    d /= length
    axis = 0
    for i in (1, 2):
        if abs(d[i]) < abs(d[axis]):
            axis = i
    # e1 = d × (unit vector along the axis of d's smallest component), e2 = d × e1.
    e1 = np.zeros(3)
    e1[(axis + 1) % 3] = d[(axis + 2) % 3]
    e1[(axis + 2) % 3] = -d[(axis + 1) % 3]
    e1 /= math.sqrt(e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2])
    e2 = np.empty(3)
    e2[0] = d[1] * e1[2] - d[2] * e1[1]
    e2[1] = d[2] * e1[0] - d[0] * e1[2]
    e2[2] = d[0] * e1[1] - d[1] * e1[0]
    for i in range(3):
        b1[i] = e1[i] / units[i]
        b2[i] = e2[i] / units[i]
        twist[i] = d[i] / (length * units[i])


def _start_on_plane(units, start, twist, b1, b2):  # pragma: no cover - compiled
    """Move ``twist`` (the ellipsoid's, on the plane ``L·V = 1``) within the plane to where the
    ray of ``start`` meets it, if that ray is within :data:`START_MAX_ANGLE` of the load's
    (normalised coordinates). Only the components along ``b1`` and ``b2`` are added: the twist
    stays on the plane to rounding whatever the start's size."""
    s = np.empty(3)
    largest = 0.0
    for i in range(3):
        s[i] = start[i] * units[i]
        if not math.isfinite(s[i]):
            return
        largest = max(largest, abs(s[i]))
    if largest == 0.0:
        return
    s /= largest
    t0 = np.empty(3)  # the ellipsoid's twist, normalised: the load's direction over its size
    for i in range(3):
        t0[i] = twist[i] * units[i]
    along = s[0] * t0[0] + s[1] * t0[1] + s[2] * t0[2]
    t0_squared = t0[0] * t0[0] + t0[1] * t0[1] + t0[2] * t0[2]
    s_length = math.sqrt(s[0] * s[0] + s[1] * s[1] + s[2] * s[2])
    if along <= math.cos(START_MAX_ANGLE) * s_length * math.sqrt(t0_squared):
        return
    stretch = t0_squared / along  # s * stretch is on the plane
    alpha = 0.0
    beta = 0.0
    for i in range(3):
        alpha += s[i] * stretch * b1[i] * units[i]
        beta += s[i] * stretch * b2[i] * units[i]
    for i in range(3):
        twist[i] += alpha * b1[i] + beta * b2[i]


def _solve_load(kernel, discrete, load, units, scale, twist, start, final):  # pragma: no cover
    """Safety factor of one nonzero ``load`` (its sliding twist [SI] in ``twist``) and, where
    Newton stopped away from a minimum, its projected gradient relative to ``h`` (else 0).
    Newton starts where the ray of ``start`` meets the plane ``L·V = 1``
    (:func:`_start_on_plane`), else from the ellipsoid's twist. ``final`` (10,) is left with
    the terms of :func:`_newton` at ``twist`` where its iteration found the answer, else NaN
    (facets, kinks, smoothing)."""
    b1 = np.empty(3)
    b2 = np.empty(3)
    _plane(load, units, twist, b1, b2)
    _start_on_plane(units, start, twist, b1, b2)
    kinks = PROBES if discrete else SMOOTH
    stalled, h, kink = _newton(kernel, 0.0, twist, b1, b2, kinks, final)
    if kink >= 0:
        final[0] = np.nan
        certified = _certify_kink(kernel, load, scale, twist, b1, b2, kink)
        if certified > 0.0:
            return certified, 0.0
        stalled, h, _ = _newton(kernel, 0.0, twist, b1, b2, CRAWLS, final)
    safety = scale * h
    on_facet = False
    if discrete:
        slowest, speed = _slowest_point(kernel, twist)
        if stalled or speed <= NEAR_KINK * h:
            safety, on_facet = _facets(kernel, load, scale, twist, safety)
        if stalled or on_facet:
            final[0] = np.nan
        if stalled and not on_facet:
            certified = _certify_kink(kernel, load, scale, twist, b1, b2, slowest)
            if certified > 0.0:
                return certified, 0.0
            safety = _continuation(kernel, units, scale, twist, safety, b1, b2)
            safety, on_facet = _facets(kernel, load, scale, twist, safety)
    if not stalled or on_facet:
        return safety, 0.0
    local = np.empty(10)
    terms = np.empty(10)
    _terms(kernel, 0.0, twist, False, local, terms)
    g1 = terms[1] * b1[0] + terms[2] * b1[1] + terms[3] * b1[2]
    g2 = terms[1] * b2[0] + terms[2] * b2[1] + terms[3] * b2[2]
    return safety, math.hypot(g1, g2) / terms[0]


def _solve_row(
    kernel,
    discrete,
    loads,
    units,
    scale,
    k,
    start,
    out_safety,
    out_twist,
    out_gradient,
    out_hessian,
):  # pragma: no cover - compiled
    """Row ``k`` of :func:`_solve`: the answer of ``loads[k]``, Newton started from ``start``."""
    # Solve for a load of unit size (normalised): s(c L) = s(L) / c.
    size = 0.0
    for i in range(3):
        size = max(size, abs(loads[k, i] / units[i]))
    final = np.empty(10)
    final[0] = np.nan
    if size == 0.0:
        out_safety[k] = np.inf
        out_twist[k, :] = np.nan
        out_gradient[k] = 0.0
    else:
        safety, out_gradient[k] = _solve_load(
            kernel, discrete, loads[k] / size, units, scale, out_twist[k], start, final
        )
        out_safety[k] = safety / size
    if out_hessian.shape[0] == 0:
        return
    if math.isnan(final[0]):
        out_hessian[k, :, :] = np.nan
    else:
        _unpack(final, out_hessian[k])


def _solve(
    kernel, discrete, loads, units, scale, out_safety, out_twist, out_gradient, out_hessian
):  # pragma: no cover - compiled
    """Safety factors, twists, (where Newton stalled) relative gradients of ``loads`` and, if
    ``out_hessian`` has their rows, the Hessians that Newton found at the twists (NaN where
    none)."""
    start = np.zeros(3)  # none (read only): Newton starts from the ellipsoid's twist
    for k in numba.prange(loads.shape[0]):
        _solve_row(
            kernel, discrete, loads, units, scale, k, start, out_safety, out_twist, out_gradient,
            out_hessian,
        )  # fmt: skip


def _solve_from(
    kernel, discrete, loads, units, scale, starts, out_safety, out_twist, out_gradient, out_hessian
):  # pragma: no cover - compiled
    """:func:`_solve` with Newton started from ``starts`` (a separate loop: the extra argument
    costs a single query about a microsecond)."""
    for k in numba.prange(loads.shape[0]):
        _solve_row(
            kernel, discrete, loads, units, scale, k, starts[k], out_safety, out_twist,
            out_gradient, out_hessian,
        )  # fmt: skip


def _supports(kernel, twists, out):  # pragma: no cover - compiled
    """Support values ``out`` ``(K,)`` of the unit-friction ``kernel`` at ``twists`` ``(K, 3)``
    (0 at a zero twist)."""
    local = np.empty(10)
    terms = np.empty(10)
    for k in range(twists.shape[0]):
        if twists[k, 0] == 0.0 and twists[k, 1] == 0.0 and twists[k, 2] == 0.0:
            out[k] = 0.0
            continue
        _terms(kernel, 0.0, twists[k], False, local, terms)
        out[k] = terms[0]


def _loads(kernel, twists, out):  # pragma: no cover - compiled
    """Loads (gradients) ``out`` ``(K, 3)`` of the unit-friction ``kernel`` at nonzero
    ``twists`` ``(K, 3)``."""
    local = np.empty(10)
    terms = np.empty(10)
    for k in range(twists.shape[0]):
        _terms(kernel, 0.0, twists[k], False, local, terms)
        out[k, :] = terms[1:4]


def _hessians(kernel, twists, out):  # pragma: no cover - compiled
    """Support Hessians ``out`` ``(K, 3, 3)`` of the unit-friction ``kernel`` at ``twists``."""
    for k in numba.prange(twists.shape[0]):
        local = np.empty(10)
        terms = np.empty(10)
        _terms(kernel, 0.0, twists[k], True, local, terms)
        _unpack(terms, out[k])


_ball_terms = compiled_scalar(_ball_terms, inline=True)
_table_terms = compiled_scalar(_table_terms, inline=True)
_part_terms = compiled_scalar(_part_terms, inline=True)
_whole_terms = compiled_scalar(_whole_terms, inline=True)
_terms = compiled_scalar(_terms)
_unpack = compiled_scalar(_unpack)
_supports = compiled_scalar(_supports)
_loads = compiled_scalar(_loads)
_projected = compiled_scalar(_projected)
_newton_step = compiled_scalar(_newton_step)
_newton = compiled_scalar(_newton)
_slowest = compiled_scalar(_slowest)
_slowest_point = compiled_scalar(_slowest_point)
_facets = compiled_scalar(_facets)
_facet = compiled_scalar(_facet)
_nearest_kink = compiled_scalar(_nearest_kink)
_terms_near_facet = compiled_scalar(_terms_near_facet)
_escape_kink = compiled_scalar(_escape_kink)
_certify_kink = compiled_scalar(_certify_kink)
_continuation = compiled_scalar(_continuation)
_plane = compiled_scalar(_plane)
_start_on_plane = compiled_scalar(_start_on_plane)
_solve_load = compiled_scalar(_solve_load)
_solve_row = compiled_scalar(_solve_row)
_SOLVE = _compiled(_solve)
_SOLVE_FROM = _compiled(_solve_from)
_HESSIANS = _compiled(_hessians)

#: The ``out_hessian`` of :func:`_solve` where no Hessians are asked for.
_NO_HESSIANS = np.empty((0, 3, 3))


@dataclass(frozen=True, slots=True)
class CompiledKernel:
    """A support kernel in the form the compiled inverse map reads (see the module docstring).

    ``discrete`` marks point supports, whose facets are tested; ``work`` is the number of terms
    (points or edges) summed per evaluation.
    """

    parts: tuple
    discrete: bool
    work: int

    def solve(
        self,
        loads: np.ndarray,
        units: np.ndarray,
        scale: float,
        start: np.ndarray | None = None,
        out_hessians: np.ndarray | None = None,
    ) -> tuple[np.ndarray, np.ndarray]:
        """Safety factors ``(K,)`` and sliding twists ``(K, 3)`` [SI] of ``loads`` ``(K, 3)``
        [N, N m] (``inf`` and NaN for a zero load); ``units`` = ``(max_force, max_force,
        max_moment)`` normalise the coordinates and ``scale`` (``mu * N``) multiplies the kernel.
        ``start`` ``(K, 3)`` are twists (any size) near the answers to start Newton from; rows
        more than :data:`START_MAX_ANGLE` from their load's ray (or not finite) start from the
        ellipsoid's twist, as all do without it.

        ``out_hessians`` ``(K, 3, 3)``, where given, receives the Hessians of the unit-friction
        support at the twists that Newton computed on its way (see :func:`_newton`; relative
        difference up to about 1e-6 from :meth:`hessians` there), NaN where the answer came
        otherwise (facets, kinks).

        Raises :class:`ConvergenceError` where Newton stopped away from a minimum.
        """
        count = len(loads)
        safety = np.empty(count)
        twist = np.empty((count, 3))
        gradient = np.empty(count)
        loads = np.ascontiguousarray(loads, dtype=float)
        hessians = _NO_HESSIANS if out_hessians is None else out_hessians
        if start is None:
            _pick(_SOLVE, count, self.work)(
                self.parts, self.discrete, loads, units, scale, safety, twist, gradient, hessians
            )
        else:
            starts = np.array(start, dtype=float)
            if starts.shape != (count, 3):
                raise InvalidArgumentError(
                    f"start must have the shape of the loads {(count, 3)}, got {starts.shape}"
                )
            _pick(_SOLVE_FROM, count, self.work)(
                self.parts, self.discrete, loads, units, scale, starts, safety, twist, gradient,
                hessians,
            )  # fmt: skip
        worst = int(np.argmax(gradient)) if count > 1 else 0
        if count and gradient[worst] > INVERSE_GRADIENT_RTOL:
            raise not_converged(loads[worst], float(gradient[worst]))
        return safety, twist

    def supports(self, twists: np.ndarray) -> np.ndarray:
        """Values ``(K,)`` of the unit-friction support at ``twists`` ``(K, 3)``."""
        out = np.empty(len(twists))
        _supports(self.parts, np.ascontiguousarray(twists, dtype=float), out)
        return out

    def loads(self, twists: np.ndarray) -> np.ndarray:
        """Loads ``(K, 3)`` of the unit-friction support at nonzero ``twists`` ``(K, 3)``."""
        out = np.empty((len(twists), 3))
        _loads(self.parts, np.ascontiguousarray(twists, dtype=float), out)
        return out

    def hessians(self, twists: np.ndarray) -> np.ndarray:
        """Hessians ``(K, 3, 3)`` of the unit-friction support at nonzero ``twists`` ``(K, 3)``."""
        out = np.empty((len(twists), 3, 3))
        twists = np.ascontiguousarray(twists, dtype=float)
        _pick(_HESSIANS, len(twists), self.work)(self.parts, twists, out)
        return out


def not_converged(load: np.ndarray, relative_gradient: float) -> ConvergenceError:
    """The error of a load where Newton stopped away from a minimum."""
    return ConvergenceError(
        f"the inverse map did not converge for load {load.tolist()} (relative gradient "
        f"{relative_gradient:.2g}). Pressure and friction functions must be smooth over the "
        "patch: where mu or p jumps or has a kink (two materials, a step in pressure), describe "
        "each smooth region as its own patch and sum them with LimitSurface.combine. Otherwise, "
        "please report this load."
    )


#: Work of one disk in terms of points summed (it sets when a batch runs in parallel).
DISK_WORK = 64


#: The table of a part without one (points, an ellipsoid).
_NO_TABLE = np.empty((TABLE_ROWS, 0))
_NO_POINTS = np.empty(0)


def compile_kernel(kernel: SupportKernel) -> CompiledKernel | None:
    """The compiled form of a point-set, polygon, grid, disk or ellipsoid kernel, or of a sum
    of them, posed or not (``None`` where any part is another kernel: those take the NumPy
    path). The parts are flattened into one table: each with its weight and the transform
    from contact-frame to local twists; discrete point supports become one part of points in
    the contact frame, the kernel's (merged) facets, which the facet tests read too."""
    parts: list[tuple] = []
    if not _flatten(kernel, np.eye(3), 1.0, parts):
        return None
    points, friction = kernel.facets
    discrete = len(friction) > 0
    if discrete:
        points = np.asarray(points, dtype=float).reshape(-1, 2)
        facets = (points[:, 0].copy(), points[:, 1].copy(), np.array(friction, dtype=float))
        parts.insert(0, (POINTS, 1.0, np.eye(3), *facets, _NO_TABLE, 0.0, len(friction)))
    else:
        facets = (_NO_POINTS,) * 3
    kinds, weights, transforms, xs, ys, ws, tables, reach, work = zip(*parts, strict=True)
    table = np.zeros((len(parts), TRANSFORM + 9))
    table[:, KIND] = kinds
    table[:, POINT_STOP] = np.cumsum([len(x) for x in xs])
    table[1:, POINT_START] = table[:-1, POINT_STOP]
    table[:, TABLE_STOP] = np.cumsum([t.shape[1] for t in tables])
    table[1:, TABLE_START] = table[:-1, TABLE_STOP]
    table[:, WEIGHT] = weights
    table[:, REACH] = reach
    table[:, POSED] = [not np.array_equal(t, np.eye(3)) for t in transforms]
    table[:, TRANSFORM:] = np.array(transforms, dtype=float).reshape(-1, 9)
    padded = np.zeros((TABLE_ROWS, int(table[-1, TABLE_STOP])))
    for start, part in zip(table[:, TABLE_START].astype(int), tables, strict=True):
        padded[: part.shape[0], start : start + part.shape[1]] = part
    whole = len(parts) == 1 and not table[0, POSED] and weights[0] == 1.0
    columns = np.vstack([np.concatenate(xs), np.concatenate(ys), np.concatenate(ws)])
    kernel_tuple = (whole, int(kinds[0]), float(reach[0]), len(facets[0]), table, columns, padded)
    return CompiledKernel(parts=kernel_tuple, discrete=discrete, work=sum(work))


def _flatten(kernel: SupportKernel, transform: np.ndarray, weight: float, out: list) -> bool:
    """Append the parts of ``kernel`` (reached from the contact frame by ``transform`` (3x3,
    contact-frame to local twists) and weighed by ``weight``) to ``out`` as ``(kind, weight,
    transform, x, y, point weights, table, reach, work)``; whether every part compiles.
    Discrete point supports are left out: they are the kernel's facets (see
    :func:`compile_kernel`)."""
    if isinstance(kernel, PosedKernel):
        return _flatten(kernel.local, twist_to_local(kernel.pose) @ transform, weight, out)
    if isinstance(kernel, SumKernel):
        return all(_flatten(part, transform, weight * scale, out)
                   for part, scale in zip(kernel.parts, kernel.scales, strict=True))  # fmt: skip
    if isinstance(kernel, PointSetKernel):
        if kernel.smoothing != 0.0:
            return False
        if not kernel.discrete:
            columns = tuple(kernel.columns)
            out.append((POINTS, weight, transform, *columns, _NO_TABLE, 0.0, len(columns[0])))
        return True
    disks = _disk_table(kernel)
    if disks is not None:
        work = DISK_WORK * disks.shape[1]
        out.append((DISKS, weight, transform, *(_NO_POINTS,) * 3, disks, 0.0, work))
        return True
    if isinstance(kernel, ClosedFormKernel):
        table = np.array(kernel.table, dtype=float)
        reach = FAR_FIELD_RADII * kernel.size
        columns = tuple(kernel.far.columns)
        out.append((kernel._KIND, weight, transform, *columns, table, reach, kernel.work))
        return True
    if isinstance(kernel, EllipsoidKernel):
        # h(V) = sqrt(Vᵀ B V) = |C V| with B = Cᵀ C: the unit ball's, through C.
        factor = np.linalg.cholesky(kernel.inverse).T
        out.append((BALL, weight, factor @ transform, *(_NO_POINTS,) * 3, _NO_TABLE, 0.0, 1))
        return True
    return False


def _disk_table(kernel: SupportKernel) -> np.ndarray | None:
    """The disk table ``(3, D)`` (radius [m], profile row, weight) of a disk or annulus kernel;
    ``None`` for other kernels."""
    if isinstance(kernel, DiskKernel):
        disks = [(kernel.radius, PROFILES.index(kernel.profile), 1.0)]
    elif isinstance(kernel, AnnulusKernel):
        disks = [(part.radius, PROFILES.index(part.profile), weight)
                 for part, weight in kernel.parts]  # fmt: skip
    else:
        return None
    return np.array(disks, dtype=float).T.copy()
