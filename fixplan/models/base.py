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
- as cvxpy constraints the set is ``g(q) <= N`` with ``q = (fx/mu, fy/mu, m/(mu rho))``, which
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
from dataclasses import dataclass
from typing import TYPE_CHECKING, ClassVar

import numpy as np

from fixplan import validation
from fixplan.errors import InvalidArgumentError, ModelError
from fixplan.surface.sphere import circle
from fixplan.tolerances import CONTAINMENT_RTOL

if TYPE_CHECKING:  # pragma: no cover - typing only; cvxpy is imported when constraints are built
    pass

_PLANES = {"fx-m": (0, 2), "fy-m": (1, 2), "fx-fy": (0, 1)}


class FrictionModel(ABC):
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

    @abstractmethod
    def _unit_conic(self) -> ConicForm:
        """``g(q) <= N`` as a :class:`ConicForm` in the normalised coordinates ``q``."""

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

    # -- convex constraints ------------------------------------------------------------------

    def conic_form(self) -> ConicForm:
        """The set at normal force ``N`` as cones on affine rows of ``(N, load, aux)``.

        The form stacks: the planner writes every contact and load case of a model type into
        one cone constraint. ``load`` is ``(ft1, ft2, mn)`` [N, N, N m] about the frame origin
        (area models) or ``(ft1, ft2)`` [N] (point models).
        """
        if self.frictionless:  # the load is zero
            width = self.load_dimension
            return ConicForm(
                normal=np.zeros(width), load=np.eye(width), aux=np.zeros((width, 0)),
                cones=(("zero", width),),
            )  # fmt: skip
        unit = self._unit_conic()
        if self.torsion:
            cx, cy = self.center
            about_center = np.array([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [cy, -cx, 1.0]])
        else:
            about_center = np.eye(2)
        to_q = about_center / self._units()[:, None]
        return ConicForm(normal=unit.normal, load=unit.load @ to_q, aux=unit.aux, cones=unit.cones)

    def constraints(self, load, normal_force) -> list:
        """cvxpy constraints stating that ``load`` lies in the set at ``normal_force``.

        Parameters
        ----------
        load : cvxpy expression or array_like
            Area models: shape ``(3,)``, ``(ft1, ft2, mn)`` [N, N, N m] in the patch frame.
            Point models: shape ``(2,)`` ``(ft1, ft2)``, or ``(3,)`` whose moment is then
            constrained to 0.
        normal_force : cvxpy expression, Parameter or float
            Scalar normal force of the contact [N]. The constraints are homogeneous in it, so
            it may itself be a decision variable.

        Returns
        -------
        list of cvxpy.Constraint
            Convex and DPP (``problem.is_dcp(dpp=True)`` holds with Parameters): one per cone
            kind of :meth:`conic_form`. For a frictionless model: ``load == 0``.
        """
        import cvxpy as cp

        load = load if isinstance(load, cp.Expression) else cp.Constant(np.asarray(load, float))
        if not isinstance(normal_force, cp.Expression):
            normal_force = cp.Constant(validation.nonnegative_scalar("normal_force", normal_force))
        if normal_force.shape not in ((), (1,)):
            raise InvalidArgumentError(
                f"normal_force must be a scalar expression, got shape {normal_force.shape}"
            )
        if normal_force.shape == (1,):
            normal_force = cp.reshape(normal_force, (), order="C")
        allowed = ((3,),) if self.torsion else ((2,), (3,))
        if load.shape not in allowed:
            raise InvalidArgumentError(
                f"load must have shape {' or '.join(str(s) for s in allowed)} for "
                f"{type(self).__name__}, got {load.shape}"
            )
        extra = []
        if not self.torsion and load.shape == (3,):
            extra.append(load[2] == 0.0)
            load = load[:2]
        form = self.conic_form()
        rows = form.normal * normal_force + form.load @ load
        if form.aux.shape[1]:
            rows = rows + form.aux @ cp.Variable(form.aux.shape[1], name="aux")
        return form.cvxpy_constraints(cp.reshape(rows, (form.rows, 1), order="F")) + extra


