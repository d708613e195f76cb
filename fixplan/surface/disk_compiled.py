r"""The closed-form disk support functions of :mod:`~fixplan.surface.disk_kernel`, compiled.

Per profile, two functions of one argument carry everything: ``F(x) = M(ρ)/ρ`` with
``x = R²/ρ²`` outside the disk (``₂F₁(-1/2, -1/2; c; x)``) and ``G(y) = M(ρ)/R`` with
``y = ρ²/R²`` inside. Each is evaluated with its first two derivatives (a "jet"): by its power
series for small arguments, else by its closed form

.. math:: \frac{P(z) E(z) + Q(z) (1 - z) K(z)}{z^m}

with quadratic ``P``, ``Q`` and ``E``, ``K`` of parameter ``z`` from Carlson's symmetric
integrals (the uniform forms are those of DESIGN.md §4; the parabolic ``F`` follows from the
uniform and ring ones by Gauss' contiguous relation in ``c``). The Hertz ``F`` (``c = 5/2``)
uses instead its expansion about the rim (Abramowitz & Stegun 15.3.6),
``F = S(1 - z) + (1 - z)^{7/2} T(1 - z)`` with power series ``S``, ``T``, free of the
cancellations of its elementary form. ``1 - z`` is passed alongside ``z``, formed without
cancellation from the twist.

A disk table ``(3, D)`` lists per disk its radius [m], its profile's row in :data:`PROFILES`
and its friction weight (an annulus is two uniform disks).
"""

from __future__ import annotations

import math

import numpy as np
from scipy.special import gamma, poch

from fixplan.surface.disk_kernel import _OUTSIDE_C, _PARABOLIC_SERIES
from fixplan.surface.point_kernel import compiled_scalar

#: Profiles with a compiled form, in the order of their rows.
PROFILES = ("uniform", "hertz", "parabolic", "ring")

#: Forms above the power series: complete elliptic integrals, or the expansion about the rim.
ELLIPTIC = 0
RIM = 1

#: Terms of the power series; they are used for arguments up to :data:`SERIES_BELOW`
#: (:data:`RIM_SERIES_BELOW` where the other form is the rim's): ``0.5**60`` is below rounding.
SERIES_TERMS = 60
SERIES_BELOW = 0.3
RIM_SERIES_BELOW = 0.5

#: ``1 - z`` is kept above this: the forms are then finite on the rim (``z = 1``), where the
#: support function is smooth but ``K`` and the powers of ``1 - z`` below one are not.
RIM_GAP = 1e-40

#: Within this of the rim (in ``1 - z``) second derivatives are taken at this distance: the
#: ring's curvature is infinite on its rim, and the cap gives Newton a finite Hessian to steer
#: by (as the central differences of the NumPy path do). Values and slopes stay exact.
CURVATURE_GAP = 1e-12

#: Relative size of the spread of Carlson's duplication below which its series is truncated
#: (its error is about the sixth power of this); each duplication divides the spread by 4, so
#: the iterations are bounded (NaN arguments end there).
_CARLSON_TOLERANCE = 1e-3
_CARLSON_ITERATIONS = 40


def _hypergeometric_series(a: float, b: float, c: float) -> np.ndarray:
    """The first :data:`SERIES_TERMS` power-series coefficients of ``₂F₁(a, b; c; z)``."""
    n = np.arange(SERIES_TERMS, dtype=float)
    return poch(a, n) * poch(b, n) / (poch(c, n) * poch(1.0, n))


def _rim_series(a: float, b: float, c: float) -> np.ndarray:
    """Coefficients ``(2, SERIES_TERMS)`` of ``S`` and ``T`` in ``₂F₁(a, b; c; z) = S(1 - z) +
    (1 - z)^(c - a - b) T(1 - z)`` (``c - a - b`` not an integer)."""
    e = c - a - b
    first = gamma(c) * gamma(e) / (gamma(c - a) * gamma(c - b))
    second = gamma(c) * gamma(-e) / (gamma(a) * gamma(b))
    return np.array(
        [
            first * _hypergeometric_series(a, b, 1.0 - e),
            second * _hypergeometric_series(c - a, c - b, 1.0 + e),
        ]
    )


