"""Pressure fields of planar contact patches.

A pressure field says how the normal force of a contact is spread over its patch. Every field is
normalised to unit total normal force; the limit surface scales it by the actual normal force.
Coordinates are in the contact frame [m]; the constructors put the origin at the patch centroid
(the centre of pressure for the standard profiles) with the long side of a rectangle along x.
Fields are immutable; :meth:`PressureField.shifted` and :meth:`PressureField.rotated` return moved
copies.

Profiles of :func:`disk` (``R`` the radius, ``r`` the distance from the centre):

- ``"uniform"``: ``p = const``;
- ``"hertz"``: ``p ∝ sqrt(1 - r²/R²)`` (elastic sphere on a flat);
- ``"parabolic"``: ``p ∝ 1 - r²/R²``;
- ``"annulus"``: uniform between ``inner_radius`` and ``R`` (end of a tube, a ring pad);
- ``"ring"``: all force on the circle ``r = R`` (thin ring).
"""

from __future__ import annotations

import dataclasses
from abc import ABC, abstractmethod
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from fixplan import validation
from fixplan.errors import GeometryError, InvalidArgumentError
from fixplan.surface.geometry import (
    Pose,
    merged_points,
    polygon_centroid,
    signed_area,
    simple_polygon,
    triangulate,
)
from fixplan.surface.rules import gauss_jacobi_unit, triangle_rule
from fixplan.tolerances import (
    MAX_ANNULUS_RATIO,
    MAX_ASPECT_RATIO,
    MAX_LENGTH,
    MAX_MU,
    MIN_PATCH_LENGTH,
    MIN_POINT_GAP_RATIO,
    MIN_WEIGHT_RATIO,
)

DISK_PROFILES = ("uniform", "hertz", "parabolic", "annulus", "ring")

#: Exponent ``alpha`` of ``p ∝ (1 - r²/R²)^alpha`` for the profiles of that family.
_PROFILE_EXPONENT = {"uniform": 0.0, "hertz": 0.5, "parabolic": 1.0}

#: Default quadrature order (Gauss nodes per dimension and panel) of :meth:`quadrature`.
DEFAULT_ORDER = 24

MuLike = float | Callable[[np.ndarray, np.ndarray], np.ndarray]


@dataclass(frozen=True, slots=True, kw_only=True)
class PressureField(ABC):
    """Base of all pressure fields: a shape in a local frame placed by a :class:`Pose`."""

    pose: Pose = field(default_factory=Pose)

    @property
    @abstractmethod
    def radius(self) -> float:
        """Radius [m] of the smallest circle about the local origin that holds the patch."""

    @property
    def center(self) -> np.ndarray:
        """Position of the local origin in the contact frame [m]."""
        return np.array(self.pose.offset, dtype=float)

    @property
    def is_discrete(self) -> bool:
        """Whether the field is a set of point supports (its limit surface has facets)."""
        return False

    @abstractmethod
    def _local_quadrature(self, order: int) -> tuple[np.ndarray, np.ndarray]:
        """Points ``(n, 2)`` [m] in the local frame and weights summing to 1."""

    def quadrature(self, order: int = DEFAULT_ORDER) -> tuple[np.ndarray, np.ndarray]:
        """Quadrature points ``(n, 2)`` [m] in the contact frame and weights summing to 1.

        The weight of a point is the fraction of the normal force it stands for. ``order`` is the
        number of Gauss nodes per dimension and panel (ignored by point sets).
        """
        order = int(order)
        if order < 1:
            raise InvalidArgumentError(f"order must be >= 1, got {order}")
        points, weights = self._local_quadrature(order)
        keep = weights > 0.0
        points, weights = self.pose.apply(points[keep]), weights[keep]
        weights = weights / weights.sum()
        points.setflags(write=False)
        weights.setflags(write=False)
        return points, weights

    def center_of_pressure(self, mu: MuLike | None = None) -> np.ndarray:
        """Centre of pressure ``(x, y)`` [m] in the contact frame (paper eq. 2).

        With a position-dependent friction coefficient ``mu(x, y)`` the centre is weighted by
        ``mu * p`` as in the paper; a scalar or ``None`` gives the plain centre of pressure.
        """
        points, weights = self.quadrature()
        if callable(mu):
            weights = weights * friction_values(mu, points)
        return weights @ points / weights.sum()

    def shifted(self, dx: float, dy: float) -> PressureField:
        """The same field translated by ``(dx, dy)`` [m]."""
        dx = validation.finite_scalar("dx", dx)
        dy = validation.finite_scalar("dy", dy)
        return self._placed(self.pose.shifted(dx, dy))

    def rotated(self, angle: float, about: tuple[float, float] = (0.0, 0.0)) -> PressureField:
        """The same field rotated by ``angle`` [rad] counter-clockwise about ``about`` [m]."""
        angle = validation.finite_scalar("angle", angle)
        about_xy = validation.finite_array("about", about, shape=(2,))
        return self._placed(self.pose.rotated(angle, tuple(about_xy)))

    def _placed(self, pose: Pose) -> PressureField:
        """The same field at ``pose``, whose offset must stay within ``MAX_LENGTH``."""
        validation.coordinates("the field's placed origin", np.array(pose.offset))
        return dataclasses.replace(self, pose=pose)


