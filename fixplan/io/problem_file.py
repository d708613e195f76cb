"""Problem files: a fixture or grasp problem in TOML, read into a :class:`~fixplan.planner.problem.Problem`.

:func:`load_problem` checks the whole file before it builds anything and reports every mistake
at once in a :class:`ProblemFileError`, one :class:`Issue` per mistake, each with the key path
of the offending value (``contacts[2].mu``, ``loads[0].force``; indices are 0-based). Units are
SI throughout. The schema::

    schema_version = 1                    # required, must be 1
    name = "vise-milling"                 # required
    kind = "fixture"                      # "fixture" or "grasp"; required
    objective = "min-total-clamp-force"   # required; one of fixplan.planner.problem.OBJECTIVES
    description = "..."                   # optional free text

    [defaults]                            # optional; mu, model, facets, inscribed, stiffness
    mu = 0.3                              #   apply to every contact that does not set them
    model = "ellipsoid"                   #   (facets and inscribed only to pyramid models)
    stiffness = { normal = 1e8, tangential = 5e7, torsional = 30.0 }

    [body]
    mass = 2.0                            # [kg], required
    center_of_mass = [0.0, 0.0, 0.02]     # [m], required
    gravity = [0.0, 0.0, -9.81]           # [m/s^2], optional (default that)
    inertia = [[0.01, 0, 0], [0, 0.02, 0], [0, 0, 0.02]]  # [kg m^2] about the centre of
                                          # mass, optional (needed by turning loads)
    size = [0.15, 0.1, 0.03]              # [m], optional: a box; its inertia is the default

    # or a body from a closed mesh (its mass properties computed, no center_of_mass/inertia):
    # mesh = "part.stl"                   # relative to this file; STL, OBJ, PLY, ...
    # density = 7850.0                    # [kg/m^3], or mass = ... [kg] (exactly one)
    # mesh_scale = 0.001                  # [m per mesh unit], optional (1: metres)

    [[contacts]]                          # at least one
    name = "jaw-fixed"                    # required, unique
    role = "locator"                      # locator | support | clamp | finger
    position = [-0.05, 0.0, 0.02]         # [m]
    normal = [1.0, 0.0, 0.0]              # into the body, a unit vector
    # on_surface = [-0.05, 0.0, 0.02]     # instead of position and normal, with a mesh body:
                                          # the closest surface point, its inward normal
    mu = 0.25                             # >= 0 (0: frictionless); required unless
                                          # [defaults] gives it
    model = "exact"                       # exact | ellipsoid | cone | pyramid | point-cone
                                          # | point-pyramid | fitted; required unless
                                          # [defaults] gives it ("fitted": not in [defaults])
    facets = 8                            # pyramid models only, >= 3
    inscribed = true                      # pyramid models only
    fit = "fits/jaw.json"                 # model "fitted" only, required with it
    cuts = 256                            # model "fitted" with a quartic fit only
    axis = [0.0, 1.0, 0.0]                # optional world direction of the patch x axis
    patch = { shape = "rectangle", length = 0.08, width = 0.03 }
    force = 150.0                         # fixed normal force of a clamp or finger [N]
    max_force = 2000.0                    # bound on a clamp's or finger's normal force [N]
    stiffness = { normal = 6.2e7, tangential = 5.1e7 }   # springs in the contact frame:
                                          # normal > 0 and tangential >= 0 [N/m], optional
                                          # torsional >= 0 [N m/rad] (omitted: no moment)

    [[loads]]                             # at least one
    name = "face-mill-pass-1"             # required, unique
    force = [120.0, -40.0, -60.0]         # [N], optional (default 0)
    point = [0.03, 0.0, 0.04]             # [m], required with force
    torque = [0.0, 0.0, 1.5]              # [N m], optional
    acceleration = [0.0, 0.0, 5.0]        # [m/s^2] of the centre of mass, optional: the body
    angular_velocity = [0.0, 0.0, 2.0]    # [rad/s] and angular acceleration [rad/s^2] move,
    angular_acceleration = [0.0, 0.0, 8.0]  # optional; their d'Alembert wrench joins the load

A contact's **stiffness** (:class:`fixplan.motion.Stiffness`) is its own table, else the one of
``[defaults]`` (a contact's table replaces it whole). Stiffnesses feed the compliant analysis
(:func:`fixplan.motion.compliance.analyse`); the objective ``check-compliant`` (the rigid
``check`` followed by that analysis) needs one for every contact. They are kept out of the
:class:`~fixplan.planner.problem.Problem`, in :attr:`ProblemFile.stiffness`.

A **fitted** contact (``model = "fitted"``) takes its friction set from a fit saved by
:meth:`fixplan.motion.Fit.save` (``fixplan fit ... --json``), the file named by ``fit``, relative
to the problem file's folder. A fitted ellipsoid enters the planner as its
:class:`~fixplan.models.FittedEllipsoid`; a quartic as its inscribed polytope of ``cuts``
tangent planes (even, default :data:`~fixplan.models.polytope.DEFAULT_CUTS` = 256; one linear
inequality per cut, contact and load case), which lies inside the fitted surface and
underestimates it by at most its reported ``error`` (about 2 % at 256 cuts). The contact's
``mu`` is the fit's: leave ``mu`` out (``[defaults]``' ``mu`` does not apply), or give the same
value. It takes no ``patch`` (the fit is its friction set; the normal force acts at
``position``). A model override (``--model``) replaces the fitted model too, keeping the fit's
``mu``.

Patch shapes (lengths [m], coordinates in the contact's patch frame):

- ``disk``: ``radius``, ``pressure`` (``uniform`` default, ``hertz``, ``parabolic``,
  ``annulus`` with ``inner_radius``, ``ring``);
- ``rectangle``: ``length``, ``width``, ``pressure = "uniform"`` (the only one), ``axis`` (world
  direction of the length; it sets the contact's axis unless the contact gives the same one);
- ``polygon``: ``vertices = [[x, y], ...]``;
- ``points``: ``xy = [[x, y], ...]``, optional relative ``weights``;
- ``grid``: cell centres ``x``, ``y`` and relative pressures ``values``, one row per ``y``:
  an array of rows or the name of a CSV file, relative to the problem file's folder.

A **layout file** (``fixplan layout``, :func:`load_problem` with ``layout=True``) is a problem
file whose ``[[contacts]]`` (now optional) are the fixed contacts, plus candidate contacts and how
many of each role a layout uses::

    [[candidates]]                        # at least one; the keys of [[contacts]]
    name = "rest-a"
    role = "locator"
    position = [-0.055, -0.035, 0.0]
    normal = [0.0, 0.0, 1.0]

    [[candidates]]                        # or candidates spread over faces of the body's mesh:
    name = "top"                          # named top-0, top-1, ... (no position or normal)
    role = "clamp"
    sample = { facing = [0.0, 0.0, 1.0], count = 12, seed = 0 }   # or faces = [indices]

    [choose]                              # role -> a count or [min, max]
    locator = 3
    clamp = [1, 2]
"""

