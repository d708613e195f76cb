r"""The exact limit surface as a friction model: the engine's own set, stated by tangent planes.

The limit set of a contact at normal force ``N`` is, by definition,

.. math:: \{L : L \cdot V \le N\, h_1(V) \ \text{for all twists } V\},

with ``h_1`` the support function at unit normal force. The numeric methods (containment,
safety factor, motion) ask the exact engine (:class:`~fixplan.LimitSurface`) directly, so they
are exact to its accuracy (about 1e-13 for the closed-form fields, facets of point supports
included). As convex constraints the set is an intersection of infinitely many halfspaces, so
the model states a finite subset of them: the tangent planes at ``SEED_PLANES`` evenly spread
twists (:meth:`Exact.conic_form`, an outer polytope, homogeneous in ``N``), and :meth:`Exact.cut`
gives the tangent plane at the ray of any load, the cut that removes that load when it lies
outside. :meth:`Exact.osculating` gives the ellipsoid with the set's point, tangent plane and
curvature on the ray of any load. The planner moves such ellipsoids
(:mod:`fixplan.planner.osculating`) or adds such cuts (:mod:`fixplan.planner.cuts`) until every
contact load lies inside its exact surface at the exact optimum; used on its own,
:meth:`constraints` states the seed polytope only, which holds the exact set
(:attr:`Exact.constraint_error` says by how much), but on a few point supports alone, whose set
it states exactly, a cone per point (:attr:`Exact.stated_exactly`).

A frictionless contact keeps the shape of its patch (:attr:`LimitSurface.friction_shape`):
its set is the load 0 and its motion the limit ``mu → 0+`` (:mod:`fixplan.models.base`).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import TYPE_CHECKING, ClassVar

import numpy as np

from fixplan.models.base import FrictionModel, fmt
from fixplan.models.conic import unit_conic
from fixplan.models.ellipsoid import surface_units
from fixplan.surface.point_kernel import compiled_scalar
from fixplan.surface.sphere import fibonacci_sphere
from fixplan.tolerances import STATED_SET_MARGIN

if TYPE_CHECKING:  # pragma: no cover
    from fixplan.surface.limit_surface import LimitSurface

#: Tangent planes of the seed polytope (mirror pairs of a Fibonacci lattice of twists in
#: normalised coordinates). More planes: fewer cutting rounds in the planner, larger problems.
SEED_PLANES = 24

#: Point supports up to this many are stated exactly, a cone per point
#: (:attr:`Exact.stated_exactly`); more take the seed polytope and the planner's cuts: each point
#: adds a cone and two variables per contact and load case. On the fixture of
#: benchmarks/bench_planner.py (8 contacts x 20 milling loads; benchmarks/bench_exact.py) a
#: re-solve stated exactly took 15, 33 and 233 ms on 3, 9 and 64 points per pad against 400, 390
#: and 376 ms by the cuts, on 256 points 1,090 ms against 374 ms.
MAX_STATED_POINTS = 64

#: Point supports are the whole surface where their friction is its largest force to this
#: fraction (a pure translation moves every point alike).
WHOLE_FRICTION_RTOL = 1e-12


@dataclass(frozen=True, slots=True, kw_only=True, repr=False, eq=False)
class Exact(FrictionModel):
    """The exact limit surface of a contact, as a friction model.

    Attributes
    ----------
    surface : LimitSurface
        The contact's exact limit surface; its normal force is the model's default
        ``normal_force`` [N]. Moments are about its frame origin.
    """

    surface: LimitSurface
    _seed: np.ndarray = dataclasses.field(init=False)
    _unit_scale: np.ndarray = dataclasses.field(init=False)  # (see _units)
    _points: tuple | None = dataclasses.field(init=False)  # (see stated_exactly)

    conservative: ClassVar[bool] = True

    def __post_init__(self):
        surface_units(self.surface)  # checks the type
        units = FrictionModel._units(self)
        units.setflags(write=False)
        object.__setattr__(self, "_unit_scale", units)
        directions = fibonacci_sphere(SEED_PLANES)[: SEED_PLANES // 2]
        shape = self.surface.friction_shape
        # A twist d in normalised coordinates is the load-space twist d / units; its plane is
        # d · q <= h_1(d / units) N.
        support = shape.support(directions / self._units()) / self.surface.normal_force
        seed = np.vstack([directions, -directions]) / np.concatenate([support, support])[:, None]
        seed.setflags(write=False)
        object.__setattr__(self, "_seed", seed)
        object.__setattr__(self, "_points", _whole_point_supports(self.surface))

    def _units(self) -> np.ndarray:
        """:meth:`FrictionModel._units`, computed once (read-only): the planner's rounds ask
        for them at every query."""
        return self._unit_scale

    @classmethod
    def from_limit_surface(cls, ls: LimitSurface) -> Exact:
        """The exact model of ``ls`` (constant or position-dependent ``mu``, combined surfaces,
        frictionless surfaces)."""
        return cls(surface=ls)

    @property
    def mu(self) -> float:
        """Largest friction force per unit normal force [-] (0 when frictionless)."""
        return self.surface.max_force / self.surface.normal_force

    @property
    def normal_force(self) -> float:
        """Default normal force of the numeric methods [N]: that of :attr:`surface`."""
        return self.surface.normal_force

    @property
    def rho(self) -> float:
        return self.surface.characteristic_length

    @property
    def _shape_mu(self) -> float:
        shape = self.surface.friction_shape
        return shape.max_force / shape.normal_force

    def _with_shape_friction(self) -> Exact:
        return Exact(surface=self.surface.friction_shape)

    @property
    def stated_exactly(self) -> bool:
        r"""Whether :meth:`constraints` state the exact set: a surface of at most
        ``MAX_STATED_POINTS`` point supports alone (or none with friction), whose set at normal
        force ``N`` is the sum of the points' friction disks (paper §4.4), a cone per point:
        ``ℓ = Σ_i (f_i, x_i f_{i,y} - y_i f_{i,x})`` with ``|f_i| <= c_i N`` (``c_i`` the
        point's friction per unit normal force), shrunk by ``STATED_SET_MARGIN`` (1e-8) so that
        a solver's loads lie inside it. Otherwise they state the seed polytope, which holds it."""
        return self.frictionless or self._points is not None

    @property
    def constraint_error(self) -> float:
        """Largest relative radial gap of the set :meth:`constraints` state to the exact surface
        [-]: 0 where :attr:`stated_exactly`, else the seed polytope's, read at its vertices (the
        polytope holds the surface)."""
        if self.stated_exactly:
            return 0.0
        from scipy.spatial import ConvexHull

        hull = ConvexHull(self._seed)
        vertices = hull.equations[:, :3] / -hull.equations[:, 3:]
        return float(np.max(self.friction_shape._gauge(vertices)) - 1.0)

    def cut(
        self, loads: np.ndarray, start: np.ndarray | None = None
    ) -> tuple[np.ndarray, np.ndarray]:
        r"""The tangent plane of the exact set at the ray of each load, and the loads' excess.

        Parameters
        ----------
        loads : numpy.ndarray
            ``(K, 3)`` loads ``(fx, fy, m)`` per unit normal force [-, -, m], nonzero and
            finite (not checked: the planner's loads, many times per solve).
        start : numpy.ndarray, optional
            ``(K, 3)`` guesses of the loads' sliding twists (any size) for the inverse map to
            start from.

        Returns
        -------
        planes : numpy.ndarray
            ``(K, 3)`` rows ``a`` [-, -, 1/m] with the plane :math:`a \cdot L \le N` for loads
            ``L`` [N, N, N m] at normal force ``N`` [N]:
            ``a = V / h_1(V)`` for the sliding twist ``V`` of the load (a facet's own plane
            for a load beyond a facet of point supports).
        excess : numpy.ndarray
            ``(K,)`` ``1 / s - 1`` for the exact safety factor ``s`` of each load at unit
            normal force: positive outside the set.

        Notes
        -----
        ``s L`` is the surface point whose normal is ``V``, so ``h_1(V) = s L · V``: the
        support is read from the inverse map's answer instead of being integrated again
        (relative difference about 1e-14, far below the planner's ``CUT_MARGIN``).
        """
        safety, twists = self.surface._trusted_inverse(loads * self.surface.normal_force, start)
        support = safety * np.einsum("ij,ij->i", loads, twists)
        return twists / support[:, None], 1.0 / safety - 1.0

    def osculating(
        self, loads: np.ndarray, start: np.ndarray | None = None
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        r"""The ellipsoid that osculates the exact set where the ray of each load meets it.

        Parameters
        ----------
        loads : numpy.ndarray
            ``(K, 3)`` loads ``(fx, fy, m)`` per unit normal force [-, -, m], nonzero and
            finite (not checked).
        start : numpy.ndarray, optional
            ``(K, 3)`` guesses of the loads' sliding twists, as for :meth:`cut`.

        Returns
        -------
        excess : numpy.ndarray
            ``(K,)`` ``1 / s - 1`` for the exact safety factor ``s`` of each load.
        points : numpy.ndarray
            ``(K, 3)`` the surface points ``u = s q`` on the loads' rays.
        factors : numpy.ndarray
            ``(K, 3, 3)`` upper triangular ``R`` [-, -, 1/m]: the ellipsoid
            :math:`\lVert R L \rVert \le N` has the exact surface's point ``u``, tangent plane
            and curvature there (non-finite where the surface has no curvature: at a facet).

        Notes
        -----
        With ``a = V / h_1(V)`` the tangent plane at ``u`` (``V`` its sliding twist) and
        ``J = ∇²h_1(a)`` (``J a = 0``), the gauge ``g`` of the set (``g(u) = 1``, ``∇g(u) = a``)
        has the Hessian ``∇²g(u) = (I - a uᵀ) J⁺ (I - u aᵀ)``: differentiate ``∇g(∇h_1(V)) =
        V / h_1(V)``. The ellipsoid's gauge ``√(qᵀ Q q)`` with ``Q = ∇²g(u) + a aᵀ = RᵀR`` has
        the same value, gradient and Hessian at ``u``. The algebra runs in normalised
        coordinates (loads over :meth:`_units`), where ``J`` is well conditioned.
        """
        scaled = loads * self.surface.normal_force
        safety, twists, hessians = self.surface._trusted_inverse_and_hessians(scaled, start)
        excess, points = np.empty(len(loads)), np.empty((len(loads), 3))
        factors = np.empty((len(loads), 3, 3))
        _RAY_OSCULATION(loads, safety, twists, hessians, self.surface.normal_force,
                        self._units(), excess, points, factors)  # fmt: skip
        return excess, points, factors

    def osculating_at(self, twists: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The ellipsoid that osculates the exact set at its point with the normal ``V``.

        Parameters
        ----------
        twists : numpy.ndarray
            ``(K, 3)`` nonzero load-space twists ``V`` [m/s, m/s, rad/s] (not checked).

        Returns
        -------
        points : numpy.ndarray
            ``(K, 3)`` the surface points ``u = ∇h_1(V)`` [-, -, m] (the forward map: no
            Newton iterations, unlike :meth:`osculating`).
        factors : numpy.ndarray
            ``(K, 3, 3)`` as :meth:`osculating` gives them at ``u``.
        """
        force = self.surface.normal_force
        points = self.surface.load(twists) / force
        support = np.einsum("kc,kc->k", points, twists)  # h_1(V) = ∇h_1(V) · V
        curvature = self.surface._trusted_hessians(twists) * (support / force)[:, None, None]
        return points, self._osculating_factors(twists / support[:, None], points, curvature)

    def _osculating_factors(self, planes, points, curvature) -> np.ndarray:
        """Factors ``(K, 3, 3)`` of the ellipsoids with the tangent ``planes`` at ``points``
        ``(K, 3)`` and the support Hessians ``curvature`` ``(K, 3, 3)`` at the planes."""
        factors = np.empty((len(points), 3, 3))
        _OSCULATING_FACTORS(planes, points, curvature, self._units(), factors)
        return factors

    def planes(self, twists: np.ndarray) -> np.ndarray:
        r"""Tangent planes :math:`a \cdot L \le N`, ``a = V / h_1(V)``, of the exact set at the
        nonzero twists ``V`` ``(K, 3)``; ``a`` ``(K, 3)``."""
        support = np.atleast_1d(self.surface.support(twists)) / self.surface.normal_force
        return twists / support[:, None]

    def _loads(self, q):
        """Loads at the surface's normal force along the normalised loads ``q``."""
        return q * self._units() * self.surface.normal_force

    def _gauge(self, q):
        return 1.0 / np.atleast_1d(self.surface.safety_factor(self._loads(q)))

    def _normal(self, q):
        twists = np.atleast_2d(self.surface.friction_shape.motion(self._loads(q)))
        return twists * self._units()

    def _unit_conic(self):
        if self._points is not None:
            return self._point_supports_conic()
        count = len(self._seed)
        return unit_conic(np.ones(count), -self._seed, cones=[("nonneg", count)])

    def _point_supports_conic(self):
        """The exact set of point supports (:attr:`stated_exactly`) in normalised coordinates:
        three rows ``ℓ(q) - Σ_i A_i f_i = 0``, then a cone ``(c_i N, f_i)`` per point, the
        forces ``f_i`` [N] the auxiliary variables."""
        (x, y), per_force = self._points
        count = len(per_force)
        normal = np.zeros(3 + 3 * count)
        load = np.zeros((3 + 3 * count, 3))
        aux = np.zeros((3 + 3 * count, 2 * count))
        load[:3] = np.linalg.inv(self._normalising_map())  # (the rows take the load ℓ)
        aux[0, 0::2], aux[1, 1::2] = -1.0, -1.0
        aux[2, 0::2], aux[2, 1::2] = y, -x
        first = 3 + 3 * np.arange(count)
        normal[first] = per_force / (1.0 + STATED_SET_MARGIN)
        aux[first + 1, 0::2] = np.eye(count)
        aux[first + 2, 1::2] = np.eye(count)
        return unit_conic(normal, load, aux, cones=[("zero", 3)] + [("soc", 3)] * count)

    def __repr__(self) -> str:
        return (
            f"Exact({self.surface!r}, mu={fmt(self.mu)}, rho={fmt(self.rho)} m, "
            f"normal_force={fmt(self.normal_force)} N)"
        )


def osculating_factor(a, u, curvature, units, r):  # pragma: no cover - compiled
    """Upper triangular ``r`` ``(3, 3)`` with ``RᵀR = (I - a uᵀ) J⁺ (I - u aᵀ) + a aᵀ`` in
    normalised coordinates (loads over ``units``; ``r`` then back in load units) for the plane
    ``a``, point ``u`` and support Hessian ``J`` = ``curvature`` at ``a`` (``J a = 0``), all in
    load units, from ``J⁺ = (J + â âᵀ)⁻¹ - â âᵀ``; NaN where that matrix is not positive
    definite."""
    a = a * units
    u = u / units
    size = np.sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2])
    m = np.empty((3, 3))
    for i in range(3):
        for j in range(3):
            m[i, j] = curvature[i, j] / (units[i] * units[j]) + a[i] * a[j] / (size * size)
    cof = np.empty((3, 3))
    cof[0, 0] = m[1, 1] * m[2, 2] - m[1, 2] * m[2, 1]
    cof[0, 1] = m[0, 2] * m[2, 1] - m[0, 1] * m[2, 2]
    cof[0, 2] = m[0, 1] * m[1, 2] - m[0, 2] * m[1, 1]
    cof[1, 0] = m[1, 2] * m[2, 0] - m[1, 0] * m[2, 2]
    cof[1, 1] = m[0, 0] * m[2, 2] - m[0, 2] * m[2, 0]
    cof[1, 2] = m[0, 2] * m[1, 0] - m[0, 0] * m[1, 2]
    cof[2, 0] = m[1, 0] * m[2, 1] - m[1, 1] * m[2, 0]
    cof[2, 1] = m[0, 1] * m[2, 0] - m[0, 0] * m[2, 1]
    cof[2, 2] = m[0, 0] * m[1, 1] - m[0, 1] * m[1, 0]
    det = m[0, 0] * cof[0, 0] + m[0, 1] * cof[1, 0] + m[0, 2] * cof[2, 0]
    pinv = np.empty((3, 3))
    for i in range(3):
        for j in range(3):
            pinv[i, j] = cof[i, j] / det - a[i] * a[j] / (size * size)
    away = np.empty((3, 3))  # I - a uᵀ
    for i in range(3):
        for j in range(3):
            away[i, j] = (1.0 if i == j else 0.0) - a[i] * u[j]
    shape = np.empty((3, 3))
    for i in range(3):
        for j in range(3):
            total = a[i] * a[j]
            for p in range(3):
                for q in range(3):
                    total += away[i, p] * pinv[p, q] * away[j, q]
            shape[i, j] = total
    r[:] = 0.0
    r[0, 0] = np.sqrt(shape[0, 0]) if shape[0, 0] > 0.0 else np.nan
    r[0, 1] = 0.5 * (shape[0, 1] + shape[1, 0]) / r[0, 0]
    r[0, 2] = 0.5 * (shape[0, 2] + shape[2, 0]) / r[0, 0]
    rest = shape[1, 1] - r[0, 1] * r[0, 1]
    r[1, 1] = np.sqrt(rest) if rest > 0.0 else np.nan
    r[1, 2] = (0.5 * (shape[1, 2] + shape[2, 1]) - r[0, 1] * r[0, 2]) / r[1, 1]
    rest = shape[2, 2] - r[0, 2] * r[0, 2] - r[1, 2] * r[1, 2]
    r[2, 2] = np.sqrt(rest) if rest > 0.0 else np.nan
    for column in range(3):
        for row in range(column + 1):
            r[row, column] /= units[column]


def osculating_factors(planes, points, curvatures, units, out):  # pragma: no cover - compiled
    """:func:`osculating_factor` of each plane ``(K, 3)``, point ``(K, 3)`` and Hessian
    ``(K, 3, 3)`` into ``out`` ``(K, 3, 3)``."""
    for k in range(planes.shape[0]):
        _OSCULATING_FACTOR(planes[k], points[k], curvatures[k], units, out[k])


def ray_osculation(
    loads, safety, twists, hessians, normal_force, units, excess, points, factors
):  # pragma: no cover - compiled
    """:meth:`Exact.osculating` from the inverse map's answers for ``loads`` ``(K, 3)`` per unit
    normal force at ``normal_force`` [N]: the safety factors ``s``, sliding twists ``V`` and
    Hessians of the support ``h`` at ``V``. The surface point is ``s q``, the plane ``a = V /
    h_1(V)`` with ``h_1(V) = s q · V`` (read from the answer rather than integrated again), and
    the Hessian of ``h_1`` at ``a`` is ``h_1(V) ∇²h(V) / N`` (``h_1`` is homogeneous of degree
    1)."""
    plane = np.empty(3)
    curvature = np.empty((3, 3))
    for k in range(loads.shape[0]):
        support = safety[k] * (
            loads[k, 0] * twists[k, 0] + loads[k, 1] * twists[k, 1] + loads[k, 2] * twists[k, 2]
        )
        excess[k] = 1.0 / safety[k] - 1.0
        for i in range(3):
            plane[i] = twists[k, i] / support
            points[k, i] = loads[k, i] / (1.0 + excess[k])
            for j in range(3):
                curvature[i, j] = hessians[k, i, j] * (support / normal_force)
        _OSCULATING_FACTOR(plane, points[k], curvature, units, factors[k])


_OSCULATING_FACTOR = compiled_scalar(osculating_factor, inline=True)


_OSCULATING_FACTORS = compiled_scalar(osculating_factors)
_RAY_OSCULATION = compiled_scalar(ray_osculation)


def _whole_point_supports(surface: LimitSurface) -> tuple | None:
    """The point supports of ``surface`` as ``((x, y), friction per unit normal force)`` where
    they are all of its friction and at most ``MAX_STATED_POINTS`` (see
    :attr:`Exact.stated_exactly`), else ``None``."""
    if surface.frictionless:
        return None
    points, friction = surface.point_supports
    whole = surface.max_force
    if not 0 < len(friction) <= MAX_STATED_POINTS:
        return None
    if abs(float(friction.sum()) - whole) > WHOLE_FRICTION_RTOL * whole:
        return None
    return (points[:, 0].copy(), points[:, 1].copy()), friction / surface.normal_force
