r"""The exact limit surface as a friction model that cvxpy can use.

The pressure field is discretised by its quadrature rule into points ``x_j`` carrying the
fractions ``w_j`` of the normal force. Each point holds a friction force inside its own disk,
and the contact holds the resultant:

.. math::
    \|f_j\| \le \mu_j w_j N, \qquad
    L = \Big(\sum_j f_j,\; \sum_j x_j \times f_j\Big).

This is exactly the limit surface of the point set (the Minkowski sum of the points' disks,
paper §4.1), so the numeric methods use that surface (:attr:`Exact.surface`) and agree with
the constraints to solver accuracy. It differs from the exact surface of the continuous field
by the quadrature error, which the model measures when it is built
(:attr:`Exact.quadrature_error`). The error has both signs, so the model is not conservative.

A frictionless contact keeps the per-point capacities of its shape (``mu = 1``) with
``frictionless=True``: its set is the load 0 and its motion the limit ``mu → 0+``
(:mod:`fixplan.models.base`).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, ClassVar

import numpy as np

from fixplan import validation
from fixplan.errors import InvalidArgumentError
from fixplan.models.base import FrictionModel, fmt
from fixplan.models.conic import unit_conic
from fixplan.surface.sphere import fibonacci_sphere

if TYPE_CHECKING:  # pragma: no cover
    from fixplan.surface.limit_surface import LimitSurface

#: Default quadrature order (Gauss nodes per dimension and panel): 128 points on a disk or a
#: rectangle, a radial error of about 1e-3 (the tests measure it).
DEFAULT_ORDER = 8

#: Number of evenly spread load directions on which the quadrature error is measured.
ERROR_DIRECTIONS = 256


@dataclass(frozen=True, slots=True, kw_only=True, repr=False, eq=False)
class Exact(FrictionModel):
    """The limit surface of a pressure field discretised into per-point friction disks.

    Attributes
    ----------
    points : numpy.ndarray
        Quadrature points ``(n, 2)`` [m] in the contact frame.
    capacity : numpy.ndarray
        Friction force of each point per unit normal force, ``mu_j w_j`` ``(n,)`` [-]; of a
        frictionless model, that of its shape (``w_j``: ``mu = 1``).
    frictionless : bool
        Whether the contact has no friction (``mu = 0``); ``capacity`` then gives only the
        shape, used by :meth:`motion`.
    normal_force : float
        Default normal force of the numeric methods [N].
    quadrature_error : float
        Largest relative radial gap to the exact surface over ``ERROR_DIRECTIONS`` load
        directions (``nan`` when not measured, e.g. built directly from points).
    order : int or None
        Quadrature order the points came from.
    """

    points: np.ndarray
    capacity: np.ndarray
    frictionless: bool = False
    normal_force: float = 1.0
    quadrature_error: float = float("nan")
    order: int | None = None
    _surface: LimitSurface = field(init=False)

    conservative: ClassVar[bool] = False

    def __post_init__(self):
        from fixplan.surface import pressure
        from fixplan.surface.limit_surface import LimitSurface

        points = validation.finite_array("points", self.points, shape=(None, 2))
        capacity = validation.finite_array("capacity", self.capacity, shape=(len(points),))
        if np.any(capacity < 0.0):
            raise InvalidArgumentError(f"capacity must be >= 0, got {capacity.min()!r}")
        if not np.any(capacity > 0.0):
            raise InvalidArgumentError(
                "capacity must have a positive entry; for a frictionless contact pass "
                "frictionless=True with the capacity of its shape (the force fractions w_j)"
            )
        normal_force = validation.positive_scalar("normal_force", self.normal_force)
        loaded = capacity > 0.0
        points, capacity = points[loaded], capacity[loaded]
        points.setflags(write=False)
        capacity.setflags(write=False)
        field_ = pressure.points(points, capacity, centered=False)
        surface = LimitSurface(field_, mu=float(capacity.sum()), normal_force=1.0)
        object.__setattr__(self, "points", points)
        object.__setattr__(self, "capacity", capacity)
        object.__setattr__(self, "frictionless", bool(self.frictionless))
        object.__setattr__(self, "normal_force", normal_force)
        object.__setattr__(self, "quadrature_error", float(self.quadrature_error))
        object.__setattr__(self, "_surface", surface)

    @classmethod
    def from_limit_surface(cls, ls: LimitSurface, *, order: int = DEFAULT_ORDER) -> Exact:
        """Discretise the field of ``ls`` with ``field.quadrature(order)`` and measure the error.

        Works for constant and position-dependent ``mu``, for combined surfaces (the
        quadrature points of every part, weighted by its share of the normal force) and for
        frictionless surfaces (the points of the shape, ``frictionless=True``; the error is
        that of the shape).
        """
        from fixplan.models.ellipsoid import surface_units

        surface_units(ls)
        if isinstance(order, bool) or not isinstance(order, int | np.integer) or order < 1:
            raise InvalidArgumentError(f"order must be a positive integer, got {order!r}")
        shape = ls.friction_shape
        points, capacity = _discretise(shape, int(order))
        model = cls(
            points=points,
            capacity=capacity,
            frictionless=ls.frictionless,
            normal_force=ls.normal_force,
            order=int(order),
        )
        units = np.array([shape.max_force, shape.max_force, shape.max_moment])
        loads = fibonacci_sphere(ERROR_DIRECTIONS) * units
        approx = model.friction_shape.safety_factor(loads)
        error = np.max(np.abs(approx / shape.safety_factor(loads) - 1.0))
        object.__setattr__(model, "quadrature_error", float(error))
        return model

    @property
    def surface(self) -> LimitSurface:
        """Limit surface of the point set at unit normal force: the set the constraints state
        (of the shape for a frictionless model, whose set is the load 0)."""
        return self._surface

    @property
    def mu(self) -> float:
        return 0.0 if self.frictionless else self._shape_mu

    @property
    def _shape_mu(self) -> float:
        return float(self.capacity.sum())

    def _with_shape_friction(self) -> Exact:
        return dataclasses.replace(self, frictionless=False)

    @property
    def rho(self) -> float:
        return self._surface.characteristic_length

    def _surface_loads(self, q):
        """Loads of the surface along ``q``, scaled to unit size, and the scales."""
        size = np.abs(q).max(axis=1)
        size = np.where(size > 0.0, size, 1.0)
        return q / size[:, None] * self._units()[None, :], size

    def _gauge(self, q):
        loads, size = self._surface_loads(q)
        return size / self._surface.safety_factor(loads)

    def _normal(self, q):
        loads, _ = self._surface_loads(q)
        return self._surface.motion(loads) * np.array([1.0, 1.0, self.rho])

    def _unit_conic(self):
        # Auxiliary variables: the point forces z = (f_1, ..., f_n), f_j = (fx_j, fy_j).
        # Rows: q - resultant(z) / units = 0, then (capacity_j N, f_j) in a cone per point.
        x, y = self.points[:, 0], self.points[:, 1]
        count = len(self.capacity)
        resultant = np.zeros((3, 2 * count))
        resultant[0, 0::2] = 1.0
        resultant[1, 1::2] = 1.0
        resultant[2, 0::2], resultant[2, 1::2] = -y, x
        normal = np.zeros(3 + 3 * count)
        normal[3::3] = self.capacity
        q = np.zeros((3 + 3 * count, 3))
        q[:3] = np.eye(3)
        aux = np.zeros((3 + 3 * count, 2 * count))
        aux[:3] = -resultant / self._units()[:, None]
        aux[4::3, 0::2] = np.eye(count)
        aux[5::3, 1::2] = np.eye(count)
        return unit_conic(normal, q, aux, cones=[("zero", 3)] + [("soc", 3)] * count)

    def __repr__(self) -> str:
        order = "" if self.order is None else f", order={self.order}"
        return (
            f"Exact({len(self.points)} points{order}, mu={fmt(self.mu)}, rho={fmt(self.rho)} m, "
            f"quadrature_error={self.quadrature_error:.2g}, "
            f"normal_force={fmt(self.normal_force)} N)"
        )


def _discretise(ls: LimitSurface, order: int) -> tuple[np.ndarray, np.ndarray]:
    """Points and friction per unit normal force of the surface ``ls``."""
    if ls.parts:
        pieces = [_discretise(part, order) for part in ls.parts]
        shares = [part.normal_force / ls.normal_force for part in ls.parts]
        points = np.concatenate([p for p, _ in pieces])
        capacity = np.concatenate([c * s for (_, c), s in zip(pieces, shares, strict=True)])
        return points, capacity
    from fixplan.surface.pressure import friction_values

    points, weights = ls.field.quadrature(order)
    friction = friction_values(ls.mu, points) if callable(ls.mu) else ls.mu
    return np.asarray(points), np.asarray(weights * friction)
