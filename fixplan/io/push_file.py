"""Push files: a part pushed across its support, in TOML, read into the arguments of
:func:`fixplan.motion.push`.

Like :mod:`fixplan.io.problem_file`, :func:`load_push` checks the whole file before it builds
anything and reports every mistake at once in a :class:`ProblemFileError`, each at its key path.
Units are SI; angles in radians. The schema::

    schema_version = 1                    # required, must be 1
    name = "box-on-a-point-pusher"        # required
    kind = "push"                         # required
    description = "..."                   # optional free text

    [part]
    outline = { shape = "rectangle", length = 0.09, width = 0.06 }
                                          # or { shape = "polygon", vertices = [[x, y], ...] }
                                          # or { shape = "disk", radius = 0.04 } (part frame [m])
    mass = 0.8                            # [kg], required (normal force = mass * gravity)
    pose = [0.0, 0.0, 0.0]                # start pose (x, y, theta) in the world [m, m, rad]

    [support]
    mu = 0.3                              # part-support friction, > 0; required
    model = "exact"                       # "exact" (default: the exact limit surface) or
                                          # "ellipsoid" (its ellipsoid model)
    patch = { shape = "disk", radius = 0.03 }
                                          # pressure under the part (patch shapes as in problem
                                          # files); default: uniform over the outline
    offset = [0.0, 0.0]                   # where the patch's centre sits in the part frame [m]
    gravity = 9.81                        # [m/s^2], default 9.81

    [pusher]
    shape = "point"                       # "point" (round, of radius) or "line" (flat face)
    mu = 0.2                              # pusher-part friction, >= 0 (0: frictionless)
    radius = 0.005                        # point pusher [m], default 0
    width = 0.12                          # line pusher: length of its face [m], required
    normal = [1.0, 0.0]                   # line pusher: direction it faces (default: velocity)
    start = [-0.06, 0.01]                 # world position of its centre at t = 0 [m]
    velocity = [0.01, 0.0]                # constant velocity [m/s]

    [simulation]
    duration = 5.0                        # [s], required
    steps = 500                           # integration steps, required
    start_overlap = 0.0                   # [m], default 0: how far the pusher may start inside
                                          # the part (a measured start; a round pusher: below
                                          # its radius)
"""

from __future__ import annotations

import hashlib
import math
import os
from dataclasses import dataclass
from pathlib import Path

from fixplan.io.patch_schema import LENGTH, read_patch
from fixplan.io.toml_schema import (
    MAX_FILE_BYTES,
    Array,
    Choice,
    Integer,
    InvalidValueError,
    Issue,
    Number,
    ProblemFileError,
    Table,
    Text,
    build,
    check_schema_version,
    describe,
    parse_toml,
    read_regular_file,
)
from fixplan.models.ellipsoid import Ellipsoid
from fixplan.motion import LinePusher, Outline, PointPusher
from fixplan.surface import pressure
from fixplan.surface.limit_surface import LimitSurface
from fixplan.tolerances import (
    MAX_ACCELERATION,
    MAX_DURATION,
    MAX_LENGTH,
    MAX_MASS,
    MAX_MU,
    MAX_POLYGON_VERTICES,
    MAX_SPEED,
    MAX_STEPS,
    MIN_MU,
    MIN_PUSHED_GRAVITY,
    MIN_PUSHED_MASS,
)

KIND = "push"
SUPPORT_MODELS = ("exact", "ellipsoid")
PUSHER_SHAPES = ("point", "line")
OUTLINE_SHAPES = ("rectangle", "polygon", "disk")

#: Standard gravity [m/s²], the default of ``[support] gravity``.
STANDARD_GRAVITY = 9.81

_TOP_KEYS = ("schema_version", "name", "kind", "description", "part", "support", "pusher",
             "simulation")  # fmt: skip
_PART_KEYS = ("outline", "mass", "pose")
_SUPPORT_KEYS = ("mu", "model", "patch", "offset", "gravity")
_PUSHER_KEYS = {
    "point": ("shape", "mu", "radius", "start", "velocity"),
    "line": ("shape", "mu", "width", "normal", "start", "velocity"),
}
_OUTLINE_KEYS = {
    "rectangle": ("shape", "length", "width"),
    "polygon": ("shape", "vertices"),
    "disk": ("shape", "radius"),
}
_SIMULATION_KEYS = ("duration", "steps", "start_overlap")

