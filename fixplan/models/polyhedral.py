r"""Conservative and linear friction models: the cone and pyramids of the paper (§4.2, eq. 11)
and the Coulomb cone and pyramids of point contacts.

None of them has a motion map: the normals of a cone or a pyramid do not give the sliding
direction (paper §4.2), except for the Coulomb cone of a point, whose normal is the sliding
direction of the point (maximum dissipation).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, ClassVar

import numpy as np

from fixplan import validation
from fixplan.errors import InvalidArgumentError
from fixplan.models.base import FrictionModel, facet_count, fmt, polygon_normals
from fixplan.models.conic import unit_conic
from fixplan.models.ellipsoid import (
    _shear,
    area_parameters,
    area_repr,
    check_area,
    limit_parameters,
    surface_axis,
    surface_units,
)
from fixplan.tolerances import TILT_ATOL

if TYPE_CHECKING:  # pragma: no cover
    from fixplan.surface.limit_surface import LimitSurface


@dataclass(frozen=True, slots=True, kw_only=True, repr=False)
class Cone(FrictionModel):
    r"""Double cone with apexes at the maximum moment and base circle of radius ``max_force``.

    In normalised coordinates (forces over ``mu N``, moment over ``mu rho N``)

    .. math:: \|q_f - q_m t\| \le 1 - |q_m|,

    the convex hull of the pure-translation circle and the two loads at maximum moment
    ``±(t, 1)``; all of them lie on the exact limit surface, which is convex, so the cone lies
    inside it: conservative for every contact (paper §4.2). ``t`` tilts the axis through the
    load at maximum moment, as for :class:`~fixplan.models.Ellipsoid`; moments are taken about
    the centre of pressure ``center``, where the translation loads have no moment. Any section
    through the moment axis is the straight line ``|f|/max_force + |m|/max_moment = 1`` of the
    paper's moment-force plots (:meth:`curve`).

    Attributes
    ----------
    mu : float
        Maximum friction force per unit normal force [-]; 0 for a frictionless contact.
    rho : float
        Maximum moment over maximum force [m] (of the pressure shape when ``mu = 0``).
    tilt : tuple of float
        Force at maximum moment over the maximum force [-].
    center : tuple of float
        Centre of pressure [m] about which the moments are taken.
    normal_force : float
        Default normal force of the numeric methods [N].
    apex_on_surface : bool
        Whether the apexes ``±(t, 1)`` are the loads at maximum moment of the contact's limit
        surface. Only then is the cone conservative: an untilted cone of a skewed pressure
        field has its apexes outside the surface. :meth:`from_limit_surface` sets it; with
        :meth:`from_limits` it is the caller's claim that ``apex_force`` is the true one.
    """

    mu: float
    rho: float
    tilt: tuple[float, float] = (0.0, 0.0)
    center: tuple[float, float] = (0.0, 0.0)
    normal_force: float = 1.0
    apex_on_surface: bool = True

    def __post_init__(self):
        check_area(self)

    @property
    def conservative(self) -> bool:  # type: ignore[override]
        """True when the apexes are the surface's loads at maximum moment."""
        return self.apex_on_surface

    @classmethod
    def from_limit_surface(cls, ls: LimitSurface, *, tilted: bool = True) -> Cone:
        """The cone of an exact limit surface (tilted through its load at maximum moment)."""
        return cls(**area_parameters(ls, tilted), apex_on_surface=_apex_on_surface(ls, tilted))

    @classmethod
    def from_limits(
        cls,
        *,
        max_force: float,
        max_moment: float,
        normal_force: float = 1.0,
        apex_force: tuple[float, float] = (0.0, 0.0),
        center: tuple[float, float] = (0.0, 0.0),
    ) -> Cone:
        """From the largest force [N] and moment [N m] about ``center`` [m] at
        ``normal_force`` [N]; ``apex_force`` [N] is the force of the load at largest moment."""
        return cls(**limit_parameters(max_force, max_moment, normal_force, apex_force, center))

    def _gauge(self, q):
        t = self.tilt
        fx = q[:, 0] - t[0] * q[:, 2]
        fy = q[:, 1] - t[1] * q[:, 2]
        return np.sqrt(fx * fx + fy * fy) + np.abs(q[:, 2])

    def _gauge_terms(self):
        return (("norm", _shear(self.tilt)[:2]), ("norm", np.array([[0.0, 0.0, 1.0]])))

    def _unit_conic(self):
        # ||F q|| + |q_m| <= N  as  ||F q|| <= N - q_m  and  ||F q|| <= N + q_m.
        force = _shear(self.tilt)[:2]
        moment = np.array([[0.0, 0.0, 1.0]])
        return unit_conic(
            [1.0, 0.0, 0.0, 1.0, 0.0, 0.0],
            np.vstack([-moment, force, moment, force]),
            cones=[("soc", 3), ("soc", 3)],
        )

    def __repr__(self) -> str:
        return area_repr(self, _apex_note(self))