def friction_values(mu: Callable, points: np.ndarray) -> np.ndarray:
    """Evaluate ``mu(x, y)`` at ``points`` and check that it is from 0 to ``MAX_MU``."""
    values = validation.field_values("mu", mu, points[:, 0], points[:, 1], within=(0.0, MAX_MU))
    if not np.any(values > 0.0):
        raise InvalidArgumentError("mu(x, y) is zero over the whole patch: there is no friction")
    return values


@dataclass(frozen=True, slots=True, kw_only=True)
class DiskField(PressureField):
    """An axisymmetric pressure profile on a disk (see the module docstring)."""

    radius_m: float
    profile: str = "uniform"
    inner_radius: float = 0.0

    @property
    def radius(self) -> float:
        return self.radius_m

    def _local_quadrature(self, order):
        radius, profile = self.radius_m, self.profile
        n_theta = 2 * order
        theta = (np.arange(n_theta) + 0.5) * (2.0 * np.pi / n_theta)
        if profile == "ring":
            s, ws = np.array([1.0]), np.array([1.0])
        elif profile == "annulus":
            lo = (self.inner_radius / radius) ** 2
            t, wt = gauss_jacobi_unit(order)
            s, ws = lo + (1.0 - lo) * t, wt
        else:  # in s = r²/R², p r dr ∝ (1 - s)^alpha ds: a Gauss-Jacobi weight
            s, ws = gauss_jacobi_unit(order, _PROFILE_EXPONENT[profile], 0.0)
        r = radius * np.sqrt(s)
        rr, tt = np.meshgrid(r, theta, indexing="ij")
        weights = np.outer(ws, np.full(n_theta, 1.0 / n_theta)).ravel()
        points = np.column_stack([(rr * np.cos(tt)).ravel(), (rr * np.sin(tt)).ravel()])
        return points, weights / weights.sum()


@dataclass(frozen=True, slots=True, kw_only=True)
class PolygonField(PressureField):
    """Uniform pressure on a simple polygon (vertices counter-clockwise, local frame)."""

    vertices: np.ndarray

    @property
    def radius(self) -> float:
        return float(np.max(np.hypot(self.vertices[:, 0], self.vertices[:, 1])))

    @property
    def area(self) -> float:
        """Area of the polygon [m^2]."""
        return signed_area(self.vertices)

    def _local_quadrature(self, order):
        points, weights = triangle_rule(triangulate(self.vertices), order)
        return points, weights / weights.sum()