_COORDINATE = Number("", MAX_LENGTH, "m")
_POINT = Array((2,), _COORDINATE)
_POSE = Array((3,), Number("", MAX_LENGTH, "m or rad"))
_VELOCITY = Array((2,), Number("", MAX_SPEED, "m/s"))
_DIRECTION = Array((2,))
_VERTICES = Array((None, 2), _COORDINATE, MAX_POLYGON_VERTICES)
_MASS = Number("> 0", MAX_MASS, "kg", smallest=MIN_PUSHED_MASS, why_smallest="(a microgram)")
_GRAVITY = Number("> 0", MAX_ACCELERATION, "m/s^2", smallest=MIN_PUSHED_GRAVITY,
                  why_smallest="(its normal force would vanish in the arithmetic)")  # fmt: skip
_SUPPORT_MU = Number("> 0", MAX_MU, smallest=MIN_MU, why_smallest="(rounding noise)")
_PUSHER_MU = Number(">= 0", MAX_MU)
_RADIUS = Number(">= 0", MAX_LENGTH, "m")
_DURATION = Number("> 0", MAX_DURATION, "s")
_STEPS = Integer(1, MAX_STEPS)


@dataclass(frozen=True, slots=True, kw_only=True)
class PushFile:
    """A push read from a file: the arguments of :func:`fixplan.motion.push` and where they
    came from.

    Attributes
    ----------
    name, path, sha256
        The file's ``name``, the file read and the hex SHA-256 digest of its bytes.
    surface
        The support's limit surface in the part frame, at the part's weight (``LimitSurface``
        or its ``Ellipsoid``).
    model : str
        ``"exact"`` or ``"ellipsoid"``.
    shape : Outline
        The part's outline (part frame).
    pusher : PointPusher or LinePusher
        The pusher.
    pose : tuple of float
        The part's start pose ``(x, y, θ)`` [m, m, rad].
    duration : float
        Pushing time [s].
    steps : int
        Integration steps.
    start_overlap : float
        How far the pusher may start inside the part [m].
    normal_force : float
        The part's weight on the support [N].
    support_mu : float
        Part–support friction coefficient.
    """

    name: str
    path: Path
    sha256: str
    surface: object
    model: str
    shape: Outline
    pusher: PointPusher | LinePusher
    pose: tuple[float, float, float]
    duration: float
    steps: int
    start_overlap: float
    normal_force: float
    support_mu: float


def file_kind(path: str | os.PathLike[str]) -> str | None:
    """The ``kind`` of a TOML input file, or ``None`` if it cannot be read or has none (the
    reader of the file then says what is wrong)."""
    try:
        document = parse_toml(Path(path), read_regular_file(Path(path), MAX_FILE_BYTES))
    except (InvalidValueError, ProblemFileError):
        return None
    kind = document.get("kind")
    return kind if isinstance(kind, str) else None


def load_push(path: str | os.PathLike[str]) -> PushFile:
    """Read and validate a push file (schema in the module docstring).

    Raises
    ------
    ProblemFileError
        The file cannot be read, is not TOML, or breaks the schema; lists every issue.
    """
    path = Path(path)
    try:
        content = read_regular_file(path, MAX_FILE_BYTES)
    except InvalidValueError as exc:
        message = f"cannot read the file: {exc}"
        raise ProblemFileError(path, [Issue(key_path="", message=message)]) from None
    issues: list[Issue] = []
    top = Table(parse_toml(path, content), "", issues)
    top.check_keys(_TOP_KEYS)
    check_schema_version(top)
    name = top.get("name", Text(name=True), required=True)
    top.get("kind", Choice((KIND,)), required=True)
    if "description" in top.data and not isinstance(top.data["description"], str):
        top.report("description", f"expected a string, got {describe(top.data['description'])}")
    part = _part(top.table("part", required=True))
    support = _support(top.table("support", required=True), folder=path.parent)
    pusher = _pusher(top.table("pusher", required=True))
    simulation = _simulation(top.table("simulation", required=True))
    if issues or None in (part, support, pusher, simulation):
        raise ProblemFileError(path, issues)
    shape, mass, pose = part
    mu, model, patch, gravity, support_table = support
    if patch is None:
        patch = _outline_pressure(shape)
    normal_force = mass * gravity
    surface = build(support_table, LimitSurface, field=patch, mu=mu, normal_force=normal_force)
    if surface is not None and model == "ellipsoid":
        surface = build(support_table, Ellipsoid.from_limit_surface, ls=surface)
    if issues or surface is None:
        raise ProblemFileError(path, issues)
    duration, steps, start_overlap = simulation
    return PushFile(
        name=name, path=path, sha256=hashlib.sha256(content).hexdigest(), surface=surface,
        model=model, shape=shape, pusher=pusher, pose=tuple(pose), duration=duration,
        steps=steps, start_overlap=start_overlap, normal_force=normal_force, support_mu=mu,
    )  # fmt: skip


