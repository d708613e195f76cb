"""The planner's problem description: a body, its contacts and the loads it must withstand.

All values are immutable and validated on construction; errors name the contact or load and the
field. Frames and signs follow DESIGN.md §2: positions in the world frame [m], ``normal`` points
into the body, a contact's tangents ``t1``, ``t2`` satisfy ``t1 × t2 = normal`` and its patch
coordinates ``(x, y)`` lie along them.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from fixplan import validation
from fixplan.errors import InvalidArgumentError
from fixplan.planner.mesh_body import mass_properties, read_mesh
from fixplan.surface.pressure import PressureField
from fixplan.tolerances import (
    INERTIA_RTOL,
    MAX_ACCELERATION,
    MAX_ANGULAR_ACCELERATION,
    MAX_ANGULAR_VELOCITY,
    MAX_FACETS,
    MAX_FORCE,
    MAX_INERTIA,
    MAX_LENGTH,
    MAX_MASS,
    MAX_MU,
    MAX_NAME_LENGTH,
    MAX_TORQUE,
    MIN_MU,
)

ROLES = ("locator", "support", "clamp", "finger")
PASSIVE_ROLES = ("locator", "support")
ACTIVE_ROLES = ("clamp", "finger")
MODEL_NAMES = ("exact", "ellipsoid", "cone", "pyramid", "point-cone", "point-pyramid")
AREA_MODEL_NAMES = ("exact", "ellipsoid", "cone", "pyramid")
OBJECTIVES = (
    "min-total-clamp-force",
    "min-max-normal-force",
    "min-total-normal-force",
    "min-squared-normal-force",
    "max-safety-factor",
    "check",
    "check-compliant",
)
#: Objectives that take the active forces as given.
FIXED_FORCE_OBJECTIVES = ("max-safety-factor", "check", "check-compliant")
#: The objective whose rigid check is followed by the compliant analysis of the layer above
#: (:func:`fixplan.motion.compliance.analyse`), which its callers run; it needs every
#: contact's stiffness.
COMPLIANT_OBJECTIVE = "check-compliant"
#: The objective the planner solves for each objective it does not solve as itself.
SOLVED_AS = {COMPLIANT_OBJECTIVE: "check"}

#: Facets of a pyramid model when none are given (the four of the paper's eq. 11).
DEFAULT_FACETS = 4
#: Pyramids are inscribed (conservative) unless told otherwise.
DEFAULT_INSCRIBED = True


class ProblemError(InvalidArgumentError):
    """A problem description is invalid; the message names the item and field."""


def _vector(
    where: str, value: object, *, unit: bool = False, limit: float | None = None, units: str = ""
) -> np.ndarray:
    """A finite 3-vector; a unit vector along it (``unit``), or one whose components are at
    most ``limit`` (in ``units``) in size."""
    try:
        array = validation.finite_array(where, value, shape=(3,))
    except InvalidArgumentError as exc:
        raise ProblemError(str(exc)) from None
    if limit is not None and np.abs(array).max() > limit:
        raise ProblemError(
            f"{where} must have components within ±{limit:g} {units}, got {array.tolist()}"
        )
    if unit:
        largest = float(np.abs(array).max())
        if largest == 0.0:
            raise ProblemError(f"{where} must be a nonzero direction, got {array.tolist()}")
        array = array / largest  # no overflow in the norm of huge components
        array = array / np.linalg.norm(array)
        array.setflags(write=False)
    return array


def _scalar(
    where: str, value: object, *, positive: bool = False, limit: float, units: str = ""
) -> float:
    """A finite number >= 0 (> 0 if ``positive``) and at most ``limit`` (in ``units``)."""
    try:
        check = validation.positive_scalar if positive else validation.nonnegative_scalar
        number = check(where, value)
    except InvalidArgumentError as exc:
        raise ProblemError(str(exc)) from None
    if number > limit:
        raise ProblemError(f"{where} must be at most {limit:g} {units}, got {number!r}".rstrip())
    return number


def _mu(where: str, value: object) -> float:
    """A friction coefficient: 0 (frictionless) or from ``MIN_MU`` to ``MAX_MU``."""
    mu = _scalar(where, value, limit=MAX_MU)
    if 0.0 < mu < MIN_MU:
        raise ProblemError(
            f"{where} must be 0 (frictionless) or at least {MIN_MU:g} (friction that small is "
            f"rounding noise against the forces), got {mu!r}"
        )
    return mu


def _name(where: str, value: object) -> str:
    if not isinstance(value, str) or not value.strip():
        raise ProblemError(f"{where} must be a non-empty string, got {value!r}")
    if len(value) > MAX_NAME_LENGTH or not value.isprintable():
        raise ProblemError(
            f"{where} must have at most {MAX_NAME_LENGTH} characters and no control "
            f"characters, got {len(value)} characters: {value[:40]!r}"
        )
    return value


def box_inertia(mass: float, size: np.ndarray) -> np.ndarray:
    """Inertia tensor [kg m²] of a uniform box of ``mass`` [kg] and edges ``size`` [m] along the
    world axes, about its centre."""
    squares = np.asarray(size, dtype=float) ** 2
    return np.diag(mass / 12.0 * (squares.sum() - squares))


def _inertia(where: str, value: object) -> np.ndarray:
    """A physical inertia tensor [kg m²]: symmetric, its principal moments >= 0 and each at most
    the sum of the other two (within ``INERTIA_RTOL`` of the largest)."""
    try:
        array = validation.finite_array(where, value, shape=(3, 3))
    except InvalidArgumentError as exc:
        raise ProblemError(str(exc)) from None
    size = float(np.abs(array).max())
    if size > MAX_INERTIA:
        raise ProblemError(f"{where} must have entries within ±{MAX_INERTIA:g} kg m², got {size:g}")
    if np.abs(array - array.T).max() > INERTIA_RTOL * size:
        raise ProblemError(f"{where} must be symmetric, got {array.tolist()}")
    array = 0.5 * (array + array.T)
    moments = np.linalg.eigvalsh(array)
    if (
        moments[0] < -INERTIA_RTOL * size
        or moments[2] > moments[0] + moments[1] + INERTIA_RTOL * size
    ):
        raise ProblemError(
            f"{where} is not the inertia of a body: its principal moments {moments.tolist()} "
            "kg m² must be >= 0 and each at most the sum of the other two"
        )
    array.setflags(write=False)
    return array


def default_axis(normal: np.ndarray) -> np.ndarray:
    """The default patch x axis: the world axis least aligned with ``normal`` (x, then y, then
    z on ties), projected onto the contact plane and normalised."""
    axis = np.eye(3)[int(np.argmin(np.abs(normal)))]
    tangent = axis - (axis @ normal) * normal
    return tangent / np.linalg.norm(tangent)


@dataclass(frozen=True, slots=True, kw_only=True)
class Body:
    """A rigid body.

    Attributes
    ----------
    mass : float
        Mass [kg], >= 0.
    center_of_mass : array (3,)
        Centre of mass in the world frame [m].
    gravity : array (3,)
        Gravitational acceleration [m/s²]; zero turns gravity off.
    inertia : array (3, 3), optional
        Inertia tensor about the centre of mass, world axes [kg m²] (symmetric, positive
        semidefinite, principal moments obeying the triangle inequality). Default: that of a
        uniform box of ``size`` if given, else none (loads with angular terms then need one).
    size : array (3,), optional
        Edge lengths [m] of the body as a box along the world axes (its default inertia).
    mesh : trimesh.Trimesh, optional
        The closed surface of the body, in the world frame (:meth:`from_mesh`).
    """

    mass: float
    center_of_mass: np.ndarray
    gravity: np.ndarray = field(default_factory=lambda: np.array([0.0, 0.0, -9.81]))
    inertia: np.ndarray | None = None
    size: np.ndarray | None = None
    mesh: object = field(default=None, repr=False, compare=False)
    _weight: np.ndarray = field(init=False, repr=False, compare=False)

    @classmethod
    def from_mesh(
        cls,
        source,
        *,
        density: float | None = None,
        mass: float | None = None,
        scale: float = 1.0,
        gravity=(0.0, 0.0, -9.81),
    ) -> Body:
        """The uniform solid bounded by a closed triangle mesh (a file path, STL/OBJ/PLY/…,
        or a ``trimesh.Trimesh``) in world coordinates times ``scale`` [m]: its mass (from
        ``density`` [kg/m³] or given as ``mass`` [kg]), centre of mass and inertia tensor.

        Raises :class:`~fixplan.planner.mesh_body.MeshError` for a mesh that is not a solid (not
        watertight, inconsistent or inverted normals, zero volume).
        """
        mesh = read_mesh(source, scale=scale)
        total, center, inertia = mass_properties(mesh, density=density, mass=mass)
        return cls(mass=total, center_of_mass=center, gravity=gravity, inertia=inertia, mesh=mesh)

    def inertial_wrench(self, load: Load) -> np.ndarray:
        """The d'Alembert wrench ``(-m a, c × (-m a) - (I α + ω × I ω))`` [N, N m about the world
        origin] of ``load``'s motion of the body (all world frame)."""
        force = -self.mass * load.acceleration
        moment = np.cross(self.center_of_mass, force)
        if load.rotates:
            inertia = self.inertia
            spin = inertia @ load.angular_velocity
            moment -= inertia @ load.angular_acceleration + np.cross(load.angular_velocity, spin)
        return np.concatenate([force, moment])

    def __post_init__(self):
        mass = _scalar("body.mass", self.mass, limit=MAX_MASS, units="kg")
        center = _vector("body.center_of_mass", self.center_of_mass, limit=MAX_LENGTH, units="m")
        gravity = _vector("body.gravity", self.gravity, limit=MAX_ACCELERATION, units="m/s²")
        object.__setattr__(self, "mass", mass)
        object.__setattr__(self, "center_of_mass", center)
        object.__setattr__(self, "gravity", gravity)
        force = mass * gravity
        weight = np.concatenate([force, np.cross(center, force)])
        weight.setflags(write=False)
        object.__setattr__(self, "_weight", weight)
        if self.size is not None:
            size = _vector("body.size", self.size, limit=MAX_LENGTH, units="m")
            if np.any(size <= 0.0):
                raise ProblemError(
                    f"body.size must have positive edge lengths, got {size.tolist()}"
                )
            object.__setattr__(self, "size", size)
        if self.inertia is not None:
            object.__setattr__(self, "inertia", _inertia("body.inertia", self.inertia))
        elif self.size is not None:
            object.__setattr__(self, "inertia", box_inertia(mass, self.size))

    @property
    def weight_wrench(self) -> np.ndarray:
        """Gravity wrench ``(force [N], moment about the world origin [N m])`` (read-only)."""
        return self._weight


