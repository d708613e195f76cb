r"""Support function of an arbitrary smooth pressure and friction field, by adapted quadrature.

For pressure ``p`` and friction ``mu`` (smooth functions of the local coordinates) on a union of
regions, a twist ``V = (vx, vy, w)`` has the support function and load

.. math::

   h(V) = \frac{1}{N} \int \mu p \, |v| \, dA, \qquad
   L(V) = \nabla h = \frac{1}{N} \int \mu p \, (\hat v, \; x \times \hat v) \, dA, \qquad
   N = \int p \, dA.

With ``w != 0`` the velocity is ``v = w J (x - c)`` about the centre of rotation ``c`` (``J`` the
90-degree rotation), so ``|v| = |w| |x - c|`` has a cone point at ``c`` and ``v̂`` jumps there.
A fixed rule on the patch converges slowly when ``c`` is on or near the patch, so every region
with ``c`` closer than ``FAR_FIELD_RADII`` of its radii is integrated in polar coordinates about
``c``, ``dA = ρ dρ dθ``, where the cone point is harmless (``|x - c| = ρ`` and the unit vector
is constant along a ray). What is left are near-singular *angular* integrals when ``c`` is close
to an edge: a boundary at distance ``d`` from ``c`` puts the integrand's singularities at
``±i d`` in the coordinate ``t`` along it. The substitution ``t = d sinh τ`` makes
``sqrt(d² + t²) = d cosh τ`` smooth, and Gauss panels graded geometrically towards the ends of
the ``τ`` range (the integrand grows like ``e^{kτ}`` there) integrate it to machine precision
for any ``d``, with a number of points that grows like ``log(1/d)``:

- **polygon**: signed triangles ``(c, a, b)`` over the directed edges; in each the ray to the
  edge point at ``t`` has length ``r = |d| cosh τ`` and angle ``dθ = sign(d) dτ / cosh τ``.
  The triangles leave the polygon when ``c`` lies outside it, so ``p`` and ``mu`` are evaluated
  there too: they must extend smoothly to a neighbourhood of the polygon.
- **disk** (radius ``R``, ``c`` at distance ``D``): with ``c`` inside, the chords through ``c``
  at angle ``α`` to ``ĉ`` have half-length ``H = sqrt(g² + D² cos² α)``, ``g² = R² - D²``;
  near ``α = π/2`` the map ``D cos α = g sinh τ`` gives ``H = g cosh τ``. With ``c`` outside,
  the lines of the tangent cone, ``D sin α = R sin φ``, have half-chord ``R cos φ`` and
  ``cos α = sqrt(γ² + κ² cos² φ)`` (``κ = R/D``, ``γ² = 1 - κ²``); near ``φ = ±π/2`` the map
  ``κ cos φ = γ sinh τ`` gives ``cos α = γ cosh τ``. The disk is only sampled inside, and the
  radial rule is tanh-sinh when ``p`` is given, so that edge singularities such as the Hertz
  ``sqrt(1 - r²/R²)`` converge double exponentially.
- **circle** (a line density on ``|x| = R``): with ``u = D/R`` the distance is
  ``|x - c| = R sqrt((1 - u)² + t²)``, ``t = 2 sqrt(u) sin(ψ/2)`` at angle ``ψ`` from ``ĉ``;
  ``t = |1 - u| sinh τ`` on the arc ``|ψ| <= π/4`` and Gauss panels on the rest.

Regions farther from ``c`` (and every region when ``w = 0``) use a fixed rule (triangle Gauss,
polar tanh-sinh, trapezoidal) on which the integrand is analytic; it is precomputed with its
``mu p`` values and summed by the compiled :class:`~fixplan.surface.point_kernel.PointSetKernel`. The
fixed rule also gives ``N``. Accuracy (relative, measured against closed forms and independent
adaptive quadrature): ``1e-12`` or better for smooth fields and for the Hertz profile, for any
centre of rotation.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field, replace

import numpy as np

from fixplan import validation
from fixplan.errors import InvalidArgumentError
from fixplan.surface.geometry import simple_polygon, triangulate
from fixplan.surface.kernels import SupportKernel
from fixplan.surface.point_kernel import PointSetKernel
from fixplan.surface.rules import gauss_jacobi_unit, tanh_sinh_unit, triangle_rule
from fixplan.tolerances import FAR_FIELD_RADII

REGION_KINDS = ("polygon", "disk", "circle")

_POLYGON, _DISK, _CIRCLE = range(3)

#: Distances (in the sinh variable ``τ``) from the ends of a ``τ`` range at which it is cut
#: into Gauss panels. The integrand grows like ``e^{kτ}`` towards the ends, so the panels are
#: graded geometrically; only cuts inside the range are made, so short ranges get few panels.
_PANEL_OFFSETS = np.array([1.5, 4.0, 8.0, 16.0])

#: Gauss nodes per ``τ`` panel.
_PANEL_ORDER = 10

#: Half-width [rad] of the angular pieces of a disk mapped by the sinh substitution.
_DISK_MAPPED_ANGLE = math.pi / 8.0

#: Gauss nodes on the rest of the angular range of a disk.
_DISK_SIDE_ORDER = 20

#: Half-angle [rad] of the arc of a circle about ``c`` mapped by the sinh substitution.
_CIRCLE_MAPPED_ANGLE = math.pi / 4.0

#: Gauss nodes per panel of the circle (two panels on the rest of the circle).
_CIRCLE_ORDER = 16

#: Gauss nodes along the rays of a polygon for smooth fields, and for constant ones.
_POLYGON_RAY_ORDER = 16
_CONSTANT_RAY_ORDER = 3

#: Level of the tanh-sinh rule along the rays of a disk when a pressure function is given.
_DISK_RAY_LEVEL = 3

#: Orders of the fixed (far-field) rules: triangle Gauss, polar disk, trapezoidal circle.
_FAR_TRIANGLE_ORDER = 12
_FAR_DISK_ANGLES = 48
_FAR_DISK_RADIAL = 16
_FAR_CIRCLE_ANGLES = 64

#: Largest diameter of the triangles of the fixed polygon rule, as a fraction of the kernel
#: size: big polygons are subdivided so that the rule resolves the variation of ``p`` and
#: ``mu`` over the patch (and gives ``N`` to about machine precision for smooth fields).
_FAR_PIECE = 0.5

#: Below this ``|d| / edge length`` the signed triangle of an edge is dropped (its share of the
#: integral is of that order).
_THIN_TRIANGLE = 1e-13

#: A centre of rotation inside a disk with ``sqrt(R² - D²) < _RIM_GAP * R`` (a gap below
#: ``1e-14 R``) is taken as on the rim; outside, the tangent-cone map stops refining when
#: ``γ < _RIM_GAP`` (the lines it no longer resolves carry a share of order ``γ²``).
_RIM_GAP = 1e-7

#: Smallest ``|1 - D/R|`` the sinh map of a circle resolves (the error of treating a smaller
#: gap as zero is of order ``gap * log(1/gap)``).
_CIRCLE_GAP = 1e-14

#: Smallest span of a sinh range (it is zero when ``c`` is at the centre of a disk or circle).
_TINY_SPAN = 1e-100

#: Where the two rules are compared (:meth:`FunctionKernel.rule_disagreement`): centres of
#: rotation at these fractions of the near range, in ``_PROBE_DIRECTIONS`` directions about
#: each of at most ``_PROBED_REGIONS`` regions (evenly spread over the regions).
_PROBE_FRACTIONS = (0.75,)
_PROBE_DIRECTIONS = 8
_PROBED_REGIONS = 8

#: Most quadrature nodes evaluated in one call of ``p`` and ``mu`` (bounds memory).
_NODE_BUDGET = 1 << 20

Field = Callable[[np.ndarray, np.ndarray], np.ndarray]


def _gauss(lo: float, hi: float, order: int) -> tuple[np.ndarray, np.ndarray]:
    """Gauss-Legendre nodes and weights on ``[lo, hi]``."""
    x, w = gauss_jacobi_unit(order)
    return lo + (hi - lo) * x, (hi - lo) * w


def _graded_rule(lo: np.ndarray, hi: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Gauss panels on the ``τ`` ranges ``[lo, hi]`` ``(M,)``, cut at 0 and graded to the ends.

    Returns the row (range index), node and weight of every node, flattened.
    """
    top = np.minimum(hi, 0.0)[:, None]
    bottom = np.maximum(lo, 0.0)[:, None]
    from_lo = lo[:, None] + _PANEL_OFFSETS
    from_hi = hi[:, None] - _PANEL_OFFSETS
    unused = hi[:, None]
    cuts = np.concatenate(
        [
            np.where(from_lo < top, from_lo, unused),
            np.where(from_hi > bottom, from_hi, unused),
            np.where((lo < 0.0) & (hi > 0.0), 0.0, hi)[:, None],
        ],
        axis=1,
    )
    edges = np.sort(np.concatenate([lo[:, None], cuts, hi[:, None]], axis=1), axis=1)
    a, b = edges[:, :-1, None], edges[:, 1:, None]
    x, w = gauss_jacobi_unit(_PANEL_ORDER)
    nodes = a + (b - a) * x
    weights = (b - a) * w
    keep = np.broadcast_to(b > a, nodes.shape)
    rows = np.broadcast_to(np.arange(len(lo))[:, None, None], nodes.shape)
    return rows[keep], nodes[keep], weights[keep]


