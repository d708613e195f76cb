r"""The inverse map of a limit surface: load → safety factor and motion.

For a load ``L`` the safety factor is ``s(L) = min_{V: L·V = 1} h(V)`` and the minimising twist
is the sliding motion (normality, maximum power). The minimisation runs in the normalised
coordinates of the paper (force divided by the maximum force, moment by the maximum moment), as
a damped Newton method on the plane ``L·V = 1`` started from the twist normal to the unit sphere
(the paper's ellipsoid). The support function restricted to that plane is convex, so Newton with
a backtracking line search converges from any start where ``h`` is smooth.

Point supports make ``h`` kink where the centre of rotation meets a support point: the surface
has a flat facet there. After Newton, the facets of the support points nearest to the found
centre are tested exactly: a load lies on facet ``k`` when the force that point must carry to
balance it is within its friction limit.
"""

from __future__ import annotations

import math
import operator
from dataclasses import dataclass

import numpy as np

from fixplan.surface.compiled_inverse import (
    CRAWL,
    FACETS_TESTED,
    MAX_HALVINGS,
    NEAR_KINK,
    QUADRATIC_REGION,
    RIDGE,
    SMOOTHING_STAGES,
    not_converged,
)
from fixplan.surface.compiled_inverse import _newton_step as _newton_step_one
from fixplan.surface.kernels import SupportKernel
from fixplan.surface.point_kernel import slowest_points
from fixplan.tolerances import (
    FACET_RTOL,
    INVERSE_GRADIENT_RTOL,
    INVERSE_MAX_ITERATIONS,
    INVERSE_RTOL,
)

#: Newton decrement (relative to h) below which a step that the line search damps below
#: ``CRAWL`` ends Newton (then the gradient test decides): the gradient no longer matches ``h``
#: to that precision. Kernels integrated by adapted rules (:mod:`~fixplan.surface.function_kernel`)
#: are accurate to 1e-12..1e-6, and their exact Hessian is not that of their rules: with
#: ``p = exp(-(x/a)²)`` on a rectangle four lengths ``a`` long, a centre of rotation outside it
#: left the decrement at 4e-12 of ``h`` while the line search took steps of 1e-12, for all 100
#: iterations (0.7 s for a query that now takes 10 ms).
NOISE_DECREMENT = 1e-8


@dataclass(frozen=True, slots=True)
class InverseResult:
    """Safety factors ``(K,)`` and sliding twists ``(K, 3)`` (SI units, any scale) of loads."""

    safety_factor: np.ndarray
    twist: np.ndarray