def _table() -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Per function (row ``2 p`` the outside ``F``, ``2 p + 1`` the inside ``G`` of profile
    ``p``): series coefficients, ``(switch, form, m or the rim exponent)``, the coefficients
    of ``P``, ``Q``, and of the rim's ``S``, ``T``."""
    pi = math.pi
    series = np.zeros((2 * len(PROFILES), SERIES_TERMS))
    kind = np.zeros((2 * len(PROFILES), 3))
    poly = np.zeros((2 * len(PROFILES), 2, 3))
    rim = np.zeros((2 * len(PROFILES), 2, SERIES_TERMS))
    for p, profile in enumerate(PROFILES):
        series[2 * p] = _hypergeometric_series(-0.5, -0.5, _OUTSIDE_C[profile])
        kind[2 * p] = kind[2 * p + 1] = SERIES_BELOW, ELLIPTIC, 0.0
    series[1] = (2.0 / 3.0) * _hypergeometric_series(-0.5, -1.5, 1.0)
    series[3, :3] = (3.0 * pi / 16.0) * np.array([1.0, 1.0, -0.125])
    series[5, : len(_PARABOLIC_SERIES)] = _PARABOLIC_SERIES
    series[7] = series[6]
    kind[0, 2] = 1.0
    poly[0] = np.array([[1.0, 7.0, 0.0], [-1.0, -3.0, 0.0]]) * 4.0 / (9.0 * pi)
    poly[1] = np.array([[7.0, 1.0, 0.0], [-4.0, 0.0, 0.0]]) * 4.0 / (9.0 * pi)
    kind[2] = RIM_SERIES_BELOW, RIM, 3.5
    rim[2] = _rim_series(-0.5, -0.5, 2.5)
    kind[3, 0] = 2.0  # a polynomial: its series is exact
    kind[4, 2] = 2.0
    poly[4] = np.array([[-32.0, 192.0, 608.0], [32.0, -176.0, -240.0]]) / (225.0 * pi)
    poly[5] = np.array([[608.0, 192.0, -32.0], [-368.0, -16.0, 0.0]]) / (225.0 * pi)
    poly[6] = poly[7] = np.array([[4.0, 0.0, 0.0], [-2.0, 0.0, 0.0]]) / pi
    return series, kind, poly, rim


_SERIES, _KIND, _POLY, _RIM = _table()


def carlson_rf(x, y, z):  # pragma: no cover - compiled
    """Carlson's ``R_F(x, y, z)`` by duplication (at most one argument zero)."""
    for _ in range(_CARLSON_ITERATIONS):
        a = (x + y + z) / 3.0
        spread = max(abs(a - x), abs(a - y), abs(a - z))
        if spread <= _CARLSON_TOLERANCE * a:
            break
        sx, sy, sz = math.sqrt(x), math.sqrt(y), math.sqrt(z)
        lam = sx * sy + sy * sz + sz * sx
        x, y, z = 0.25 * (x + lam), 0.25 * (y + lam), 0.25 * (z + lam)
    dx, dy = 1.0 - x / a, 1.0 - y / a
    dz = -(dx + dy)
    e2 = dx * dy - dz * dz
    e3 = dx * dy * dz
    return (1.0 - e2 / 10.0 + e3 / 14.0 + e2 * e2 / 24.0 - 3.0 * e2 * e3 / 44.0) / math.sqrt(a)


