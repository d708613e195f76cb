r"""The exact limit surface of a planar sliding contact.

For a pressure field ``p`` (unit total), friction ``mu`` and normal force ``N`` the support
(dissipation) function of a twist ``V = (vx, vy, w)`` is

.. math:: h(V) = N \int \mu \, p \, |v(x)| \, dA, \qquad v(x) = (v_x - w y, v_y + w x),

the load that sustains sliding with ``V`` is ``L(V) = ∇h(V)`` (paper eqs. 4-5) and the set of
loads the contact holds is ``{L : L·V <= h(V) for all V}``, whose boundary is the limit surface.
Loads ``(fx, fy, m)`` are the applied force [N] and moment [N m] about the field's origin;
twists are ``(vx, vy, w)`` in [m/s] and [rad/s] (DESIGN.md §2).

Accuracy (relative, measured by the tests against independent quadrature):

- uniform, Hertz, parabolic, annulus and ring disks, uniform polygons and rectangles, and
  tactile grids (piecewise-uniform cells): closed forms, about 1e-13 everywhere; on noisy
  grids (random cell pressures) the corner sums lose digits with the distance of the centre of
  rotation: support values within 2e-12 and Hessians 1.2e-11 of the same sums in long double
  on a 200 x 200 map, just inside the far-field switch;
- point supports: exact, facets included;
- pressure functions and position-dependent ``mu``: adaptive quadrature centred at the centre
  of rotation, better than 1e-9 for smooth integrands (1e-7 with a Hertz profile);
- inverse map (safety factor, motion): Newton's method to 1e-12 on the twist, so the safety
  factor matches the forward map to about 1e-15 and motions are within 1e-10 rad.

A frictionless contact (``mu = 0``) transmits its normal force only: ``h = 0``, its limit
surface is the single load 0 and every other load slides (safety factor 0). Its shape is that of
the same patch with ``mu = 1`` (:attr:`LimitSurface.friction_shape`), which shrinks onto 0 as
``mu → 0+``; the sliding motion at a fixed load direction does not change along the way, so
:meth:`LimitSurface.motion` returns that limit, the motion of the shape.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable, Iterable

import numpy as np

from fixplan import validation
from fixplan.errors import InvalidArgumentError
from fixplan.surface.closed_form import EdgeSumKernel, GridKernel
from fixplan.surface.compiled_inverse import compile_kernel
from fixplan.surface.disk_kernel import AnnulusKernel, DiskKernel
from fixplan.surface.geometry import Pose, triangulate
from fixplan.surface.grid_kernel import block_rule, grid_nodes
from fixplan.surface.inverse import solve
from fixplan.surface.kernels import EllipsoidKernel, PosedKernel, SumKernel, SupportKernel
from fixplan.surface.point_kernel import PointSetKernel
from fixplan.surface.polygon_kernel import polygon_edges
from fixplan.surface.pressure import (
    DiskField,
    FunctionField,
    GridField,
    PointsField,
    PolygonField,
    PressureField,
    check_weight_ratio,
)
from fixplan.surface.rules import triangle_rule
from fixplan.surface.sphere import circle, fibonacci_sphere
from fixplan.tolerances import (
    CONTAINMENT_RTOL,
    FAR_FIELD_RADII,
    MAX_MU,
    MIN_FRICTION_FORCE,
    QUADRATURE_RTOL,
)

#: Gauss order per triangle of the far-field rule of polygons (exact to machine precision for
#: centres of rotation beyond FAR_FIELD_RADII patch radii).
_FAR_ORDER = 12

#: Loads are solved in chunks of this many to bound memory.
_CHUNK = 4096

#: Up to this many twists, the support function (and the load) is evaluated by the compiled
#: kernel one twist at a time (a Hertz disk: 1.8 µs for 2 twists and 14 µs for 64, against 49
#: and 59 µs of the NumPy kernel; a rectangle: 1.9 and 19 µs against 2.8 and 25 µs); larger
#: batches take the vectorised NumPy kernels.
COMPILED_SUPPORT_MAX_TWISTS = 64

_PLANES = {"fx-m": (0, 2), "fy-m": (1, 2), "fx-fy": (0, 1)}

_PROFILE_PRESSURE: dict[str, Callable | None] = {
    "uniform": None,
    "hertz": lambda r2: np.sqrt(np.clip(1.0 - r2, 0.0, None)),
    "parabolic": lambda r2: np.clip(1.0 - r2, 0.0, None),
}


class LimitSurface:
    """Exact limit surface of a planar contact with pressure ``field``.

    Parameters
    ----------
    field : PressureField
        Pressure distribution, normalised to unit total; coordinates [m].
    mu : float or callable
        Friction coefficient, a constant >= 0 or a function ``mu(x, y)`` >= 0 of contact-frame
        coordinates [m] returning arrays. A function must be smooth over the patch and positive
        somewhere on it; a patch of two materials is two patches summed with :meth:`combine`.
        One the quadrature does not resolve to ``QUADRATURE_RTOL`` (as for ``p`` of
        :func:`~fixplan.pressure.from_function`) is refused, except on point supports.
        ``mu = 0`` is a frictionless contact (see the module docstring).
    normal_force : float
        Total normal force [N], > 0.
    """

    __slots__ = (
        "_compiled",
        "_kernel",
        "_mu",
        "_normal_force",
        "_parts",
        "_rho",
        "_scale",
        "_shape",
        "_twist_scales",
        "_units",
        "field",
    )

    def __init__(self, field: PressureField, *, mu: float | Callable, normal_force: float = 1.0):
        if not isinstance(field, PressureField):
            raise InvalidArgumentError(
                f"field must be a pressure field from fixplan.surface.pressure, got {type(field).__name__}"
            )
        normal_force = validation.positive_scalar("normal_force", normal_force)
        if callable(mu):
            kernel, scale = _varying_friction_kernel(field, mu), normal_force
        else:
            mu = validation.nonnegative_scalar("mu", mu)
            kernel, scale = _field_kernel(field), mu * normal_force
        _check_forces(normal_force, scale)
        self.field = field
        self._mu = mu
        self._normal_force = normal_force
        self._parts: tuple[LimitSurface, ...] = ()
        frictionless = not callable(mu) and mu == 0.0
        shape = LimitSurface(field, mu=1.0, normal_force=normal_force) if frictionless else None
        self._setup(kernel, scale, shape)
        if callable(mu) and self.max_force == 0.0:
            raise InvalidArgumentError(
                "mu(x, y) is 0 over the whole patch: pass mu=0 for a frictionless contact"
            )

    def _setup(
        self, kernel: SupportKernel, scale: float, shape: LimitSurface | None = None
    ) -> None:
        self._kernel = kernel
        self._compiled = compile_kernel(kernel)
        #: What bounds a twist's size in :meth:`_normalized` (kept: a kernel computes its size
        #: at each call, a third of a slide's forward map on a contact set).
        self._twist_scales = np.array([1.0, 1.0, kernel.size])
        self._scale = scale
        self._shape = shape
        probe = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])
        max_force, max_moment = scale * kernel.support(probe)
        self._units = np.array([max_force, max_force, max_moment])
        force, moment = (self._units if shape is None else shape._units)[1:].tolist()
        self._rho = moment / force if force > 0.0 else math.nan  # 0: mu(x, y) = 0, refused

    @classmethod
    def combine(cls, surfaces: Iterable[LimitSurface]) -> LimitSurface:
        """Limit surface of rigidly connected patches: the Minkowski sum of ``surfaces``.

        Its support function is the sum of the parts' (paper §4.4); all parts must be written
        in the same contact frame. The result offers the same API; its ``field`` is ``None``.
        """
        parts = tuple(surfaces)
        if not parts or not all(isinstance(p, LimitSurface) for p in parts):
            raise InvalidArgumentError("combine needs one or more LimitSurface objects")
        combined = cls.__new__(cls)
        combined.field = None
        combined._mu = None
        combined._normal_force = sum(p.normal_force for p in parts)
        combined._parts = parts
        kernel = SumKernel(tuple(p._kernel for p in parts), tuple(p._scale for p in parts))
        # Frictionless parts add nothing; when every part is frictionless, so is the sum, and
        # its shape is the sum of the parts' shapes.
        frictionless = all(p.frictionless for p in parts)
        shape = cls.combine(p.friction_shape for p in parts) if frictionless else None
        combined._setup(kernel, 1.0, shape)
        return combined

    @classmethod
    def ellipsoid(cls, load_matrix, *, normal_force: float) -> LimitSurface:
        """The surface of the ellipsoid ``L^T A L <= N²`` with ``A`` the ``load_matrix`` (per
        unit normal force, as :attr:`~fixplan.models.Ellipsoid.load_matrix` gives it) at the
        ``normal_force`` ``N`` [N]: a friction model's set as a surface, to be placed and
        summed with patches and point supports (:meth:`placed`, :meth:`combine`). Its support
        ``N sqrt(V^T A^{-1} V)``, load and Hessian are closed forms; its ``field`` and ``mu``
        are ``None``."""
        matrix = validation.finite_array("load_matrix", load_matrix, shape=(3, 3))
        if not np.allclose(matrix, matrix.T, rtol=1e-12, atol=0.0):
            raise InvalidArgumentError("load_matrix must be symmetric")
        try:
            inverse = np.linalg.inv(np.linalg.cholesky(matrix))  # (refuses all but SPD)
        except np.linalg.LinAlgError:
            raise InvalidArgumentError("load_matrix must be positive definite") from None
        force = validation.positive_scalar("normal_force", normal_force)
        _check_forces(force, force * float(np.sqrt((inverse.T @ inverse)[0, 0])))
        surface = cls.__new__(cls)
        surface.field, surface._mu, surface._normal_force, surface._parts = None, None, force, ()
        surface._setup(EllipsoidKernel(inverse.T @ inverse), force)
        return surface

    def placed(self, pose: Pose, *, normal_force: float | None = None) -> LimitSurface:
        """This surface with its frame placed by ``pose`` in another frame (a contact's surface
        in the plane of the part it holds; the pose is mirrored where the contact faces the
        other way), at ``normal_force`` [N] (default its own: the pressure keeps its shape, so
        the friction scales with the force). Its loads are about the other frame's origin and
        its point supports in that frame; its ``field`` is ``None``, its ``mu`` this one's
        where that is a constant (``None`` for a function of this frame's coordinates)."""
        if not isinstance(pose, Pose):
            raise InvalidArgumentError(f"pose must be a Pose, got {type(pose).__name__}")
        force = self._normal_force
        if normal_force is not None:
            force = validation.positive_scalar("normal_force", normal_force)
        scale = self._scale * (force / self._normal_force)
        _check_forces(force, scale)
        placed = LimitSurface.__new__(LimitSurface)
        placed.field = None
        placed._mu = None if callable(self._mu) else self._mu
        placed._normal_force = force
        placed._parts = ()
        shape = None if self._shape is None else self._shape.placed(pose, normal_force=force)
        placed._setup(_posed(self._kernel, pose), scale, shape)
        return placed

    # -- description ------------------------------------------------------------------------

    @property
    def mu(self) -> float | Callable | None:
        """Friction coefficient (``None`` for a combined surface)."""
        return self._mu

    @property
    def frictionless(self) -> bool:
        """Whether the contact has no friction (``mu = 0``): its limit surface is the load 0."""
        return self._shape is not None

    @property
    def friction_shape(self) -> LimitSurface:
        """A surface of this one's shape: itself, or for a frictionless surface the same
        patches with ``mu = 1`` (the surface that shrinks onto 0 as ``mu → 0+``)."""
        return self if self._shape is None else self._shape

    @property
    def normal_force(self) -> float:
        """Total normal force [N] (summed over the parts of a combined surface)."""
        return self._normal_force

    @property
    def parts(self) -> tuple[LimitSurface, ...]:
        """The surfaces a combined surface was summed from (empty otherwise)."""
        return self._parts

    @property
    def max_force(self) -> float:
        """Largest friction force [N]: ``∫ mu p dA · N`` (pure translation, paper eq. 8)."""
        return float(self._units[0])

    @property
    def max_moment(self) -> float:
        """Largest friction moment about the origin [N m]: rotation about the origin."""
        return float(self._units[2])

    @property
    def characteristic_length(self) -> float:
        """``rho = max_moment / max_force`` [m], the scale of the paper's normalised plots
        (of a frictionless surface: that of its :attr:`friction_shape`)."""
        return self._rho

    def __repr__(self) -> str:
        if self._parts:
            what = f"{len(self._parts)} parts"
        else:
            what = "placed" if self.field is None else type(self.field).__name__
            what = "ellipsoid" if isinstance(self._kernel, EllipsoidKernel) else what
        return (
            f"LimitSurface({what}, max_force={self.max_force:.6g} N, "
            f"max_moment={self.max_moment:.6g} N m)"
        )

    # -- forward map ------------------------------------------------------------------------

    def support(self, twist) -> np.ndarray | float:
        """Support function ``h(V)`` [W per unit speed] of twists ``(3,)`` or ``(K, 3)`` (0 at
        a zero twist)."""
        twists, single = validation.vector_batch("twist", twist, width=3)
        unit, exponents = self._normalized(twists)
        values = np.ldexp(self._trusted_support(unit), exponents)  # h(c V) = c h(V)
        return float(values[0]) if single else values

    def _normalized(self, twists: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Twists ``(K, 3)`` scaled by powers of two ``2^-e`` (exactly) so that the largest of
        ``|vx|``, ``|vy|`` and ``size * |w|`` is in ``[0.5, 1)``, and the exponents ``e`` ``(K,)``.

        The kernels square speeds: twists far from unit size (beyond about 1e±154) would
        underflow or overflow there, though the load is homogeneous of degree 0 in the twist,
        the support of degree 1 and its Hessian of degree -1."""
        return _binary_scaled(twists, self._twist_scales)

    def _trusted_support(self, twists: np.ndarray) -> np.ndarray:
        """:meth:`support` ``(K,)`` of finite twists ``(K, 3)`` from a caller that checked them
        (the planner's exact models, every round; see :meth:`_trusted_inverse`)."""
        if self._compiled is not None and len(twists) <= COMPILED_SUPPORT_MAX_TWISTS:
            return self._scale * self._compiled.supports(twists)
        with np.errstate(invalid="ignore", divide="ignore"):  # (the disk kernels at 0)
            values = self._scale * self._kernel.support(twists)
        values[~np.any(twists != 0.0, axis=1)] = 0.0
        return values

    def support_hessian(self, twist) -> np.ndarray:
        """Hessian ``∇²h`` ``(3, 3)`` or ``(K, 3, 3)`` of the support function at nonzero twists:
        the derivative of :meth:`load` (analytic for disks, polygons and grids)."""
        twists, single, zero = _vectors("twist", twist)
        if zero is not None:
            raise InvalidArgumentError(f"twist[{zero}] is zero: the support has no Hessian there")
        unit, exponents = self._normalized(twists)
        hessians = np.ldexp(self._trusted_hessians(unit), -exponents[:, None, None])
        return hessians[0] if single else hessians

    @property
    def has_facets(self) -> bool:
        """Whether the surface has facets: discrete point supports, where ``h`` has kinks."""
        return len(self._kernel.facets[0]) > 0

    @property
    def point_supports(self) -> tuple[np.ndarray, np.ndarray]:
        """The discrete point supports: positions ``(P, 2)`` [m] in the surface's frame and the
        friction force each can take ``(P,)`` [N] (``mu`` times its normal force); ``P = 0``
        for patches. A part turning about one of them (its twist on that point's facet) keeps
        it still while its friction holds."""
        points, friction = self._kernel.facets
        return np.array(points, dtype=float).reshape(-1, 2), self._scale * np.array(friction)

    def load(self, twist) -> np.ndarray:
        """Load ``(fx, fy, m)`` on the surface that sustains sliding with ``twist``.

        ``twist`` is ``(3,)`` or ``(K, 3)``, nonzero. For a twist rotating about a point support
        the stationary point carries no force (one point of the facet).
        """
        twists, single, zero = _vectors("twist", twist)
        if zero is not None:
            raise InvalidArgumentError(f"twist[{zero}] is zero: a body at rest has no sliding load")
        unit = self._normalized(twists)[0]
        if self._compiled is not None and len(unit) <= COMPILED_SUPPORT_MAX_TWISTS:
            loads = self._scale * self._compiled.loads(unit)
        else:
            loads = self._scale * self._kernel.evaluate(unit)[1]
        return loads[0] if single else loads

    def load_at_cor(self, cor, ccw: bool = True) -> np.ndarray:
        """Load for rotation about the centre of rotation ``cor`` ``(2,)`` or ``(K, 2)`` [m]."""
        cors, single = validation.vector_batch("cor", cor, width=2)
        sign = 1.0 if ccw else -1.0
        twists = sign * np.column_stack([cors[:, 1], -cors[:, 0], np.ones(len(cors))])
        loads = self.load(twists)
        return loads[0] if single else loads

    # -- inverse map ------------------------------------------------------------------------

    def _inverse(self, load):
        loads, single, zero = _vectors("load", load)
        if single:
            x, y, z = loads[0].tolist()
            peaks = max(abs(x), abs(y), abs(z))
            ordinary = peaks == 0.0 or _SMALLEST_LOAD < peaks < _LARGEST_LOAD
        else:
            peaks = np.max(np.abs(loads), axis=1)
            ordinary = np.all((peaks == 0.0) | ((peaks > _SMALLEST_LOAD) & (peaks < _LARGEST_LOAD)))
        if ordinary:
            return self._scaled_inverse(loads, single, zero)
        # s(c L) = s(L) / c and the motion does not change (1e308 N gave NaN, 5e-324 N a NaN
        # motion).
        loads, exponents = _binary_scaled(loads, np.ones(3))
        safety, twists, single = self._scaled_inverse(loads, single, zero)
        with np.errstate(over="ignore"):  # (a safety factor beyond the floats is inf)
            return np.ldexp(safety, -exponents), twists, single

    def _scaled_inverse(self, loads, single, zero):
        """:meth:`_inverse` of ``loads`` ``(K, 3)`` whose largest entries lie within 2^±500 (or
        are 0: a zero load)."""
        if self._shape is not None:
            # Frictionless: only the load 0 is held; the motion is the limit mu -> 0+.
            safety = np.where(np.any(loads != 0.0, axis=1), 0.0, np.inf)
            return safety, self._shape._inverse(loads)[1], single
        if self._compiled is not None:
            return (*self._compiled.solve(loads, self._units, self._scale), single)
        if single and zero is None:
            # Solve for a load of unit size (normalised): s(c L) = s(L) / c.
            size = float(np.max(np.abs(loads[0] / self._units)))
            result = solve(self._kernel, self._scale, loads / size, self._units)
            return result.safety_factor / size, result.twist, True
        safety = np.full(len(loads), np.inf)
        twists = np.full((len(loads), 3), np.nan)
        nonzero = np.flatnonzero(np.any(loads != 0.0, axis=1))
        # Solve for loads of unit size (normalised): s(c L) = s(L) / c.
        size = np.max(np.abs(loads[nonzero] / self._units), axis=1)
        for start in range(0, len(nonzero), _CHUNK):
            rows = nonzero[start : start + _CHUNK]
            scale = size[start : start + _CHUNK, None]
            result = solve(self._kernel, self._scale, loads[rows] / scale, self._units)
            safety[rows] = result.safety_factor / scale[:, 0]
            twists[rows] = result.twist
        return safety, twists, single

    def _trusted_inverse(
        self, loads: np.ndarray, start: np.ndarray | None = None
    ) -> tuple[np.ndarray, np.ndarray]:
        """Safety factors ``(K,)`` and sliding twists ``(K, 3)`` (SI, of any size) of nonzero
        finite loads ``(K, 3)`` [N, N m] from a caller that checked them (the planner's exact
        models, many times per solve): :meth:`motion_and_safety_factor` without the checks and
        the twists' normalisation, which cost more than the compiled solve itself. Compiled
        kernels start Newton from the twists ``start`` ``(K, 3)`` where given (a guess: the
        answers are those of any start, to Newton's tolerance)."""
        if self._compiled is not None and self._shape is None:
            return self._compiled.solve(loads, self._units, self._scale, start)
        safety, twists, _ = self._inverse(loads)
        return safety, twists

    def _trusted_inverse_and_hessians(
        self, loads: np.ndarray, start: np.ndarray | None = None
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """:meth:`_trusted_inverse` and the support Hessians ``(K, 3, 3)`` at the twists found:
        for compiled kernels those Newton computed there (one evaluation fewer per load),
        else (facets, kinks, other kernels) :meth:`_trusted_hessians`."""
        if self._compiled is None or self._shape is not None:
            safety, twists = self._trusted_inverse(loads, start)
            return safety, twists, self._trusted_hessians(twists)
        hessians = np.empty((len(loads), 3, 3))
        safety, twists = self._compiled.solve(loads, self._units, self._scale, start, hessians)
        missing = np.flatnonzero(np.isnan(hessians[:, 0, 0]))
        if missing.size:
            hessians[missing] = self._compiled.hessians(twists[missing])
        return safety, twists, self._scale * hessians

    def _trusted_hessians(self, twists: np.ndarray) -> np.ndarray:
        """:meth:`support_hessian` ``(K, 3, 3)`` of nonzero finite twists ``(K, 3)`` from a
        caller that checked them (see :meth:`_trusted_inverse`)."""
        if self._compiled is not None:
            return self._scale * self._compiled.hessians(twists)
        return self._scale * self._kernel.hessian(twists)

    def safety_factor(self, load) -> np.ndarray | float:
        """Factor ``s`` with ``s * load`` on the surface (``inf`` for the zero load).

        ``s > 1``: held with that margin; ``s < 1``: the contact slides. A frictionless surface
        gives 0 for every nonzero load.
        """
        safety, _, single = self._inverse(load)
        return float(safety[0]) if single else safety

    def contains(self, load) -> np.ndarray | bool:
        """Whether the contact holds ``load`` (safety factor >= 1 - CONTAINMENT_RTOL)."""
        safety, _, single = self._inverse(load)
        held = safety >= 1.0 - CONTAINMENT_RTOL
        return bool(held[0]) if single else held

    def motion(self, load) -> np.ndarray:
        """Unit twist of impending sliding under ``load`` (normality; NaN for the zero load).

        For a load inside the surface it is the motion the load would cause if scaled up to the
        surface. Scaled so that ``(vx, vy, rho * w)`` has unit norm,
        ``rho = characteristic_length``. For a frictionless surface it is the limit ``mu → 0+``
        at the load's direction: the motion of the same patch with ``mu = 1``.
        """
        _, twists, single = self._inverse(load)
        return self._unit_twists(twists[0] if single else twists)

    def motion_and_safety_factor(self, load) -> tuple[np.ndarray, np.ndarray | float]:
        """:meth:`motion` and :meth:`safety_factor` from one solve."""
        safety, twists, single = self._inverse(load)
        if single:
            return self._unit_twists(twists[0]), float(safety[0])
        return self._unit_twists(twists), safety

    def _unit_twists(self, twists: np.ndarray) -> np.ndarray:
        rho = self._rho
        if twists.ndim == 1:  # one query: floats cost less than NumPy calls
            vx, vy, w = twists.tolist()
            return twists / math.sqrt(vx * vx + vy * vy + (rho * w) ** 2)
        scaled = twists * np.array([1.0, 1.0, rho])
        return twists / np.linalg.norm(scaled, axis=-1, keepdims=True)

    # -- plotting and fitting -----------------------------------------------------------------

    def curve(self, plane: str = "fy-m", n: int = 361, *, normalized: bool = False) -> np.ndarray:
        """Cross section of the surface by a coordinate plane, as loads ``(n, 3)``.

        ``plane`` is ``"fx-m"``, ``"fy-m"`` or ``"fx-fy"`` (the third coordinate is zero); the
        points are spread evenly in angle in normalised coordinates, counter-clockwise from the
        first axis (paper Figs. 2, 3, 5). With ``normalized`` forces are divided by
        ``max_force`` and moments by ``max_moment``. A frictionless surface is the load 0: every
        point is 0 (also normalised).
        """
        axes = _PLANES.get(plane)
        if axes is None:
            raise InvalidArgumentError(f"plane must be one of {', '.join(_PLANES)}; got {plane!r}")
        n = _count("n", n)
        directions = np.zeros((n, 3))
        directions[:, axes] = circle(n)
        return self._radial(directions, normalized)

    def sample(self, n: int = 1000, *, normalized: bool = False) -> np.ndarray:
        """``n`` loads ``(n, 3)`` spread evenly over the whole surface (paper Fig. 4).

        Directions are a Fibonacci lattice in normalised coordinates, each scaled onto the
        surface; deterministic.
        """
        return self._radial(fibonacci_sphere(_count("n", n)), normalized)

    def _radial(self, directions: np.ndarray, normalized: bool) -> np.ndarray:
        if self.frictionless:
            return np.zeros_like(directions)
        loads = directions * self._units
        loads = loads * self._inverse(loads)[0][:, None]
        return loads / self._units if normalized else loads


def _binary_scaled(vectors: np.ndarray, reach: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``vectors`` ``(K, 3)`` scaled by powers of two ``2^-e`` (exactly) so that the largest of
    their entries times ``reach`` ``(3,)`` is in ``[0.5, 1)`` (a zero vector stays), and the
    exponents ``e`` ``(K,)``."""
    _, exponents = np.frexp(np.max(np.abs(vectors) * reach, axis=1))
    return np.ldexp(vectors, -exponents[:, None]), exponents


#: Loads whose largest entry [N, N m] lies outside these are scaled before the inverse map
#: (its normalisations by the surface's extents, down to 1e-109, would overflow or underflow).
_SMALLEST_LOAD, _LARGEST_LOAD = 2.0**-500, 2.0**500


def _vectors(name: str, value: object) -> tuple[np.ndarray, bool, int | None]:
    """:func:`validation.vector_batch` of 3-vectors, and the index of the first zero vector
    (``None`` if there is none); one finite 3-vector takes a fast path (single queries)."""
    if isinstance(value, np.ndarray) and value.shape == (3,) and value.dtype == np.float64:
        entries = value.tolist()
        if all(map(math.isfinite, entries)):
            return value[np.newaxis, :], True, None if any(entries) else 0
    array, single = validation.vector_batch(name, value, width=3)
    zero = np.flatnonzero(~np.any(array != 0.0, axis=1))
    return array, single, int(zero[0]) if zero.size else None


def _count(name: str, n: object) -> int:
    if not isinstance(n, int | np.integer) or n < 1:
        raise InvalidArgumentError(f"{name} must be a positive integer, got {n!r}")
    return int(n)


def _check_forces(normal_force: float, scale: float) -> None:
    """Refuse a normal force or friction force ``scale`` [N] below ``MIN_FRICTION_FORCE``."""
    if normal_force < MIN_FRICTION_FORCE or 0.0 < scale < MIN_FRICTION_FORCE:
        small = normal_force < MIN_FRICTION_FORCE
        what, value = ("normal_force", normal_force) if small else ("mu * normal_force", scale)
        hint = "" if small else " (give mu = 0 for a frictionless contact)"
        raise InvalidArgumentError(
            f"{what} = {value!r} N is below {MIN_FRICTION_FORCE:g} N, where the surface's "
            f"arithmetic underflows{hint}"
        )


def _posed(kernel: SupportKernel, pose: Pose) -> SupportKernel:
    """``kernel`` placed by ``pose``: points moved (no rounding from a twist transform), the
    pose of a posed kernel composed with ``pose`` (it stays compiled), others posed."""
    if pose.is_identity:
        return kernel
    if isinstance(kernel, PointSetKernel):
        return dataclasses.replace(kernel, points=pose.apply(kernel.points))
    if isinstance(kernel, PosedKernel):
        return _posed(kernel.local, kernel.pose.then(pose))
    return PosedKernel(kernel, pose)


def _field_kernel(field: PressureField) -> SupportKernel:
    """Unit-friction kernel of a field with constant friction: closed forms where they exist."""
    if isinstance(field, DiskField):
        if field.profile == "annulus":
            local = AnnulusKernel(field.radius_m, field.inner_radius)
        else:
            local = DiskKernel(field.radius_m, field.profile)
    elif isinstance(field, PolygonField):
        starts, ends = polygon_edges(field.vertices)
        far_points, far_weights = triangle_rule(triangulate(field.vertices), _FAR_ORDER)
        local = EdgeSumKernel(
            starts,
            ends,
            np.full(len(starts), 1.0 / field.area),
            PointSetKernel(far_points, far_weights / far_weights.sum()),
        )
    elif isinstance(field, GridField):
        local, middle = _grid_kernel(field)
        offset = field.pose.apply(middle[None, :])[0]
        return _posed(local, dataclasses.replace(field.pose, offset=(offset[0], offset[1])))
    elif isinstance(field, PointsField):  # placed directly: no rounding from a twist transform
        return PointSetKernel(field.pose.apply(field.xy), field.weights, discrete=True)
    elif isinstance(field, FunctionField):
        from fixplan.surface.function_kernel import FunctionKernel

        local = _resolved(
            FunctionKernel(regions=_regions(field.shape), pressure=field.function), "p(x, y)"
        )
    else:  # pragma: no cover - every field class is handled above
        raise InvalidArgumentError(f"unsupported field type {type(field).__name__}")
    return _posed(local, field.pose)


def _cell_squares(field: GridField) -> tuple[np.ndarray, np.ndarray]:
    """Corners ``(n, 4, 2)`` (counter-clockwise) and force fractions of the loaded cells."""
    centers, fractions = field.cells()
    dx, dy = field.cell_size
    corners = np.array([[-dx, -dy], [dx, -dy], [dx, dy], [-dx, dy]]) / 2.0
    return centers[:, None, :] + corners[None, :, :], fractions


def _grid_kernel(field: GridField) -> tuple[GridKernel, np.ndarray]:
    """The node kernel of a grid, with a point rule for far centres of rotation (that of blocks
    of its loaded cells where it has fewer points than a Gauss rule per cell), and the point
    ``(2,)`` [m] of the grid's local frame that is its origin.

    That is the grid's own origin, unless it lies outside the grid (farther from the middle of
    the grid than its corners: a grid not centred, placed away from the contact point): then
    the middle, so that the far rule takes over at four sizes of the grid, not of its distance
    from the origin (closer, the corner sums lose a digit per ten grid sizes).
    """
    centers, fractions = field.cells()
    dx, dy = field.cell_size
    ny, nx = field.values.shape
    middle = np.array([field.x[0] + field.x[-1], field.y[0] + field.y[-1]]) / 2.0
    half_diagonal = np.hypot(field.x[-1] - field.x[0] + dx, field.y[-1] - field.y[0] + dy) / 2
    if np.hypot(*middle) <= half_diagonal:
        middle = np.zeros(2)
    pressure = np.zeros((ny, nx))
    pressure[field.values > 0.0] = fractions / (dx * dy)
    corner_x = field.x[0] - middle[0] + (np.arange(nx + 1) - 0.5) * dx
    corner_y = field.y[0] - middle[1] + (np.arange(ny + 1) - 0.5) * dy
    if len(centers) > 256:
        points, weights = block_rule(corner_x, corner_y, pressure)
    if len(centers) <= 256 or len(weights) >= 9 * len(centers):  # (a Gauss rule per cell: fewer)
        order = 8 if len(centers) <= 16 else 4 if len(centers) <= 256 else 3
        points, weights = field._local_quadrature(order)
        points = points - middle
    far = PointSetKernel(points, weights)
    return GridKernel(*grid_nodes(corner_x, corner_y, pressure), far), middle


def _regions(shape: DiskField | PolygonField) -> tuple:
    """Regions of the function kernel covering a uniform disk or polygon shape."""
    if isinstance(shape, DiskField):
        return (("disk", shape.radius_m, 1.0),)
    return (("polygon", np.asarray(shape.vertices), 1.0),)


def _varying_friction_kernel(field: PressureField, mu: Callable) -> SupportKernel:
    """Kernel of ``mu(x, y) * p`` (unit normal force) for position-dependent friction."""
    from fixplan.surface.function_kernel import SAMPLED, FunctionKernel

    pose = field.pose

    def local_mu(x, y):
        xy = pose.apply(np.column_stack([np.ravel(x), np.ravel(y)]))
        values = validation.field_values("mu", mu, xy[:, 0], xy[:, 1], SAMPLED, (0.0, MAX_MU))
        return values.reshape(np.shape(x))

    if isinstance(field, PointsField):
        friction = field.weights * local_mu(field.xy[:, 0], field.xy[:, 1])
        rubbing = friction > 0.0
        if np.count_nonzero(rubbing) == 1:
            (k,) = np.flatnonzero(rubbing)
            raise InvalidArgumentError(
                f"mu(x, y) is positive at one support point only, {field.xy[k].tolist()} (local "
                "frame): a single point has no torsional friction; use a point-contact model, "
                "or a mu positive at two or more of the points"
            )
        if np.any(rubbing):  # (none: refused by the caller as mu = 0 over the whole patch)
            check_weight_ratio("mu(x, y) times the weights", friction)
            friction = friction[rubbing]
        points = field.xy[rubbing] if np.any(rubbing) else field.xy
        return PointSetKernel(pose.apply(points), friction, discrete=True)
    pressure = None
    if isinstance(field, DiskField):
        radius = field.radius_m
        if field.profile == "ring":
            regions = (("circle", radius, 1.0),)
        elif field.profile == "annulus":
            regions = (("disk", radius, 1.0), ("disk", field.inner_radius, -1.0))
        else:
            regions = (("disk", radius, 1.0),)
            profile = _PROFILE_PRESSURE[field.profile]
            if profile is not None:
                pressure = lambda x, y: profile((x * x + y * y) / radius**2)  # noqa: E731
    elif isinstance(field, PolygonField):
        regions = _regions(field)
    elif isinstance(field, GridField):
        squares, fractions = _cell_squares(field)
        regions = tuple(("polygon", s, f) for s, f in zip(squares, fractions, strict=True))
    elif isinstance(field, FunctionField):
        regions, pressure = _regions(field.shape), field.function
    else:  # pragma: no cover
        raise InvalidArgumentError(f"unsupported field type {type(field).__name__}")
    kernel = FunctionKernel(regions=regions, pressure=pressure, friction=local_mu)
    what = "mu(x, y) times p(x, y)" if isinstance(field, FunctionField) else "mu(x, y)"
    return _posed(_resolved(kernel, what), pose)


def _resolved(kernel: SupportKernel, what: str) -> SupportKernel:
    """``kernel`` (a ``FunctionKernel`` of a user's function ``what``), checked to be resolved
    by its quadrature (:meth:`~fixplan.surface.function_kernel.FunctionKernel.rule_disagreement`
    within ``QUADRATURE_RTOL``)."""
    disagreement = kernel.rule_disagreement()
    if disagreement > QUADRATURE_RTOL:
        raise InvalidArgumentError(
            f"{what} is not smooth enough for the limit surface's quadrature: its rules about a "
            f"centre of rotation near the patch and far from it disagree by {disagreement:.1e} "
            f"of the friction power (smooth fields agree to 1e-14; up to {QUADRATURE_RTOL:g} is "
            "accepted), and its answers would be off by about as much. Where it jumps or has a "
            "kink (a step in pressure, two materials), describe each smooth region as its own "
            "patch and sum them with LimitSurface.combine; sample a narrow peak on a "
            "pressure.grid. On a polygon it must also extend smoothly to "
            f"{FAR_FIELD_RADII:g} patch radii around it, where the rules evaluate it"
        )
    return kernel