from __future__ import annotations

import hashlib
import math
import os
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from fixplan import validation
from fixplan.errors import FixplanError, InvalidArgumentError
from fixplan.io.patch_schema import read_patch
from fixplan.io.toml_schema import (
    MAX_FILE_BYTES,
    SHORT,
    Array,
    Boolean,
    Choice,
    Integer,
    InvalidValueError,
    Issue,
    Kind,
    Number,
    ProblemFileError,
    Table,
    Text,
    build,
    check_schema_version,
    check_unique_names,
    describe,
    given,
    parse_toml,
    read_regular_file,
)
from fixplan.motion import Fit, FittedQuartic, Stiffness
from fixplan.planner.contact_models import contact_model
from fixplan.planner.mesh_body import surface_contact
from fixplan.planner.problem import (
    AREA_MODEL_NAMES,
    COMPLIANT_OBJECTIVE,
    FIXED_FORCE_OBJECTIVES,
    MODEL_NAMES,
    OBJECTIVES,
    PASSIVE_ROLES,
    ROLES,
    Body,
    Contact,
    Load,
    Problem,
)
from fixplan.tolerances import (
    MAX_ACCELERATION,
    MAX_ANGULAR_ACCELERATION,
    MAX_ANGULAR_VELOCITY,
    MAX_DENSITY,
    MAX_FACETS,
    MAX_FORCE,
    MAX_INERTIA,
    MAX_LENGTH,
    MAX_MASS,
    MAX_MU,
    MAX_STIFFNESS,
    MAX_TORQUE,
    MIN_MU,
    MIN_STIFFNESS,
)

KINDS = ("fixture", "grasp")
#: Largest mesh file of a body read [bytes] (a finely tessellated part of a few million faces).
MAX_MESH_BYTES = 200_000_000
#: The model of a contact whose friction set is a saved fit (its ``fit`` key names the file).
FITTED = "fitted"
PYRAMID_MODEL_NAMES = ("pyramid", "point-pyramid")
#: The point model a model override gives to contacts without a patch.
POINT_VERSION = {
    "exact": "point-cone",
    "ellipsoid": "point-cone",
    "cone": "point-cone",
    "pyramid": "point-pyramid",
}

#: Most tangent planes of a fitted quartic's polytope (each is one inequality per load case;
#: 4096 cuts approximate a quartic to about 0.1 %).
MAX_CUTS = 4096
#: A contact's ``mu`` agrees with its fit's when they differ by at most this fraction (a fit's
#: ``mu`` typed from a printout with 7 significant digits).
FIT_MU_RTOL = 1e-6