def _linear_conic(rows: np.ndarray):
    """``rows @ q <= N``: linear inequalities."""
    return unit_conic(np.ones(len(rows)), -rows, cones=[("nonneg", len(rows))])


def _apex_note(model) -> str:
    """Repr fragment flagging apexes off the limit surface (not conservative)."""
    return "" if model.apex_on_surface else "apex off the surface, "


def _apex_on_surface(ls: LimitSurface, tilted: bool) -> bool:
    """Whether a (possibly untilted) cone of ``ls`` has its apexes on the surface."""
    return tilted or max(abs(t) for t in area_parameters(ls, True)["tilt"]) <= TILT_ATOL


def _apothem(facets: int, inscribed: bool) -> float:
    """Distance of the facets from the centre of a regular polygon about the unit circle."""
    return math.cos(math.pi / facets) if inscribed else 1.0


def _polygon_gauge(fx: np.ndarray, fy: np.ndarray, facets: int, apothem: float) -> np.ndarray:
    """``max_j n_j · f / apothem`` for the normals ``n_j`` at angles ``2πj/k``.

    Written as ``|f| cos(δ)`` with ``δ`` the angle from ``f`` to the nearest normal: the cost
    does not grow with ``k``, and it avoids thin matrix products (slow in BLAS).
    """
    sector = 2.0 * math.pi / facets
    delta = np.mod(np.arctan2(fy, fx) + 0.5 * sector, sector) - 0.5 * sector
    return np.hypot(fx, fy) * np.cos(delta) / apothem