@dataclass(frozen=True, slots=True)
class ConicForm:
    r"""A friction set at normal force ``N`` as cones on affine rows, in a form that stacks.

    .. math:: r = a N + B \ell + C z \in \mathcal K_1 \times \dots \times \mathcal K_m

    for the load ``ℓ`` and auxiliary variables ``z`` (e.g. the per-point forces of
    :class:`~fixplan.models.Exact`). ``cones`` lists ``(kind, size)`` in row order, ``kind``
    one of ``"zero"`` (rows equal 0), ``"nonneg"`` (rows >= 0) and ``"soc"`` (the first row
    bounds the norm of the others). Homogeneous in ``(N, ℓ, z)``, so it scales with ``N``.

    Attributes
    ----------
    normal : numpy.ndarray
        ``a`` ``(r,)``.
    load : numpy.ndarray
        ``B`` ``(r, d)``.
    aux : numpy.ndarray
        ``C`` ``(r, p)``, ``p >= 0``.
    cones : tuple of (str, int)
        The cones, in row order; their sizes add up to ``r``.
    """

    normal: np.ndarray
    load: np.ndarray
    aux: np.ndarray
    cones: tuple[tuple[str, int], ...]

    @property
    def rows(self) -> int:
        """Number of rows ``r``."""
        return len(self.normal)

    @property
    def bounds_normal(self) -> bool:
        """Whether the cones imply ``N >= 0`` on their own (a cone's first row is ``a N`` with
        ``a > 0``, or the first rows and inequalities add up to a positive multiple of ``N``):
        then the planner needs no separate sign constraint on the normal force."""
        first = [self.rows_of("soc", size)[::size] for size in self._soc_sizes]
        rows = np.concatenate([*first, self.rows_of("nonneg")]).astype(int)
        if rows.size == 0:
            return False
        coefficients = np.hstack([self.load[rows], self.aux[rows]])
        scale = max(float(np.abs(coefficients).max(initial=0.0)), 1e-300)
        pure = (np.abs(coefficients).max(axis=1, initial=0.0) <= 1e-12 * scale) & (
            self.normal[rows] > 0.0
        )
        total = np.abs(coefficients.sum(axis=0)).max(initial=0.0) <= 1e-12 * scale * len(rows)
        return bool(pure.any() or (total and self.normal[rows].sum() > 0.0))

    @property
    def _soc_sizes(self) -> list[int]:
        return sorted({size for kind, size in self.cones if kind == "soc"})

    def rows_of(self, kind: str, size: int | None = None) -> np.ndarray:
        """Indices of the rows in cones of ``kind`` (and ``size``), cone after cone."""
        found, start = [], 0
        for cone_kind, cone_size in self.cones:
            if cone_kind == kind and (size is None or cone_size == size):
                found.append(np.arange(start, start + cone_size))
            start += cone_size
        return np.concatenate(found) if found else np.empty(0, dtype=int)

    def cvxpy_constraints(self, rows) -> list:
        """Constraints on ``rows``, an expression ``(r, n)`` of ``n`` stacked columns: one
        constraint per cone kind and size over all columns."""

        constraints = []
        for kind in ("zero", "nonneg"):
            index = self.rows_of(kind)
            if index.size:
                part = rows[index, :]
                constraints.append(part == 0 if kind == "zero" else part >= 0)
        for size in self._soc_sizes:
            index = self.rows_of("soc", size)
            constraints.append(soc_columns(rows[index, :], size))
        return constraints


def soc_columns(rows, size: int):
    """One cvxpy SOC constraint: ``rows`` ``(m * size, n)`` holds ``m`` cones of ``size`` rows
    in each of its ``n`` columns (the first row of each cone bounds the norm of the rest)."""
    import cvxpy as cp

    count = rows.shape[0] // size * rows.shape[1]
    cones = cp.reshape(rows, (size, count), order="F")
    return cp.SOC(cones[0, :], cones[1:, :], axis=0)


def unit_conic(normal, q, aux=None, cones=()) -> ConicForm:
    """A :class:`ConicForm` in normalised coordinates (what :meth:`_unit_conic` returns)."""
    normal = np.asarray(normal, dtype=float)
    q = np.atleast_2d(np.asarray(q, dtype=float))
    aux = np.zeros((len(normal), 0)) if aux is None else np.asarray(aux, dtype=float)
    return ConicForm(normal=normal, load=q, aux=aux, cones=tuple(cones))


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
