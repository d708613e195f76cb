r"""Closed-form support functions of axisymmetric pressure on a disk.

For a disk of radius ``R`` about the origin, a twist ``V = (v, w)`` rotates the patch about a
centre at distance ``ρ = |v|/|w|``; with the moment function ``M(ρ) = ∫ p |x - c| dA`` (unit
friction) the support function is ``h = |w| M(ρ)``, the force is ``M'(ρ) v̂`` and the moment
``sign(w) (M - ρ M')``. With ``u = ρ/R``, ``x = 1/u²`` and
``c_n = ((-1/2)_n / n!)²`` (the coefficients of the mean distance of a circle to a point,
``₂F₁(-1/2, -1/2; 1; ·)``) every profile ``p ∝ (1 - r²/R²)^α`` gives outside the disk

.. math:: M(ρ) = ρ \, {}_2F_1(-\tfrac12, -\tfrac12; α + 2; R^2/ρ^2),

(thin ring: ``α + 2 → 1``), which is free of cancellation for far centres and smooth at
``w = 0``. Inside the disk (``u < 1``, ``E``, ``K`` of modulus ``u``):

- uniform: ``M = (2R/3) ₂F₁(-1/2, -3/2; 1; u²)``, ``M' = u ₂F₁(1/2, -1/2; 2; u²)``;
- Hertz: ``M' = (3π/32) u (4 - u²)``, ``M - ρM' = (3π/16) R (1 - u² + 3u⁴/8)``;
- parabolic: ``π M/R = [(608 + 192u² - 32u⁴) E - 16 (1 - u²)(23 + u²) K] / 225``,
  ``π M' = 16 [(3 + 7u² - 2u⁴) E - (1 - u²)(3 + u²) K] / (45 u)`` (series below ``u = 0.3``);
- thin ring: ``M' = (u/2) ₂F₁(1/2, 1/2; 2; u²)``, ``M - ρM' = (2R/π) E(u)``.

These reproduce the forms of DESIGN.md §4 and were derived and checked against 30-digit
quadrature; the parabolic form was found by exact fitting of its hypergeometric series.
An annulus is a weighted difference of two uniform disks.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.special import ellipe, ellipk, hyp2f1, poch

from fixplan.surface.kernels import SupportKernel

#: ``c`` of ``₂F₁(-1/2, -1/2; c; x)`` giving ``M(ρ)/ρ`` outside the disk, per profile.
_OUTSIDE_C = {"uniform": 2.0, "hertz": 2.5, "parabolic": 3.0, "ring": 1.0}

#: Below this ``u`` the parabolic force uses its power series (the E/K form cancels).
_PARABOLIC_SERIES_BELOW = 0.3


def _parabolic_series_coefficients(terms: int = 40) -> np.ndarray:
    n = np.arange(terms, dtype=float)
    c_n = (poch(-0.5, n) / np.array([math.factorial(int(k)) for k in n])) ** 2
    return 4.0 * c_n * (1.0 / (3.0 - 2.0 * n) - 1.0 / (5.0 - 2.0 * n))


_PARABOLIC_SERIES = _parabolic_series_coefficients()


def _inside(profile: str, u: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Force ``M'`` and moment ``(M - ρM')/R`` per unit friction for ``0 <= u < 1``."""
    u2 = u * u
    if profile == "uniform":
        force = u * hyp2f1(0.5, -0.5, 2.0, u2)
        moment = (2.0 / 3.0) * hyp2f1(-0.5, -1.5, 1.0, u2) - u * force
    elif profile == "hertz":
        force = (3.0 * math.pi / 32.0) * u * (4.0 - u2)
        moment = (3.0 * math.pi / 16.0) * (1.0 - u2 + 0.375 * u2 * u2)
    elif profile == "ring":
        force = 0.5 * u * hyp2f1(0.5, 0.5, 2.0, u2)
        moment = (2.0 / math.pi) * ellipe(u2)
    else:  # parabolic
        e, k = ellipe(u2), ellipk(u2)
        whole = (
            (608.0 + 192.0 * u2 - 32.0 * u2 * u2) * e - 16.0 * (1.0 - u2) * (23.0 + u2) * k
        ) / (225.0 * math.pi)
        small = u < _PARABOLIC_SERIES_BELOW
        force = np.empty_like(u)
        big = ~small
        ub, ub2 = u[big], u2[big]
        force[big] = (16.0 / (45.0 * math.pi * ub)) * (
            (3.0 + 7.0 * ub2 - 2.0 * ub2 * ub2) * e[big] - (1.0 - ub2) * (3.0 + ub2) * k[big]
        )
        n = np.arange(1, len(_PARABOLIC_SERIES))
        us = u[small]
        force[small] = (
            (2.0 * n * _PARABOLIC_SERIES[1:])[None, :] * us[:, None] ** (2 * n - 1)[None, :]
        ).sum(axis=1)
        moment = whole - u * force
    return force, moment