#: A contact normal in a file must have length 1 within this absolute tolerance (a guard against
#: typos; the value is normalised exactly when the contact is built).
UNIT_NORMAL_ATOL = 1e-6
#: A contact ``axis`` and its rectangle patch's ``axis`` are the same direction when their unit
#: vectors differ by at most this much in every component.
SAME_AXIS_ATOL = 1e-6

_TOP_KEYS = (
    "schema_version",
    "name",
    "kind",
    "objective",
    "description",
    "defaults",
    "body",
    "contacts",
    "loads",
)
_LAYOUT_KEYS = ("candidates", "choose")
_SAMPLE_KEYS = ("count", "facing", "faces", "seed")
#: Most candidates one ``sample`` table may spread over a mesh. The search grows faster than
#: their number: on ``problems/layouts/layout-plate.toml`` with its sampled clamps 100, 300 and
#: 1,000 took 7, 17 and 105 s (large mode); 10,000 did not end in 120 s.
MAX_SAMPLED = 1_000
_DEFAULT_KEYS = ("mu", "model", "facets", "inscribed", "stiffness")
_CONTACT_KEYS = (
    "name",
    "role",
    "on_surface",
    "position",
    "normal",
    "mu",
    "model",
    "facets",
    "inscribed",
    "fit",
    "cuts",
    "axis",
    "patch",
    "force",
    "max_force",
    "stiffness",
)


@dataclass(frozen=True, slots=True)
class SurfaceContact:
    """Where a contact given by ``on_surface`` sits on the body's mesh: the ``requested`` point,
    the closest surface ``position`` and its inward ``normal`` (world frame), and the
    ``distance`` between the two points [m]."""

    requested: tuple[float, float, float]
    position: tuple[float, float, float]
    normal: tuple[float, float, float]
    distance: float


@dataclass(frozen=True, slots=True, kw_only=True)
class ProblemFile:
    """A problem read from a file, with where it came from.

    Attributes
    ----------
    problem : Problem
        The planning problem.
    name : str
        The file's ``name``.
    kind : str
        ``"fixture"`` or ``"grasp"``.
    path : Path
        The file read.
    sha256 : str
        Hex SHA-256 digest of the file's bytes (identifies the exact input of a result).
    model_override : str or None
        The friction model that replaced every contact's model, if any.
    stiffness : dict or None
        :class:`~fixplan.motion.Stiffness` by contact name, for the contacts the file gives one
        (their own or ``[defaults]``'); ``None`` when it gives none.
    surface_contacts : dict
        :class:`SurfaceContact` by contact name, for the contacts placed with ``on_surface``.
    candidates : tuple of Contact
        A layout file's candidate contacts (also the last contacts of ``problem``).
    choose : dict
        A layout file's role -> count or ``(min, max)``.
    """

    problem: Problem
    name: str
    kind: str
    path: Path
    sha256: str
    model_override: str | None = None
    stiffness: dict[str, Stiffness] | None = None
    surface_contacts: dict[str, SurfaceContact] = field(default_factory=dict)
    candidates: tuple[Contact, ...] = ()
    choose: dict = field(default_factory=dict)


def load_problem(
    path: str | os.PathLike[str],
    *,
    model: str | None = None,
    objective: str | None = None,
    layout: bool = False,
) -> ProblemFile:
    """Read and validate a TOML problem file (schema in the module docstring).

    Parameters
    ----------
    path : str or path-like
        The problem file.
    model : str, optional
        Friction model that replaces every contact's model (one of
        :data:`fixplan.planner.problem.MODEL_NAMES`). With an area model, contacts without a patch get
        its point version (:data:`POINT_VERSION`); ``facets`` and ``inscribed`` are dropped from
        contacts when the model is not a pyramid.
    objective : str, optional
        Objective that replaces the file's (one of :data:`fixplan.planner.problem.OBJECTIVES`);
        its demands on the contacts (given forces, stiffnesses) are checked as the file's.
    layout : bool, optional
        Read a layout file: ``[[candidates]]`` and ``[choose]``, ``[[contacts]]`` optional. The
        problem's contacts are the fixed ones followed by the candidates.

    Returns
    -------
    ProblemFile
        The problem with the file's name, kind, path, digest and contact stiffnesses.

    Raises
    ------
    ProblemFileError
        The file cannot be read, is not TOML, or breaks the schema; lists every issue.
    InvalidArgumentError
        ``model`` is not a model name or ``objective`` not an objective.
    """
    path = Path(path)
    if model is not None:
        model = validation.choice("model", model, MODEL_NAMES)
    if objective is not None:
        objective = validation.choice("objective", objective, OBJECTIVES)
    try:
        content = read_regular_file(path, MAX_FILE_BYTES)
    except InvalidValueError as exc:
        message = f"cannot read the file: {exc}"
        raise ProblemFileError(path, [Issue(key_path="", message=message)]) from None
    document = parse_toml(path, content)
    reader = _Reader(folder=path.parent, model=model, objective=objective, layout=layout)
    name, kind, problem = reader.document(document)
    if reader.issues or problem is None:
        raise ProblemFileError(path, reader.issues)
    return ProblemFile(
        problem=problem,
        name=name,
        kind=kind,
        path=path,
        sha256=hashlib.sha256(content).hexdigest(),
        model_override=model,
        stiffness=reader.stiffness or None,
        surface_contacts=reader.surface_contacts,
        candidates=tuple(reader.candidates),
        choose=reader.choose,
    )