@dataclass(frozen=True, slots=True, kw_only=True)
class PointsField(PressureField):
    """Discrete point supports ``xy`` (local frame) carrying fractions ``weights`` of the force."""

    xy: np.ndarray
    weights: np.ndarray

    @property
    def radius(self) -> float:
        return float(np.max(np.hypot(self.xy[:, 0], self.xy[:, 1])))

    @property
    def is_discrete(self) -> bool:
        return True

    def _local_quadrature(self, order):
        return self.xy, self.weights


@dataclass(frozen=True, slots=True, kw_only=True)
class GridField(PressureField):
    """A pressure map of equal rectangular cells, uniform within each cell (a tactile array).

    ``x`` (``nx``) and ``y`` (``ny``) are the cell centres in the local frame [m], ``values``
    ``(ny, nx)`` the relative pressure of each cell (row ``j`` at ``y[j]``).
    """

    x: np.ndarray
    y: np.ndarray
    values: np.ndarray

    @property
    def cell_size(self) -> tuple[float, float]:
        """Cell width along x and y [m]."""
        return float(self.x[1] - self.x[0]), float(self.y[1] - self.y[0])

    @property
    def radius(self) -> float:
        dx, dy = self.cell_size
        xs = np.abs(self.x) + dx / 2
        ys = np.abs(self.y) + dy / 2
        return float(np.hypot(xs.max(), ys.max()))

    def cells(self) -> tuple[np.ndarray, np.ndarray]:
        """Centres ``(n, 2)`` [m] of the loaded cells and their fractions of the normal force."""
        xx, yy = np.meshgrid(self.x, self.y)
        loaded = self.values > 0.0
        centers = np.column_stack([xx[loaded], yy[loaded]])
        fractions = self.values[loaded] / self.values[loaded].sum()
        return centers, fractions

    def center_of_pressure(self, mu: MuLike | None = None) -> np.ndarray:
        """Centre of pressure ``(x, y)`` [m] in the contact frame (paper eq. 2): for a scalar
        or no ``mu`` exactly, from the cells' centres, instead of from a Gauss rule of
        ``DEFAULT_ORDER²`` points per cell (14 million points on a 200 x 200 grid)."""
        if callable(mu):
            return PressureField.center_of_pressure(self, mu)
        centers, fractions = self.cells()
        return self.pose.apply((fractions @ centers)[None, :])[0]

    def _local_quadrature(self, order):
        centers, fractions = self.cells()
        dx, dy = self.cell_size
        t, wt = gauss_jacobi_unit(order)
        ox, oy = np.meshgrid((t - 0.5) * dx, (t - 0.5) * dy, indexing="ij")
        w = np.outer(wt, wt).ravel()
        points = centers[:, None, :] + np.column_stack([ox.ravel(), oy.ravel()])[None, :, :]
        weights = fractions[:, None] * w[None, :]
        return points.reshape(-1, 2), weights.ravel()


@dataclass(frozen=True, slots=True, kw_only=True)
class FunctionField(PressureField):
    """Pressure ``p(x, y) >= 0`` (local coordinates of ``shape``) over a disk or polygon."""

    shape: DiskField | PolygonField
    function: Callable[[np.ndarray, np.ndarray], np.ndarray]

    @property
    def radius(self) -> float:
        return self.shape.radius

    def pressure(self, points: np.ndarray) -> np.ndarray:
        """Relative pressure at local ``points`` ``(n, 2)``, checked finite and >= 0."""
        values = validation.field_values("p", self.function, points[:, 0], points[:, 1])
        if np.any(values < 0.0):
            raise InvalidArgumentError("p(x, y) must be finite and >= 0 over the whole patch")
        return values

    def _local_quadrature(self, order):
        points, weights = self.shape._local_quadrature(order)
        weights = weights * self.pressure(points)
        return points, weights / weights.sum()


