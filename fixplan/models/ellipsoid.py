r"""Ellipsoidal friction models (paper §4.2, Table 2): the Table 2 ellipsoid, a fitted
ellipsoid, and the ellipsoid with facets for discrete supports.

All three have a motion map: the sliding twist is the outward normal of the ellipsoid at the
load (maximum power), so for the axisymmetric Table 2 ellipsoid
``|v| / w = lambda² |f| / m`` with ``lambda = max_moment / max_force`` (Table 2, step 5).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, ClassVar

import numpy as np

from fixplan import validation
from fixplan.errors import InvalidArgumentError
from fixplan.models.base import FrictionModel, finite_pair, fmt
from fixplan.models.conic import unit_conic
from fixplan.models.sdp import solve_sdp
from fixplan.surface.sphere import fibonacci_sphere
from fixplan.tolerances import FIT_MIN_EIGENVALUE, TILT_ATOL

if TYPE_CHECKING:  # pragma: no cover
    from fixplan.surface.limit_surface import LimitSurface

#: Default number of limit-surface samples an ellipsoid is fitted to.
DEFAULT_FIT_SAMPLES = 1000


def surface_units(ls: LimitSurface) -> tuple[float, float, float]:
    """``(mu, rho, normal_force)`` of a limit surface: friction per unit normal force [-] (0
    for a frictionless surface), characteristic length [m] and normal force [N]."""
    from fixplan.surface.limit_surface import LimitSurface

    if not isinstance(ls, LimitSurface):
        raise InvalidArgumentError(
            f"ls must be a fixplan.LimitSurface, got {type(ls).__name__}; build one with "
            "LimitSurface(field, mu=..., normal_force=...)"
        )
    return ls.max_force / ls.normal_force, ls.characteristic_length, ls.normal_force


def surface_axis(ls: LimitSurface) -> tuple[tuple[float, float], float, tuple[float, float]]:
    """Centre of pressure, characteristic length and tilt of a surface (Table 2, steps 1-2).

    Returns
    -------
    center : tuple of float
        Friction-weighted centre of pressure ``c`` [m] (paper eq. 2), read off the loads of
        pure translation, whose moments are ``c × f``.
    rho : float
        Largest moment about ``c`` (rotation about ``c``) over the largest force [m].
    tilt : tuple of float
        Force ``(fx0, fy0)`` of the load at that largest moment, over ``max_force`` [-].

    Components below ``TILT_ATOL`` (of ``rho`` for the centre) are rounding noise of a
    symmetric field and are set to 0. A frictionless surface has those of its shape
    (``ls.friction_shape``, the same patch with ``mu = 1``).
    """
    ls = ls.friction_shape
    max_force, length = ls.max_force, ls.characteristic_length
    along_x, along_y = ls.load(np.eye(3)[:2])
    center = np.array([along_y[2], -along_x[2]]) / max_force
    center = np.where(np.abs(center) < TILT_ATOL * length, 0.0, center)
    rotation = np.array([center[1], -center[0], 1.0])
    apex = ls.load(rotation)
    tilt = apex[:2] / max_force
    tilt = np.where(np.abs(tilt) < TILT_ATOL, 0.0, tilt)
    rho = float(ls.support(rotation)) / max_force
    return (float(center[0]), float(center[1])), rho, (float(tilt[0]), float(tilt[1]))


def area_parameters(ls: LimitSurface, tilted: bool) -> dict:
    """Keyword arguments ``mu, rho, tilt, center, normal_force`` of an area model of ``ls``."""
    mu, _, normal_force = surface_units(ls)
    center, rho, tilt = surface_axis(ls)
    return {
        "mu": mu,
        "rho": rho,
        "tilt": tilt if tilted else (0.0, 0.0),
        "center": center,
        "normal_force": normal_force,
    }


def limit_parameters(
    max_force: float,
    max_moment: float,
    normal_force: float,
    apex_force: tuple[float, float],
    center: tuple[float, float],
) -> dict:
    """Keyword arguments of an area model from its largest force [N] and moment [N m]."""
    max_force = validation.positive_scalar("max_force", max_force)
    max_moment = validation.positive_scalar("max_moment", max_moment)
    normal_force = validation.positive_scalar("normal_force", normal_force)
    apex = finite_pair("apex_force", apex_force)
    return {
        "mu": max_force / normal_force,
        "rho": max_moment / max_force,
        "tilt": (apex[0] / max_force, apex[1] / max_force),
        "center": finite_pair("center", center),
        "normal_force": normal_force,
    }


def check_area(model) -> None:
    """Validate and normalise the fields ``mu, rho, tilt, center, normal_force`` of ``model``."""
    object.__setattr__(model, "mu", validation.nonnegative_scalar("mu", model.mu))
    object.__setattr__(model, "rho", validation.positive_scalar("rho", model.rho))
    object.__setattr__(model, "tilt", finite_pair("tilt", model.tilt))
    object.__setattr__(model, "center", finite_pair("center", model.center))
    object.__setattr__(
        model, "normal_force", validation.positive_scalar("normal_force", model.normal_force)
    )


def area_repr(model, extra: str = "") -> str:
    """``Name(extra mu=..., rho=... m, tilt=(..), [center=(..) m, ]normal_force=... N)``."""
    tilt = f"({fmt(model.tilt[0])}, {fmt(model.tilt[1])})"
    center = ""
    if model.center != (0.0, 0.0):
        center = f"center=({fmt(model.center[0])}, {fmt(model.center[1])}) m, "
    return (
        f"{type(model).__name__}({extra}mu={fmt(model.mu)}, rho={fmt(model.rho)} m, "
        f"tilt={tilt}, {center}normal_force={fmt(model.normal_force)} N)"
    )


def _shear(tilt: tuple[float, float]) -> np.ndarray:
    """Matrix ``S`` with ``S q = (qx - tx qm, qy - ty qm, qm)``: the tilted axis made vertical."""
    shear = np.eye(3)
    shear[:2, 2] = -np.asarray(tilt)
    return shear


@dataclass(frozen=True, slots=True, kw_only=True, repr=False)
class Ellipsoid(FrictionModel):
    r"""The ellipsoid of the paper's Table 2, built from the maximum force and moment.

    In normalised coordinates ``q`` (forces over ``mu N``, moment over ``mu rho N``) the
    axisymmetric ellipsoid is the unit sphere (Table 2, step 3). When the load at maximum
    moment ``(fx0, fy0, m_max)`` has a force component (asymmetric pressure), the ellipsoid is
    tilted so that its major axis runs through that load (step 2); this is done by the affine
    shear

    .. math:: \|(q_f - q_m t,\; q_m)\| \le 1, \qquad t = (f_{x0}, f_{y0}) / (\mu N),

    which keeps both exact features of the limit surface: the circle of pure translation at
    ``m = 0`` and the load at maximum moment, where the tangent plane stays horizontal as on
    the exact surface. Motion is the ellipsoid normal (step 5). Moments are taken about the
    centre of pressure ``center`` (step 1), the frame origin for the standard fields.

    Attributes
    ----------
    mu : float
        Maximum friction force per unit normal force [-]; 0 for a frictionless contact.
    rho : float
        Maximum moment over maximum force [m] (the paper's ``lambda``; of the pressure shape
        when ``mu = 0``).
    tilt : tuple of float
        Force at maximum moment over the maximum force [-]; ``(0, 0)`` for symmetric pressure.
    center : tuple of float
        Centre of pressure [m] about which the moments are taken.
    normal_force : float
        Default normal force of the numeric methods [N].
    """

    mu: float
    rho: float
    tilt: tuple[float, float] = (0.0, 0.0)
    center: tuple[float, float] = (0.0, 0.0)
    normal_force: float = 1.0

    conservative: ClassVar[bool] = False

    def __post_init__(self):
        check_area(self)

    @classmethod
    def from_limit_surface(cls, ls: LimitSurface, *, tilted: bool = True) -> Ellipsoid:
        """The Table 2 ellipsoid of an exact limit surface (steps 1-3 and 5).

        With ``tilted=False`` the major axis is taken vertical even for asymmetric pressure
        (the paper's choice when ``fx0`` and ``fy0`` are small).
        """
        return cls(**area_parameters(ls, tilted))

    @classmethod
    def from_limits(
        cls,
        *,
        max_force: float,
        max_moment: float,
        normal_force: float = 1.0,
        apex_force: tuple[float, float] = (0.0, 0.0),
        center: tuple[float, float] = (0.0, 0.0),
    ) -> Ellipsoid:
        """From measured (or computed) largest force [N] and moment [N m] about ``center``
        [m] at ``normal_force`` [N]; ``apex_force`` [N] is the force of the load at largest
        moment (tilt)."""
        return cls(**limit_parameters(max_force, max_moment, normal_force, apex_force, center))

    @property
    def matrix(self) -> np.ndarray:
        """Matrix ``M`` (3x3) of the ellipsoid ``q^T M q <= 1`` in normalised coordinates."""
        shear = _shear(self.tilt)
        return shear.T @ shear

    @property
    def load_matrix(self) -> np.ndarray:
        """Matrix ``A`` [1/N², …] of the ellipsoid ``L^T A L <= 1`` for loads ``(fx, fy, m)``
        about the frame origin at unit normal force; its normals are ``A L``."""
        return _load_matrix(self)

    def _gauge(self, q):
        t = self.tilt
        fx = q[:, 0] - t[0] * q[:, 2]
        fy = q[:, 1] - t[1] * q[:, 2]
        return np.sqrt(fx * fx + fy * fy + q[:, 2] * q[:, 2])

    def _gauge_terms(self):
        return (("norm", _shear(self.tilt)),)

    def _normal(self, q):
        return q @ self.matrix

    def _unit_conic(self):
        return _ellipsoid_conic(_shear(self.tilt))

    def __repr__(self) -> str:
        return area_repr(self)


@dataclass(frozen=True, slots=True, kw_only=True, repr=False, eq=False)
class FittedEllipsoid(FrictionModel):
    r"""An ellipsoid ``q^T M q <= 1`` fitted to loads on the limit surface (or measured).

    ``M`` (positive definite, any orientation) minimises

    .. math:: \sum_i (q_i^T M q_i - 1)^2 \quad \text{s.t.} \quad M \succeq \epsilon I,

    a convex problem (least squares over the positive-semidefinite cone, solved by cvxpy with
    Clarabel). Near the surface ``q^T M q - 1`` is twice the relative radial gap between the
    point and the ellipsoid, so this is a least-squares fit of the radial error, unbiased
    between over- and under-estimates (a minimum-volume enclosing ellipsoid would always
    overestimate and follow outliers of measured data). The centre is the origin, as every
    limit surface is centrally symmetric.

    Attributes
    ----------
    matrix : numpy.ndarray
        ``M`` (3x3), in normalised coordinates ``q`` of ``mu`` and ``rho``.
    mu, rho : float
        Normalisation units: friction per unit normal force [-] (0: frictionless, ``matrix``
        is then the shape at ``mu = 1``) and length [m].
    center : tuple of float
        Point [m] about which the moments of ``q`` are taken (the centre of pressure).
    normal_force : float
        Default normal force of the numeric methods [N].
    fit_error : float
        Root-mean-square relative radial gap ``sqrt(q^T M q) - 1`` over the fitted points.
    """

    matrix: np.ndarray
    mu: float
    rho: float
    center: tuple[float, float] = (0.0, 0.0)
    normal_force: float = 1.0
    fit_error: float = 0.0
    _factor: np.ndarray = field(init=False)

    conservative: ClassVar[bool] = False

    def __post_init__(self):
        matrix = validation.finite_array("matrix", self.matrix, shape=(3, 3))
        if not np.allclose(matrix, matrix.T, rtol=1e-12, atol=0.0):
            raise InvalidArgumentError("matrix must be symmetric")
        try:
            factor = np.linalg.cholesky(matrix).T
        except np.linalg.LinAlgError as exc:
            raise InvalidArgumentError("matrix must be positive definite") from exc
        factor.setflags(write=False)
        object.__setattr__(self, "matrix", matrix)
        object.__setattr__(self, "_factor", factor)
        object.__setattr__(self, "mu", validation.nonnegative_scalar("mu", self.mu))
        object.__setattr__(self, "rho", validation.positive_scalar("rho", self.rho))
        object.__setattr__(self, "center", finite_pair("center", self.center))
        object.__setattr__(
            self, "normal_force", validation.positive_scalar("normal_force", self.normal_force)
        )
        object.__setattr__(
            self, "fit_error", validation.nonnegative_scalar("fit_error", self.fit_error)
        )

    @classmethod
    def from_limit_surface(
        cls, ls: LimitSurface, *, samples: int = DEFAULT_FIT_SAMPLES
    ) -> FittedEllipsoid:
        """Fit to ``samples`` loads on the exact surface, spread evenly in direction.

        The directions are a Fibonacci lattice in the normalised coordinates of the Table 2
        ellipsoid (moments about the centre of pressure), so the fit does not depend on where
        the frame origin lies. A frictionless surface is fitted by the shape of its patch
        (``mu = 1``) and gives a frictionless model.
        """
        if isinstance(samples, bool) or not isinstance(samples, int | np.integer) or samples < 6:
            raise InvalidArgumentError(f"samples must be an integer >= 6, got {samples!r}")
        parameters = area_parameters(ls, tilted=False)
        del parameters["tilt"]
        frame = Ellipsoid(**parameters)
        directions = fibonacci_sphere(int(samples))
        units = frame._units() * frame.normal_force
        cx, cy = frame.center
        loads = directions * units
        loads[:, 2] += cx * loads[:, 1] - cy * loads[:, 0]  # moments about the origin
        points = directions * np.atleast_1d(ls.friction_shape.safety_factor(loads))[:, None]
        matrix, error = fit_ellipsoid(points)
        return cls(matrix=matrix, fit_error=error, **parameters)

    @classmethod
    def from_loads(cls, loads, *, normal_force: float) -> FittedEllipsoid:
        """Fit to measured slip loads ``(K, 3)`` [N, N, N m] taken at ``normal_force`` [N].

        At least 6 loads spanning all three directions are needed. ``mu`` and ``rho`` are
        read off the fitted ellipsoid (its mean largest force and its largest moment).
        """
        loads = validation.finite_array("loads", loads, shape=(None, 3))
        normal_force = validation.positive_scalar("normal_force", normal_force)
        force_scale = float(np.max(np.hypot(loads[:, 0], loads[:, 1]), initial=0.0))
        moment_scale = float(np.max(np.abs(loads[:, 2]), initial=0.0))
        if len(loads) < 6 or force_scale == 0.0 or moment_scale == 0.0:
            raise InvalidArgumentError(
                "from_loads needs at least 6 loads with nonzero forces and moments, got "
                f"{len(loads)} loads"
            )
        scale = np.array([force_scale, force_scale, moment_scale])
        if np.linalg.matrix_rank(loads / scale, tol=1e-9) < 3:
            raise InvalidArgumentError("loads must span all three directions (fx, fy, m)")
        matrix, error = fit_ellipsoid(loads / scale)
        # Support function of the fitted set in SI units: h(V) = sqrt(V^T B V).
        inverse = scale[:, None] * np.linalg.inv(matrix) * scale[None, :]
        max_force = float(np.sqrt(0.5 * (inverse[0, 0] + inverse[1, 1])))
        max_moment = float(np.sqrt(inverse[2, 2]))
        units = np.array([max_force, max_force, max_moment])
        normalised = units[:, None] * np.linalg.inv(inverse) * units[None, :]
        normalised = 0.5 * (normalised + normalised.T)
        return cls(
            matrix=normalised,
            mu=max_force / normal_force,
            rho=max_moment / max_force,
            normal_force=normal_force,
            fit_error=error,
        )

    def _gauge(self, q):
        m = self.matrix
        x, y, z = q[:, 0], q[:, 1], q[:, 2]
        # q^T M q written out: thin matrix products are slow in BLAS.
        form = (
            m[0, 0] * x * x
            + m[1, 1] * y * y
            + m[2, 2] * z * z
            + 2.0 * (m[0, 1] * x * y + m[0, 2] * x * z + m[1, 2] * y * z)
        )
        return np.sqrt(np.maximum(form, 0.0))

    def _gauge_terms(self):
        return (("norm", np.linalg.cholesky(self.matrix).T),)

    def _normal(self, q):
        return q @ self.matrix

    @property
    def load_matrix(self) -> np.ndarray:
        """As :attr:`Ellipsoid.load_matrix`."""
        return _load_matrix(self)

    def _unit_conic(self):
        return _ellipsoid_conic(self._factor)

    def __repr__(self) -> str:
        center = ""
        if self.center != (0.0, 0.0):
            center = f"center=({fmt(self.center[0])}, {fmt(self.center[1])}) m, "
        return (
            f"FittedEllipsoid(mu={fmt(self.mu)}, rho={fmt(self.rho)} m, {center}"
            f"normal_force={fmt(self.normal_force)} N, fit_error={self.fit_error:.3g})"
        )


def _load_matrix(model) -> np.ndarray:
    """``A`` with ``L^T A L = q^T M q``: the ellipsoid in load coordinates."""
    to_q = model._normalising_map()
    return to_q.T @ model.matrix @ to_q


def _ellipsoid_conic(factor: np.ndarray):
    """``||F q|| <= N``: one second-order cone of size 4."""
    return unit_conic([1.0, 0.0, 0.0, 0.0], np.vstack([np.zeros(3), factor]), cones=[("soc", 4)])


def fit_ellipsoid(points: np.ndarray) -> tuple[np.ndarray, float]:
    """Least-squares ellipsoid ``q^T M q = 1`` through ``points`` ``(K, 3)``, centred at 0.

    Returns ``M`` and the root-mean-square relative radial gap of the points. Solved with
    Clarabel, retried once with SCS.
    """
    import cvxpy as cp

    matrix = cp.Variable((3, 3), PSD=True)
    residual = cp.sum(cp.multiply(points @ matrix, points), axis=1) - 1.0
    problem = cp.Problem(
        cp.Minimize(cp.sum_squares(residual)), [matrix >> FIT_MIN_EIGENVALUE * np.eye(3)]
    )
    solve_sdp(problem, what="the ellipsoid fit",
              advice="check that the points surround the origin in all three directions")  # fmt: skip
    value = np.asarray(matrix.value)
    value = 0.5 * (value + value.T)
    gap = np.sqrt(np.einsum("ij,jk,ik->i", points, value, points)) - 1.0
    return value, float(np.sqrt(np.mean(gap * gap)))


@dataclass(frozen=True, slots=True, kw_only=True, repr=False, eq=False)
class FacetedEllipsoid(FrictionModel):
    r"""An ellipsoid with the facets of discrete point supports (Table 2, step 4).

    For each support point ``(xi, yi)`` the centre of rotation on that point gives a facet of
    the exact surface: the plane with normal the twist ``Vi = (yi, -xi, 1)`` through the load
    ``L(Vi)`` at which that point carries no force (DESIGN.md §2). The model is the
    ellipsoid cut by these planes and their mirror images,

    .. math:: |V_i \cdot L| \le h(V_i) \quad \text{for every support point } i,

    where ``h`` is the exact support function. The planes are supporting planes of the exact
    surface, so the cut removes only overestimated loads. Motion: the ellipsoid normal, or the
    twist ``±Vi`` (rotation about point ``i``) on a facet.

    Attributes
    ----------
    ellipsoid : Ellipsoid or FittedEllipsoid
        The ellipsoid that is cut; it supplies ``mu``, ``rho`` and ``normal_force``.
    points : numpy.ndarray
        Support points ``(P, 2)`` [m].
    facet_support : numpy.ndarray
        ``h(Vi)`` per unit normal force ``(P,)`` [m] (for a frictionless ellipsoid, that of the
        pressure shape at ``mu = 1``).
    """

    ellipsoid: Ellipsoid | FittedEllipsoid
    points: np.ndarray
    facet_support: np.ndarray
    _planes: np.ndarray = field(init=False)

    conservative: ClassVar[bool] = False

    def __post_init__(self):
        if not isinstance(self.ellipsoid, Ellipsoid | FittedEllipsoid):
            raise InvalidArgumentError(
                f"ellipsoid must be an Ellipsoid or FittedEllipsoid, got {self.ellipsoid!r}"
            )
        points = validation.finite_array("points", self.points, shape=(None, 2))
        support = validation.finite_array("facet_support", self.facet_support, shape=(None,))
        if len(points) == 0 or len(support) != len(points) or np.any(support <= 0.0):
            raise InvalidArgumentError(
                "points (P, 2) and facet_support (P,) must have the same P >= 1, support > 0"
            )
        # Twist V_i of rotation about point i, written about the centre c (the velocity of
        # the body point at c), so that V_i · L = V_i,c · (f, m - c × f).
        cx, cy = self.ellipsoid.center
        twists = np.column_stack([points[:, 1] - cy, cx - points[:, 0], np.ones(len(points))])
        # Facet i in normalised coordinates: |a_i · q| <= 1, a_i = units * V_i,c / h_i.
        planes = twists * self.ellipsoid._units()[None, :] / support[:, None]
        planes.setflags(write=False)
        object.__setattr__(self, "points", points)
        object.__setattr__(self, "facet_support", support)
        object.__setattr__(self, "_planes", planes)

    @classmethod
    def from_limit_surface(
        cls,
        ls: LimitSurface,
        *,
        ellipsoid: Ellipsoid | FittedEllipsoid | None = None,
        points=None,
    ) -> FacetedEllipsoid:
        """Facets of the support points of ``ls`` cut from ``ellipsoid``.

        ``ellipsoid`` defaults to the Table 2 ellipsoid of ``ls``. ``points`` ``(P, 2)`` [m]
        default to the points of a discrete field (``pressure.points``, also as parts of a
        combined surface); give them for small regions of support that act like points.
        """
        normal_force = surface_units(ls)[2]
        if ellipsoid is None:
            ellipsoid = Ellipsoid.from_limit_surface(ls)
        if points is None:
            points = _support_points(ls)
            if len(points) == 0:
                raise InvalidArgumentError(
                    f"{ls!r} has no discrete point supports; pass points= to place facets"
                )
        points = validation.finite_array("points", points, shape=(None, 2))
        twists = np.column_stack([points[:, 1], -points[:, 0], np.ones(len(points))])
        support = np.atleast_1d(ls.friction_shape.support(twists)) / normal_force
        return cls(ellipsoid=ellipsoid, points=points, facet_support=support)

    @property
    def mu(self) -> float:
        return self.ellipsoid.mu

    @property
    def rho(self) -> float:
        return self.ellipsoid.rho

    @property
    def center(self) -> tuple[float, float]:
        return self.ellipsoid.center

    @property
    def normal_force(self) -> float:
        return self.ellipsoid.normal_force

    def _with_shape_friction(self) -> FacetedEllipsoid:
        return dataclasses.replace(self, ellipsoid=self.ellipsoid.friction_shape)

    def _pieces(self, q):
        """Gauges of the ellipsoid ``(K,)`` and of the facet pairs ``(K, P)``."""
        return self.ellipsoid._gauge(q), np.abs(np.einsum("ij,kj->ik", q, self._planes))

    def _gauge(self, q):
        ellipsoid, facets = self._pieces(q)
        return np.maximum(ellipsoid, facets.max(axis=1))

    def _normal(self, q):
        ellipsoid, facets = self._pieces(q)
        normals = self.ellipsoid._normal(q)
        best = np.argmax(facets, axis=1)
        rows = np.arange(len(q))
        on_facet = facets[rows, best] > ellipsoid
        signs = np.sign(q @ self._planes.T)[rows, best]
        normals[on_facet] = signs[on_facet, None] * self._planes[best[on_facet]]
        return normals

    def _unit_conic(self):
        # The ellipsoid's cone, then |a_i · q| <= N as N - a_i · q >= 0 and N + a_i · q >= 0.
        cone = self.ellipsoid._unit_conic()
        count = 2 * len(self._planes)
        return unit_conic(
            np.concatenate([cone.normal, np.ones(count)]),
            np.vstack([cone.load, -self._planes, self._planes]),
            cones=[*cone.cones, ("nonneg", count)],
        )

    def __repr__(self) -> str:
        return f"FacetedEllipsoid({self.ellipsoid!r}, {len(self.points)} facet pairs)"


def _support_points(ls: LimitSurface) -> np.ndarray:
    """Point supports of a discrete field, or of the discrete parts of a combined surface."""
    if ls.parts:
        found = [_support_points(part) for part in ls.parts]
        return np.concatenate(found) if found else np.empty((0, 2))
    if ls.field is not None and ls.field.is_discrete:
        return np.asarray(ls.field.quadrature()[0])
    return np.empty((0, 2))