def problem_from_document(
    document: dict,
    path: str | os.PathLike[str],
    *,
    model: str | None = None,
    objective: str | None = None,
) -> Problem:
    """The problem of a parsed problem file (the dict ``tomllib`` gives), checked exactly as
    :func:`load_problem` checks a file's; ``path`` names it in messages and its folder is where
    relative paths (meshes, grids, fits) start. Sweeps vary a document and read each case so.

    Raises
    ------
    ProblemFileError
        The document breaks the schema; lists every issue.
    """
    path = Path(path)
    reader = _Reader(folder=path.parent, model=model, objective=objective)
    _, _, problem = reader.document(document)
    if reader.issues or problem is None:
        raise ProblemFileError(path, reader.issues)
    return problem


def check_problem(
    path: str | os.PathLike[str], *, model: str | None = None, objective: str | None = None
) -> ProblemFile:
    """Read a problem file like :func:`load_problem` and also build every contact's friction
    model, so that every mistake of the input that planning would meet is found, without
    solving.

    Raises
    ------
    ProblemFileError
        As :func:`load_problem`, or a contact's friction model cannot be built from its patch
        (reported at the contact's key path).
    """
    problem_file = load_problem(path, model=model, objective=objective)
    issues = []
    for index, contact in enumerate(problem_file.problem.contacts):
        try:
            contact_model(contact)
        except InvalidArgumentError as exc:
            message = f"its friction model cannot be built: {exc}"
            issues.append(Issue(key_path=f"contacts[{index}]", message=message))
    if issues:
        raise ProblemFileError(problem_file.path, issues)
    return problem_file


_MASS = Number(">= 0", MAX_MASS, "kg")
_FORCE = Number(">= 0", MAX_FORCE, "N")
_MU = Number(
    ">= 0",
    MAX_MU,
    smallest=MIN_MU,
    why_smallest="(friction that small is rounding noise against the forces; give 0 for a "
    "frictionless contact)",
)
_TEXT = Text()
_NAME = Text(name=True)
_BOOLEAN = Boolean()
_FACETS = Integer(3, MAX_FACETS)
_MODEL = Choice(MODEL_NAMES)
_CONTACT_MODEL = Choice((*MODEL_NAMES, FITTED))
_CUTS = Integer(6, MAX_CUTS)
_POSITION = Array((3,), Number("", MAX_LENGTH, "m"))
_FORCE_VECTOR = Array((3,), Number("", MAX_FORCE, "N"))
_TORQUE_VECTOR = Array((3,), Number("", MAX_TORQUE, "N m"))
_GRAVITY = Array((3,), Number("", MAX_ACCELERATION, "m/s^2"))
_SOFTEST = "(springs that soft leave the compliant analysis too badly scaled to solve"
_NORMAL_STIFFNESS = Number(
    "> 0", MAX_STIFFNESS, "N/m", smallest=MIN_STIFFNESS, why_smallest=_SOFTEST + ")"
)
_TANGENTIAL_STIFFNESS = Number(
    ">= 0", MAX_STIFFNESS, "N/m", smallest=MIN_STIFFNESS, why_smallest=_SOFTEST + "; or give 0)"
)
_TORSIONAL_STIFFNESS = Number(
    ">= 0", MAX_STIFFNESS, "N m/rad", smallest=MIN_STIFFNESS, why_smallest=_SOFTEST + "; or give 0)"
)
_INERTIA = Array((3, 3), Number("", MAX_INERTIA, "kg m^2"))
_SIZE = Array((3,), Number("> 0", MAX_LENGTH, "m"))
_DENSITY = Number("> 0", MAX_DENSITY, "kg/m^3")
_MESH_SCALE = Number("> 0", MAX_LENGTH, "m per mesh unit")
_BODY_KINDS = {
    "mass": _MASS,
    "center_of_mass": _POSITION,
    "gravity": _GRAVITY,
    "inertia": _INERTIA,
    "size": _SIZE,
}
_MESH_BODY_KINDS = {"mesh": _TEXT, "density": _DENSITY, "mass": _MASS, "mesh_scale": _MESH_SCALE,
                    "gravity": _GRAVITY}  # fmt: skip