def _inside_slope(profile: str, u: np.ndarray) -> np.ndarray:
    """Slope ``dM'/du`` of the force per unit friction for ``0 <= u < 1`` (``R M''(ρ)``)."""
    u2 = u * u
    if profile == "uniform":
        return hyp2f1(0.5, -0.5, 2.0, u2) - 0.25 * u2 * hyp2f1(1.5, 0.5, 3.0, u2)
    if profile == "hertz":
        return (3.0 * math.pi / 32.0) * (4.0 - 3.0 * u2)
    if profile == "ring":
        return 0.5 * hyp2f1(0.5, 0.5, 2.0, u2) + 0.125 * u2 * hyp2f1(1.5, 1.5, 3.0, u2)
    # Parabolic: the derivative of the E/K form (dE/du = (E - K)/u,
    # dK/du = E/(u (1 - u²)) - K/u), its power series below the cancelling range.
    slope = np.empty_like(u)
    small = u < _PARABOLIC_SERIES_BELOW
    n = np.arange(1, len(_PARABOLIC_SERIES))
    us = u[small]
    terms = (2.0 * n * (2.0 * n - 1.0) * _PARABOLIC_SERIES[1:])[None, :]
    slope[small] = (terms * us[:, None] ** (2 * n - 2)[None, :]).sum(axis=1)
    ub = u[~small]
    ub2 = ub * ub
    e, k = ellipe(ub2), ellipk(ub2)
    p = (3.0 + 7.0 * ub2 - 2.0 * ub2 * ub2) * e - (1.0 - ub2) * (3.0 + ub2) * k
    dp = (
        (14.0 * ub - 8.0 * ub2 * ub) * e
        + (3.0 + 7.0 * ub2 - 2.0 * ub2 * ub2) * (e - k) / ub
        + 4.0 * ub * (1.0 + ub2) * k
        - (3.0 + ub2) * e / ub
        + (1.0 - ub2) * (3.0 + ub2) * k / ub
    )
    slope[~small] = (16.0 / (45.0 * math.pi)) * (dp / ub - p / ub2)
    return slope


