r"""Independent references for the limit-surface tests (nothing here imports fixplan).

Conventions are those of DESIGN.md §2: a twist ``V = (vx, vy, w)`` rotates about the centre of
rotation (COR) ``c = (-vy/w, vx/w)``; the load is ``L(V) = ∫ mu p v̂ (1, x×) dA`` (unit total
pressure times the normal force ``N``) and the support value ``h(V) = ∫ mu p |v| dA``. For
``w != 0`` both follow from counter-clockwise rotation about ``c``:
``L(V) = sign(w) L_ccw(c)`` and ``h(V) = |w| M(c)`` with ``M(c) = ∫ mu p |x - c| dA``.

Two kinds of reference are offered.

**Closed forms** (:func:`closed_form`): the formulas of DESIGN.md §4, written out again here and
evaluated with mpmath at 40 significant digits plus 3 per decade of ``|c| / size``, so their
cancellation near ``u = 0`` and far away costs nothing. Uniform and ring disks everywhere, Hertz
disks for ``u <= 1``, annuli as the area-weighted difference of two uniform disks, and uniform
rectangles from the moment function ``F`` of §4. The rectangle load needs ``∇M``;
differentiating ``F`` gives

.. math:: \partial F/\partial x = G(x, y) = \tfrac12 [\, y r + x^2 \operatorname{asinh}(y/|x|)\,],
          \qquad \partial F/\partial y = G(y, x),

(``G`` even in ``x``, odd in ``y``), so ``∂M/∂cx = -ΣΣ ± G(xi - cx, yj - cy)`` with the signs of
``M``; ``test_rectangle_reference_gradient_is_the_derivative_of_its_moment_function`` checks
this by finite differences of ``M``.

**Quadrature** (:func:`quadrature`): an independent high-accuracy quadrature of ``h`` and ``L``
for any pressure ``p(x, y)`` (local coordinates) and friction ``mu(x, y)`` (contact coordinates)
over disks, annuli, thin rings and polygons. It works in polar coordinates centred at the COR,
where ``v̂`` does not depend on the radius and ``dA = ρ dρ dψ`` absorbs the kink of ``|x - c|``,
so no integrand is singular at the COR:

- disk: ``ψ`` (angle about the COR) and ``ρ`` (distance from it) both by tanh-sinh rules, which
  converge double-exponentially even with endpoint singularities (the ``sqrt`` edge of a Hertz
  profile, the ``sqrt`` chord length at tangent rays). ``ψ`` is split where rays graze the
  circle; points are built from the foot of the perpendicular from the disk centre to each ray,
  so nothing cancels for far CORs;
- annulus: the disk of the outer radius minus that of the inner radius, same density;
- thin ring: tanh-sinh in the angle along the ring, split at the COR's own angle (where ``v̂``
  jumps when the COR is on the ring);
- polygon, COR near the patch: the signed triangles ``(c, a, b)`` over the directed edges
  ``a → b``, each in Duffy coordinates ``x = c + s (q(t) - c)``; along the edge the substitution
  ``t - t0 = |d| sinh τ`` (``d`` the distance of the COR from the edge's line) makes ``v̂``
  analytic in ``τ`` however close the COR is to the edge, and Gauss–Legendre panels of unit
  length in ``τ`` integrate it. ``p`` and ``mu`` must be analytic over the convex hull of the
  patch and the COR (true of the polynomials the tests use);
- polygon, COR farther than 2.5 patch radii (and pure translation): a 40 x 40 Duffy Gauss rule
  on a fan of signed triangles, exact to rounding because the integrand is analytic there;
- points: the exact finite sums (a point at the COR carries no force).

Accuracy of the quadrature (tests ``test_reference_quadrature_matches_*`` of
test_limit_surface_accuracy.py): norm-wise within 5e-15 of the closed forms for uniform, Hertz
and ring disks and annuli and within 1e-14 for rectangles, at every COR tested (centre, inside,
``u = 1 ± 1e-6``, on the edge, outside, ``u = 1e3``, translation), and within 1e-13 of a 20-digit
mpmath quadrature for a non-uniform pressure, i.e. four orders below the 1e-9 the library is held
to. Far CORs lose ``~u * 1e-16`` relative in the moment alone, far below the norm-wise error of
the load (dominated by the force there). A disk costs ~5 ms, a polygon ~0.5 ms per twist.

Error measures: :func:`relative_error` is the norm-wise ``||L - L_ref|| / ||L_ref||`` with the
moment divided by a length (the patch size), so it does not depend on the unit of length;
:func:`angle_between` is ``atan2(|a x b|, a·b)``, accurate for tiny angles where ``arccos`` is not.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from functools import cache
from typing import NamedTuple

import mpmath
import numpy as np

#: Significant digits of the mpmath closed forms (more for far CORs, see :func:`closed_form`).
CLOSED_FORM_DPS = 40

Function = Callable[[np.ndarray, np.ndarray], np.ndarray]

# ------------------------------------------------------------------------------------------
# Error measures
# ------------------------------------------------------------------------------------------


def angle_between(a, b) -> np.ndarray:
    """Angle [rad] between vectors (rows), ``atan2(|a x b|, a·b)``; accurate for tiny angles."""
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    if a.shape[-1] == 2:
        cross = np.abs(a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0])
    else:
        cross = np.linalg.norm(np.cross(a, b), axis=-1)
    return np.arctan2(cross, np.sum(a * b, axis=-1))


def relative_error(actual, expected, length: float = 1.0) -> float:
    """Norm-wise relative error of loads (rows ``(fx, fy, m)``), moments divided by ``length``.

    For a batch, the largest row error is returned.
    """
    scale = np.array([1.0, 1.0, 1.0 / length])
    actual = np.atleast_2d(np.asarray(actual, dtype=float)) * scale
    expected = np.atleast_2d(np.asarray(expected, dtype=float)) * scale
    errors = np.linalg.norm(actual - expected, axis=1) / np.linalg.norm(expected, axis=1)
    return float(errors.max())


def twist_about(cor, ccw: bool = True) -> np.ndarray:
    """Unit-rate twist rotating about ``cor`` (counter-clockwise unless ``ccw`` is False)."""
    cx, cy = cor
    sign = 1.0 if ccw else -1.0
    return sign * np.array([cy, -cx, 1.0])


def rotation(cor, spin: float) -> np.ndarray:
    """Twist rotating about ``cor`` at rate ``spin`` [rad/s] (counter-clockwise if positive)."""
    return spin * twist_about(cor)


def central_differences(kernel, twist, step: float) -> np.ndarray:
    """Hessian ``(3, 3)`` of a support kernel at ``twist`` by central differences of its exact
    gradient, with steps ``step`` relative to the twist's size (the spin scaled by the kernel's
    size)."""
    size = kernel.size
    scale = np.hypot(np.hypot(twist[0], twist[1]), size * twist[2])
    columns = []
    for j in range(3):
        offset = np.zeros(3)
        offset[j] = step * scale / (size if j == 2 else 1.0)
        plus = kernel.evaluate((twist + offset)[None, :])[1][0]
        minus = kernel.evaluate((twist - offset)[None, :])[1][0]
        columns.append((plus - minus) / (2.0 * offset[j]))
    return np.column_stack(columns)


def cor_of(twist) -> np.ndarray | None:
    """Centre of rotation of ``twist``, or ``None`` for a pure translation."""
    vx, vy, w = (float(v) for v in twist)
    return None if w == 0.0 else np.array([-vy / w, vx / w])


# ------------------------------------------------------------------------------------------
# Closed forms of DESIGN.md §4, in mpmath
# ------------------------------------------------------------------------------------------

#: Maximum moment / (mu N R) of DESIGN.md §4 and Table 1 of the paper.
MAX_MOMENT_RATIO = {
    "uniform": 2.0 / 3.0,
    "hertz": 3.0 * math.pi / 16.0,
    "parabolic": 8.0 / 15.0,
    "ring": 1.0,
}


def annulus_max_moment_ratio(s: float) -> float:
    """``m_max / (mu N R)`` of a uniform annulus with inner radius ``s R`` (Table 1)."""
    return 2.0 * (1.0 - s**3) / (3.0 * (1.0 - s**2))


def rectangle_max_moment(a: float, b: float) -> float:
    """``m_max / (mu N)`` [m] of a uniform ``a`` x ``b`` rectangle (DESIGN.md §4)."""
    d = math.hypot(a, b)
    return (
        d / 6.0
        + a * a / (12.0 * b) * math.log((b + d) / a)
        + b * b / (12.0 * a) * math.log((a + d) / b)
    )


def _uniform_disk(u):
    """``(|f|/(mu N), |m|/(mu N R))`` of a uniform disk, COR at ``u R`` (mpmath)."""
    if u == 0:
        return mpmath.mpf(0), mpmath.mpf(2) / 3
    if u == 1:
        return 8 / (3 * mpmath.pi), 8 / (9 * mpmath.pi)
    if u < 1:
        e, k = mpmath.ellipe(u * u), mpmath.ellipk(u * u)
        force = 4 / (3 * mpmath.pi * u) * ((1 + u * u) * e - (1 - u * u) * k)
        moment = 4 / (9 * mpmath.pi) * (2 * (2 - u * u) * e - (1 - u * u) * k)
        return force, moment
    e, k = mpmath.ellipe(1 / (u * u)), mpmath.ellipk(1 / (u * u))
    force = 4 / (3 * mpmath.pi) * ((1 + u * u) * e - (u * u - 1) * k)
    moment = 4 / (9 * mpmath.pi) * (2 * u * (2 - u * u) * e + (u * u - 1) * (2 * u * u - 3) / u * k)
    return force, moment


def _hertz_disk(u):
    """Hertz disk, ``u <= 1`` only (DESIGN.md §4 gives no closed form outside).

    ``u`` up to ``1 + 1e-12`` (a COR on the rim, up to rounding) is accepted: the outside branch
    differs from the inside one by ``O((u - 1)^(5/2))`` there.
    """
    if u > 1 + mpmath.mpf("1e-12"):
        raise ValueError("no closed form for a Hertz disk with the COR outside; use quadrature")
    return 3 * mpmath.pi / 32 * u * (4 - u * u), 3 * mpmath.pi / 16 * (1 - u * u + 3 * u**4 / 8)


def _ring(u):
    """Thin ring of radius ``R``."""
    if u == 0:
        return mpmath.mpf(0), 2 / mpmath.pi * mpmath.ellipe(0)
    if u == 1:
        return 2 / mpmath.pi, 2 / mpmath.pi
    if u < 1:
        e, k = mpmath.ellipe(u * u), mpmath.ellipk(u * u)
        return 2 / (mpmath.pi * u) * (e - (1 - u * u) * k), 2 / mpmath.pi * e
    e, k = mpmath.ellipe(1 / (u * u)), mpmath.ellipk(1 / (u * u))
    return 2 / mpmath.pi * e, 2 * u / mpmath.pi * (e - (1 - 1 / (u * u)) * k)


_AXISYMMETRIC = {"uniform": _uniform_disk, "hertz": _hertz_disk, "ring": _ring}


def _axisymmetric_ccw(profile: str, radius, cor):
    """``M(c)`` and ``L_ccw(c)`` (per unit mu N) of an axisymmetric disk, in mpmath."""
    cx, cy = (mpmath.mpf(float(v)) for v in cor)
    radius = mpmath.mpf(float(radius))
    dist = mpmath.sqrt(cx * cx + cy * cy)
    force, moment = _AXISYMMETRIC[profile](dist / radius)
    ex, ey = (cx / dist, cy / dist) if dist > 0 else (mpmath.mpf(1), mpmath.mpf(0))
    # f = (∂M/∂cy, -∂M/∂cx) with ∇M = M' ĉ; |m| = M - |c| M'.
    return radius * moment + dist * force, (force * ey, -force * ex, radius * moment)


def _rect_f(x, y):
    """``F(x, y) = ∫_0^x ∫_0^y sqrt(s² + t²) dt ds`` (DESIGN.md §4)."""
    ax, ay = abs(x), abs(y)
    if ax == 0 or ay == 0:
        return mpmath.mpf(0)
    r = mpmath.sqrt(x * x + y * y)
    value = (2 * ax * ay * r + ax**3 * mpmath.asinh(ay / ax) + ay**3 * mpmath.asinh(ax / ay)) / 6
    return mpmath.sign(x) * mpmath.sign(y) * value


def _rect_g(x, y):
    """``∂F/∂x (x, y) = ½ [y r + x² asinh(y / |x|)]``."""
    r = mpmath.sqrt(x * x + y * y)
    if x == 0:
        return y * r / 2
    return (y * r + x * x * mpmath.asinh(y / abs(x))) / 2


def _rectangle_ccw(length, width, cor):
    """``M(c)`` and ``L_ccw(c)`` (per unit mu N) of a uniform centred rectangle, in mpmath."""
    a, b = mpmath.mpf(float(length)) / 2, mpmath.mpf(float(width)) / 2
    cx, cy = (mpmath.mpf(float(v)) for v in cor)
    corners = ((a, b, 1), (-a, b, -1), (a, -b, -1), (-a, -b, 1))
    moment = sum(sign * _rect_f(x - cx, y - cy) for x, y, sign in corners)
    dm_dcx = -sum(sign * _rect_g(x - cx, y - cy) for x, y, sign in corners)
    dm_dcy = -sum(sign * _rect_g(y - cy, x - cx) for x, y, sign in corners)
    area = 4 * a * b
    moment, dm_dcx, dm_dcy = moment / area, dm_dcx / area, dm_dcy / area
    return moment, (dm_dcy, -dm_dcx, moment - cx * dm_dcx - cy * dm_dcy)


def rectangle_moment_function(length: float, width: float, cor) -> tuple[float, np.ndarray]:
    """``M(c)/(mu N)`` [m] of a centred uniform rectangle and ``∇M`` (for checking ``G``)."""
    with mpmath.workdps(CLOSED_FORM_DPS):
        moment, (fx, fy, _) = _rectangle_ccw(length, width, cor)
        return float(moment), np.array([-float(fy), float(fx)])


def disk_force_moment(profile: str, u: float, s: float | None = None) -> tuple[float, float]:
    """``(|f|/(mu N), |m|/(mu N R))`` for a COR at ``u R`` from the centre.

    ``profile`` is ``"uniform"``, ``"hertz"`` (``u <= 1``), ``"ring"`` or ``"annulus"`` (inner
    radius ``s R``).
    """
    with mpmath.workdps(CLOSED_FORM_DPS):
        _, (_, fy, m) = _disk_ccw(profile, 1.0, s, (u, 0.0))
        return float(abs(fy)), float(m)


def _disk_ccw(profile, radius, s, cor):
    if profile != "annulus":
        return _axisymmetric_ccw(profile, radius, cor)
    s2 = mpmath.mpf(float(s)) ** 2
    h_out, l_out = _axisymmetric_ccw("uniform", radius, cor)
    h_in, l_in = _axisymmetric_ccw("uniform", float(s) * radius, cor)
    combine = lambda outer, inner: (outer - s2 * inner) / (1 - s2)  # noqa: E731
    return combine(h_out, h_in), tuple(combine(o, i) for o, i in zip(l_out, l_in, strict=True))


def closed_form(
    shape: str,
    twist,
    *,
    radius: float = 1.0,
    inner_ratio: float | None = None,
    length: float = 1.0,
    width: float = 1.0,
    mu: float = 1.0,
    normal_force: float = 1.0,
    angle: float = 0.0,
    offset=(0.0, 0.0),
) -> tuple[float, np.ndarray]:
    """Support value and load of a standard field from the closed forms of DESIGN.md §4.

    ``shape`` is ``"uniform"``, ``"hertz"``, ``"ring"``, ``"annulus"`` (disks of ``radius``,
    annulus inner radius ``inner_ratio * radius``) or ``"rectangle"`` (``length`` along the local
    x axis). The field is placed by rotating it by ``angle`` and moving its centre to ``offset``.
    """

    def local(local_twist):
        cor = cor_of(local_twist)
        if cor is None:
            speed = math.hypot(local_twist[0], local_twist[1])
            return speed, np.array([local_twist[0] / speed, local_twist[1] / speed, 0.0])
        w = float(local_twist[2])
        # The forms cancel like (|c| / size)^3 far away: carry that many more digits.
        size = math.hypot(length, width) / 2 if shape == "rectangle" else radius
        extra = 3 * max(0, math.ceil(math.log10(max(1.0, math.hypot(*cor) / size))))
        with mpmath.workdps(CLOSED_FORM_DPS + extra):
            if shape == "rectangle":
                moment, load = _rectangle_ccw(length, width, cor)
            else:
                moment, load = _disk_ccw(shape, radius, inner_ratio, cor)
            return abs(w) * float(moment), math.copysign(1.0, w) * np.array(
                [float(v) for v in load]
            )

    h, load = _posed(local, twist, angle, offset)
    return mu * normal_force * h, mu * normal_force * load


def _rotation(angle: float) -> np.ndarray:
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[c, -s], [s, c]])


def _posed(local, twist, angle, offset):
    """Evaluate a local-frame map for a contact-frame ``twist`` (patch rotated, then moved).

    A local point ``q`` lies at ``x = R q + t``. The COR moves the same way (``c_loc = Rᵀ (c -
    t)``), a translation's velocity rotates (``v_loc = Rᵀ v``); loads come back as ``f = R f_loc``
    and ``m = m_loc + t × f``.
    """
    rot, t = _rotation(angle), np.asarray(offset, dtype=float)
    twist = np.asarray(twist, dtype=float)
    cor = cor_of(twist)
    if cor is None:
        local_twist = np.array([*(rot.T @ twist[:2]), 0.0])
    else:
        cx, cy = rot.T @ (cor - t)
        local_twist = abs(twist[2]) * np.array([cy, -cx, 1.0]) * np.sign(twist[2])
    h, load = local(local_twist)
    force = rot @ load[:2]
    return h, np.array([force[0], force[1], load[2] + t[0] * force[1] - t[1] * force[0]])


# ------------------------------------------------------------------------------------------
# Quadrature rules
# ------------------------------------------------------------------------------------------


@cache
def _tanh_sinh(step: float = 1.0 / 16.0, reach: float = 3.6) -> tuple[np.ndarray, np.ndarray]:
    """Tanh-sinh nodes in (0, 1) and weights (sum 1)."""
    k = np.arange(-int(reach / step), int(reach / step) + 1) * step
    arg = 0.5 * np.pi * np.sinh(k)
    nodes = 0.5 * (1.0 + np.tanh(arg))
    weights = 0.5 * step * 0.5 * np.pi * np.cosh(k) / np.cosh(arg) ** 2
    keep = (nodes > 0.0) & (nodes < 1.0)
    return nodes[keep], weights[keep]


@cache
def _gauss(n: int) -> tuple[np.ndarray, np.ndarray]:
    """Gauss–Legendre nodes in (0, 1) and weights (sum 1)."""
    x, w = np.polynomial.legendre.leggauss(n)
    return 0.5 * (x + 1.0), 0.5 * w


def _panels(edges, rule) -> tuple[np.ndarray, np.ndarray]:
    """A 1D rule (nodes, weights on (0, 1)) repeated over consecutive intervals ``edges``."""
    nodes, weights = rule
    lo, hi = np.asarray(edges[:-1], dtype=float), np.asarray(edges[1:], dtype=float)
    return (
        (lo[:, None] + (hi - lo)[:, None] * nodes[None, :]).ravel(),
        ((hi - lo)[:, None] * weights[None, :]).ravel(),
    )


class Rule(NamedTuple):
    """Quadrature about a COR: points ``x``, unit vectors ``(x - c)/|x - c|``, distances, weights.

    ``Σ weights g(points) ≈ ∫ g dA`` (or ``∫ g ds`` / point sums for rings / points).
    """

    points: np.ndarray
    units: np.ndarray
    dist: np.ndarray
    weights: np.ndarray


@dataclass(frozen=True)
class Disk:
    """Disk of ``radius`` centred at the local origin (pressure from the ``pressure`` function)."""

    radius: float

    def rule(self, cor) -> Rule:
        radius = self.radius
        c = np.asarray(cor, dtype=float)
        dist = math.hypot(*c)
        chat = c / dist if dist > 0.0 else np.array([1.0, 0.0])
        cperp = np.array([-chat[1], chat[0]])
        u = dist / radius
        if u < 1.0:
            edges = [-np.pi, -0.5 * np.pi, 0.0, 0.5 * np.pi, np.pi]
        else:
            top = 0.5 * np.pi if u == 1.0 else math.asin(1.0 / u)
            edges = [-top, 0.0, top]
        psi, wpsi = _panels(edges, _tanh_sinh())
        cos_psi, sin_psi = np.cos(psi), np.sin(psi)
        # Ray direction, psi measured from the direction towards the disk centre.
        e = -cos_psi[:, None] * chat - sin_psi[:, None] * cperp
        along = dist * cos_psi  # distance from the COR to the foot of the perpendicular
        off = dist * np.abs(sin_psi)  # distance of the ray's line from the centre
        half = np.sqrt(np.clip((radius - off) * (radius + off), 0.0, None))
        foot = (dist * sin_psi)[:, None] * (sin_psi[:, None] * chat - cos_psi[:, None] * cperp)
        tau, wtau = _tanh_sinh()
        if u < 1.0:
            # along + half, without cancellation where the ray leaves close behind the COR
            width = np.where(
                along >= 0.0, along + half, (radius - dist) * (radius + dist) / (half - along)
            )
            rho = width[:, None] * tau[None, :]
            sigma = rho - along[:, None]
        else:
            width = 2.0 * half
            sigma = half[:, None] * (2.0 * tau[None, :] - 1.0)
            rho = np.clip(along[:, None] + sigma, 0.0, None)
        points = foot[:, None, :] + sigma[:, :, None] * e[:, None, :]
        weights = rho * width[:, None] * wtau[None, :] * wpsi[:, None]
        units = np.broadcast_to(e[:, None, :], points.shape)
        return Rule(points.reshape(-1, 2), units.reshape(-1, 2), rho.ravel(), weights.ravel())

    def area_rule(self) -> tuple[np.ndarray, np.ndarray]:
        rule = self.rule((0.0, 0.0))
        return rule.points, rule.weights


@dataclass(frozen=True)
class Annulus:
    """Region between ``inner_radius`` and ``radius`` about the local origin."""

    radius: float
    inner_radius: float

    def rule(self, cor) -> Rule:
        outer, inner = Disk(self.radius).rule(cor), Disk(self.inner_radius).rule(cor)
        return Rule(
            np.concatenate([outer.points, inner.points]),
            np.concatenate([outer.units, inner.units]),
            np.concatenate([outer.dist, inner.dist]),
            np.concatenate([outer.weights, -inner.weights]),
        )

    def area_rule(self) -> tuple[np.ndarray, np.ndarray]:
        rule = self.rule((0.0, 0.0))
        return rule.points, rule.weights


@dataclass(frozen=True)
class Ring:
    """Thin ring of ``radius`` about the local origin; weights are arc length / (2 pi R)."""

    radius: float

    def rule(self, cor) -> Rule:
        radius = self.radius
        c = np.asarray(cor, dtype=float)
        dist = math.hypot(*c)
        chat = c / dist if dist > 0.0 else np.array([1.0, 0.0])
        cperp = np.array([-chat[1], chat[0]])
        # A finer rule than the disk's: v̂ turns within |1 - u| R of the COR's angle.
        quarters = [0.0, 0.5 * np.pi, np.pi, 1.5 * np.pi, 2.0 * np.pi]
        delta, weights = _panels(quarters, _tanh_sinh(1.0 / 64.0))
        cos_d, sin_d = np.cos(delta), np.sin(delta)
        points = radius * (cos_d[:, None] * chat + sin_d[:, None] * cperp)
        # x - c in the (chat, cperp) frame, written so that nothing cancels near the COR.
        rel_c = (radius - dist) - 2.0 * radius * np.sin(0.5 * delta) ** 2
        rel_p = radius * sin_d
        length = np.hypot(rel_c, rel_p)
        units = (rel_c[:, None] * chat + rel_p[:, None] * cperp) / length[:, None]
        return Rule(points, units, length, weights / (2.0 * np.pi))

    def area_rule(self) -> tuple[np.ndarray, np.ndarray]:
        rule = self.rule((0.0, 0.0))
        return rule.points, rule.weights


@dataclass(frozen=True)
class Polygon:
    """Simple polygon with counter-clockwise ``vertices`` ``(n, 2)`` in the local frame."""

    vertices: np.ndarray

    #: A COR farther than this many patch radii from the vertex centroid uses the fan rule.
    FAR = 2.5

    def _fan(self, order: int = 40):
        v = np.asarray(self.vertices, dtype=float)
        s, ws = _gauss(order)
        t, wt = _gauss(order)
        points, weights = [], []
        for i in range(1, len(v) - 1):
            a, b, c = v[0], v[i], v[i + 1]
            area2 = (b - a)[0] * (c - a)[1] - (b - a)[1] * (c - a)[0]
            q = b[None, :] + t[:, None] * (c - b)[None, :]  # (nt, 2)
            x = a + s[:, None, None] * (q[None, :, :] - a)  # (ns, nt, 2)
            points.append(x.reshape(-1, 2))
            weights.append((area2 * (s * ws)[:, None] * wt[None, :]).ravel())
        return np.concatenate(points), np.concatenate(weights)

    def area_rule(self) -> tuple[np.ndarray, np.ndarray]:
        return self._fan()

    def rule(self, cor) -> Rule:
        v = np.asarray(self.vertices, dtype=float)
        c = np.asarray(cor, dtype=float)
        center = v.mean(axis=0)
        size = np.max(np.hypot(*(v - center).T))
        if math.hypot(*(c - center)) > self.FAR * size:
            points, weights = self._fan()
            rel = points - c
            dist = np.hypot(rel[:, 0], rel[:, 1])
            return Rule(points, rel / dist[:, None], dist, weights)
        s, ws = _gauss(24)
        parts = []
        for a, b in zip(v, np.roll(v, -1, axis=0), strict=True):
            edge = b - a
            length = math.hypot(*edge)
            e_hat = edge / length
            n_hat = np.array([e_hat[1], -e_hat[0]])  # outward for a ccw polygon
            d = float(np.dot(a - c, n_hat))
            if d == 0.0:
                continue  # the COR is on this edge's line: a degenerate triangle
            t_a = float(np.dot(a - c, e_hat))
            tau_a, tau_b = math.asinh(t_a / abs(d)), math.asinh((t_a + length) / abs(d))
            count = max(1, math.ceil(tau_b - tau_a))
            tau, wtau = _panels(np.linspace(tau_a, tau_b, count + 1), _gauss(20))
            sigma = abs(d) * np.sinh(tau)
            dist_q = abs(d) * np.cosh(tau)  # |q - c|
            units = (
                math.copysign(1.0, d) * n_hat / np.cosh(tau)[:, None]
                + np.tanh(tau)[:, None] * e_hat
            )
            rel_q = d * n_hat + sigma[:, None] * e_hat  # q - c
            points = c + s[:, None, None] * rel_q[None, :, :]
            dist = s[:, None] * dist_q[None, :]
            weights = (s * ws)[:, None] * (d * abs(d) * np.cosh(tau) * wtau)[None, :]
            parts.append(
                Rule(
                    points.reshape(-1, 2),
                    np.broadcast_to(units[None], points.shape).reshape(-1, 2),
                    dist.ravel(),
                    weights.ravel(),
                )
            )
        return Rule(*(np.concatenate(field) for field in zip(*parts, strict=True)))


@dataclass(frozen=True)
class Points:
    """Point supports ``xy`` ``(n, 2)`` carrying fractions ``weights`` of the normal force."""

    xy: np.ndarray
    weights: np.ndarray

    def rule(self, cor) -> Rule:
        xy = np.asarray(self.xy, dtype=float)
        rel = xy - np.asarray(cor, dtype=float)
        dist = np.hypot(rel[:, 0], rel[:, 1])
        safe = np.where(dist > 0.0, dist, 1.0)
        units = np.where(dist[:, None] > 0.0, rel / safe[:, None], 0.0)
        return Rule(xy, units, dist, np.asarray(self.weights, dtype=float))

    def area_rule(self) -> tuple[np.ndarray, np.ndarray]:
        return np.asarray(self.xy, dtype=float), np.asarray(self.weights, dtype=float)


Region = Disk | Annulus | Ring | Polygon | Points


def _values(function, points) -> np.ndarray:
    return np.broadcast_to(np.asarray(function(points[:, 0], points[:, 1]), float), len(points))


def quadrature(
    region: Region,
    twist,
    *,
    pressure: Function | None = None,
    mu: float | Function = 1.0,
    normal_force: float = 1.0,
    angle: float = 0.0,
    offset=(0.0, 0.0),
) -> tuple[float, np.ndarray]:
    """Support value and load by independent quadrature (see the module docstring).

    ``pressure(x, y)`` (local coordinates, default uniform) is normalised to unit total over
    ``region``; ``mu`` is a constant or a function of contact-frame coordinates. The region is
    rotated by ``angle`` about the local origin and then moved by ``offset``.
    """
    rot, t = _rotation(angle), np.asarray(offset, dtype=float)

    def density(points):
        value = np.ones(len(points)) if pressure is None else _values(pressure, points)
        friction = _values(mu, points @ rot.T + t) if callable(mu) else mu
        return value * friction

    area_points, area_weights = region.area_rule()
    p_total = area_weights @ (
        np.ones(len(area_points)) if pressure is None else _values(pressure, area_points)
    )
    scale = normal_force / p_total

    def local(local_twist):
        cor = cor_of(local_twist)
        if cor is None:
            wd = area_weights * density(area_points)
            speed = math.hypot(local_twist[0], local_twist[1])
            vhat = np.asarray(local_twist[:2]) / speed
            total, first = wd.sum(), wd @ area_points
            moment = first[0] * vhat[1] - first[1] * vhat[0]
            return speed * total, np.array([vhat[0] * total, vhat[1] * total, moment])
        rule = region.rule(cor)
        wd = rule.weights * density(rule.points)
        w = float(local_twist[2])
        ux, uy = rule.units[:, 0], rule.units[:, 1]
        # v̂ = J û for counter-clockwise rotation; x × v̂ = x·û.
        moment = wd @ (rule.points[:, 0] * ux + rule.points[:, 1] * uy)
        load = math.copysign(1.0, w) * np.array([-(wd @ uy), wd @ ux, moment])
        return abs(w) * (wd @ rule.dist), load

    h, load = _posed(local, twist, angle, offset)
    return scale * h, scale * load


def points_exact(
    xy, weights, twist, *, mu: float | Function = 1.0, normal_force: float = 1.0
) -> tuple[float, np.ndarray]:
    """Exact support value and load of point supports (contact frame; stationary point: 0)."""
    xy = np.asarray(xy, dtype=float)
    weights = np.asarray(weights, dtype=float) / np.sum(weights)
    friction = _values(mu, xy) if callable(mu) else np.full(len(xy), float(mu))
    vx, vy, w = (float(v) for v in twist)
    vel = np.column_stack([vx - w * xy[:, 1], vy + w * xy[:, 0]])
    speed = np.hypot(vel[:, 0], vel[:, 1])
    moving = speed > 0.0
    vhat = np.zeros_like(vel)
    vhat[moving] = vel[moving] / speed[moving, None]
    force = normal_force * friction * weights
    load = np.array(
        [
            force @ vhat[:, 0],
            force @ vhat[:, 1],
            force @ (xy[:, 0] * vhat[:, 1] - xy[:, 1] * vhat[:, 0]),
        ]
    )
    return float(force @ speed), load


def facet_load(
    xy, weights, k: int, carried, *, mu: float | Function = 1.0, normal_force: float = 1.0
) -> np.ndarray:
    """A load on the facet of support point ``k`` (counter-clockwise rotation about it).

    The other points slide at their friction limit; point ``k`` carries the force ``carried``
    ``(2,)`` [N], which must not exceed its own limit ``mu_k N w_k``.
    """
    xy = np.asarray(xy, dtype=float)
    _, sliding = points_exact(xy, weights, twist_about(xy[k]), mu=mu, normal_force=normal_force)
    fx, fy = carried
    return sliding + np.array([fx, fy, xy[k, 0] * fy - xy[k, 1] * fx])