@dataclass(frozen=True, slots=True, kw_only=True)
class Load:
    """A task load: ``force`` [N] applied at ``point`` [m] plus a pure ``torque`` [N m], while
    the body moves with ``acceleration`` [m/s²] of its centre of mass, ``angular_velocity``
    [rad/s] and ``angular_acceleration`` [rad/s²] (world frame; default at rest).

    The motion adds the body's d'Alembert wrench (:meth:`Body.inertial_wrench`) to the case's
    task wrench (:meth:`Problem.task_wrenches`): safety factors scale it with the applied load,
    while gravity stays as it is.
    """

    name: str
    force: np.ndarray = field(default_factory=lambda: np.zeros(3))
    point: np.ndarray = field(default_factory=lambda: np.zeros(3))
    torque: np.ndarray = field(default_factory=lambda: np.zeros(3))
    acceleration: np.ndarray = field(default_factory=lambda: np.zeros(3))
    angular_velocity: np.ndarray = field(default_factory=lambda: np.zeros(3))
    angular_acceleration: np.ndarray = field(default_factory=lambda: np.zeros(3))
    _wrench: np.ndarray = field(init=False, repr=False, compare=False)
    _moves: bool = field(init=False, repr=False, compare=False)

    def __post_init__(self):
        where = f"load {self.name!r}" if isinstance(self.name, str) else "load"
        _name(f"{where}.name", self.name)
        limits = {
            "force": (MAX_FORCE, "N"),
            "point": (MAX_LENGTH, "m"),
            "torque": (MAX_TORQUE, "N m"),
            "acceleration": (MAX_ACCELERATION, "m/s²"),
            "angular_velocity": (MAX_ANGULAR_VELOCITY, "rad/s"),
            "angular_acceleration": (MAX_ANGULAR_ACCELERATION, "rad/s²"),
        }
        for key, (limit, units) in limits.items():
            value = _vector(f"{where}.{key}", getattr(self, key), limit=limit, units=units)
            object.__setattr__(self, key, value)
        # The wrench once, its cross product written out in floats (np.cross costs more).
        (x, y, z), (fx, fy, fz), (tx, ty, tz) = (
            getattr(self, k).tolist() for k in ("point", "force", "torque")
        )
        wrench = np.array(
            [fx, fy, fz, y * fz - z * fy + tx, z * fx - x * fz + ty, x * fy - y * fx + tz]
        )
        wrench.setflags(write=False)
        object.__setattr__(self, "_wrench", wrench)
        object.__setattr__(self, "_moves", bool(self.acceleration.any() or self.rotates))

    @property
    def rotates(self) -> bool:
        """Whether the load has an angular velocity or acceleration (needs the body's inertia)."""
        return bool(self.angular_velocity.any() or self.angular_acceleration.any())

    @property
    def wrench(self) -> np.ndarray:
        """``(force, moment about the world origin)`` [N, N m] (read-only)."""
        return self._wrench