def disk(
    radius: float, profile: str = "uniform", *, inner_radius: float | None = None
) -> DiskField:
    """Axisymmetric pressure on a disk of ``radius`` [m] centred at the origin.

    ``inner_radius`` [m] (``0 < inner_radius <= MAX_ANNULUS_RATIO * radius``) is required by,
    and only allowed with, ``profile="annulus"``.
    """
    radius = _patch_length("radius", radius)
    profile = validation.choice("profile", profile, DISK_PROFILES)
    if profile == "annulus":
        if inner_radius is None:
            raise InvalidArgumentError(
                "profile 'annulus' needs inner_radius (0 < inner_radius < radius)"
            )
        inner = validation.positive_scalar("inner_radius", inner_radius)
        if inner >= radius:
            raise InvalidArgumentError(f"inner_radius must be < radius = {radius!r}, got {inner!r}")
        if inner > MAX_ANNULUS_RATIO * radius:
            raise InvalidArgumentError(
                f"inner_radius / radius = {inner / radius!r} is above {MAX_ANNULUS_RATIO}: the "
                "annulus's closed form (two disks subtracted) loses the digits of the ratio "
                f"1 / (1 - (inner_radius / radius)²); up to {MAX_ANNULUS_RATIO} it keeps 1e-13. "
                "Model so thin a ring with profile 'ring' at the mean radius"
            )
        return DiskField(radius_m=radius, profile=profile, inner_radius=inner)
    if inner_radius is not None:
        raise InvalidArgumentError(f"inner_radius is only for profile 'annulus', not {profile!r}")
    return DiskField(radius_m=radius, profile=profile)


def _patch_length(name: str, value) -> float:
    """``value`` [m] as a float from ``MIN_PATCH_LENGTH`` to ``MAX_LENGTH``."""
    length = validation.positive_scalar(name, value)
    if length < MIN_PATCH_LENGTH:
        raise GeometryError(
            f"{name} must be at least {MIN_PATCH_LENGTH:g} m (below it the limit surface's "
            f"arithmetic underflows), got {length!r}"
        )
    if length > MAX_LENGTH:
        raise GeometryError(f"{name} must be at most {MAX_LENGTH:g} m, got {length!r}")
    return length


def rectangle(length: float, width: float) -> PolygonField:
    """Uniform pressure on a ``length`` x ``width`` [m] rectangle, long side along x, centred."""
    a = _patch_length("length", length) / 2.0
    b = _patch_length("width", width) / 2.0
    vertices = np.array([[-a, -b], [a, -b], [a, b], [-a, b]])
    vertices.setflags(write=False)
    return PolygonField(vertices=vertices)


def polygon(vertices, *, centered: bool = True) -> PolygonField:
    """Uniform pressure on a simple polygon with ``vertices`` ``(n, 2)`` [m], in order.

    With ``centered`` (default) the polygon is moved so that its centroid is the origin; otherwise
    the given coordinates are kept. Raises :class:`GeometryError` for self-intersecting or
    degenerate polygons.
    """
    points = validation.coordinates(
        "vertices", validation.finite_array("vertices", vertices, shape=(None, 2))
    )
    ccw = simple_polygon("vertices", points)
    _patch_length("vertices' extent", float(np.max(np.ptp(ccw, axis=0))))
    if centered:
        ccw = ccw - polygon_centroid(ccw)
    ccw = np.array(ccw, dtype=float)
    ccw.setflags(write=False)
    return PolygonField(vertices=ccw)