def _sinh_ratio(tau: np.ndarray, span: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``sinh(τ) / sinh(T)`` and its derivative in ``τ``."""
    scale = np.sinh(span)
    return np.sinh(tau) / scale, np.cosh(tau) / scale


@dataclass(frozen=True, slots=True)
class _Rays:
    """Rays ``c + ρ ê``, ``start <= ρ <= end`` [m], of angular weight ``dθ`` (``dA = ρ dρ dθ``);
    ``rows`` says which centre ``c`` each ray leaves from."""

    rows: np.ndarray
    direction: np.ndarray
    start: np.ndarray
    end: np.ndarray
    angle_weight: np.ndarray

    def relabel(self, owner: np.ndarray) -> _Rays:
        """The same rays with ``rows`` mapped through ``owner``."""
        return replace(self, rows=owner[self.rows])


def _polygon_rays(starts: np.ndarray, ends: np.ndarray, centers: np.ndarray) -> _Rays:
    """Rays of the signed triangles ``(c, a, b)`` of edges ``(M, 2)`` about ``centers``."""
    edge = ends - starts
    length = np.hypot(edge[:, 0], edge[:, 1])
    e = edge / length[:, None]
    n = np.column_stack([e[:, 1], -e[:, 0]])  # outward for a counter-clockwise polygon
    rel_a, rel_b = starts - centers, ends - centers
    d = np.einsum("ij,ij->i", n, rel_a)
    ta = np.einsum("ij,ij->i", e, rel_a)
    tb = np.einsum("ij,ij->i", e, rel_b)
    live = np.flatnonzero(np.abs(d) > _THIN_TRIANGLE * length)
    d, e, n = d[live], e[live], n[live]
    scale = np.abs(d)
    rows, tau, weight = _graded_rule(np.arcsinh(ta[live] / scale), np.arcsinh(tb[live] / scale))
    cosh, side = np.cosh(tau), np.sign(d[rows])
    direction = (side / cosh)[:, None] * n[rows] + np.tanh(tau)[:, None] * e[rows]
    return _Rays(
        live[rows], direction, np.zeros_like(tau), scale[rows] * cosh, side * weight / cosh
    )


def _frame(centers: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Distances ``D`` of ``centers`` from the origin, unit vectors ``ĉ`` and ``J ĉ``."""
    dist = np.hypot(centers[:, 0], centers[:, 1])
    safe = np.where(dist > 0.0, dist, 1.0)
    unit = np.where((dist > 0.0)[:, None], centers / safe[:, None], np.array([1.0, 0.0]))
    return dist, unit, np.column_stack([-unit[:, 1], unit[:, 0]])


def _disk_inside_rays(radius: np.ndarray, centers: np.ndarray) -> _Rays:
    """Rays about ``centers`` ``(M, 2)`` inside disks of ``radius`` ``(M,)`` [m]: both halves
    of every chord through ``c``, by its angle ``α`` to ``ĉ``."""
    dist, unit, perp = _frame(centers)
    g2 = (radius - dist) * (radius + dist)
    sin_b = math.sin(_DISK_MAPPED_ANGLE)
    # Chords within _DISK_MAPPED_ANGLE of perpendicular to ĉ: D cos α = g sinh τ.
    span = np.maximum(np.arcsinh(dist * sin_b / np.sqrt(g2)), _TINY_SPAN)
    mapped, tau, wt = _graded_rule(-span, span)
    ratio, dratio = _sinh_ratio(tau, span[mapped])
    cos_m = sin_b * ratio
    sin_m = np.sqrt(1.0 - cos_m * cos_m)
    # The other chords, through ĉ.
    alpha, wa = _gauss(
        0.5 * math.pi + _DISK_MAPPED_ANGLE, 1.5 * math.pi - _DISK_MAPPED_ANGLE, _DISK_SIDE_ORDER
    )
    count = len(dist)
    side = np.repeat(np.arange(count), len(alpha))
    cos_s = np.tile(np.cos(alpha), count)
    rows = np.concatenate([mapped, side])
    cos_a = np.concatenate([cos_m, cos_s])
    sin_a = np.concatenate([sin_m, np.tile(np.sin(alpha), count)])
    weight = np.concatenate([wt * sin_b * dratio / sin_m, np.tile(wa, count)])
    half = np.concatenate(
        [np.sqrt(g2[mapped]) * np.cosh(tau), np.sqrt(g2[side] + (dist[side] * cos_s) ** 2)]
    )
    # The chord runs from ρ = -half - along to half - along; the short side without cancellation.
    along = dist[rows] * cos_a
    g2r = g2[rows]
    forward = np.where(along <= 0.0, half - along, g2r / (half + along))
    backward = np.where(along >= 0.0, half + along, g2r / (half - along))
    direction = cos_a[:, None] * unit[rows] + sin_a[:, None] * perp[rows]
    zero = np.zeros_like(half)
    return _Rays(
        np.concatenate([rows, rows]),
        np.concatenate([direction, -direction]),
        np.concatenate([zero, zero]),
        np.concatenate([forward, backward]),
        np.concatenate([weight, weight]),
    )


def _disk_outside_rays(radius: np.ndarray, centers: np.ndarray) -> _Rays:
    """Chords of disks of ``radius`` ``(M,)`` [m] on the lines through ``centers`` ``(M, 2)``
    outside or on the rim, by the angle ``φ`` with ``D sin α = R sin φ``."""
    dist, unit, perp = _frame(centers)
    kappa = np.minimum(radius / dist, 1.0)
    gamma2 = np.maximum((dist - radius) * (dist + radius), 0.0) / dist**2
    sin_b = math.sin(_DISK_MAPPED_ANGLE)
    # Lines within _DISK_MAPPED_ANGLE of a tangent (φ = ±π/2): κ cos φ = γ sinh τ.
    span = np.arcsinh(kappa * sin_b / np.maximum(np.sqrt(gamma2), _RIM_GAP))
    mapped, tau, wt = _graded_rule(np.zeros_like(span), span)
    ratio, dratio = _sinh_ratio(tau, span[mapped])
    cos_m = sin_b * ratio
    sin_m = np.sqrt(1.0 - cos_m * cos_m)
    w_m = wt * sin_b * dratio / sin_m
    # The other lines, about the one through the centre of the disk.
    phi, wp = _gauss(
        _DISK_MAPPED_ANGLE - 0.5 * math.pi, 0.5 * math.pi - _DISK_MAPPED_ANGLE, _DISK_SIDE_ORDER
    )
    count = len(dist)
    rows = np.concatenate([mapped, mapped, np.repeat(np.arange(count), len(phi))])
    cos_phi = np.concatenate([cos_m, cos_m, np.tile(np.cos(phi), count)])
    sin_phi = np.concatenate([sin_m, -sin_m, np.tile(np.sin(phi), count)])
    w_phi = np.concatenate([w_m, w_m, np.tile(wp, count)])
    kr, g2r, dr = kappa[rows], gamma2[rows], dist[rows]
    sin_a = kr * sin_phi
    cos_a = np.sqrt(g2r + (kr * cos_phi) ** 2)
    half = radius[rows] * cos_phi
    direction = -cos_a[:, None] * unit[rows] + sin_a[:, None] * perp[rows]
    entry = dr * dr * g2r / (dr * cos_a + half)  # D cos α - half without cancellation
    return _Rays(rows, direction, entry, dr * cos_a + half, w_phi * kr * cos_phi / cos_a)


def _circle_nodes(radius: np.ndarray, centers: np.ndarray):
    """Nodes ``(rows, x, ds, ρ, ê)`` on circles of ``radius`` ``(M,)`` about ``centers``
    ``(M, 2)`` (``ds`` the arc length weights [m])."""
    dist, unit, perp = _frame(centers)
    u = dist / radius
    gap = (radius - dist) / radius
    sin_b = math.sin(0.5 * _CIRCLE_MAPPED_ANGLE)
    span = np.maximum(
        np.arcsinh(2.0 * np.sqrt(u) * sin_b / np.maximum(np.abs(gap), _CIRCLE_GAP)), _TINY_SPAN
    )
    rows, tau, wt = _graded_rule(-span, span)
    ratio, dratio = _sinh_ratio(tau, span[rows])
    half_sin = sin_b * ratio  # sin(ψ/2)
    half_cos = np.sqrt(1.0 - half_sin * half_sin)
    w_psi = 2.0 * wt * sin_b * dratio / half_cos
    psi, wf = (
        np.concatenate(pair)
        for pair in zip(
            _gauss(_CIRCLE_MAPPED_ANGLE, math.pi, _CIRCLE_ORDER),
            _gauss(math.pi, 2.0 * math.pi - _CIRCLE_MAPPED_ANGLE, _CIRCLE_ORDER),
            strict=True,
        )
    )
    count = len(dist)
    rows = np.concatenate([rows, np.repeat(np.arange(count), len(psi))])
    half_sin = np.concatenate([half_sin, np.tile(np.sin(0.5 * psi), count)])
    half_cos = np.concatenate([half_cos, np.tile(np.cos(0.5 * psi), count)])
    w_psi = np.concatenate([w_psi, np.tile(wf, count)])
    ur, gr, rr = u[rows], gap[rows], radius[rows]
    radial = gr - 2.0 * half_sin**2  # cos ψ - u
    tangential = 2.0 * half_sin * half_cos  # sin ψ
    scaled_rho = np.sqrt(gr * gr + 4.0 * ur * half_sin**2)  # ρ / R
    points = rr[:, None] * (
        (1.0 - 2.0 * half_sin**2)[:, None] * unit[rows] + tangential[:, None] * perp[rows]
    )
    rel = radial[:, None] * unit[rows] + tangential[:, None] * perp[rows]
    return rows, points, rr * w_psi, rr * scaled_rho, rel / scaled_rho[:, None]


def _ray_nodes(rays: _Rays, centers: np.ndarray, rule: tuple[np.ndarray, np.ndarray]):
    """Nodes ``(rows, x, dA, ρ, ê)`` of ``rule`` on ``[0, 1]`` mapped along every ray."""
    s, ws = rule
    length = rays.end - rays.start
    rho = rays.start[:, None] + length[:, None] * s
    area = rho * (length * rays.angle_weight)[:, None] * ws
    points = centers[rays.rows][:, None, :] + rho[..., None] * rays.direction[:, None, :]
    count = len(s)
    return (
        np.repeat(rays.rows, count),
        points.reshape(-1, 2),
        area.ravel(),
        rho.ravel(),
        np.repeat(rays.direction, count, axis=0),
    )


#: Where the rules evaluate ``p`` and ``mu``, in words (for errors).
SAMPLED = (
    "where the limit surface's quadrature evaluates it: on the patch and, for a polygon, up to "
    f"{FAR_FIELD_RADII:g} patch radii around it (the rules about a centre of rotation near a "
    "polygon integrate over triangles that leave it)"
)


def _field_values(name: str, function: Field | None, points: np.ndarray) -> np.ndarray:
    """``function(x, y)`` at ``points`` ``(n, 2)`` (1 when ``None``), checked finite."""
    if function is None:
        return np.ones(len(points))
    return validation.field_values(name, function, points[:, 0], points[:, 1], SAMPLED)


@dataclass(frozen=True, slots=True)
class _Layout:
    """Kernel size [m] and the loaded regions as arrays: kind, bounding circle, weight, disk
    or circle radius, polygon edges and the fixed rule (both CSR by region; rule weights
    ``weight mu p dA / N``)."""

    size: float
    kinds: np.ndarray
    centers: np.ndarray
    reach: np.ndarray
    weights: np.ndarray
    radii: np.ndarray
    edge_offsets: np.ndarray
    starts: np.ndarray
    ends: np.ndarray
    far_offsets: np.ndarray
    far_points: np.ndarray
    far_weights: np.ndarray


def _parse_region(index: int, region: object) -> tuple[int, np.ndarray | float, float]:
    """Check one region tuple; return its kind code, geometry and weight."""
    name = f"regions[{index}]"
    if not isinstance(region, tuple | list) or len(region) != 3:
        raise InvalidArgumentError(
            f"{name} must be a tuple (kind, geometry, weight), got {region!r}"
        )
    kind = validation.choice(f"{name} kind", region[0], REGION_KINDS)
    weight = validation.finite_scalar(f"{name} weight", region[2])
    if kind == "polygon":
        vertices = validation.finite_array(f"{name} vertices", region[1], shape=(None, 2))
        return _POLYGON, simple_polygon(name, vertices), weight
    radius = validation.positive_scalar(f"{name} radius", region[1])
    return (_DISK if kind == "disk" else _CIRCLE), radius, weight


def _subdivided(triangles: np.ndarray, largest: float) -> np.ndarray:
    """Triangles ``(T, 3, 2)`` cut into ``n²`` similar pieces of diameter <= ``largest``."""
    pieces = []
    for a, b, c in triangles:
        diameter = max(np.hypot(*(b - a)), np.hypot(*(c - b)), np.hypot(*(a - c)))
        n = math.ceil(diameter / largest)
        if n <= 1:
            pieces.append(np.array([[a, b, c]]))
            continue
        i, j = np.meshgrid(np.arange(n), np.arange(n), indexing="ij")
        up = (i + j <= n - 1).ravel()
        down = (i + j <= n - 2).ravel()
        i, j = i.ravel(), j.ravel()

        def corner(di, dj, i=i, j=j, a=a, b=b, c=c, n=n):
            return a + ((i + di) / n)[:, None] * (b - a) + ((j + dj) / n)[:, None] * (c - a)

        pieces.append(np.stack([corner(0, 0), corner(1, 0), corner(0, 1)], axis=1)[up])
        pieces.append(np.stack([corner(1, 0), corner(1, 1), corner(0, 1)], axis=1)[down])
    return np.concatenate(pieces)


def _round_rule(kind: int, radius: float, with_pressure: bool):
    """Points ``(n, 2)`` [m] and area (or length) weights of the fixed rule of a disk or a
    circle of ``radius`` [m]."""
    theta = np.arange(_FAR_DISK_ANGLES if kind == _DISK else _FAR_CIRCLE_ANGLES) + 0.5
    theta *= 2.0 * np.pi / len(theta)
    ring = np.column_stack([np.cos(theta), np.sin(theta)])
    if kind == _CIRCLE:
        return radius * ring, np.full(len(theta), 2.0 * np.pi * radius / len(theta))
    if with_pressure:  # tanh-sinh in r: exact enough for edge singularities of p
        r, wr = tanh_sinh_unit(_DISK_RAY_LEVEL)
        wr = wr * r
    else:
        r, wr = gauss_jacobi_unit(_FAR_DISK_RADIAL, 0.0, 1.0)
    points = radius * (r[:, None, None] * ring[None, :, :])
    weights = np.outer(wr, np.full(len(theta), 2.0 * np.pi * radius**2 / len(theta)))
    return points.reshape(-1, 2), weights.ravel()


@dataclass(frozen=True, slots=True)
class FunctionKernel(SupportKernel):
    """Unit-friction-normalised support function of ``mu p`` on a union of regions.

    ``h(V) = ∫ mu p |v| dA / ∫ p dA`` and its gradient, accurate to about ``1e-12`` (relative)
    for any twist, including centres of rotation on or next to the patch edges (see the module
    docstring for the method).

    Parameters
    ----------
    regions : tuple
        Regions in the local frame [m], each ``("polygon", vertices, weight)`` (vertices
        ``(n, 2)`` of a simple polygon), ``("disk", radius, weight)`` or
        ``("circle", radius, weight)`` (a line density on the circle, ``dA`` replaced by arc
        length); disks and circles are centred at the origin. ``weight`` multiplies
        ``p`` on that region, e.g. the measured pressure of a tactile cell; it may be negative (an
        annulus is a disk minus a smaller disk).
    pressure : callable or None
        ``p(x, y)`` for arrays ``x, y`` [m] of equal shape, smooth, >= 0 on the patch; ``None``
        for ``p = 1``. On polygons it is also evaluated (and must be smooth) on the triangles
        joining a nearby centre of rotation to the polygon; disks are only sampled inside.
    friction : callable or None
        ``mu(x, y)`` [-], smooth and >= 0, with the same conventions; ``None`` for ``mu = 1``.

    Attributes
    ----------
    normal_force : float
        ``∫ weight p dA`` over all regions (the normal force [N] when ``p`` is in Pa and the
        weights are 1), the normalisation of ``h``.
    """

    regions: tuple
    pressure: Field | None = None
    friction: Field | None = None
    normal_force: float = field(init=False)
    _layout: _Layout = field(init=False, repr=False)
    _far: PointSetKernel = field(init=False, repr=False)

    def __post_init__(self):
        object.__setattr__(self, "regions", tuple(self.regions))
        if self.pressure is not None:
            validation.callable_argument("pressure", self.pressure)
        if self.friction is not None:
            validation.callable_argument("friction", self.friction)
        parsed = [_parse_region(i, region) for i, region in enumerate(self.regions)]
        if not parsed:
            raise InvalidArgumentError("regions must hold at least one region")
        size = max(
            float(np.max(np.hypot(*geometry.T))) if kind == _POLYGON else geometry
            for kind, geometry, _ in parsed
        )
        parsed = [region for region in parsed if region[2] != 0.0]
        if not parsed:
            raise InvalidArgumentError("every region has weight 0: the patch carries no load")
        kinds = np.array([kind for kind, _, _ in parsed])
        weights = np.array([weight for _, _, weight in parsed])
        centers = np.zeros((len(parsed), 2))
        reach = np.zeros(len(parsed))
        radii = np.zeros(len(parsed))
        edges, rules, triangles = [], [], []
        for i, (kind, geometry, _) in enumerate(parsed):
            if kind == _POLYGON:
                centers[i] = 0.5 * (geometry.min(axis=0) + geometry.max(axis=0))
                reach[i] = np.max(np.hypot(*(geometry - centers[i]).T))
                edges.append(geometry)
                triangles.append(_subdivided(triangulate(geometry), _FAR_PIECE * size))
                rules.append(None)
            else:
                reach[i] = radii[i] = geometry
                edges.append(np.empty((0, 2)))
                rules.append(_round_rule(kind, geometry, self.pressure is not None))
        if triangles:  # one triangle rule for all polygons, split back by region
            points, area = triangle_rule(np.concatenate(triangles), _FAR_TRIANGLE_ORDER)
            cuts = np.cumsum([len(t) * _FAR_TRIANGLE_ORDER**2 for t in triangles])[:-1]
            polygon_rules = iter(zip(np.split(points, cuts), np.split(area, cuts), strict=True))
            rules = [next(polygon_rules) if rule is None else rule for rule in rules]
        edge_offsets = np.concatenate([[0], np.cumsum([len(v) for v in edges])])
        starts = np.concatenate(edges)
        ends = np.concatenate([np.roll(v, -1, axis=0) for v in edges])
        far_offsets = np.concatenate([[0], np.cumsum([len(r[1]) for r in rules])])
        points = np.concatenate([r[0] for r in rules])
        measure = np.concatenate([r[1] for r in rules]) * np.repeat(weights, np.diff(far_offsets))
        pressure = _field_values("p", self.pressure, points)
        friction = _field_values("mu", self.friction, points)
        if np.any(pressure < 0.0) or np.any(friction < 0.0):
            raise InvalidArgumentError("pressure and friction must be >= 0 on the patch")
        normal_force = float(measure @ pressure)
        if not normal_force > 0.0:
            raise InvalidArgumentError("the pressure integrates to zero: the patch carries no load")
        far_weights = measure * pressure * friction / normal_force
        layout = _Layout(
            size,
            kinds,
            centers,
            reach,
            weights,
            radii,
            edge_offsets,
            starts,
            ends,
            far_offsets,
            points,
            far_weights,
        )
        object.__setattr__(self, "normal_force", normal_force)
        object.__setattr__(self, "_layout", layout)
        object.__setattr__(self, "_far", PointSetKernel(points, far_weights))

    @property
    def size(self) -> float:
        return self._layout.size

    def evaluate(self, twists):
        return self._terms(twists, with_hessian=False)[:2]

    def newton_terms(self, twists):
        return self._terms(twists, with_hessian=True)

    def hessian(self, twists):
        return self._terms(twists, with_hessian=True)[2]

    def _terms(self, twists, with_hessian: bool):
        """Support values ``(K,)``, loads ``(K, 3)`` and, ``with_hessian``, Hessians
        ``(K, 3, 3)`` (else ``None``) by the same rules: the Hessian of ``|v|`` is
        ``Aᵀ (I - v̂ v̂ᵀ) A / |v|`` (``A = [[1, 0, -y], [0, 1, x]]``, ``v = A V``)."""
        twists = np.ascontiguousarray(twists, dtype=float)
        near = self._near(twists)
        h = np.zeros(len(twists))
        loads = np.zeros((len(twists), 3))
        hess = np.zeros((len(twists), 3, 3)) if with_hessian else None
        mixed = ~np.all(near, axis=1)  # twists for which the compiled fixed rule is summed
        if np.any(mixed):
            if with_hessian:
                h[mixed], loads[mixed], hess[mixed] = self._far.newton_terms(twists[mixed])
            else:
                h[mixed], loads[mixed] = self._far.evaluate(twists[mixed])
        pair_twist, pair_region = np.nonzero(near)
        for chunk in self._chunks(pair_region):
            dh, dloads, dhess = self._near_correction(
                twists, pair_twist[chunk], pair_region[chunk], mixed[pair_twist[chunk]],
                with_hessian,
            )  # fmt: skip
            h += dh
            loads += dloads
            if with_hessian:
                hess += dhess
        return h, loads, hess

    def rule_disagreement(self) -> float:
        """Largest difference of ``h`` between the polar rule about a centre of rotation near a
        region and the fixed rule there, relative to the largest ``h`` of the centres tried
        (``_PROBE_FRACTIONS`` of the near range of ``FAR_FIELD_RADII`` reaches, where both rules
        are accurate for smooth fields): about 1e-14 then; of the order of the error of both
        where ``p`` or ``mu`` jumps, has a kink or a peak the rules do not resolve."""
        lay = self._layout
        count = len(lay.kinds)
        regions = np.unique(np.linspace(0, count - 1, min(count, _PROBED_REGIONS)).astype(int))
        angles = 2.0 * np.pi * np.arange(_PROBE_DIRECTIONS) / _PROBE_DIRECTIONS
        ring = np.column_stack([np.cos(angles), np.sin(angles)])
        distance = FAR_FIELD_RADII * np.outer(lay.reach[regions], _PROBE_FRACTIONS)
        centers = lay.centers[regions, None, None, :] + distance[..., None, None] * ring
        centers = centers.reshape(-1, 2)
        twists = np.column_stack([centers[:, 1], -centers[:, 0], np.ones(len(centers))])
        pair_region = np.repeat(regions, len(centers) // len(regions))
        pair_twist = np.arange(len(centers))
        difference = self._near_correction(
            twists, pair_twist, pair_region, np.ones(len(centers), dtype=bool), False
        )[0]
        power = float(np.max(self._far.evaluate(twists)[0]))  # (0: no friction anywhere)
        return float(np.max(np.abs(difference))) / power if power > 0.0 else 0.0

    def _near(self, twists: np.ndarray) -> np.ndarray:
        """Whether the centre of rotation of each twist is near each region ``(K, J)``."""
        lay = self._layout
        vx, vy, w = twists[:, 0, None], twists[:, 1, None], twists[:, 2, None]
        speed = np.hypot(vx - w * lay.centers[:, 1], vy + w * lay.centers[:, 0])
        return speed < np.abs(w) * FAR_FIELD_RADII * lay.reach

    def _node_bound(self, regions: np.ndarray) -> np.ndarray:
        """Upper bound of the quadrature nodes of the near rule of ``regions``."""
        lay = self._layout
        tau = (2 * len(_PANEL_OFFSETS) + 2) * _PANEL_ORDER
        edges = np.diff(lay.edge_offsets)[regions]
        disk = 2 * (tau + _DISK_SIDE_ORDER) * len(tanh_sinh_unit(_DISK_RAY_LEVEL)[0])
        bound = np.where(lay.kinds[regions] == _DISK, disk, tau + 2 * _CIRCLE_ORDER)
        return np.where(lay.kinds[regions] == _POLYGON, edges * tau * _POLYGON_RAY_ORDER, bound)

    def _chunks(self, regions: np.ndarray) -> list[slice]:
        """Consecutive slices of the pairs with at most ``_NODE_BUDGET`` nodes (or one pair)."""
        total = np.cumsum(self._node_bound(regions))
        chunks, start = [], 0
        while start < len(regions):
            base = total[start - 1] if start else 0
            stop = max(int(np.searchsorted(total, base + _NODE_BUDGET, side="right")), start + 1)
            chunks.append(slice(start, stop))
            start = stop
        return chunks

    def _ray_rules(self) -> tuple[tuple[np.ndarray, np.ndarray], tuple[np.ndarray, np.ndarray]]:
        """Rules on ``[0, 1]`` along the rays of polygons and of disks."""
        smooth = gauss_jacobi_unit(_POLYGON_RAY_ORDER)
        constant = gauss_jacobi_unit(_CONSTANT_RAY_ORDER)
        polygon = smooth if self.pressure is not None or self.friction is not None else constant
        if self.pressure is not None:
            return polygon, tanh_sinh_unit(_DISK_RAY_LEVEL)
        return polygon, polygon

    def _near_nodes(self, centers: np.ndarray, regions: np.ndarray):
        """Nodes ``(pair, x, dA, ρ, ê)`` of the polar rules about ``centers`` of the pairs."""
        lay = self._layout
        polygon_rule, disk_rule = self._ray_rules()
        parts = []
        pairs = np.flatnonzero(lay.kinds[regions] == _POLYGON)
        if pairs.size:
            first = lay.edge_offsets[regions[pairs]]
            counts = lay.edge_offsets[regions[pairs] + 1] - first
            owner = np.repeat(pairs, counts)
            edge = np.repeat(first - np.cumsum(counts) + counts, counts) + np.arange(counts.sum())
            rays = _polygon_rays(lay.starts[edge], lay.ends[edge], centers[owner]).relabel(owner)
            parts.append(_ray_nodes(rays, centers, polygon_rule))
        pairs = np.flatnonzero(lay.kinds[regions] == _DISK)
        if pairs.size:
            radius = lay.radii[regions[pairs]]
            dist = np.hypot(centers[pairs, 0], centers[pairs, 1])
            inside = (radius - dist) * (radius + dist) > (_RIM_GAP * radius) ** 2
            for build, sel in ((_disk_inside_rays, inside), (_disk_outside_rays, ~inside)):
                if np.any(sel):
                    rays = build(radius[sel], centers[pairs[sel]]).relabel(pairs[sel])
                    parts.append(_ray_nodes(rays, centers, disk_rule))
        pairs = np.flatnonzero(lay.kinds[regions] == _CIRCLE)
        if pairs.size:
            rows, *rest = _circle_nodes(lay.radii[regions[pairs]], centers[pairs])
            parts.append((pairs[rows], *rest))
        return [np.concatenate(arrays) for arrays in zip(*parts, strict=True)]

    def _near_correction(self, twists, pair_twist, pair_region, summed, with_hessian):
        """Change of ``h`` ``(K,)``, loads ``(K, 3)`` and, ``with_hessian``, Hessians
        ``(K, 3, 3)`` (else ``None``): polar rules replace the fixed rule on the near pairs
        (whose fixed rule was ``summed`` or not).

        On a ray ``x = c + ρ ê`` from the centre of rotation ``v̂ = ±J ê``, so ``I - v̂ v̂ᵀ = ê êᵀ``,
        and ``Aᵀ ê = (ê, x × ê)`` is the same all along it: a node of weight ``dA`` adds
        ``dA / (|w| ρ) (Aᵀ ê)(Aᵀ ê)ᵀ`` to the Hessian (``dA`` holds a factor ``ρ``, or the
        rules' sinh maps absorb ``1/ρ``, as they do ``ρ`` for ``h``)."""
        lay = self._layout
        vx, vy, w = twists[pair_twist].T
        centers = np.column_stack([-vy / w, vx / w])
        pair, points, area, rho, unit = self._near_nodes(centers, pair_region)
        values = (
            _field_values("p", self.pressure, points)
            * _field_values("mu", self.friction, points)
            * area
            * (lay.weights[pair_region] / self.normal_force)[pair]
        )
        count = len(pair_twist)
        spin = np.abs(w)
        sign = np.sign(w)
        h = spin * np.bincount(pair, values * rho, count)
        force_x = -sign * np.bincount(pair, values * unit[:, 1], count)
        force_y = sign * np.bincount(pair, values * unit[:, 0], count)
        arm = np.einsum("ij,ij->i", points, unit)
        moment = sign * np.bincount(pair, values * arm, count)
        loads = np.column_stack([force_x, force_y, moment])
        hess = None
        if with_hessian:
            along = np.column_stack([unit, points[:, 0] * unit[:, 1] - points[:, 1] * unit[:, 0]])
            hess = _outer_sums(pair, values / (spin[pair] * rho), along, count)
        if np.any(summed):
            far_h, far_loads, far_hess = self._fixed_part(
                twists, pair_twist[summed], pair_region[summed], with_hessian
            )
            h[summed] -= far_h
            loads[summed] -= far_loads
            if with_hessian:
                hess[summed] -= far_hess
        size = len(twists)
        delta = np.column_stack([np.bincount(pair_twist, part, size) for part in loads.T])
        if with_hessian:
            flat = hess.reshape(count, 9)
            hess = np.column_stack([np.bincount(pair_twist, part, size) for part in flat.T])
            hess = hess.reshape(size, 3, 3)
        return np.bincount(pair_twist, h, size), delta, hess

    def _fixed_part(self, twists, pair_twist, pair_region, with_hessian):
        """The fixed rule's ``h``, loads and (``with_hessian``, else ``None``) Hessians of each
        pair (what the compiled sum included)."""
        lay = self._layout
        first = lay.far_offsets[pair_region]
        counts = lay.far_offsets[pair_region + 1] - first
        pair = np.repeat(np.arange(len(pair_region)), counts)
        index = np.repeat(first - np.cumsum(counts) + counts, counts) + np.arange(counts.sum())
        x, y = lay.far_points[index, 0], lay.far_points[index, 1]
        weight = lay.far_weights[index]
        vx, vy, w = twists[pair_twist[pair]].T
        ux, uy = vx - w * y, vy + w * x
        speed = np.hypot(ux, uy)
        moving = speed > 0.0
        scale = np.where(moving, weight / np.where(moving, speed, 1.0), 0.0)
        count = len(pair_region)
        h = np.bincount(pair, weight * speed, count)
        loads = np.column_stack(
            [
                np.bincount(pair, scale * ux, count),
                np.bincount(pair, scale * uy, count),
                np.bincount(pair, scale * (x * uy - y * ux), count),
            ]
        )
        hess = None
        if with_hessian:  # I - ûûᵀ = n nᵀ with n = J û: Aᵀ n = (-uy, ux, x ux + y uy) / |u|
            across = np.column_stack([-uy, ux, x * ux + y * uy])
            squared = np.where(moving, speed, 1.0) ** 2
            hess = _outer_sums(pair, scale / squared, across, count)
        return h, loads, hess


def _outer_sums(groups: np.ndarray, weights: np.ndarray, vectors: np.ndarray, count: int):
    """``(count, 3, 3)``: the sums of ``weights[i] * vectors[i] vectors[i]ᵀ`` by ``groups``."""
    out = np.empty((count, 3, 3))
    for i in range(3):
        for j in range(i, 3):
            out[:, i, j] = out[:, j, i] = np.bincount(
                groups, weights * vectors[:, i] * vectors[:, j], count
            )
    return out