def carlson_rd(x, y, z):  # pragma: no cover - compiled
    """Carlson's ``R_D(x, y, z)`` by duplication (``x`` or ``y`` may be zero)."""
    total = 0.0
    factor = 1.0
    for _ in range(_CARLSON_ITERATIONS):
        a = (x + y + 3.0 * z) / 5.0
        spread = max(abs(a - x), abs(a - y), abs(a - z))
        if spread <= _CARLSON_TOLERANCE * a:
            break
        sx, sy, sz = math.sqrt(x), math.sqrt(y), math.sqrt(z)
        lam = sx * sy + sy * sz + sz * sx
        total += factor / (sz * (z + lam))
        factor *= 0.25
        x, y, z = 0.25 * (x + lam), 0.25 * (y + lam), 0.25 * (z + lam)
    dx, dy = 1.0 - x / a, 1.0 - y / a
    dz = -(dx + dy) / 3.0
    ea = dx * dy
    eb = dz * dz
    ec = ea - eb
    ed = ea - 6.0 * eb
    ee = ed + 2.0 * ec
    series = 1.0 + ed * (-3.0 / 14.0 + 9.0 / 88.0 * ed - 9.0 / 52.0 * dz * ee)
    series += dz * (ee / 6.0 + dz * (-9.0 / 22.0 * ec + dz * 3.0 / 26.0 * ea))
    return 3.0 * total + factor * series / (a * math.sqrt(a))


def _elliptic(z, rest):  # pragma: no cover - compiled
    """Jets ``(value, d/dz, d²/dz²)`` of ``E`` and ``(1 - z) K`` at ``z`` (``rest = 1 - z``)."""
    k = carlson_rf(0.0, rest, 1.0)
    e = k - (z / 3.0) * carlson_rd(0.0, rest, 1.0)
    ell = rest * k
    e1 = (e - k) / (2.0 * z)
    k1 = (e - ell) / (2.0 * z * rest)
    ell1 = (e - ell) / (2.0 * z) - k
    e2 = (e1 - k1) / (2.0 * z) - e1 / z
    ell2 = (e1 - ell1) / (2.0 * z) - (ell1 + k) / z - k1
    return e, e1, e2, ell, ell1, ell2


def _power_series(c, z):  # pragma: no cover - compiled
    """``Σ c_n z^n`` and its first two derivatives (Horner)."""
    v = 0.0
    d1 = 0.0
    d2 = 0.0
    for n in range(c.shape[0] - 1, -1, -1):
        d2 = d2 * z + 2.0 * d1
        d1 = d1 * z + v
        v = v * z + c[n]
    return v, d1, d2


def jet(row, z, rest):  # pragma: no cover - compiled
    """Function ``row`` of the table and its first two derivatives at ``z`` (``rest = 1 - z``);
    the second derivative within :data:`CURVATURE_GAP` of the rim is the one at that gap."""
    v, d1, d2 = _jet(row, z, rest)
    if rest < CURVATURE_GAP:
        d2 = _jet(row, 1.0 - CURVATURE_GAP, CURVATURE_GAP)[2]
    return v, d1, d2


def _jet(row, z, rest):  # pragma: no cover - compiled
    if z <= _KIND[row, 0]:
        return _power_series(_SERIES[row], z)
    rest = max(rest, RIM_GAP)
    if _KIND[row, 1] == RIM:
        # F = S(s) + s^e T(s) in s = 1 - z: d/dz = -d/ds.
        e = _KIND[row, 2]
        s0, s1, s2 = _power_series(_RIM[row, 0], rest)
        t0, t1, t2 = _power_series(_RIM[row, 1], rest)
        power = rest**e
        return (
            s0 + power * t0,
            -(s1 + power * (e * t0 / rest + t1)),
            s2 + power * (e * (e - 1.0) * t0 / (rest * rest) + 2.0 * e * t1 / rest + t2),
        )
    b0, b1, b2, c0, c1, c2 = _elliptic(z, rest)
    p = _POLY[row, 0]
    q = _POLY[row, 1]
    p0, p1, p2 = p[0] + z * (p[1] + z * p[2]), p[1] + 2.0 * z * p[2], 2.0 * p[2]
    q0, q1, q2 = q[0] + z * (q[1] + z * q[2]), q[1] + 2.0 * z * q[2], 2.0 * q[2]
    v = p0 * b0 + q0 * c0
    d1 = p1 * b0 + p0 * b1 + q1 * c0 + q0 * c1
    d2 = p2 * b0 + 2.0 * p1 * b1 + p0 * b2 + q2 * c0 + 2.0 * q1 * c1 + q0 * c2
    m = _KIND[row, 2]
    if m == 0.0:
        return v, d1, d2
    # Divided by z^m.
    inverse = 1.0 / z
    scale = inverse**m
    return (
        scale * v,
        scale * (d1 - m * inverse * v),
        scale * (d2 - 2.0 * m * inverse * d1 + m * (m + 1.0) * inverse * inverse * v),
    )


