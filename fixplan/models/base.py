r"""The interface shared by every friction model of :mod:`fixplan.models`.

A friction model is a convex, centrally symmetric set of loads ``(fx, fy, m)`` (area contacts)
or forces ``(fx, fy)`` (point contacts) that scales linearly with the normal force ``N`` of its
contact. Every model stores its geometry per unit normal force and works in the normalised
coordinates of the paper (Table 2, step 3),

.. math:: q = \left(\frac{f_x}{\mu N}, \frac{f_y}{\mu N}, \frac{m}{\mu \rho N}\right),

where ``mu`` is the model's friction coefficient (maximum force per unit normal force) and
``rho`` [m] its characteristic length (maximum moment over maximum force, the paper's
``lambda``). The moment ``m`` is taken about the model's ``center``, the centre of pressure
(paper eq. 2 and Table 2, step 1), which is the frame origin for the standard fields; loads and
twists are still given and returned about the frame origin (DESIGN.md §2). There the set is
``{q : g(q) <= 1}`` for a gauge ``g`` (a positively homogeneous convex function), so that

- the safety factor of a load is ``1 / g(q)``;
- the model holds the load when the safety factor is at least ``1 - CONTAINMENT_RTOL``;
- the sliding motion, for models that have one, is the outward normal ``∇g(q)`` of the set at
  the load scaled onto its boundary (normality); returned as a twist ``(vx, vy, w)`` scaled so
  that the twist about the centre, ``(vx - cy w, vy + cx w, rho * w)``, has unit norm (with the
  centre at the origin, as :meth:`fixplan.LimitSurface.motion` does);
- as cvxpy constraints (:mod:`fixplan.models.conic`) the set is ``g(q) <= N`` with ``q = (fx/mu, fy/mu, m/(mu rho))``, which
  is homogeneous in ``N``: ``N`` may be a float, a Parameter or an affine expression of
  variables (the normal force of a contact that the planner chooses).

**Frictionless contacts** (``mu = 0``) transmit their normal force only: the set is the single
load 0. Every model accepts ``mu = 0`` and keeps its shape (``rho``, tilt, centre, ...) from the
pressure shape, as with ``mu = 1``; the normalised coordinates ``q`` are then those of that shape
(:attr:`FrictionModel.friction_shape`). The set scales with ``mu``, so the sliding motion at a
fixed load direction does not depend on ``mu`` and its limit ``mu → 0+`` is the motion of the
shape. Hence, for ``mu = 0``:

- the safety factor is ``inf`` for the zero load and 0 for any other; :meth:`contains` holds for
  the zero load only; ``max_force`` and ``max_moment`` are 0 and :meth:`curve` is all zeros;
- :meth:`motion` is that limit, the motion of the shape;
- :meth:`constraints` states ``load == 0`` (homogeneous in ``N`` and DPP).
"""

from __future__ import annotations

import dataclasses
from abc import ABC, abstractmethod
from typing import TYPE_CHECKING, ClassVar

import numpy as np

from fixplan import validation
from fixplan.errors import InvalidArgumentError, ModelError
from fixplan.models.conic import ConvexForm
from fixplan.surface.sphere import circle
from fixplan.tolerances import CONTAINMENT_RTOL

if TYPE_CHECKING:  # pragma: no cover - typing only; cvxpy is imported when constraints are built
    pass

_PLANES = {"fx-m": (0, 2), "fy-m": (1, 2), "fx-fy": (0, 1)}