@dataclass(frozen=True, slots=True, kw_only=True)
class Contact:
    """A frictional contact between the body and a locator, support, clamp or finger.

    Attributes
    ----------
    name : str
        Unique name.
    role : str
        ``"locator"``/``"support"`` (passive: its normal force is a reaction, per load case),
        ``"clamp"`` (active: one force for all load cases) or ``"finger"`` (active: a force per
        load case).
    position : array (3,)
        Contact point, the origin of the patch coordinates [m].
    normal : array (3,)
        Direction in which the contact pushes the body (into the body); normalised.
    mu : float
        Friction coefficient, >= 0; 0 is a frictionless contact (a frictionless clamp or
        locator), which transmits its normal force only.
    model : str or friction model
        ``"exact"``, ``"ellipsoid"``, ``"cone"``, ``"pyramid"`` (need a ``patch``),
        ``"point-cone"``, ``"point-pyramid"``, or a model object from :mod:`fixplan.models`
        built for unit normal force.
    patch : PressureField, optional
        Pressure distribution of an area contact; its torsional friction and limit-surface
        shape come from it. Required by the area models.
    axis : array (3,), optional
        World direction of the patch x axis, projected onto the contact plane. Default:
        :func:`default_axis`.
    facets, inscribed : int, bool, optional
        Pyramid models only: number of facets (default 4) and whether the pyramid is inscribed
        in the exact set (conservative, default) or circumscribed.
    force : float, optional
        Fixed normal force of an active contact [N].
    max_force : float, optional
        Upper bound on an active contact's normal force [N].
    """

    name: str
    role: str
    position: np.ndarray
    normal: np.ndarray
    mu: float
    model: object
    patch: PressureField | None = None
    axis: np.ndarray | None = None
    facets: int | None = None
    inscribed: bool | None = None
    force: float | None = None
    max_force: float | None = None

    def __post_init__(self):
        where = f"contact {self.name!r}" if isinstance(self.name, str) else "contact"
        _name(f"{where}.name", self.name)
        if self.role not in ROLES:
            raise ProblemError(f"{where}.role must be one of {', '.join(ROLES)}; got {self.role!r}")
        position = _vector(f"{where}.position", self.position, limit=MAX_LENGTH, units="m")
        object.__setattr__(self, "position", position)
        object.__setattr__(self, "normal", _vector(f"{where}.normal", self.normal, unit=True))
        object.__setattr__(self, "mu", _mu(f"{where}.mu", self.mu))
        if self.patch is not None and not isinstance(self.patch, PressureField):
            raise ProblemError(f"{where}.patch must be a pressure field, got {self.patch!r}")
        self._check_model(where)
        if self.axis is not None:
            axis = _vector(f"{where}.axis", self.axis, unit=True)
            tangent = axis - (axis @ self.normal) * self.normal
            if np.linalg.norm(tangent) <= 1e-9 * np.linalg.norm(axis):
                raise ProblemError(f"{where}.axis must not be parallel to the normal")
            object.__setattr__(self, "axis", tangent / np.linalg.norm(tangent))
        for key in ("force", "max_force"):
            value = getattr(self, key)
            if value is not None:
                if self.role in PASSIVE_ROLES:
                    raise ProblemError(
                        f"{where}.{key} is only for active contacts (clamp, finger); a "
                        f"{self.role}'s normal force is a reaction"
                    )
                force = _scalar(f"{where}.{key}", value, limit=MAX_FORCE, units="N")
                object.__setattr__(self, key, force)
        if self.force is not None and self.max_force is not None and self.force > self.max_force:
            raise ProblemError(f"{where}.force {self.force} exceeds max_force {self.max_force}")

    def _check_model(self, where: str) -> None:
        model = self.model
        if isinstance(model, str):
            if model not in MODEL_NAMES:
                raise ProblemError(
                    f"{where}.model must be one of {', '.join(MODEL_NAMES)} or a model object; "
                    f"got {model!r}"
                )
            if model in AREA_MODEL_NAMES and self.patch is None:
                raise ProblemError(
                    f"{where}.model {model!r} needs a patch (pressure field); use 'point-cone' "
                    "or 'point-pyramid' for a point contact"
                )
            pyramid = model in ("pyramid", "point-pyramid")
        else:
            if not hasattr(model, "constraints"):
                raise ProblemError(f"{where}.model must be a model name or object, got {model!r}")
            model_mu = getattr(model, "mu", self.mu)
            if abs(model_mu - self.mu) > 1e-12 * self.mu:
                raise ProblemError(
                    f"{where}.mu is {self.mu} but its model object was built with mu = "
                    f"{model_mu}; give the same friction coefficient to both"
                )
            pyramid = False
        if not pyramid and (self.facets is not None or self.inscribed is not None):
            raise ProblemError(f"{where}.facets and .inscribed are only for pyramid models")
        facets = self.facets
        if facets is not None and (
            isinstance(facets, bool)
            or not isinstance(facets, int | np.integer)
            or not 3 <= facets <= MAX_FACETS
        ):
            raise ProblemError(
                f"{where}.facets must be an integer from 3 to {MAX_FACETS}, got {facets!r}"
            )
        if self.inscribed is not None and not isinstance(self.inscribed, bool | np.bool_):
            raise ProblemError(f"{where}.inscribed must be true or false, got {self.inscribed!r}")

    @property
    def is_active(self) -> bool:
        """Whether the contact's normal force is chosen (clamp, finger)."""
        return self.role in ACTIVE_ROLES

    @property
    def frame(self) -> np.ndarray:
        """Rows ``t1, t2, normal`` of the contact frame (world directions)."""
        t1 = self.axis if self.axis is not None else default_axis(self.normal)
        t2 = np.cross(self.normal, t1)
        return np.array([t1, t2, self.normal])

    @property
    def has_torsion(self) -> bool:
        """Whether the contact transmits a moment about its normal (area models)."""
        if isinstance(self.model, str):
            return self.model in AREA_MODEL_NAMES
        return getattr(self.model, "torsion", True)

    @property
    def center_of_pressure(self) -> np.ndarray:
        """World point [m] where the normal force acts: the patch's centre of pressure (the
        contact position for point models and centred patches)."""
        if self.patch is None:
            return self.position
        t1, t2, _ = self.frame
        x, y = self.patch.center_of_pressure()
        return self.position + x * t1 + y * t2

    def wrench_basis(self) -> np.ndarray:
        """Map ``(6, 4)`` from ``(fn, ft1, ft2, mn)`` to the body wrench about the world origin.

        The normal force acts at the patch's centre of pressure; the friction load (about the
        contact position, like the patch's limit surface) at the contact position.
        """
        t1, t2, n = self.frame
        p = self.position
        columns = [
            np.concatenate([n, np.cross(self.center_of_pressure, n)]),
            np.concatenate([t1, np.cross(p, t1)]),
            np.concatenate([t2, np.cross(p, t2)]),
            np.concatenate([np.zeros(3), n]),
        ]
        return np.column_stack(columns)