@dataclass(frozen=True, slots=True, kw_only=True, repr=False)
class Pyramid(FrictionModel):
    r"""Linear pyramid of the paper's eq. 11 and its generalisation to ``k`` facets.

    The cone's circle is replaced by a regular ``k``-gon with facet normals
    ``n_j = (cos 2πj/k, sin 2πj/k)``, inscribed in the circle (``c = cos(π/k)``, conservative)
    or circumscribed about it (``c = 1``):

    .. math:: n_j \cdot (q_f - q_m t) \le c\,(1 - |q_m|), \qquad j = 1 \dots k.

    For ``k = 4`` inscribed and no tilt this is eq. 11 (Kerr and Roth):
    ``|fx|, |fy| <= (mu N - |m|/lambda)/sqrt(2)``, whose bound ``|m| <= m_max`` the facets
    imply. The ``2k`` linear inequalities (:meth:`inequalities`) suit LP and QP solvers such
    as OSQP.

    Attributes
    ----------
    mu, rho, tilt, center, normal_force
        As for :class:`Cone`.
    facets : int
        Number of facets ``k >= 3`` of the force polygon.
    inscribed : bool
        Polygon inside the circle (conservative) or about it.
    apex_on_surface : bool
        As for :class:`Cone`.
    """

    mu: float
    rho: float
    tilt: tuple[float, float] = (0.0, 0.0)
    center: tuple[float, float] = (0.0, 0.0)
    facets: int = 4
    inscribed: bool = True
    normal_force: float = 1.0
    apex_on_surface: bool = True
    _rows: np.ndarray = field(init=False, compare=False)

    def __post_init__(self):
        check_area(self)
        object.__setattr__(self, "facets", facet_count(self.facets))
        object.__setattr__(self, "inscribed", bool(self.inscribed))
        normals = polygon_normals(self.facets) / _apothem(self.facets, self.inscribed)
        slope = normals @ np.asarray(self.tilt)
        rows = np.vstack(
            [
                np.column_stack([normals, 1.0 - slope]),
                np.column_stack([normals, -1.0 - slope]),
            ]
        )
        rows.setflags(write=False)
        object.__setattr__(self, "_rows", rows)

    @property
    def conservative(self) -> bool:  # type: ignore[override]
        """True for the inscribed pyramid whose apexes are on the surface (inside the cone,
        hence inside the surface)."""
        return self.inscribed and self.apex_on_surface

    @classmethod
    def from_limit_surface(
        cls, ls: LimitSurface, *, facets: int = 4, inscribed: bool = True, tilted: bool = True
    ) -> Pyramid:
        """The pyramid of an exact limit surface (tilted through its load at maximum moment)."""
        return cls(
            facets=facets,
            inscribed=inscribed,
            apex_on_surface=_apex_on_surface(ls, tilted),
            **area_parameters(ls, tilted),
        )

    @classmethod
    def from_limits(
        cls,
        *,
        max_force: float,
        max_moment: float,
        normal_force: float = 1.0,
        apex_force: tuple[float, float] = (0.0, 0.0),
        center: tuple[float, float] = (0.0, 0.0),
        facets: int = 4,
        inscribed: bool = True,
    ) -> Pyramid:
        """As :meth:`Cone.from_limits`, with ``facets`` and ``inscribed``."""
        parameters = limit_parameters(max_force, max_moment, normal_force, apex_force, center)
        return cls(facets=facets, inscribed=inscribed, **parameters)

    def inequalities(self, *, normal_force: float | None = None) -> tuple[np.ndarray, np.ndarray]:
        """``(A, b)`` with the pyramid ``{L : A @ L <= b}`` for loads ``L`` [N, N, N m].

        ``A`` is ``(2k, 3)``, ``b`` ``(2k,)`` [N]; ``normal_force`` [N] defaults to the model's.
        A frictionless model gives ``A`` of its shape and ``b = 0``: the pyramid is bounded, so
        ``A @ L <= 0`` holds for ``L = 0`` only.
        """
        force = self.normal_force if normal_force is None else normal_force
        force = validation.positive_scalar("normal_force", force)
        matrix = self._rows @ self._normalising_map()
        return matrix, np.full(len(self._rows), 0.0 if self.frictionless else force)

    def _gauge(self, q):
        t = self.tilt
        fx = q[:, 0] - t[0] * q[:, 2]
        fy = q[:, 1] - t[1] * q[:, 2]
        apothem = _apothem(self.facets, self.inscribed)
        return _polygon_gauge(fx, fy, self.facets, apothem) + np.abs(q[:, 2])

    def _gauge_terms(self):
        return (("max", self._rows),)

    def _unit_conic(self):
        return _linear_conic(self._rows)

    def __repr__(self) -> str:
        kind = "inscribed" if self.inscribed else "circumscribed"
        return area_repr(self, f"facets={self.facets}, {kind}, {_apex_note(self)}")


def _point_mu(ls: LimitSurface) -> tuple[float, float]:
    """Friction coefficient and normal force of a point model of ``ls``.

    Only the section ``m = 0`` about the centre of pressure is the whole disk of radius
    ``max_force``; about another origin the disk would stick out of the surface.
    """
    mu, _, normal_force = surface_units(ls)
    (cx, cy), _, _ = surface_axis(ls)
    if cx != 0.0 or cy != 0.0:
        raise InvalidArgumentError(
            f"the frame origin of {ls!r} is not its centre of pressure ({cx:.6g}, {cy:.6g}) m: "
            "a point contact bears no moment, so place it at the centre of pressure (build the "
            "surface of field.shifted(-cx, -cy))"
        )
    return mu, normal_force