class FrictionModel(ConvexForm, ABC):
    """A friction model: a convex set of loads, scaled by the normal force of its contact.

    Subclasses are frozen dataclasses with the attributes ``mu`` [-] (>= 0; 0 is a
    frictionless contact), ``normal_force`` [N] (the default of the numeric methods) and, for
    area models, ``rho`` [m].
    """

    __slots__ = ()

    #: Whether the model's set lies inside the exact limit surface for every load (it never
    #: claims a load is held that the exact surface would let slide).
    conservative: ClassVar[bool]

    #: Whether the contact bears a torsional moment (area models) or only force (point models).
    torsion: ClassVar[bool] = True

    mu: float
    normal_force: float

    # -- geometry hooks (normalised coordinates q, see the module docstring) ------------------

    @abstractmethod
    def _gauge(self, q: np.ndarray) -> np.ndarray:
        """Gauge ``g(q)`` ``(K,)`` of normalised loads ``q`` ``(K, d)``; 0 at 0."""

    def _normal(self, q: np.ndarray) -> np.ndarray:
        """Outward normals ``(K, d)`` (any length) of the set at the rays through ``q``."""
        raise ModelError(
            f"{type(self).__name__} has no motion map: the normals of its surface do not give "
            "the sliding direction (paper §4.2); use Ellipsoid, FittedEllipsoid, "
            "FacetedEllipsoid or Exact to predict motion"
        )

    def _gauge_terms(self) -> tuple[tuple[str, np.ndarray], ...] | None:
        """The gauge as a sum of terms linear in ``q`` (see :meth:`gauge_terms`), or ``None``."""
        return None

    def gauge_terms(self) -> tuple[tuple[str, np.ndarray], ...] | None:
        """The gauge at unit normal force as a sum of terms linear in the load, or ``None``.

        A term ``("norm", G)`` contributes ``‖G L‖₂``, a term ``("max", G)`` contributes
        ``max(G L)``, for loads ``L`` in the coordinates of :meth:`constraints` (about the frame
        origin). The safety factor of ``L`` at normal force ``N`` is ``N`` over the sum; with
        these terms many contacts' loads are checked in a few matrix products
        (:mod:`fixplan.planner.verify`). ``None`` for a frictionless model and for models whose
        gauge has no such form.
        """
        terms = None if self.frictionless else self._gauge_terms()
        if terms is None:
            return None
        to_q = self._normalising_map()
        return tuple((kind, np.asarray(matrix, dtype=float) @ to_q) for kind, matrix in terms)

    # -- description -------------------------------------------------------------------------

    @property
    def rho(self) -> float:
        """Characteristic length [m]: maximum moment over maximum force (0 for point models)."""
        return 0.0

    @property
    def center(self) -> tuple[float, float]:
        """Point [m] about which the model takes moments: the centre of pressure."""
        return (0.0, 0.0)

    @property
    def frictionless(self) -> bool:
        """Whether the contact has no friction (``mu = 0``): it transmits normal force only."""
        return self.mu == 0.0

    @property
    def _shape_mu(self) -> float:
        """Friction coefficient of the normalised coordinates: ``mu``, or 1 for a frictionless
        model (the coordinates of its shape)."""
        return self.mu if self.mu > 0.0 else 1.0

    @property
    def friction_shape(self) -> FrictionModel:
        """A model of this one's shape: itself, or for a frictionless model the same model with
        the friction of its shape (``mu = 1``), which shrinks onto 0 as ``mu → 0+``."""
        return self._with_shape_friction() if self.frictionless else self

    def _with_shape_friction(self) -> FrictionModel:
        """This frictionless model with ``mu`` set to :attr:`_shape_mu`."""
        return dataclasses.replace(self, mu=self._shape_mu)

    def _about_center(self, loads: np.ndarray) -> np.ndarray:
        """Loads ``(K, 3)`` with the moment taken about :attr:`center`: ``m - c × f``."""
        cx, cy = self.center
        if cx == 0.0 and cy == 0.0:
            return loads
        moved = loads.copy()
        moved[:, 2] -= cx * loads[:, 1] - cy * loads[:, 0]
        return moved

    @property
    def constraint_error(self) -> float:
        """Largest relative radial gap by which :meth:`constraints` overestimate the model's set
        [-]: 0 when they state it exactly (the exact model states an outer polytope that the
        planner refines with cuts)."""
        return 0.0

    @property
    def has_motion(self) -> bool:
        """Whether :meth:`motion` is defined (the normals of the set give the sliding twist)."""
        return type(self)._normal is not FrictionModel._normal

    @property
    def load_dimension(self) -> int:
        """Length of the load vector of :meth:`constraints`: 3 ``(ft1, ft2, mn)`` or 2."""
        return 3 if self.torsion else 2

    @property
    def max_force(self) -> float:
        """Largest friction force [N] at the model's ``normal_force``."""
        return self.mu * self.normal_force

    @property
    def max_moment(self) -> float:
        """Largest friction moment [N m] about :attr:`center` at the model's ``normal_force``
        (0 for point models)."""
        return self.mu * self.rho * self.normal_force

    def _units(self) -> np.ndarray:
        """Normalisation per unit normal force: ``(mu, mu, mu rho)`` or ``(mu, mu)``, with
        ``mu`` that of the shape for a frictionless model."""
        mu = self._shape_mu
        if self.torsion:
            return np.array([mu, mu, mu * self.rho])
        return np.array([mu, mu])

    def _normalising_map(self) -> np.ndarray:
        """The matrix that takes a load about the frame origin to its normalised coordinates
        ``q`` (moment about :attr:`center`, divided by the units), ``(3, 3)`` or ``(2, 2)``."""
        if not self.torsion:
            return np.diag(1.0 / self._units())
        cx, cy = self.center
        about_center = np.array([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [cy, -cx, 1.0]])
        return about_center / self._units()[:, None]

    # -- numeric queries ---------------------------------------------------------------------

    def _normalised(self, load, normal_force) -> tuple[np.ndarray, bool, np.ndarray]:
        """Normalised loads ``q``, whether one load was given, and which loads twist a point."""
        force = (
            self.normal_force
            if normal_force is None
            else validation.positive_scalar("normal_force", normal_force)
        )
        if self.torsion:
            loads, single = validation.vector_batch("load", load, width=3)
            loads = self._about_center(loads)
            twisted = np.zeros(len(loads), dtype=bool)
        else:
            loads, single = _point_loads(load)
            twisted = loads[:, 2] != 0.0
            loads = loads[:, :2]
        return loads / (force * self._units()), single, twisted

    def safety_factor(self, load, *, normal_force: float | None = None) -> np.ndarray | float:
        """Factor ``s`` with ``s * load`` on the boundary of the model's set.

        Parameters
        ----------
        load : array_like
            ``(fx, fy, m)`` [N, N, N m], ``(3,)`` or ``(K, 3)``; point models also take
            ``(fx, fy)`` and give 0 for loads with a moment (a point bears no torsion).
        normal_force : float, optional
            Normal force of the contact [N]; default the model's ``normal_force``.

        Returns
        -------
        float or numpy.ndarray
            ``inf`` for the zero load; ``s > 1``: held with that margin; ``s < 1``: slides.
            A frictionless model gives 0 for every nonzero load.
        """
        q, single, twisted = self._normalised(load, normal_force)
        if self.frictionless:
            safety = np.where(np.any(q != 0.0, axis=1), 0.0, np.inf)
        else:
            with np.errstate(divide="ignore", over="ignore"):
                safety = 1.0 / self._gauge(q)
        safety[twisted] = 0.0
        return float(safety[0]) if single else safety

    def contains(self, load, *, normal_force: float | None = None) -> np.ndarray | bool:
        """Whether the model holds ``load`` (safety factor >= ``1 - CONTAINMENT_RTOL``)."""
        safety = self.safety_factor(load, normal_force=normal_force)
        held = np.asarray(safety) >= 1.0 - CONTAINMENT_RTOL
        return bool(held) if held.ndim == 0 else held

    def motion(self, load, *, normal_force: float | None = None) -> np.ndarray:
        """Unit twist of impending sliding under ``load``, by normality on the model's surface.

        The load is scaled onto the surface first (its magnitude does not matter). The twist
        ``(vx, vy, w)`` (velocity of the body point at the frame origin) is scaled so that the
        twist about :attr:`center`, ``(vx - cy w, vy + cx w, rho * w)``, has unit norm (for the
        standard fields ``center`` is the origin, as for ``LimitSurface.motion``); point models
        return the unit sliding velocity ``(vx, vy)`` (``(vx, vy, 0)`` for 3-vector loads).
        NaN for the zero load and for a point model loaded by a moment. A frictionless model
        returns the limit ``mu → 0+`` at the load's direction: the motion of its
        :attr:`friction_shape`.

        Raises
        ------
        ModelError
            For models whose normals do not give the sliding direction (cone, pyramids).
        """
        q, single, twisted = self._normalised(load, normal_force)
        width = q.shape[1]
        normals = np.full((len(q), width), np.nan)
        moving = np.flatnonzero(np.any(q != 0.0, axis=1) & ~twisted)
        if moving.size:
            normals[moving] = self._normal(q[moving])
        normals /= np.linalg.norm(normals, axis=1, keepdims=True)
        if self.torsion:
            # Normal n in q coordinates -> twist about the centre (n_f, n_m / rho) -> about the
            # origin: the origin moves with v_c + w J (0 - c) = (vx + cy w, vy - cx w).
            twists = normals / np.array([1.0, 1.0, self.rho])
            cx, cy = self.center
            twists[:, 0] += cy * twists[:, 2]
            twists[:, 1] -= cx * twists[:, 2]
        else:
            twists = normals
            if np.ndim(load) and np.shape(load)[-1] == 3:
                twists = np.column_stack([normals, np.where(np.isnan(normals[:, 0]), np.nan, 0.0)])
        return twists[0] if single else twists

    def curve(
        self,
        plane: str = "fy-m",
        n: int = 361,
        *,
        normalized: bool = False,
        normal_force: float | None = None,
    ) -> np.ndarray:
        """Cross section of the model's set by a coordinate plane, as loads ``(n, 3)``.

        Same conventions as :meth:`fixplan.LimitSurface.curve`: ``plane`` is ``"fx-m"``,
        ``"fy-m"`` or ``"fx-fy"`` (point models: ``"fx-fy"`` only); points evenly spread in
        angle in normalised coordinates. With ``normalized`` forces are divided by
        ``max_force`` and moments by ``max_moment`` (both at ``normal_force``). A frictionless
        model's set is the load 0: every point is 0 (also normalised).
        """
        axes = _PLANES.get(plane)
        if axes is None:
            raise InvalidArgumentError(f"plane must be one of {', '.join(_PLANES)}; got {plane!r}")
        if not self.torsion and plane != "fx-fy":
            raise InvalidArgumentError(
                f"a point model bears no moment: its only section is 'fx-fy', got {plane!r}"
            )
        if not isinstance(n, int | np.integer) or n < 1:
            raise InvalidArgumentError(f"n must be a positive integer, got {n!r}")
        force = self.normal_force if normal_force is None else normal_force
        force = validation.positive_scalar("normal_force", force)
        if self.frictionless:
            return np.zeros((int(n), 3))
        units = np.array([self.mu, self.mu, self.mu * self.rho]) * force
        directions = np.zeros((int(n), 3))
        directions[:, axes] = circle(int(n))
        safety = self.safety_factor(directions * units, normal_force=force)
        loads = directions * units * safety[:, None]
        if normalized:
            return loads / np.where(units > 0.0, units, 1.0)
        return loads


