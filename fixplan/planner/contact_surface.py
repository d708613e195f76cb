r"""Limit surface of rigidly connected contacts: a Minkowski sum in body-wrench space.

With the normal forces of a set of contacts fixed (given, or taken from a solved plan), the
wrenches their friction can supply to the body form the Minkowski sum of the contacts' friction
sets mapped into body-wrench space (paper §4.4, Lee & Cutkosky 1991). Restricted to a subspace
of wrench components, e.g. ``("fx", "fy", "mz")`` for a part sliding on its base, its boundary is
the limit surface of the whole fixture in that subspace. Wrench components are about the world
origin: ``fx, fy, fz`` [N], ``mx, my, mz`` [N m]; twists pair with them as
``(vx, vy, vz, wx, wy, wz)``.

The set is written with each contact's friction model as cvxpy constraints and queried with
DPP problems compiled once (Clarabel); every query is a small conic solve.
"""

from __future__ import annotations

import functools
from collections.abc import Sequence

import cvxpy as cp
import numpy as np

from fixplan.errors import FixplanError, InvalidArgumentError
from fixplan.models import PointCone
from fixplan.planner.contact_models import contact_models
from fixplan.planner.problem import Contact
from fixplan.surface import pressure
from fixplan.surface.limit_surface import LimitSurface
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
        select = np.array([np.eye(6)[COMPONENTS.index(c)] for c in subspace])
        models = contact_models(contacts)
        parts = []
        for contact, model in zip(contacts, models, strict=True):
            parts.append(select @ contact.wrench_basis()[:, 1 : 1 + model.load_dimension])
        self._maps = parts
        self._models = models
        dim = len(subspace)
        self._direction = cp.Parameter(dim, name="direction")
        loads = [cp.Variable(m.load_dimension) for m in models]
        constraints = []
        for load, model, fn in zip(loads, models, forces, strict=True):
            constraints += model.constraints(load, float(fn))
        wrench = sum(part @ load for part, load in zip(parts, loads, strict=True))
        self._scale = cp.Variable(name="scale")
        self._balance = wrench == self._scale * self._direction
        self._gauge = cp.Problem(cp.Maximize(self._scale), [*constraints, self._balance])
        self._wrench = wrench
        self._support = cp.Problem(cp.Maximize(self._direction @ wrench), constraints)
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

    def as_point_supports(self) -> LimitSurface | None:
        """The same surface as the exact :class:`~fixplan.LimitSurface` of point supports, where
        it is one: the subspace :data:`PLANAR` and every contact that takes friction a
        :class:`~fixplan.models.PointCone` with its normal along ``±z`` (its friction the disk
        of ``mu`` times its normal force, at its ``(x, y)``), at least two of them in distinct
        places; ``None`` otherwise. The sliding dynamics and pushing trajectories use it:
        its forward map is compiled rather than a conic solve per call, and a part turning about
        one of its points is followed as such (the programs' friction at a point at rest is
        any of its disk). Its points are the contacts' with friction, those at one place merged
        into one: the indices of :attr:`~fixplan.motion.Sliding.pivots` are into its
        :attr:`~fixplan.LimitSurface.point_supports`, not into the contacts."""
        return self._point_supports

    @functools.cached_property
    def _point_supports(self) -> LimitSurface | None:
        if self.subspace != PLANAR:
            return None
        places, friction = [], []
        for contact, model, force in zip(self.contacts, self._models, self.normal_forces,
                                         strict=True):  # fmt: skip
            if force == 0.0 or model.frictionless:
                continue  # (no friction: it takes no part in sliding)
            if not isinstance(model, PointCone) or abs(contact.normal[2]) < 1.0 - PLANAR_RTOL:
                return None
            places.append(contact.position[:2])
            friction.append(float(model.mu) * force)
        total = float(np.sum(self.normal_forces))
        try:
            field = pressure.points(places, friction, centered=False)
            return LimitSurface(field, mu=float(np.sum(friction)) / total, normal_force=total)
        except FixplanError:  # (fewer than two distinct places, places too close to tell apart,
            return None  # forces out of the surfaces' range)

    def _solve(self, problem: cp.Problem) -> None:
        problem.solve(solver=cp.CLARABEL, **_OPTIONS)
        if problem.status not in (cp.OPTIMAL, cp.OPTIMAL_INACCURATE):
            raise FixplanError(f"contact-set surface query failed: solver status {problem.status}")

    def _axis_extents(self) -> np.ndarray:
        extents = []
        for axis in np.eye(len(self.subspace)):
            extents.append(self.support(axis))
        extents = np.array(extents)
        return np.where(extents > 0.0, extents, 1.0)

    # -- the LimitSurface API --------------------------------------------------------------------

    def support(self, twist) -> float:
        """Support function ``max w·V`` over the set for a subspace twist ``V``."""
        direction = _vector("twist", twist, len(self.subspace))
        if not np.any(direction):
            return 0.0
        unit, size = unit_vector(direction)  # (h is homogeneous: the solver sees a unit twist)
        self._direction.value = unit
        self._solve(self._support)
        return float(self._support.value) * size

    def load(self, twist) -> np.ndarray:
        """A wrench on the surface that sustains sliding with ``twist`` (a support point)."""
        self.support(twist)
        return np.asarray(self._wrench.value, dtype=float)

    def motion_and_safety_factor(self, load) -> tuple[np.ndarray, float]:
        """Sliding twist (unit, in the subspace) and safety factor of a subspace wrench."""
        wrench = _vector("load", load, len(self.subspace))
        if not np.any(wrench):
            return np.full(len(self.subspace), np.nan), float("inf")
        # (The gauge is homogeneous: the solver sees the load at the scale of the axis extents.)
        unit, size = unit_vector(wrench / self._units)
        self._direction.value = unit * self._units
        try:
            self._solve(self._gauge)
        except FixplanError:
            if self._gauge.status in (cp.UNBOUNDED, cp.UNBOUNDED_INACCURATE):
                return np.full(len(self.subspace), np.nan), float("inf")
            raise
        twist = -np.asarray(self._balance.dual_value, dtype=float)
        twist = twist if twist @ wrench >= 0.0 else -twist
        norm = np.linalg.norm(twist)
        return (twist / norm if norm > 0 else twist), float(self._scale.value) / size

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


def _vector(name: str, value, size: int) -> np.ndarray:
    array = np.asarray(value, dtype=float)
    if array.shape != (size,) or not np.all(np.isfinite(array)):
        raise InvalidArgumentError(f"{name} must be {size} finite numbers, got {value!r}")
    return array
