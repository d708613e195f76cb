r"""Limit surface of rigidly connected contacts: a Minkowski sum in body-wrench space.

With the normal forces of a set of contacts fixed (given, or taken from a solved plan), the
wrenches their friction can supply to the body form the Minkowski sum of the contacts' friction
sets mapped into body-wrench space (paper §4.4, Lee & Cutkosky 1991). Restricted to a subspace
of wrench components, e.g. ``("fx", "fy", "mz")`` for a part sliding on its base, its boundary is
the limit surface of the whole fixture in that subspace. Wrench components are about the world
origin: ``fx, fy, fz`` [N], ``mx, my, mz`` [N m]; twists pair with them as
``(vx, vy, vz, wx, wy, wz)``.

Point contacts and exact or ellipsoid patches on a plane (subspace ``("fx", "fy", "mz")``,
normals along ``±z``) make up a :class:`~fixplan.LimitSurface`: the patches' sets placed in the
part's frame (mirrored for a contact from above) and summed with the points'
(:meth:`ContactSetSurface.as_limit_surface`), which the queries then ask. Other sets are written
with each contact's friction model as cvxpy constraints and queried with DPP problems compiled
once (Clarabel): a support is one conic solve (the exact contacts' parts from their surfaces), a
safety factor with exact contacts a few, which move ellipsoids that osculate their exact sets.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Sequence

import cvxpy as cp
import numpy as np

from fixplan.errors import ConvergenceError, FixplanError, InvalidArgumentError
from fixplan.models import Ellipsoid, Exact, FittedEllipsoid, PointCone
from fixplan.planner.contact_models import contact_models
from fixplan.planner.osculating_contact import (
    MAX_OSCULATING_ROUNDS,
    OsculatingContact,
    osculates,
)
from fixplan.planner.problem import Contact
from fixplan.surface import pressure
from fixplan.surface.geometry import Pose
from fixplan.surface.limit_surface import LimitSurface
from fixplan.surface.pressure import PointsField
from fixplan.surface.sphere import circle, fibonacci_sphere
from fixplan.validation import unit_vector

COMPONENTS = ("fx", "fy", "fz", "mx", "my", "mz")
#: The sliding subspace of a part on a plane, in the order of a planar limit surface's loads.
PLANAR = ("fx", "fy", "mz")
#: A point contact's normal counts as along ``±z`` within this of 1 in ``|n_z|`` (a tilt of
#: 1.4e-6 rad, which shrinks its friction disk in the plane by 1e-12: a CAD model's rounding).
PLANAR_RTOL = 1e-12
_OPTIONS = {"tol_gap_abs": 1e-9, "tol_gap_rel": 1e-9, "tol_feas": 1e-9}


class ContactSetSurface:
    """Friction limit surface of rigidly connected contacts in a wrench subspace.

    Parameters
    ----------
    contacts : sequence of Contact
        The contacts (their models, patches and frames are used).
    normal_forces : sequence of float
        Normal force of each contact [N], >= 0.
    subspace : sequence of str
        Wrench components spanning the sliding subspace (from ``fx fy fz mx my mz``).
    """

    def __init__(
        self,
        contacts: Sequence[Contact],
        normal_forces: Sequence[float],
        subspace: Sequence[str] = ("fx", "fy", "mz"),
    ):
        contacts = tuple(contacts)
        forces = np.asarray(normal_forces, dtype=float)
        if not contacts or forces.shape != (len(contacts),):
            raise InvalidArgumentError("normal_forces must give one force per contact")
        if not np.all(np.isfinite(forces)) or np.any(forces < 0.0):
            raise InvalidArgumentError("normal_forces must be finite and >= 0 [N]")
        unknown = [c for c in subspace if c not in COMPONENTS]
        if unknown or not subspace or len(set(subspace)) != len(subspace):
            raise InvalidArgumentError(
                f"subspace must name distinct components from {', '.join(COMPONENTS)}; "
                f"got {list(subspace)}"
            )
        self.contacts = contacts
        self.normal_forces = forces
        self.subspace = tuple(subspace)
        self._models = contact_models(contacts)
        self._units = self._axis_extents()

    @classmethod
    def from_plan(
        cls, problem, plan, load: str, subspace: Sequence[str] = ("fx", "fy", "mz")
    ) -> ContactSetSurface:
        """The surface of ``problem``'s contacts with the normal forces ``plan`` found for load
        case ``load`` (at the state the plan reports for it)."""
        if plan.normal_forces is None:
            raise InvalidArgumentError(f"the plan has no contact forces (status {plan.status!r})")
        if load not in plan.load_names:
            raise InvalidArgumentError(
                f"load must be one of the plan's load cases {list(plan.load_names)}; got {load!r}"
            )
        forces = np.clip(plan.normal_forces[:, plan.load_names.index(load)], 0.0, None)
        return cls(problem.contacts, forces, subspace)

    def as_limit_surface(self) -> LimitSurface | None:
        """The same surface as an exact :class:`~fixplan.LimitSurface`, where it is one: the
        subspace :data:`PLANAR`, and every contact that takes friction with its normal along
        ``±z`` and a :class:`~fixplan.models.PointCone` (its friction the disk of ``mu`` times
        its normal force, at its ``(x, y)``), an :class:`~fixplan.models.Exact` model (its
        patch's exact surface at its normal force) or an :class:`~fixplan.models.Ellipsoid` or
        :class:`~fixplan.models.FittedEllipsoid` (its ellipsoid, :meth:`LimitSurface.ellipsoid`),
        a patch's placed in the plane by its frame (mirrored where the normal is ``-z``); a
        patch, or point contacts in two or more places. ``None`` otherwise. Where it exists,
        the queries of this class ask it (exact, and no conic solve per call), and so do the
        sliding dynamics and pushing trajectories, which
        follow a part turning about one of its points as such (the conic programs' friction at
        a point at rest is any of its disk). Its point supports are the point contacts' with
        friction and the patches', those at one place merged into one: the indices of
        :attr:`~fixplan.motion.Sliding.pivots` are into its
        :attr:`~fixplan.LimitSurface.point_supports`, not into the contacts."""
        return self._exact

    @functools.cached_property
    def _exact(self) -> LimitSurface | None:
        if self.subspace != PLANAR:
            return None
        places, friction, points_force, patches = [], [], 0.0, []
        for contact, model, force in zip(self.contacts, self._models, self.normal_forces,
                                         strict=True):  # fmt: skip
            if force == 0.0 or model.frictionless:
                continue  # (no friction: it takes no part in sliding)
            if abs(contact.normal[2]) < 1.0 - PLANAR_RTOL:
                return None
            if isinstance(model, PointCone):
                places.append(contact.position[:2])
                friction.append(float(model.mu) * force)
                points_force += float(force)
            elif isinstance(model, Exact):
                patches.append((model.surface, _plane_pose(contact), float(force)))
            elif isinstance(model, Ellipsoid | FittedEllipsoid):
                ellipsoid = LimitSurface.ellipsoid(model.load_matrix, normal_force=float(force))
                patches.append((ellipsoid, _plane_pose(contact), float(force)))
            else:
                return None
        try:
            parts = [surface.placed(pose, normal_force=force) for surface, pose, force in patches]
            if places:
                parts.append(_points_surface(places, friction, points_force, bool(patches)))
        except FixplanError:  # (one point and no patch, places too close to tell apart, forces
            return None  # out of the surfaces' range)
        if not parts:
            return None
        return LimitSurface.combine(parts) if len(parts) > 1 else parts[0]

    @functools.cached_property
    def _conic(self) -> _ConicPrograms:
        """The conic programs of the queries, where there is no exact form (built once)."""
        return _ConicPrograms(self.contacts, self._models, self.normal_forces, self.subspace)

    def _axis_extents(self) -> np.ndarray:
        extents = np.array([self.support(axis) for axis in np.eye(len(self.subspace))])
        return np.where(extents > 0.0, extents, 1.0)

    # -- the LimitSurface API --------------------------------------------------------------------

    def support(self, twist) -> float:
        """Support function ``max w·V`` over the set for a subspace twist ``V``."""
        direction = _vector("twist", twist, len(self.subspace))
        if not np.any(direction):
            return 0.0
        if self._exact is not None:
            return float(self._exact.support(direction))
        return self._conic.support(direction)[0]

    def load(self, twist) -> np.ndarray:
        """A wrench on the surface that sustains sliding with ``twist`` (a support point)."""
        direction = _vector("twist", twist, len(self.subspace))
        if not np.any(direction):
            return np.zeros(len(self.subspace))
        if self._exact is not None:
            return self._exact.load(direction)
        return self._conic.support(direction)[1]

    def motion_and_safety_factor(self, load) -> tuple[np.ndarray, float]:
        """Sliding twist (unit, in the subspace) and safety factor of a subspace wrench."""
        wrench = _vector("load", load, len(self.subspace))
        if not np.any(wrench):
            return np.full(len(self.subspace), np.nan), float("inf")
        if self._exact is not None:
            twist, safety = self._exact.motion_and_safety_factor(wrench)
        else:
            twist, safety = self._conic.motion_and_safety_factor(wrench, self._units)
        norm = np.linalg.norm(twist)
        return (twist / norm if norm > 0 else twist), float(safety)

    def safety_factor(self, load) -> float:
        """Factor ``s`` with ``s * load`` on the surface (``inf`` if unbounded or zero)."""
        return self.motion_and_safety_factor(load)[1]

    def motion(self, load) -> np.ndarray:
        """Unit twist (subspace coordinates) of impending sliding under ``load``."""
        return self.motion_and_safety_factor(load)[0]

    def contains(self, load) -> bool:
        """Whether the contacts hold ``load`` by friction."""
        return self.safety_factor(load) >= 1.0 - 1e-9

    def sample(self, n: int = 200) -> np.ndarray:
        """``n`` wrenches ``(n, k)`` spread over the surface (directions scaled by extents)."""
        dim = len(self.subspace)
        if dim == 3:
            directions = fibonacci_sphere(n)
        elif dim == 2:
            directions = circle(n)
        else:
            rng = np.random.default_rng(0)
            directions = rng.normal(size=(n, dim))
            directions /= np.linalg.norm(directions, axis=1, keepdims=True)
        loads = directions * self._units
        return np.array([load * self.safety_factor(load) for load in loads])

    def curve(self, axes: tuple[str, str], n: int = 120) -> np.ndarray:
        """Cross section ``(n, 2)`` by the plane of two subspace components ``axes``."""
        index = (
            [self.subspace.index(a) for a in axes]
            if all(a in self.subspace for a in axes)
            else None
        )
        if index is None or len(set(index)) != 2:
            raise InvalidArgumentError(f"axes must be two of {self.subspace}, got {axes}")
        points = []
        for direction in circle(n):
            load = np.zeros(len(self.subspace))
            load[index] = direction * self._units[index]
            points.append(load[index] * self.safety_factor(load))
        return np.array(points)


def _plane_pose(contact: Contact) -> Pose:
    """The placement of ``contact``'s frame in the plane ``z = const`` of a part sliding on it
    (its normal along ``±z``): its x axis and position, mirrored where its normal is ``-z``."""
    t1 = contact.frame[0]
    return Pose(angle=math.atan2(t1[1], t1[0]), offset=(float(contact.position[0]),
                float(contact.position[1])), mirrored=bool(contact.normal[2] < 0.0))  # fmt: skip


def _points_surface(
    places: list, friction: list, normal_force: float, beside_patches: bool
) -> LimitSurface:
    """The exact surface of point contacts at ``places`` ``(x, y)`` [m] with ``friction`` [N]
    (``mu`` times each normal force) and ``normal_force`` [N] in all. One place alone has no
    torsional friction (:func:`~fixplan.pressure.points` needs two), but stands
    ``beside_patches`` as a support of its own. Raises :class:`~fixplan.errors.FixplanError`
    where it is no surface."""
    mu = float(np.sum(friction)) / normal_force
    if not beside_patches or len({tuple(place) for place in np.asarray(places).tolist()}) > 1:
        field = pressure.points(places, friction, centered=False)
    else:
        field = PointsField(xy=np.asarray(places[:1], dtype=float), weights=np.ones(1))
    return LimitSurface(field, mu=mu, normal_force=normal_force)


class _ConicPrograms:
    """The set of contacts written with each contact's friction model as cvxpy constraints,
    queried with DPP problems compiled once (Clarabel).

    The support function of the sum is the sum of the contacts' supports: the exact contacts'
    from their exact surfaces (facets included), the others' from one conic solve. The gauge of
    a direction (its safety factor) is one conic problem over all contacts, each smooth exact
    contact stated by the ellipsoid that osculates its exact set where its load meets it, solved
    again with the ellipsoids moved until it is the exact problem
    (:class:`~fixplan.planner.osculating_contact.OsculatingContact`); the motion is then its
    multipliers. An exact contact on point supports alone is stated exactly, a cone per point
    (:attr:`~fixplan.models.Exact.stated_exactly`); other sets with facets (point supports
    beside a patch, or very many) by their seed polytopes, which hold them.
    """

    def __init__(self, contacts, models, forces, subspace):
        select = np.array([np.eye(6)[COMPONENTS.index(c)] for c in subspace])
        self._maps = [
            select @ contact.wrench_basis()[:, 1 : 1 + model.load_dimension]
            for contact, model in zip(contacts, models, strict=True)
        ]
        self._direction = cp.Parameter(len(subspace), name="direction")
        self._loads = [cp.Variable(m.load_dimension) for m in models]
        #: The exact contacts with friction, by index: (model, normal force [N]).
        self._exact = {
            i: (model, float(fn))
            for i, (model, fn) in enumerate(zip(models, forces, strict=True))
            if isinstance(model, Exact) and fn > 0.0 and not model.frictionless
        }
        #: Their ellipsoids in the gauge, but for those with facets (see the class).
        self._ellipsoids = {
            i: OsculatingContact(model) for i, (model, _) in self._exact.items() if osculates(model)
        }
        constraints, others, wrench = [], [], 0
        for i, (load, model, fn) in enumerate(zip(self._loads, models, forces, strict=True)):
            if i in self._ellipsoids:
                constraints.append(self._ellipsoids[i].constraint(load, float(fn)))
                continue
            rows = model.constraints(load, float(fn))
            constraints += rows
            if i not in self._exact:
                others += rows
                wrench = wrench + self._maps[i] @ load
        self._others = wrench  # (the wrench of the contacts that are not exact; 0 if none)
        self._wrench = sum(m @ load for m, load in zip(self._maps, self._loads, strict=True))
        self._scale = cp.Variable(name="scale")
        self._balance = self._wrench == self._scale * self._direction
        self._gauge = cp.Problem(cp.Maximize(self._scale), [*constraints, self._balance])
        self._support = None
        if others:
            self._support = cp.Problem(cp.Maximize(self._direction @ wrench), others)

    def support(self, twist: np.ndarray) -> tuple[float, np.ndarray]:
        """The support value of a twist and a wrench on the surface that sustains it."""
        value, wrench = 0.0, np.zeros(len(twist))
        if not np.any(twist):
            return value, wrench
        unit, size = unit_vector(twist)  # (h is homogeneous: the solver sees a unit twist)
        if self._support is not None:
            self._direction.value = unit
            _solve(self._support)
            value = max(float(self._support.value), 0.0)  # (every set holds 0: noise below it)
            wrench = np.asarray(self._others.value, float)
        for i, (model, fn) in self._exact.items():
            contact_twist = self._maps[i].T @ unit
            if np.any(contact_twist):
                scale = fn / model.surface.normal_force
                value += scale * float(model.surface.support(contact_twist))
                wrench = wrench + self._maps[i] @ (scale * model.surface.load(contact_twist))
        return value * size, wrench

    def motion_and_safety_factor(self, wrench: np.ndarray, units: np.ndarray) -> tuple:
        """The sliding twist (not normalised) and safety factor of a nonzero ``wrench``;
        ``units``: the surface's axis extents, the scale at which the solver sees the load."""
        unit, size = unit_vector(wrench / units)  # (the gauge is homogeneous)
        self._direction.value = unit * units
        for ellipsoid in self._ellipsoids.values():
            ellipsoid.start()
        for _ in range(MAX_OSCULATING_ROUNDS):
            try:
                _solve(self._gauge)
            except FixplanError:
                if self._gauge.status in (cp.UNBOUNDED, cp.UNBOUNDED_INACCURATE):
                    return np.full(len(wrench), np.nan), float("inf")
                raise
            twist = -np.asarray(self._balance.dual_value, dtype=float)
            moved = [
                ellipsoid.follow(np.asarray(self._loads[i].value, dtype=float),
                                 self._exact[i][1], self._maps[i].T @ twist)
                for i, ellipsoid in self._ellipsoids.items()
            ]  # fmt: skip
            if not any(moved):
                twist = twist if twist @ wrench >= 0.0 else -twist
                return twist, max(float(self._scale.value), 0.0) / size  # (as the support)
        raise ConvergenceError(
            f"contact-set surface: the ellipsoids of its exact contacts did not settle on their "
            f"exact sets in {MAX_OSCULATING_ROUNDS} solves"
        )


def _solve(problem: cp.Problem) -> None:
    problem.solve(solver=cp.CLARABEL, **_OPTIONS)
    if problem.status not in (cp.OPTIMAL, cp.OPTIMAL_INACCURATE):
        raise FixplanError(f"contact-set surface query failed: solver status {problem.status}")


def _vector(name: str, value, size: int) -> np.ndarray:
    array = np.asarray(value, dtype=float)
    if array.shape != (size,) or not np.all(np.isfinite(array)):
        raise InvalidArgumentError(f"{name} must be {size} finite numbers, got {value!r}")
    return array
