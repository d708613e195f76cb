r"""A general polyhedral friction model: a centrally symmetric polytope of loads.

In the normalised coordinates ``q`` of every model (:mod:`fixplan.models.base`) the set is

.. math:: |g_i \cdot q| \le 1, \qquad i = 1 \dots k,

``k`` rows ``g_i`` and their mirror images: ``2k`` halfspaces, linear inequalities like those of
:class:`~fixplan.models.Pyramid` (LP and QP solvers take them). Its gauge is
``max_i |g_i · q|``; its motion is the outward normal of the facet the load's ray leaves through.

:meth:`Polytope.from_tangent_planes` cuts a convex surface by its tangent planes and measures
the approximation exactly: the polytope of tangent planes holds the surface, and its radius
along a ray exceeds the surface's most at a vertex (the surface's gauge, being convex, is
largest on each facet at a vertex), so the largest radial gap is ``max_v g_S(v) - 1`` over the
vertices ``v``, computed from the dual convex hull, not sampled. Shrunk by that factor the
polytope lies inside the surface (inscribed). :meth:`Polytope.from_limit_surface` does this for
an exact limit surface, ``FittedQuartic.planner_model`` for a fitted quartic.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from fixplan import validation
from fixplan.errors import InvalidArgumentError
from fixplan.models.base import FrictionModel, finite_pair, fmt
from fixplan.models.ellipsoid import area_parameters, surface_units
from fixplan.models.polyhedral import _linear_conic
from fixplan.surface.sphere import fibonacci_sphere

if TYPE_CHECKING:  # pragma: no cover
    from fixplan.surface.limit_surface import LimitSurface

#: Default number of tangent planes (halfspaces) of :meth:`Polytope.from_limit_surface`.
DEFAULT_CUTS = 256

#: Rows whose smallest singular value is below this fraction of the largest do not span the
#: three load directions: the polytope would be unbounded.
_RANK_RTOL = 1e-9


def symmetric_directions(cuts: int) -> np.ndarray:
    """``cuts // 2`` unit vectors ``(cuts // 2, 3)`` whose mirror images complete an evenly
    spread, centrally symmetric set of ``cuts`` directions: the upper half (``z > 0``) of a
    Fibonacci lattice of ``cuts`` points (the lower half is its mirror image to within the
    lattice's spiral). ``cuts`` is an even integer >= 6."""
    if isinstance(cuts, bool) or not isinstance(cuts, int | np.integer) or cuts < 6 or cuts % 2:
        raise InvalidArgumentError(
            f"cuts must be an even integer >= 6 (tangent planes come in mirror pairs), got {cuts!r}"
        )
    return fibonacci_sphere(int(cuts))[: int(cuts) // 2]


@dataclass(frozen=True, slots=True, kw_only=True, repr=False, eq=False)
class Polytope(FrictionModel):
    r"""A centrally symmetric polytope ``|G q| <= 1`` (row by row) of normalised loads ``q``.

    ``q = (fx / (mu N), fy / (mu N), (m - c × f) / (mu rho N))`` with the moment about
    ``center`` ``c`` (see :mod:`fixplan.models.base`). Each row ``g_i`` of ``G`` is a facet pair
    ``±g_i · q <= 1``. The sliding motion is the outward normal ``±g_i`` of the facet through
    which the load's ray leaves the set (at an edge or a vertex: the first of the facets that
    meet there, a subgradient). As cvxpy constraints: ``2k`` linear inequalities.

    Attributes
    ----------
    rows : numpy.ndarray
        ``G`` ``(k, 3)`` [-], spanning all three directions (a bounded set).
    mu : float
        Friction per unit normal force [-] of the normalisation (0: frictionless; ``rows`` are
        then the shape at ``mu = 1``).
    rho : float
        Length [m] of the normalisation.
    center : tuple of float
        Point [m] about which the moments of ``q`` are taken.
    normal_force : float
        Default normal force of the numeric methods [N].
    error : float
        Largest relative radial gap [-] to the surface the polytope was cut from (0 when it
        stands for itself): along every ray the polytope's radius is within a factor
        ``1 + error`` of that surface's, above it unless ``inscribed``.
    inscribed : bool
        Whether the polytope lies inside the surface it was cut from (it never claims a load
        held that the surface would let slide).
    """

    rows: np.ndarray
    mu: float
    rho: float
    center: tuple[float, float] = (0.0, 0.0)
    normal_force: float = 1.0
    error: float = 0.0
    inscribed: bool = False
    _facets: np.ndarray = field(init=False)

    def __post_init__(self):
        rows = validation.finite_array("rows", self.rows, shape=(None, 3))
        singular = np.linalg.svd(rows, compute_uv=False) if len(rows) >= 3 else np.zeros(1)
        if len(rows) < 3 or singular[-1] <= _RANK_RTOL * singular[0]:
            raise InvalidArgumentError(
                f"rows must span all three directions (fx, fy, m) for a bounded polytope, got "
                f"{len(rows)} rows of rank {int(np.sum(singular > _RANK_RTOL * singular[0]))}"
            )
        rows.setflags(write=False)
        facets = np.vstack([rows, -rows])
        facets.setflags(write=False)
        object.__setattr__(self, "rows", rows)
        object.__setattr__(self, "_facets", facets)
        object.__setattr__(self, "mu", validation.nonnegative_scalar("mu", self.mu))
        object.__setattr__(self, "rho", validation.positive_scalar("rho", self.rho))
        object.__setattr__(self, "center", finite_pair("center", self.center))
        object.__setattr__(
            self, "normal_force", validation.positive_scalar("normal_force", self.normal_force)
        )
        object.__setattr__(self, "error", validation.nonnegative_scalar("error", self.error))
        object.__setattr__(self, "inscribed", bool(self.inscribed))

    @property
    def conservative(self) -> bool:  # type: ignore[override]
        """Whether the polytope is ``inscribed`` in the surface it was cut from: the exact
        limit surface for :meth:`from_limit_surface`, the fitted surface for a fit's planner
        model (which is then as conservative as the fit)."""
        return self.inscribed

    # -- constructors ---------------------------------------------------------------------------

    @classmethod
    def from_tangent_planes(
        cls,
        twists,
        loads,
        *,
        gauge: Callable[[np.ndarray], np.ndarray],
        mu: float,
        rho: float,
        center: tuple[float, float] = (0.0, 0.0),
        normal_force: float = 1.0,
        inscribed: bool = True,
    ) -> Polytope:
        r"""The tangent planes of a convex, centrally symmetric set ``S`` of loads, and their
        mirror images, with the approximation error measured at the vertices.

        Plane ``i`` is ``V_i · L <= V_i · L_i`` for the load ``L_i`` on the boundary of ``S``
        and the outward normal ``V_i`` there (a twist).

        Parameters
        ----------
        twists : array_like
            ``(k, 3)`` outward normals ``V_i`` ``(vx, vy, w)`` (any length).
        loads : array_like
            ``(k, 3)`` boundary loads ``L_i`` [N, N, N m] about the frame origin at
            ``normal_force``.
        gauge : callable
            The gauge of ``S`` (1 on its boundary, positively homogeneous) of loads ``(K, 3)``
            at ``normal_force``, e.g. ``1 / safety_factor``.
        mu, rho, center, normal_force
            As the attributes (``mu > 0``).
        inscribed : bool
            Shrink the polytope by ``1 + error`` so that it lies inside ``S``; else it holds
            ``S`` and overestimates it by at most ``error``.

        Returns
        -------
        Polytope
            With ``error`` the largest relative radial gap to ``S``, ``max_v gauge(v) - 1``
            over its vertices ``v`` (exact up to rounding and the accuracy of ``gauge``).
        """
        twists = validation.finite_array("twists", twists, shape=(None, 3))
        loads = validation.finite_array("loads", loads, shape=(len(twists), 3))
        outer = cls(rows=np.eye(3), mu=mu, rho=rho, center=center, normal_force=normal_force)
        # V · L <= V · L_i with L = N M^-1 q (M the normalising map): a row N M^-T V / (V · L_i).
        to_q = outer._normalising_map()
        offsets = np.einsum("ij,ij->i", twists, loads)
        if np.any(offsets <= 0.0):
            bad = int(np.flatnonzero(offsets <= 0.0)[0])
            raise InvalidArgumentError(
                f"twists[{bad}] · loads[{bad}] = {offsets[bad]:.6g} is not positive: each twist "
                "must be the outward normal of the set at its load"
            )
        rows = normal_force * np.linalg.solve(to_q.T, twists.T).T / offsets[:, None]
        outer = dataclasses.replace(outer, rows=rows)
        error = max(float(np.max(np.asarray(gauge(outer.vertices())))) - 1.0, 0.0)
        if inscribed:
            rows = rows * (1.0 + error)
        return dataclasses.replace(outer, rows=rows, error=error, inscribed=inscribed)

    @classmethod
    def from_limit_surface(
        cls, ls: LimitSurface, *, cuts: int = DEFAULT_CUTS, inscribed: bool = True
    ) -> Polytope:
        """The tangent planes of an exact limit surface at an even spread of normals.

        The normals are a centrally symmetric Fibonacci lattice of ``cuts`` directions
        (:func:`symmetric_directions`) in the normalised coordinates of the Table 2 ellipsoid
        (forces over ``mu N``, moments about the centre of pressure over ``mu rho N``); the
        planes touch the surface at the loads of the forward map. ``error`` is measured with
        the exact inverse map at the vertices; ``inscribed`` (default) shrinks the polytope
        by it into the surface (conservative), else it holds the surface. A frictionless surface gives the polytope of
        its patch's shape (``mu = 1``) as a frictionless model.
        """
        parameters = area_parameters(ls, tilted=False)
        del parameters["tilt"]
        shape, normal_force = ls.friction_shape, surface_units(ls)[2]
        frame = cls(rows=np.eye(3), **{**parameters, "mu": surface_units(shape)[0]})
        twists = symmetric_directions(cuts) @ frame._normalising_map()
        model = cls.from_tangent_planes(
            twists,
            np.atleast_2d(shape.load(twists)),
            gauge=lambda loads: 1.0 / np.atleast_1d(shape.safety_factor(loads)),
            mu=frame.mu,
            rho=frame.rho,
            center=frame.center,
            normal_force=normal_force,
            inscribed=inscribed,
        )
        return dataclasses.replace(model, mu=parameters["mu"])

    # -- queries ----------------------------------------------------------------------------------

    def inequalities(self, *, normal_force: float | None = None) -> tuple[np.ndarray, np.ndarray]:
        """``(A, b)`` with the polytope ``{L : A @ L <= b}`` for loads ``L`` [N, N, N m].

        ``A`` is ``(2k, 3)``, ``b`` ``(2k,)`` [N]; ``normal_force`` [N] defaults to the model's.
        A frictionless model gives ``A`` of its shape and ``b = 0`` (only ``L = 0``).
        """
        force = self.normal_force if normal_force is None else normal_force
        force = validation.positive_scalar("normal_force", force)
        matrix = self._facets @ self._normalising_map()
        return matrix, np.full(len(self._facets), 0.0 if self.frictionless else force)

    def vertices(self, *, normal_force: float | None = None) -> np.ndarray:
        """The polytope's vertices as loads ``(V, 3)`` [N, N, N m] about the frame origin at
        ``normal_force`` [N] (default the model's; those of the shape for a frictionless model).

        Each vertex is dual to a facet of the convex hull of ``±g_i`` (the polar polytope);
        a vertex where more than three facets meet may appear more than once.
        """
        from scipy.spatial import ConvexHull

        force = self.normal_force if normal_force is None else normal_force
        force = validation.positive_scalar("normal_force", force)
        hull = ConvexHull(self._facets)
        # Hull facet n · p <= b (b = -offset > 0) holds every row: its dual vertex q = n / b.
        q = hull.equations[:, :3] / -hull.equations[:, 3:]
        return force * np.linalg.solve(self._normalising_map(), q.T).T

    # -- the model's hooks ----------------------------------------------------------------------

    def _gauge(self, q):
        return np.max(np.abs(q @ self.rows.T), axis=1)

    def _gauge_terms(self):
        return (("max", np.vstack([self.rows, -self.rows])),)

    def _normal(self, q):
        return self._facets[np.argmax(q @ self._facets.T, axis=1)]

    def _unit_conic(self):
        return _linear_conic(self._facets)

    def __repr__(self) -> str:
        center = ""
        if self.center != (0.0, 0.0):
            center = f"center=({fmt(self.center[0])}, {fmt(self.center[1])}) m, "
        cut = ""
        if self.error > 0.0:
            cut = f", error={self.error:.3g} {'inscribed' if self.inscribed else 'outside'}"
        return (
            f"Polytope({2 * len(self.rows)} facets, mu={fmt(self.mu)}, rho={fmt(self.rho)} m, "
            f"{center}normal_force={fmt(self.normal_force)} N{cut})"
        )