def _point_loads(load) -> tuple[np.ndarray, bool]:
    """Loads of a point model as ``(K, 3)`` (zero moment appended to 2-vectors)."""
    shape = np.shape(load)
    width = shape[-1] if shape else 0
    if width not in (2, 3):
        raise InvalidArgumentError(
            f"load of a point model must have shape (2,), (3,), (K, 2) or (K, 3), got {shape}"
        )
    loads, single = validation.vector_batch("load", load, width=width)
    if width == 2:
        loads = np.column_stack([loads, np.zeros(len(loads))])
    return loads, single


def finite_pair(name: str, value) -> tuple[float, float]:
    """``value`` as a tuple of two finite floats."""
    pair = validation.finite_array(name, value, shape=(2,))
    return float(pair[0]), float(pair[1])


def facet_count(value) -> int:
    """Number of facets of a pyramid, an integer >= 3."""
    if isinstance(value, bool) or not isinstance(value, int | np.integer) or value < 3:
        raise InvalidArgumentError(f"facets must be an integer >= 3, got {value!r}")
    return int(value)


def polygon_normals(facets: int) -> np.ndarray:
    """Outward unit normals ``(k, 2)`` of a regular ``k``-gon, the first along +x."""
    return circle(facets)


def fmt(value: float) -> str:
    """A number for a repr: 6 significant digits."""
    return f"{value:.6g}"