_LOAD_KINDS = {
    "name": _NAME,
    "force": _FORCE_VECTOR,
    "point": _POSITION,
    "torque": _TORQUE_VECTOR,
    "acceleration": _GRAVITY,
    "angular_velocity": Array((3,), Number("", MAX_ANGULAR_VELOCITY, "rad/s")),
    "angular_acceleration": Array((3,), Number("", MAX_ANGULAR_ACCELERATION, "rad/s^2")),
}
_STIFFNESS_KINDS = {
    "normal": _NORMAL_STIFFNESS,
    "tangential": _TANGENTIAL_STIFFNESS,
    "torsional": _TORSIONAL_STIFFNESS,
}


@dataclass(frozen=True, slots=True, kw_only=True)
class _Defaults:
    """The valid values of ``[defaults]`` and the keys it gives (valid or not)."""

    values: dict = field(default_factory=dict)
    keys: frozenset = frozenset()


class _Reader:
    """Reads a parsed problem file, collecting issues; builds only what is valid."""

    def __init__(
        self, *, folder: Path, model: str | None, objective: str | None, layout: bool = False
    ):
        self.folder = folder
        self.layout = layout
        self.candidates: list[Contact] = []
        self.choose: dict = {}
        self.model = model
        self.objective = objective
        self.issues: list[Issue] = []
        self.stiffness: dict[str, Stiffness] = {}  # by contact name
        self.fits: dict[tuple[str, int | None], object] = {}  # planner models of fits read
        self.mesh = None  # the body's mesh, for contacts on its surface
        self.mesh_declared = False  # whether the file names one (read or not)
        self.surface_contacts: dict[str, SurfaceContact] = {}

    def document(self, data: dict) -> tuple[str | None, str | None, Problem | None]:
        """The file's name, kind and problem (``None`` where invalid)."""
        top = Table(data, "", self.issues)
        if not self.layout and "candidates" in data:
            top.report("candidates", "a layout file (candidate contacts to choose from): run it "
                                     "with `fixplan layout FILE`")  # fmt: skip
            return None, None, None
        top.check_keys(_TOP_KEYS + (_LAYOUT_KEYS if self.layout else ()))
        check_schema_version(top)
        name = top.get("name", _NAME, required=True)
        if data.get("kind") == "push":
            top.report("kind", "a push file (kind = 'push'): run it with `fixplan push FILE`")
            return None, None, None
        kind = top.get("kind", Choice(KINDS), required=True)
        objective = top.get("objective", Choice(OBJECTIVES), required=self.objective is None)
        objective = self.objective or objective
        if "description" in data and not isinstance(data["description"], str):
            top.report("description", f"expected a string, got {describe(data['description'])}")
        defaults = self._defaults(top.table("defaults"))
        body_table = top.table("body", required=True)
        body = self._body(body_table)
        self.mesh = None if body is None else body.mesh
        self.mesh_declared = body_table is not None and "mesh" in body_table.data
        optional = self.layout and "contacts" not in data
        contact_tables = [] if optional else top.tables("contacts")
        contacts = [self._contact(table, defaults) for table in contact_tables]
        check_unique_names(contact_tables, "contact")
        if self.layout:
            self.candidates = self._candidates(top, defaults, body)
            contacts += self.candidates
            self.choose = _choose(top.table("choose", required=True))
        self._stiffnesses(top, contact_tables, defaults, objective)
        load_tables = top.tables("loads")
        loads = [self._load(table) for table in load_tables]
        check_unique_names(load_tables, "load")
        if self.issues:
            return name, kind, None
        self._demands(objective, body_table, body, contact_tables, contacts, load_tables, loads)
        if self.issues:
            return name, kind, None
        # Only the objective's demands on the contacts are left for Problem to find.
        problem = build(
            top,
            Problem,
            key="objective",
            body=body,
            contacts=contacts,
            loads=loads,
            objective=objective,
        )
        return name, kind, problem

    def _demands(self, objective, body_table, body, contact_tables, contacts, load_tables, loads):
        """The demands one table makes of another, each reported where it is to be met: the
        given forces of a fixed-force objective (at each contact), the body's inertia of a
        turning load (at the body), names of candidates the contacts use (at the candidate)."""
        if objective in FIXED_FORCE_OBJECTIVES:
            for table, contact in zip(contact_tables, contacts, strict=False):
                if contact.is_active and contact.force is None:
                    table.report("force", f"required: objective {objective!r} takes the "
                                          "active forces as given (or give a force "
                                          "objective)")  # fmt: skip
        if body is not None and body.inertia is None:
            for table, load in zip(load_tables, loads, strict=True):
                if load.rotates:
                    body_table.report(None, f"load {load.name!r} ({table.path}) has an angular "
                                            "velocity or acceleration: the body needs an inertia "
                                            "tensor (inertia, size or a mesh)")  # fmt: skip
                    break
        names = {c.name: table.path for table, c in zip(contact_tables, contacts, strict=False)}
        for candidate in self.candidates if self.layout else ():
            if candidate.name in names:
                self.issues.append(Issue(key_path=names[candidate.name] + ".name",
                                         message=f"contact name {candidate.name!r} is also a "
                                                 "candidate's"))  # fmt: skip

    def _candidates(self, top: Table, defaults: _Defaults, body: Body | None) -> list[Contact]:
        """A layout file's candidates, those of ``sample`` tables spread over the mesh."""
        tables = top.tables("candidates")
        check_unique_names(tables, "candidate")
        found = []
        for table in tables:
            if "sample" in table.data:
                found += self._sampled(table, defaults, body)
            else:
                found.append(self._contact(table, defaults))
        return found

    def _sampled(self, table: Table, defaults: _Defaults, body: Body | None) -> list:
        """The candidates of a ``sample`` table (:func:`fixplan.design.candidates.sample_surface`)."""
        from fixplan.design.candidates import sample_surface

        for key in ("position", "normal", "on_surface"):
            if key in table.data:
                table.report(key, "not with sample: the mesh gives the candidates' " + key)
        spec = table.table("sample")
        if spec is None:
            return []
        spec.check_keys(_SAMPLE_KEYS)
        count = spec.get("count", Integer(1, MAX_SAMPLED), required=True)
        facing = spec.get("facing", Array((3,), Number("", MAX_LENGTH, "")))
        faces = spec.get("faces", Array((None,), Number(">= 0", 2**31 - 1)))
        seed = spec.get("seed", Integer(0, 2**31 - 1), default=0)
        if self.mesh is None and not self.mesh_declared:
            table.report("sample", 'needs a body read from a mesh ([body] mesh = "...")')
        data = {k: v for k, v in table.data.items() if k not in ("sample", "position", "normal")}
        template = self._contact(
            Table({**data, "position": [0.0, 0.0, 0.0], "normal": [0.0, 0.0, 1.0]}, table.path,
                  self.issues), defaults,
        )  # fmt: skip
        if template is None or body is None or self.mesh is None or count is None:
            return []
        try:
            return sample_surface(
                body, template=template, n=count, faces=faces, facing=facing, seed=seed,
                prefix=f"{template.name}-",
            )  # fmt: skip
        except InvalidArgumentError as exc:
            table.report("sample", str(exc))
            return []

    def _defaults(self, table: Table | None) -> _Defaults:
        if table is None:
            return _Defaults()
        table.check_keys(_DEFAULT_KEYS)
        kinds = {"mu": _MU, "model": _MODEL, "facets": _FACETS, "inscribed": _BOOLEAN}
        values = {key: table.get(key, kind) for key, kind in kinds.items()}
        values["stiffness"] = _stiffness(table)
        return _Defaults(
            values={key: value for key, value in values.items() if value is not None},
            keys=frozenset(table.data),
        )

    def _stiffnesses(
        self, top: Table, tables: list[Table], defaults: _Defaults, objective: str | None
    ) -> None:
        """Collect each contact's stiffness (its own, else ``[defaults]``'); report the contacts
        without one if the objective needs them."""
        missing = []
        for table in tables:
            own = "stiffness" in table.data
            stiffness = _stiffness(table) if own else defaults.values.get("stiffness")
            name = table.data.get("name")
            if stiffness is not None and isinstance(name, str):
                self.stiffness[name] = stiffness
            elif not own and "stiffness" not in defaults.keys:
                missing.append(repr(name) if isinstance(name, str) else table.path)
        if objective == COMPLIANT_OBJECTIVE and missing:
            source = "the objective override" if self.objective else "objective"
            top.report(
                "objective",
                f"{source} {objective!r} needs every contact's stiffness; missing for "
                f"{', '.join(missing)}: add stiffness = {{ normal = ..., tangential = ... }} "
                "[N/m] to those [[contacts]] or to [defaults]",
            )

    def _body(self, table: Table | None) -> Body | None:
        if table is None:
            return None
        if "mesh" not in table.data:
            for key in ("density", "mesh_scale"):
                if key in table.data:
                    table.report(key, 'only for a body read from a mesh (give mesh = "...")')
            return table.read(Body, _BODY_KINDS, required=("mass", "center_of_mass"))
        for key in ("center_of_mass", "inertia", "size"):
            if key in table.data:
                table.report(key, "not with a mesh: the mesh gives the body's mass properties")
        if ("mass" in table.data) == ("density" in table.data):
            table.report("mesh", "give exactly one of density [kg/m^3] and mass [kg] with a mesh")
        start = len(self.issues)
        table.check_keys(tuple(_MESH_BODY_KINDS))
        values = {key: table.get(key, kind) for key, kind in _MESH_BODY_KINDS.items()}
        if len(self.issues) > start:
            return None
        path = self.folder / values.pop("mesh")
        scale = values.pop("mesh_scale") or 1.0
        try:
            read_regular_file(path, MAX_MESH_BYTES)
        except InvalidValueError as exc:
            table.report("mesh", f"cannot read {path.name!r}: {exc}")
            return None
        try:
            return Body.from_mesh(path, scale=scale, **given(**values))
        except FixplanError as exc:
            table.report("mesh", str(exc))
            return None

    def _load(self, table: Table) -> Load | None:
        if "force" in table.data and "point" not in table.data:
            table.report("point", "missing: a load's force needs the point it acts at [m]")
            return None
        return table.read(Load, _LOAD_KINDS, required=("name",))

    def _contact(self, table: Table, defaults: _Defaults) -> Contact | None:
        start = len(self.issues)
        table.check_keys(_CONTACT_KEYS)
        name = table.get("name", _NAME, required=True)
        role = table.get("role", Choice(ROLES), required=True)
        if "on_surface" in table.data:
            position, normal = self._on_surface(table, name)
        else:
            position = table.get("position", _POSITION, required=True)
            normal = _normal(table)
        file_model = _with_default(
            table, "model", _CONTACT_MODEL, defaults, required=self.model is None
        )
        fitted = self._fit(table) if file_model == FITTED else None
        if file_model == FITTED:
            mu = None if fitted is None else _fitted_mu(table, fitted.mu)
        else:
            mu = _with_default(table, "mu", _MU, defaults, required=True)
            for key in ("fit", "cuts"):
                if key in table.data:
                    table.report(key, f"only for model {FITTED!r}; remove it or change the model")
        model = self.model or file_model
        if self.model in AREA_MODEL_NAMES and "patch" not in table.data:
            model = POINT_VERSION[self.model]  # an override keeps point contacts point contacts
        facets = self._pyramid_option(table, "facets", _FACETS, defaults, model)
        inscribed = self._pyramid_option(table, "inscribed", _BOOLEAN, defaults, model)
        if file_model == FITTED and self.model is None and "patch" in table.data:
            table.report(
                "patch",
                f"not for model {FITTED!r}: its fit is the contact's friction set; remove the "
                "patch (the normal force acts at position)",
            )
        patch, patch_axis = read_patch(table, folder=self.folder)
        if model in AREA_MODEL_NAMES and "patch" not in table.data:
            self._report_missing_patch(table, model, name)
        axis = _contact_axis(table, patch_axis)
        force, max_force = (_active_force(table, key, role) for key in ("force", "max_force"))
        if model == FITTED:
            model = fitted
        required = (name, role, position, normal, mu, model)
        if len(self.issues) > start or None in required:
            return None
        return build(
            table,
            Contact,
            name=name,
            role=role,
            position=position,
            normal=normal,
            mu=mu,
            model=model,
            patch=patch,
            axis=axis,
            facets=facets,
            inscribed=inscribed,
            force=force,
            max_force=max_force,
        )

    def _on_surface(self, table: Table, name: str | None) -> tuple[list | None, list | None]:
        """Position and inward normal of a contact at the body's mesh surface point closest to
        its ``on_surface`` point (recorded in :attr:`surface_contacts`)."""
        for key in ("position", "normal"):
            if key in table.data:
                table.report(key, "not with on_surface: the mesh gives the contact's " + key)
        point = table.get("on_surface", _POSITION)
        if point is None:
            return None, None
        if self.mesh is None:
            if not self.mesh_declared:  # else the mesh's own issue is reported
                table.report("on_surface", 'needs a body read from a mesh ([body] mesh = "...")')
            return None, None
        position, normal, distance = surface_contact(self.mesh, point)
        if isinstance(name, str):
            self.surface_contacts[name] = SurfaceContact(
                requested=tuple(point), position=tuple(position), normal=tuple(normal),
                distance=distance,
            )  # fmt: skip
        return position.tolist(), normal.tolist()

    def _fit(self, table: Table):
        """The planner model of the contact's saved fit (``fit``, ``cuts``), or ``None`` with
        the issue reported."""
        name = table.get("fit", _TEXT, required=True)
        cuts = table.get("cuts", _CUTS)
        if name is None or ("cuts" in table.data and cuts is None):
            return None
        if cuts is not None and cuts % 2:
            table.report(
                "cuts", f"expected an even integer (planes come in mirror pairs), got {cuts}"
            )
            return None
        if (name, cuts) in self.fits:
            return self.fits[name, cuts]
        try:
            read_regular_file(self.folder / name, MAX_FILE_BYTES)
            fit = Fit.load(self.folder / name)
        except (InvalidValueError, InvalidArgumentError) as exc:
            table.report("fit", f"cannot read the fit file {SHORT.repr(name)}: {exc}")
            return None
        if cuts is not None and not isinstance(fit.surface, FittedQuartic):
            table.report(
                "cuts",
                f"only for a quartic fit; {SHORT.repr(name)} is an ellipsoid, which enters the "
                "planner exactly: remove cuts",
            )
            return None
        return self.fits.setdefault((name, cuts), fit.planner_model(cuts=cuts))

    def _pyramid_option(
        self, table: Table, key: str, kind: Kind, defaults: _Defaults, model: str | None
    ):
        """``facets`` or ``inscribed``: only for pyramid models; dropped by a non-pyramid
        override."""
        pyramid = model in PYRAMID_MODEL_NAMES
        if key not in table.data:
            return defaults.values.get(key) if pyramid else None
        value = table.get(key, kind)
        if model is None or pyramid:
            return value
        if self.model is None:
            table.report(
                key,
                f"only for pyramid models ({', '.join(PYRAMID_MODEL_NAMES)}), not model "
                f"{model!r}; remove it or change the model",
            )
        return None

    def _report_missing_patch(self, table: Table, model: str, name: str | None) -> None:
        source = f"model {model!r}" if self.model is None else f"the model override {model!r}"
        contact = f"contact {name!r}" if name else "this contact"
        table.report(
            "patch",
            f"missing: {contact} needs a patch (area and pressure) for {source}; add one or use "
            "'point-cone' or 'point-pyramid'",
        )