@dataclass(frozen=True, slots=True, kw_only=True, repr=False)
class PointCone(FrictionModel):
    r"""Coulomb's friction cone of a point contact: ``‖(fx, fy)‖ <= mu N``, no torsion.

    A second-order cone. It is the ``m = 0`` section of any limit surface with friction
    ``mu`` written about its centre of pressure, hence conservative. Motion: the point slides along the applied force (maximum
    dissipation), returned as a unit velocity.

    Attributes
    ----------
    mu : float
        Friction coefficient [-]; 0 for a frictionless contact.
    normal_force : float
        Default normal force of the numeric methods [N].
    """

    mu: float
    normal_force: float = 1.0

    conservative: ClassVar[bool] = True
    torsion: ClassVar[bool] = False

    def __post_init__(self):
        object.__setattr__(self, "mu", validation.nonnegative_scalar("mu", self.mu))
        object.__setattr__(
            self, "normal_force", validation.positive_scalar("normal_force", self.normal_force)
        )

    @classmethod
    def from_limit_surface(cls, ls: LimitSurface) -> PointCone:
        """The cone of the surface's largest force (its torsional friction is dropped)."""
        mu, normal_force = _point_mu(ls)
        return cls(mu=mu, normal_force=normal_force)

    def _gauge(self, q):
        return np.hypot(q[:, 0], q[:, 1])

    def _gauge_terms(self):
        return (("norm", np.eye(2)),)

    def _normal(self, q):
        return q

    def _unit_conic(self):
        return unit_conic([1.0, 0.0, 0.0], np.vstack([np.zeros(2), np.eye(2)]), cones=[("soc", 3)])

    def __repr__(self) -> str:
        return f"PointCone(mu={fmt(self.mu)}, normal_force={fmt(self.normal_force)} N)"


@dataclass(frozen=True, slots=True, kw_only=True, repr=False)
class PointPyramid(FrictionModel):
    r"""Polygonal linearisation of the Coulomb cone, as used in simulators.

    ``n_j · (fx, fy) <= c mu N`` for the ``k`` facet normals ``n_j = (cos 2πj/k, sin 2πj/k)``,
    with ``c = cos(π/k)`` for the polygon inscribed in the circle (conservative) and ``c = 1``
    circumscribed about it. No torsion, no motion map.

    Attributes
    ----------
    mu, normal_force
        As for :class:`PointCone`.
    facets : int
        Number of facets ``k >= 3``.
    inscribed : bool
        Polygon inside the circle (conservative) or about it.
    """

    mu: float
    facets: int = 4
    inscribed: bool = True
    normal_force: float = 1.0
    _rows: np.ndarray = field(init=False, compare=False)

    torsion: ClassVar[bool] = False

    def __post_init__(self):
        object.__setattr__(self, "mu", validation.nonnegative_scalar("mu", self.mu))
        object.__setattr__(
            self, "normal_force", validation.positive_scalar("normal_force", self.normal_force)
        )
        object.__setattr__(self, "facets", facet_count(self.facets))
        object.__setattr__(self, "inscribed", bool(self.inscribed))
        rows = polygon_normals(self.facets) / _apothem(self.facets, self.inscribed)
        rows.setflags(write=False)
        object.__setattr__(self, "_rows", rows)

    @property
    def conservative(self) -> bool:  # type: ignore[override]
        """True for the inscribed pyramid."""
        return self.inscribed

    @classmethod
    def from_limit_surface(
        cls, ls: LimitSurface, *, facets: int = 4, inscribed: bool = True
    ) -> PointPyramid:
        """The pyramid of the surface's largest force (its torsional friction is dropped)."""
        mu, normal_force = _point_mu(ls)
        return cls(mu=mu, facets=facets, inscribed=inscribed, normal_force=normal_force)

    def inequalities(self, *, normal_force: float | None = None) -> tuple[np.ndarray, np.ndarray]:
        """``(A, b)`` with the pyramid ``{f : A @ f <= b}`` for forces ``(fx, fy)`` [N].

        A frictionless model gives ``b = 0``: ``A @ f <= 0`` holds for ``f = 0`` only.
        """
        force = self.normal_force if normal_force is None else normal_force
        force = validation.positive_scalar("normal_force", force)
        rows = self._rows / self._shape_mu
        return rows, np.full(len(self._rows), 0.0 if self.frictionless else force)

    def _gauge(self, q):
        apothem = _apothem(self.facets, self.inscribed)
        return _polygon_gauge(q[:, 0], q[:, 1], self.facets, apothem)

    def _gauge_terms(self):
        return (("max", self._rows),)

    def _unit_conic(self):
        return _linear_conic(self._rows)

    def __repr__(self) -> str:
        kind = "inscribed" if self.inscribed else "circumscribed"
        return (
            f"PointPyramid(facets={self.facets}, {kind}, mu={fmt(self.mu)}, "
            f"normal_force={fmt(self.normal_force)} N)"
        )