def disk_terms(disks, vx, vy, w, with_hessian, out):  # pragma: no cover - compiled
    """Support value, gradient and (``with_hessian``) Hessian of the disks of the table
    ``disks`` (3, D) at the twist ``(vx, vy, w)`` [m/s, rad/s], written to ``out`` (10,) as
    :func:`~fixplan.surface.point_kernel.point_terms` writes them.

    In terms of ``a = |v|`` and ``t = |w|`` (see :class:`~fixplan.surface.disk_kernel.DiskKernel`
    for the Hessian's form): outside, ``h = a F``, force ``F - 2xF'``, moment ``2R²wF'/a``;
    inside (``u² = y``), ``h = tRG``, force ``2uG'``, moment ``sign(w) R (G - 2yG')``.
    """
    out[:] = 0.0
    a = math.hypot(vx, vy)
    t = abs(w)
    if a == 0.0 and t == 0.0:
        return
    ex = vx / a if a > 0.0 else 0.0
    ey = vy / a if a > 0.0 else 0.0
    for i in range(disks.shape[1]):
        radius = disks[0, i]
        row = 2 * int(disks[1, i])
        weight = disks[2, i]
        rt = radius * t
        if a >= rt:
            x = (rt / a) ** 2
            f, f1, f2 = jet(row, x, (a - rt) * (a + rt) / (a * a))
            h = a * f
            force = f - 2.0 * x * f1
            moment = 2.0 * radius * radius * w * f1 / a
            q = f1 + 2.0 * x * f2
            h_aa = 2.0 * x * q / a
            h_aw = -2.0 * radius * radius * w * q / (a * a)
            h_ww = 2.0 * radius * radius * q / a
            ratio = force / a
        else:
            u = a / rt
            y = u * u
            g, g1, g2 = jet(row + 1, y, (rt - a) * (rt + a) / (rt * rt))
            sign = 1.0 if w > 0.0 else -1.0
            h = rt * g
            force = 2.0 * u * g1
            moment = sign * radius * (g - 2.0 * y * g1)
            h_aa = (2.0 * g1 + 4.0 * y * g2) / rt
            h_aw = -h_aa * u * radius * sign
            h_ww = h_aa * (u * radius) ** 2
            ratio = 2.0 * g1 / rt
        out[0] += weight * h
        out[1] += weight * force * ex
        out[2] += weight * force * ey
        out[3] += weight * moment
        if with_hessian:
            across = h_aa - ratio
            out[4] += weight * (ratio + across * ex * ex)
            out[5] += weight * across * ex * ey
            out[6] += weight * h_aw * ex
            out[7] += weight * (ratio + across * ey * ey)
            out[8] += weight * h_aw * ey
            out[9] += weight * h_ww


carlson_rf = compiled_scalar(carlson_rf)
carlson_rd = compiled_scalar(carlson_rd)
_elliptic = compiled_scalar(_elliptic)
_power_series = compiled_scalar(_power_series)
_jet = compiled_scalar(_jet)
jet = compiled_scalar(jet)
_DISK_TERMS = compiled_scalar(disk_terms)