def _part(table: Table | None):
    if table is None:
        return None
    start = len(table.issues)
    table.check_keys(_PART_KEYS)
    shape = _outline(table.table("outline", required=True))
    mass = table.get("mass", _MASS, required=True)
    pose = table.get("pose", _POSE, default=[0.0, 0.0, 0.0])
    if len(table.issues) > start or shape is None:
        return None
    return shape, mass, pose


def _outline(table: Table | None) -> Outline | None:
    if table is None:
        return None
    shape = table.get("shape", Choice(OUTLINE_SHAPES), required=True)
    if shape is None:
        return None
    table.check_keys(_OUTLINE_KEYS[shape])
    start = len(table.issues)
    if shape == "rectangle":
        length = table.get("length", LENGTH, required=True)
        width = table.get("width", LENGTH, required=True)
        arguments = {"length": length, "width": width}
        constructor = Outline.rectangle
    elif shape == "polygon":
        arguments = {"vertices": table.get("vertices", _VERTICES, required=True)}
        constructor = Outline.polygon
    else:
        arguments = {"radius": table.get("radius", LENGTH, required=True)}
        constructor = Outline.disk
    if len(table.issues) > start:
        return None
    return build(table, constructor, **arguments)


def _support(table: Table | None, *, folder: Path):
    if table is None:
        return None
    start = len(table.issues)
    table.check_keys(_SUPPORT_KEYS)
    mu = table.get("mu", _SUPPORT_MU, required=True)
    model = table.get("model", Choice(SUPPORT_MODELS), default="exact")
    gravity = table.get("gravity", _GRAVITY, default=STANDARD_GRAVITY)
    offset = table.get("offset", _POINT)
    patch, _ = read_patch(table, folder=folder)
    if "offset" in table.data and "patch" not in table.data:
        table.report("offset", "only with a patch (the default patch is the outline, in place)")
    if len(table.issues) > start:
        return None
    if patch is not None and offset is not None:
        patch = patch.shifted(*offset)
    return mu, model, patch, gravity, table


def _pusher(table: Table | None) -> PointPusher | LinePusher | None:
    if table is None:
        return None
    shape = table.get("shape", Choice(PUSHER_SHAPES), required=True)
    if shape is None:
        return None
    start = len(table.issues)
    table.check_keys(_PUSHER_KEYS[shape])
    mu = table.get("mu", _PUSHER_MU, required=True)
    origin = table.get("start", _POINT, required=True)
    velocity = table.get("velocity", _VELOCITY, required=True)
    if velocity is not None and not any(velocity):
        table.report("velocity", "expected a nonzero velocity (a pusher at rest moves nothing)")
    if shape == "point":
        arguments = {"radius": table.get("radius", _RADIUS, default=0.0)}
        constructor = PointPusher
    else:
        arguments = {"width": table.get("width", LENGTH, required=True)}
        normal = table.get("normal", _DIRECTION)
        if normal is not None and math.hypot(*normal) == 0.0:
            table.report("normal", "expected a direction, got the zero vector")
        if normal is not None:
            arguments["normal"] = normal
        constructor = LinePusher
    if len(table.issues) > start:
        return None
    return build(table, constructor, path=(origin, velocity), mu=mu, **arguments)


def _simulation(table: Table | None):
    if table is None:
        return None
    start = len(table.issues)
    table.check_keys(_SIMULATION_KEYS)
    duration = table.get("duration", _DURATION, required=True)
    steps = table.get("steps", _STEPS, required=True)
    start_overlap = table.get("start_overlap", _RADIUS, default=0.0)
    if len(table.issues) > start:
        return None
    return duration, steps, start_overlap


def _outline_pressure(shape: Outline) -> pressure.PressureField:
    """Uniform pressure over the part's outline, in place in the part frame."""
    if not len(shape.vertices):
        return pressure.disk(shape.radius)
    return pressure.polygon(shape.vertices, centered=False)


__all__ = ["PushFile", "file_kind", "load_push"]