def points(xy, weights=None, *, centered: bool = True) -> PointsField:
    """Discrete point supports at ``xy`` ``(n, 2)`` [m] with relative normal forces ``weights``.

    Weights (default equal) must be >= 0 and are normalised to sum 1; points with zero weight are
    dropped (positive weights must be at least ``MIN_WEIGHT_RATIO`` of the largest: set
    smaller ones to 0), and a point given more than once is one support carrying the sum of its
    weights (the same field; the facet of a support point is its whole force's, which no copy
    alone carries). At least two distinct loaded points are needed: a single point has no torsional
    friction (use a point-contact model). With ``centered`` (default) the points are moved so that
    their centre of pressure is the origin.
    """
    xy_array = validation.coordinates("xy", validation.finite_array("xy", xy, shape=(None, 2)))
    if len(xy_array) == 0:
        raise InvalidArgumentError(
            "xy must hold at least two distinct loaded points (n >= 2), got an empty set"
        )
    if weights is None:
        w = np.ones(len(xy_array))
    else:
        w = validation.finite_array("weights", weights, shape=(len(xy_array),))
        if np.any(w < 0.0):
            raise InvalidArgumentError(f"weights must be >= 0, got {float(w.min())!r}")
        if not np.any(w > 0.0):
            raise InvalidArgumentError("weights are all zero: the points carry no force")
    loaded = w > 0.0
    xy_array, w = merged_points(xy_array[loaded], w[loaded])
    w = w / w.sum()
    check_weight_ratio("weights", w)
    span = float(np.max(np.ptp(xy_array, axis=0))) if len(xy_array) > 1 else 0.0
    if span == 0.0:
        raise GeometryError(
            "points needs at least two distinct loaded points; a single point has no torsional "
            "friction (use a point-contact model for it)"
        )
    _patch_length("xy: the loaded points' span", span)
    _check_separation(xy_array, span)
    if centered:
        xy_array = xy_array - w @ xy_array
    xy_array = np.array(xy_array)
    xy_array.setflags(write=False)
    w.setflags(write=False)
    return PointsField(xy=xy_array, weights=w)


def measurable(weights) -> np.ndarray:
    """``weights`` with the positive ones below ``MIN_WEIGHT_RATIO`` of the largest set to 0
    (negative ones are left for :func:`points` to refuse): the rims of a
    field measured by a sensor or computed by an engine (forces of 1e-15 of the peak), which
    :func:`points` refuses."""
    weights = np.array(weights, dtype=float)
    weights[(weights > 0.0) & (weights < MIN_WEIGHT_RATIO * weights.max(initial=0.0))] = 0.0
    return weights


def _check_separation(xy: np.ndarray, span: float) -> None:
    """Raise where two distinct points ``xy`` ``(n, 2)`` [m] lie closer than
    ``MIN_POINT_GAP_RATIO`` of their ``span`` [m]."""
    from scipy.spatial import cKDTree

    pairs = cKDTree(xy).query_pairs(MIN_POINT_GAP_RATIO * span, output_type="ndarray")
    if len(pairs):
        i, j = pairs[0]
        gap = float(np.hypot(*(xy[i] - xy[j])))
        raise GeometryError(
            f"xy: points {xy[i].tolist()} and {xy[j].tolist()} are {gap!r} m apart, closer than "
            f"{MIN_POINT_GAP_RATIO:g} of the points' span ({span!r} m): the inverse map cannot "
            "tell them apart. Give them as one point (the sum of their weights) or farther apart"
        )


def check_weight_ratio(name: str, weights: np.ndarray) -> None:
    """Raise unless every positive entry of ``weights`` is at least :data:`MIN_WEIGHT_RATIO`
    of the largest."""
    positive = weights[weights > 0.0]
    smallest, largest = float(positive.min()), float(positive.max())
    if smallest < MIN_WEIGHT_RATIO * largest:
        raise InvalidArgumentError(
            f"{name}: the smallest positive weight {smallest!r} is below {MIN_WEIGHT_RATIO:g} of "
            f"the largest {largest!r}; the limit surface of point supports is not computed "
            "accurately beyond that ratio. Set so small weights to 0 (they carry no measurable "
            "force) or spread the load more evenly"
        )