def _plane_basis(direction: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Two unit vectors ``(K, 3)`` orthogonal to unit ``direction`` and to each other."""
    helper = np.zeros_like(direction)
    axis = np.argmin(np.abs(direction), axis=1)
    helper[np.arange(len(direction)), axis] = 1.0
    e1 = np.cross(direction, helper)
    e1 /= np.linalg.norm(e1, axis=1, keepdims=True)
    e2 = np.cross(direction, e1)
    return e1, e2


def _newton_step(g, hess, b1, b2):
    """Newton step on the plane spanned by ``b1``, ``b2`` and its decrement ``gᵀ H⁻¹ g``."""
    g1 = np.einsum("ij,ij->i", b1, g)
    g2 = np.einsum("ij,ij->i", b2, g)
    hb1 = np.einsum("ijk,ik->ij", hess, b1)
    hb2 = np.einsum("ijk,ik->ij", hess, b2)
    h11 = np.einsum("ij,ij->i", b1, hb1)
    h12 = np.einsum("ij,ij->i", b1, hb2)
    h22 = np.einsum("ij,ij->i", b2, hb2)
    ridge = RIDGE * np.abs(h11 + h22) + 1e-300
    h11, h22 = h11 + ridge, h22 + ridge
    det = h11 * h22 - h12 * h12
    with np.errstate(divide="ignore", invalid="ignore"):
        s1 = -(h22 * g1 - h12 * g2) / det
        s2 = -(h11 * g2 - h12 * g1) / det
    decrement = -(g1 * s1 + g2 * s2)
    bad = ~np.isfinite(decrement) | (decrement < 0.0) | (det <= 0.0)
    # Steepest descent where the Hessian is unusable (never at a smooth minimum).
    s1, s2 = np.where(bad, -g1, s1), np.where(bad, -g2, s2)
    decrement = np.where(bad, g1 * g1 + g2 * g2, decrement)
    return s1[:, None] * b1 + s2[:, None] * b2, decrement


def _newton(z, e1, e2, active, terms, values, *, kinks: bool = False) -> np.ndarray:
    """Damped Newton on the planes, in place on rows ``active`` of ``z``; True where stalled."""
    stalled = np.zeros(len(z), dtype=bool)
    for _ in range(INVERSE_MAX_ITERATIONS):
        if active.size == 0:
            break
        za, b1, b2 = z[active], e1[active], e2[active]
        h, g, hess = terms(za)
        step, decrement = _newton_step(g, hess, b1, b2)
        done = decrement <= INVERSE_RTOL**2 * h
        # Near the minimum the sufficient decrease is below rounding: full steps are taken.
        accepted = done | (decrement <= QUADRATIC_REGION * h)
        t = np.ones(len(active))
        for _ in range(MAX_HALVINGS):
            idx = np.flatnonzero(~accepted)
            if idx.size == 0:
                break
            h_trial = values(za[idx] + t[idx, None] * step[idx])
            ok = h_trial <= h[idx] - 1e-4 * t[idx] * decrement[idx]
            accepted[idx[ok]] = True
            t[idx[~ok]] *= 0.5
        moved = accepted & ~done
        z[active[moved]] = za[moved] + t[moved, None] * step[moved]
        # With point supports, tiny accepted steps mean Newton is crawling into a kink: stop
        # and let the facet test and the smoothing continuation take over. Near the minimum
        # they mean the quadrature's noise (``NOISE_DECREMENT``): stop, the gradient decides.
        crawling = moved & (t < CRAWL) & (kinks | (decrement <= NOISE_DECREMENT * h))
        stalled[active[~accepted | crawling]] = True
        active = active[moved & ~crawling]
    stalled[active] = True
    return stalled


def solve(
    kernel: SupportKernel, scale: float, loads: np.ndarray, units: np.ndarray
) -> InverseResult:
    """Safety factor and sliding twist of nonzero ``loads`` ``(K, 3)``.

    ``scale`` multiplies the kernel (``mu * N``), ``units`` = ``(max_force, max_force,
    max_moment)`` normalise the coordinates. Kernels with a compiled form take
    :class:`~fixplan.surface.compiled_inverse.CompiledKernel` instead.
    """
    points, friction = kernel.facets
    if len(loads) == 1 and len(points) == 0:
        safety, twist = _solve_one(kernel, loads[0], units)
        return InverseResult(safety_factor=np.array([scale * safety]), twist=twist[None, :])
    count = len(loads)
    norm_loads = loads / units
    length = np.linalg.norm(norm_loads, axis=1)
    direction = norm_loads / length[:, None]
    e1, e2 = _plane_basis(direction)
    # Normalised twist Z has L̃·Z = 1; the SI twist is Z / units.
    z = direction / length[:, None]

    terms, values = _objective(kernel, scale, units)
    stalled = _newton(z, e1, e2, np.arange(count), terms, values, kinks=len(points) > 0)
    safety = values(z)
    on_facet = np.zeros(count, dtype=bool)
    if len(points):
        # Newton only stops short, or lands on a kink, next to a support point.
        _, slowest = slowest_points(points, friction, z / units, 1)
        near_kink = slowest[:, 0] <= NEAR_KINK * safety / scale
        rows = np.flatnonzero(stalled | near_kink)
        on_facet = _facets(kernel, scale, loads, units, z, safety, points, friction, rows)
        retry = np.flatnonzero(stalled & ~on_facet)
        if retry.size:
            _continuation(kernel, scale, units, z, safety, e1, e2, retry)
            on_facet |= _facets(kernel, scale, loads, units, z, safety, points, friction, retry)
    _check_converged(z[stalled & ~on_facet], e1[stalled & ~on_facet], e2[stalled & ~on_facet],
                     loads[stalled & ~on_facet], terms)  # fmt: skip
    return InverseResult(safety_factor=safety, twist=z / units)


def _solve_one(kernel: SupportKernel, load: np.ndarray, units: np.ndarray):
    """:func:`solve` for one load of a kernel without facets, in scalars: ``(safety factor of
    the unit-friction kernel, SI twist (3,))``.

    The same damped Newton method as :func:`_newton`, run on SI twists ``V = Z / units``
    projected onto the plane by ``b = e / units``: ``g·b`` and ``bᵀ H b`` are then the
    normalised gradient and Hessian of :func:`solve`, so the iterates are the same to rounding.
    The friction scale only multiplies ``h`` and drops out of every test. Vectors are lists of
    floats: numpy costs more than the arithmetic at this size.
    """
    u = units.tolist()
    normalised = [x / ux for x, ux in zip(load.tolist(), u, strict=True)]
    length = math.sqrt(sum(x * x for x in normalised))
    direction = [x / length for x in normalised]
    b1, b2 = ([x / ux for x, ux in zip(e, u, strict=True)] for e in _plane_basis_one(direction))
    twist = [x / (length * ux) for x, ux in zip(direction, u, strict=True)]
    h, g, hess = _terms_one(kernel, twist)
    stalled = True
    for _ in range(INVERSE_MAX_ITERATIONS):
        s1, s2, decrement = _newton_step_one(*_projected(g, hess, b1, b2))
        if decrement <= INVERSE_RTOL**2 * h:
            stalled = False
            break
        step = [s1 * x + s2 * y for x, y in zip(b1, b2, strict=True)]
        # The full step is tried with the terms of the next iteration: it is nearly always taken.
        trial = [x + dx for x, dx in zip(twist, step, strict=True)]
        terms = _terms_one(kernel, trial)
        # Near the minimum the sufficient decrease is below rounding: full steps are taken.
        if decrement > QUADRATIC_REGION * h and terms[0] > h - 1e-4 * decrement:
            t = 0.5
            for _ in range(MAX_HALVINGS - 1):
                trial = [x + t * dx for x, dx in zip(twist, step, strict=True)]
                if float(kernel.support(np.array([trial]))[0]) <= h - 1e-4 * t * decrement:
                    break
                t *= 0.5
            else:
                break
            if t < CRAWL and decrement <= NOISE_DECREMENT * h:
                break  # (the quadrature's noise: see NOISE_DECREMENT)
            terms = _terms_one(kernel, trial)
        twist = trial
        h, g, hess = terms
    if stalled:
        g1, g2 = _projected(g, hess, b1, b2)[:2]
        if math.hypot(g1, g2) > INVERSE_GRADIENT_RTOL * h:
            raise not_converged(load, math.hypot(g1, g2) / h)
    return h, np.array(twist)


def _terms_one(kernel: SupportKernel, twist: list[float]):
    """``h``, gradient (3 floats) and Hessian (3 rows of 3) of the kernel at one twist."""
    h, g, hess = kernel.newton_terms(np.array([twist]))
    return float(h[0]), g[0].tolist(), hess[0].tolist()


def _projected(g, hess, b1, b2) -> tuple[float, float, float, float, float]:
    """``g·b1``, ``g·b2``, ``b1ᵀ H b1``, ``b1ᵀ H b2`` and ``b2ᵀ H b2``."""
    hb1 = [sum(map(operator.mul, row, b1)) for row in hess]
    hb2 = [sum(map(operator.mul, row, b2)) for row in hess]
    return (
        sum(map(operator.mul, g, b1)),
        sum(map(operator.mul, g, b2)),
        sum(map(operator.mul, b1, hb1)),
        sum(map(operator.mul, b1, hb2)),
        sum(map(operator.mul, b2, hb2)),
    )


def _plane_basis_one(direction: list[float]) -> tuple[list[float], list[float]]:
    """:func:`_plane_basis` of one unit ``direction``."""
    dx, dy, dz = direction
    axis = min(range(3), key=lambda i: abs(direction[i]))
    hx, hy, hz = (float(i == axis) for i in range(3))
    e1 = [dy * hz - dz * hy, dz * hx - dx * hz, dx * hy - dy * hx]
    norm = math.sqrt(sum(x * x for x in e1))
    ax, ay, az = (x / norm for x in e1)
    return [ax, ay, az], [dy * az - dz * ay, dz * ax - dx * az, dx * ay - dy * ax]


def _check_converged(z, e1, e2, loads, terms) -> None:
    """Raise :class:`ConvergenceError` where Newton stopped away from a minimum."""
    if len(z) == 0:
        return
    h, g, _ = terms(z)
    projected = np.hypot(np.einsum("ij,ij->i", g, e1), np.einsum("ij,ij->i", g, e2))
    bad = np.flatnonzero(projected > INVERSE_GRADIENT_RTOL * h)
    if bad.size:
        raise not_converged(loads[bad[0]], projected[bad[0]] / h[bad[0]])


def _facets(kernel, scale, loads, units, z, safety, points, friction, rows) -> np.ndarray:
    """Where the load lies on the facet of a support point, take it (``z``, ``safety`` in place).

    Only ``rows`` are tested, against the facets of the support points slowest under their
    twists. Returns which rows were found on a facet.
    """
    on_facet = np.zeros(len(loads), dtype=bool)
    if rows.size == 0:
        return on_facet
    nearest, _ = slowest_points(points, friction, z[rows] / units, FACETS_TESTED)
    for column in range(nearest.shape[1]):
        k = nearest[:, column]
        px, py = points[k, 0], points[k, 1]
        facet_twist = np.column_stack([py, -px, np.ones(len(k))])
        power = np.einsum("ij,ij->i", loads[rows], facet_twist)
        facet_twist *= np.where(power < 0.0, -1.0, 1.0)[:, None]
        power = np.abs(power)
        usable = power > 0.0
        h, g = kernel.evaluate(facet_twist)
        h, g = scale * h, scale * g
        s_k = np.where(usable, h / np.where(usable, power, 1.0), np.inf)
        residual = s_k[:, None] * loads[rows, :2] - g[:, :2]
        carried = np.hypot(residual[:, 0], residual[:, 1])
        limit = scale * friction[k]
        hit = (
            usable & (carried <= limit * (1.0 + FACET_RTOL)) & (s_k <= safety[rows] * (1.0 + 1e-9))
        )
        hit_rows = rows[hit]
        safety[hit_rows] = s_k[hit]
        z[hit_rows] = facet_twist[hit] * units / power[hit, None]
        on_facet[hit_rows] = True
    return on_facet


def _objective(kernel, scale, units):
    """``h`` with gradient and Hessian, and ``h`` alone, in normalised coordinates."""

    def terms(zs):
        h, g, hess = kernel.newton_terms(zs / units)
        g = g / units
        hess = hess / units[:, None] / units[None, :]
        return scale * h, scale * g, scale * hess

    def values(zs):
        return scale * kernel.support(zs / units)

    return terms, values


def _continuation(kernel, scale, units, z, safety, e1, e2, rows) -> None:
    """Minimise ``h`` on rows where Newton stalled at a kink that is not the minimum.

    Newton is drawn into the kinks of point supports. Rounding each speed off as
    ``sqrt(|u|² + eps²)`` makes ``h`` smooth; Newton then converges, and ``eps`` is reduced
    stage by stage down to zero, each stage starting where the last one ended. The result
    replaces the row's twist only where it lowers ``h`` (every iterate lies on the plane, so
    the lower ``h`` is the better answer). ``z`` and ``safety`` are updated in place.
    """
    start = z[rows].copy()
    for eta in SMOOTHING_STAGES:
        terms, values = _objective(kernel.smoothed(eta / units[0]), scale, units)
        _newton(z, e1, e2, rows, terms, values)
    terms, values = _objective(kernel, scale, units)
    _newton(z, e1, e2, rows, terms, values)
    found = values(z[rows])
    better = found < safety[rows]
    z[rows[~better]] = start[~better]
    safety[rows[better]] = found[better]