@dataclass(frozen=True, slots=True)
class DiskKernel(SupportKernel):
    r"""Unit-friction support function of an axisymmetric ``profile`` on a disk of ``radius`` [m]
    centred at the origin (``profile`` one of uniform, hertz, parabolic, ring).

    The Hessian is analytic: with ``a = |v|``, ``v̂ = v/a`` and ``h(a, w)``,

    .. math:: ∇²h = \begin{pmatrix} h_{aa} v̂v̂ᵀ + (h_a/a)(I - v̂v̂ᵀ) & h_{aw} v̂ \\
              h_{aw} v̂ᵀ & h_{ww} \end{pmatrix},

    where ``h_a = M'(ρ)`` is the force, and outside the disk (``F = ₂F₁(-1/2, -1/2; c; x)``,
    ``x = R²w²/a²``, ``q = F' + 2x F''``) ``h_aa = 2xq/a``, ``h_aw = -2R²wq/a²``,
    ``h_ww = 2R²q/a``; inside (``u = a/(R|w|)``) ``h_aa = M''(ρ)/|w|``, ``h_aw = -h_aa u R
    sign(w)``, ``h_ww = h_aa u² R²`` (``h`` is homogeneous of degree one).
    """

    radius: float
    profile: str

    @property
    def size(self) -> float:
        return self.radius

    def evaluate(self, twists):
        h, loads, _ = self._terms(twists, False)
        return h, loads

    def newton_terms(self, twists):
        return self._terms(twists, True)

    def hessian(self, twists):
        return self._terms(twists, True)[2]

    def _terms(self, twists, with_hessian):
        vx, vy, w = twists[:, 0], twists[:, 1], twists[:, 2]
        speed = np.hypot(vx, vy)
        spin = np.abs(w)
        radius = self.radius
        outside = speed >= radius * spin
        h = np.empty(len(twists))
        force = np.empty(len(twists))  # magnitude, along v̂
        moment = np.empty(len(twists))  # signed, about the centre
        # Second derivatives in (a, w) and h_a / a.
        h_aa, h_aw, h_ww, ratio = (np.empty(len(twists)) for _ in range(4))

        a, t, wo = speed[outside], spin[outside], w[outside]
        x = (radius * t / a) ** 2
        c = _OUTSIDE_C[self.profile]
        big_f = hyp2f1(-0.5, -0.5, c, x)
        dbig_f = hyp2f1(0.5, 0.5, c + 1.0, x) / (4.0 * c)
        h[outside] = a * big_f
        force[outside] = big_f - 2.0 * x * dbig_f
        moment[outside] = 2.0 * radius**2 * wo * dbig_f / a
        if with_hessian:
            with np.errstate(divide="ignore", invalid="ignore"):  # infinite on a ring's rim
                d2big_f = hyp2f1(1.5, 1.5, c + 2.0, x) / (16.0 * c * (c + 1.0))
                q = dbig_f + 2.0 * x * d2big_f
            h_aa[outside] = 2.0 * x * q / a
            h_aw[outside] = -2.0 * radius**2 * wo * q / a**2
            h_ww[outside] = 2.0 * radius**2 * q / a
            ratio[outside] = force[outside] / a

        inside = ~outside
        a, t, wi = speed[inside], spin[inside], w[inside]
        u = a / (radius * t)
        f_in, m_in = _inside(self.profile, u)
        h[inside] = t * radius * (m_in + u * f_in)
        force[inside] = f_in
        moment[inside] = np.sign(wi) * radius * m_in
        if with_hessian:
            slope = _inside_slope(self.profile, u)
            k = slope / (radius * t)
            h_aa[inside] = k
            h_aw[inside] = -k * u * radius * np.sign(wi)
            h_ww[inside] = k * (u * radius) ** 2
            # h_a / a = M'(ρ) / a, which tends to M''(0) / |w| at the centre.
            with np.errstate(invalid="ignore", divide="ignore"):
                ratio[inside] = np.where(u > 0.0, f_in / np.where(u > 0.0, u, 1.0), slope) / (
                    radius * t
                )

        with np.errstate(invalid="ignore", divide="ignore"):
            ex = np.where(speed > 0.0, vx / speed, 0.0)
            ey = np.where(speed > 0.0, vy / speed, 0.0)
        loads = np.column_stack([force * ex, force * ey, moment])
        if not with_hessian:
            return h, loads, None
        hess = np.empty((len(twists), 3, 3))
        with np.errstate(invalid="ignore"):  # inf * 0 on a ring's rim: replaced below
            across = h_aa - ratio
            hess[:, 0, 0] = ratio + across * ex * ex
            hess[:, 1, 1] = ratio + across * ey * ey
            hess[:, 0, 1] = hess[:, 1, 0] = across * ex * ey
            hess[:, 0, 2] = hess[:, 2, 0] = h_aw * ex
            hess[:, 1, 2] = hess[:, 2, 1] = h_aw * ey
            hess[:, 2, 2] = h_ww
        # A thin ring rotating about one of its points is infinitely curved there: central
        # differences of the gradient give Newton a finite Hessian to steer by.
        singular = ~np.all(np.isfinite(hess), axis=(1, 2))
        if np.any(singular):
            hess[singular] = SupportKernel.hessian(self, twists[singular])
        return h, loads, hess


@dataclass(frozen=True, slots=True)
class AnnulusKernel(SupportKernel):
    """Uniform pressure between ``inner_radius`` and ``radius`` [m]: two uniform disks."""

    radius: float
    inner_radius: float

    @property
    def size(self) -> float:
        return self.radius

    @property
    def parts(self) -> tuple[tuple[DiskKernel, float], ...]:
        """The two uniform disks with their weights (the outer positive, the inner negative)."""
        radius, inner_radius = self.radius, self.inner_radius
        s2 = (inner_radius / radius) ** 2
        rest = (radius - inner_radius) * (radius + inner_radius) / radius**2  # 1 - s2, exactly
        outer = DiskKernel(radius, "uniform")
        inner = DiskKernel(inner_radius, "uniform")
        return (outer, 1.0 / rest), (inner, -s2 / rest)

    def evaluate(self, twists):
        (outer, wo), (inner, wi) = self.parts
        ho, lo = outer.evaluate(twists)
        hi, li = inner.evaluate(twists)
        return wo * ho + wi * hi, wo * lo + wi * li

    def newton_terms(self, twists):
        (outer, wo), (inner, wi) = self.parts
        ho, go, hesso = outer.newton_terms(twists)
        hi, gi, hessi = inner.newton_terms(twists)
        return wo * ho + wi * hi, wo * go + wi * gi, wo * hesso + wi * hessi

    def hessian(self, twists):
        return self.newton_terms(twists)[2]