def grid(x, y, values, *, centered: bool = True) -> GridField:
    """A measured pressure map: cell centres ``x`` ``(nx,)``, ``y`` ``(ny,)`` [m], ``values``
    ``(ny, nx)`` relative pressures (>= 0; zero cells allowed), uniform within each cell.

    Centres must be equally spaced and increasing. With ``centered`` (default) the map is moved
    so that its centre of pressure is the origin.
    """
    xs = validation.coordinates("x", validation.finite_array("x", x, shape=(None,)))
    ys = validation.coordinates("y", validation.finite_array("y", y, shape=(None,)))
    vals = validation.finite_array("values", values, shape=(len(ys), len(xs)))
    for name, axis in (("x", xs), ("y", ys)):
        steps = np.diff(axis)
        if len(steps) and (np.any(steps <= 0) or np.ptp(steps) > 1e-9 * abs(steps[0])):
            raise InvalidArgumentError(
                f"{name} must be increasing and equally spaced (cells of equal size)"
            )
        if len(axis) < 2:
            raise InvalidArgumentError(
                f"{name} must hold at least two cell centres to define the cell size"
            )
        _patch_length(f"{name}: the cells' width", float(steps[0]))
    extents = (len(xs) * float(xs[1] - xs[0]), len(ys) * float(ys[1] - ys[0]))
    if max(extents) > MAX_ASPECT_RATIO * min(extents):
        raise InvalidArgumentError(
            f"the grid is {extents[0]!r} m by {extents[1]!r} m: its sides' ratio is above "
            f"{MAX_ASPECT_RATIO:g} (the inverse map loses accuracy on needles); model so thin a "
            "strip as points along a line"
        )
    if np.any(vals < 0.0):
        j, i = np.argwhere(vals < 0.0)[0]
        raise InvalidArgumentError(
            f"values must be >= 0, got {float(vals[j, i])!r} at values[{j}][{i}]"
        )
    if not np.any(vals > 0.0):
        raise InvalidArgumentError("values are all zero: the grid carries no pressure")
    field_ = GridField(x=xs, y=ys, values=vals)
    if centered:
        centers, fractions = field_.cells()
        cx, cy = fractions @ centers
        shifted_x, shifted_y = np.array(xs - cx), np.array(ys - cy)
        shifted_x.setflags(write=False)
        shifted_y.setflags(write=False)
        field_ = GridField(x=shifted_x, y=shifted_y, values=vals)
    return field_


def from_function(shape: DiskField | PolygonField, p: Callable) -> FunctionField:
    """Arbitrary pressure ``p(x, y) >= 0`` over a uniform ``shape`` (a disk or polygon field).

    ``p`` takes arrays of local coordinates [m] and returns relative pressures. The patch keeps
    the shape's origin (its centroid), not the centre of pressure. ``p`` must be smooth over the
    patch: its limit surface integrates it by rules adapted to the centre of rotation, not to
    jumps, kinks or narrow peaks of ``p``, and refuses one they do not resolve to
    ``QUADRATURE_RTOL`` (a step: describe each smooth region as its own patch and sum their
    surfaces with ``LimitSurface.combine``; a narrow peak: sample it with :func:`grid`).
    """
    if not isinstance(shape, DiskField | PolygonField) or (
        isinstance(shape, DiskField) and shape.profile != "uniform"
    ):
        raise InvalidArgumentError(
            f"shape must be a uniform disk, rectangle or polygon field, got {type(shape).__name__}"
        )
    validation.callable_argument("p", p)
    result = FunctionField(
        shape=dataclasses.replace(shape, pose=Pose()), function=p, pose=shape.pose
    )
    points_, _ = shape._local_quadrature(DEFAULT_ORDER)
    if not np.any(result.pressure(points_) > 0.0):
        raise InvalidArgumentError("p(x, y) is zero over the whole patch: it carries no pressure")
    return result


__all__ = [
    "DISK_PROFILES",
    "MAX_ANNULUS_RATIO",
    "MIN_WEIGHT_RATIO",
    "DiskField",
    "FunctionField",
    "GridField",
    "PointsField",
    "PolygonField",
    "PressureField",
    "disk",
    "from_function",
    "grid",
    "measurable",
    "points",
    "polygon",
    "rectangle",
]