def _choose(table: Table | None) -> dict:
    """A layout file's ``[choose]``: role -> count or ``(min, max)`` (counts >= 0)."""
    if table is None:
        return {}
    table.check_keys(ROLES)
    found = {}
    for role in ROLES:
        value = table.data.get(role)
        if value is None:
            continue
        if isinstance(value, int) and not isinstance(value, bool) and value >= 0:
            found[role] = value
        elif (
            isinstance(value, list)
            and len(value) == 2
            and all(isinstance(x, int) and not isinstance(x, bool) and x >= 0 for x in value)
            and value[0] <= value[1]
        ):
            found[role] = (value[0], value[1])
        else:
            table.report(role, f"expected a count >= 0 or [min, max], got {describe(value)}")
    if not table.data:
        table.report(None, "expected at least one role, e.g. locator = 3")
    return found


def _stiffness(table: Table) -> Stiffness | None:
    """The ``stiffness`` table in ``table`` (a contact or ``[defaults]``); ``None`` if it is
    missing or invalid (the issue reported)."""
    springs = table.table("stiffness")
    if springs is None:
        return None
    return springs.read(Stiffness, _STIFFNESS_KINDS, required=("normal", "tangential"))


def _fitted_mu(table: Table, fit_mu: float) -> float | None:
    """The fit's ``mu``; reports a contact ``mu`` that contradicts it."""
    if "mu" not in table.data:
        return fit_mu
    mu = table.get("mu", _MU)
    if mu is not None and abs(mu - fit_mu) > FIT_MU_RTOL * fit_mu:
        table.report(
            "mu",
            f"{mu:g} contradicts the fit's mu {fit_mu:.7g}: a fitted contact takes mu from its "
            "fit; remove mu, or refit",
        )
        return None
    return fit_mu