@dataclass(frozen=True, slots=True, kw_only=True)
class Problem:
    """A planning problem: a body, its contacts, the task loads and the objective."""

    body: Body
    contacts: tuple[Contact, ...]
    loads: tuple[Load, ...]
    objective: str

    def __post_init__(self):
        if not isinstance(self.body, Body):
            raise ProblemError(f"body must be a Body, got {type(self.body).__name__}")
        contacts = tuple(self.contacts)
        loads = tuple(self.loads)
        if not contacts:
            raise ProblemError("contacts must hold at least one contact")
        if not loads:
            raise ProblemError("loads must hold at least one load case")
        for kind, items, cls in (("contact", contacts, Contact), ("load", loads, Load)):
            names = set()
            for index, item in enumerate(items):
                if not isinstance(item, cls):
                    raise ProblemError(f"{kind}s[{index}] must be a {cls.__name__}")
                if item.name in names:
                    raise ProblemError(f"{kind} name {item.name!r} is used twice")
                names.add(item.name)
        if self.objective not in OBJECTIVES:
            raise ProblemError(
                f"objective must be one of {', '.join(OBJECTIVES)}; got {self.objective!r}"
            )
        if self.objective in FIXED_FORCE_OBJECTIVES:
            for contact in contacts:
                if contact.is_active and contact.force is None:
                    raise ProblemError(
                        f"contact {contact.name!r}.force is required: objective "
                        f"{self.objective!r} takes the active forces as given"
                    )
        elif self.objective == "min-total-clamp-force" and not any(
            c.role == "clamp" and c.force is None for c in contacts
        ):
            raise ProblemError(
                "objective 'min-total-clamp-force' needs at least one clamp whose force is free"
            )
        elif not any(c.is_active and c.force is None for c in contacts):
            raise ProblemError(
                f"objective {self.objective!r} needs at least one clamp or finger whose force is free"
            )
        object.__setattr__(self, "contacts", contacts)
        object.__setattr__(self, "loads", loads)
        self.task_wrenches()  # loads that need the body's inertia

    def task_wrenches(self, loads: tuple[Load, ...] | None = None) -> np.ndarray:
        """Task wrenches ``(6, K)`` [N, N m about the world origin] of ``loads`` (default the
        problem's): each load's applied wrench plus the body's d'Alembert wrench of its motion
        (gravity is not included)."""
        loads = self.loads if loads is None else loads
        out = np.empty((6, len(loads)))
        for j, load in enumerate(loads):
            out[:, j] = load._wrench
            if load._moves:
                if load.rotates and self.body.inertia is None:
                    raise ProblemError(
                        f"load {load.name!r} has an angular velocity or acceleration: the body "
                        "needs an inertia tensor (body.inertia, body.size or a mesh)"
                    )
                out[:, j] += self.body.inertial_wrench(load)
        return out