def _with_default(table: Table, key: str, kind: Kind, defaults: _Defaults, *, required: bool):
    """The contact's ``key``, else ``[defaults]``'s; reports it missing from both if required."""
    if key in table.data:
        return table.get(key, kind)
    if key in defaults.values:
        return defaults.values[key]
    if required and key not in defaults.keys:
        table.report(key, f"missing required key; expected {kind.expected} here or in [defaults]")
    return None


def _normal(table: Table) -> list[float] | None:
    normal = table.direction("normal", required=True)
    if normal is None:
        return None
    length = math.hypot(*normal)
    if abs(length - 1.0) > UNIT_NORMAL_ATOL:
        unit = [round(component / length, 9) for component in normal]
        table.report(
            "normal",
            f"expected a unit vector (length 1 within {UNIT_NORMAL_ATOL:g}), got length "
            f"{length:.9g}; did you mean {unit}?",
        )
        return None
    return normal


def _contact_axis(table: Table, patch_axis: list | None) -> list | None:
    """The contact's ``axis``, else its rectangle patch's; reports the two if they differ."""
    axis = table.direction("axis")
    if "axis" not in table.data:
        return patch_axis
    if axis is not None and patch_axis is not None:
        unit, patch_unit = (np.asarray(v) / np.linalg.norm(v) for v in (axis, patch_axis))
        if not np.allclose(unit, patch_unit, rtol=0.0, atol=SAME_AXIS_ATOL):
            table.report(
                "axis",
                f"{axis} differs from patch.axis {patch_axis}; give the direction once (the "
                "rectangle's axis sets the contact's)",
            )
    return axis


def _active_force(table: Table, key: str, role: str | None) -> float | None:
    if key not in table.data:
        return None
    if role in PASSIVE_ROLES:
        table.report(
            key,
            f"only clamps and fingers take a {key}; a {role}'s normal force is a reaction (remove "
            "it, or make the role 'clamp' or 'finger')",
        )
        return None
    return table.get(key, _FORCE)


__all__ = [
    "Issue",
    "ProblemFile",
    "ProblemFileError",
    "check_problem",
    "load_problem",
    "problem_from_document",
]
