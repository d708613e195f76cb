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

    [defaults]                            # optional; mu, model, facets, inscribed
    mu = 0.3                              #   apply to every contact that does not set them
    model = "ellipsoid"                   #   (facets and inscribed only to pyramid models)

    [body]
    mass = 2.0                            # [kg], required
    center_of_mass = [0.0, 0.0, 0.02]     # [m], required
    gravity = [0.0, 0.0, -9.81]           # [m/s^2], optional (default that)

    [[contacts]]                          # at least one
    name = "jaw-fixed"                    # required, unique
    role = "locator"                      # locator | support | clamp | finger
    position = [-0.05, 0.0, 0.02]         # [m]
    normal = [1.0, 0.0, 0.0]              # into the body, a unit vector
    mu = 0.25                             # >= 0 (0: frictionless); required unless
                                          # [defaults] gives it
    model = "exact"                       # exact | ellipsoid | cone | pyramid | point-cone
                                          # | point-pyramid; required unless [defaults] gives it
    facets = 8                            # pyramid models only, >= 3
    inscribed = true                      # pyramid models only
    axis = [0.0, 1.0, 0.0]                # optional world direction of the patch x axis
    patch = { shape = "rectangle", length = 0.08, width = 0.03 }
    force = 150.0                         # fixed normal force of a clamp or finger [N]
    max_force = 2000.0                    # bound on a clamp's or finger's normal force [N]

    [[loads]]                             # at least one
    name = "face-mill-pass-1"             # required, unique
    force = [120.0, -40.0, -60.0]         # [N], required
    point = [0.03, 0.0, 0.04]             # [m], required
    torque = [0.0, 0.0, 1.5]              # [N m], optional

Patch shapes (lengths [m], coordinates in the contact's patch frame):

- ``disk``: ``radius``, ``pressure`` (``uniform`` default, ``hertz``, ``parabolic``,
  ``annulus`` with ``inner_radius``, ``ring``);
- ``rectangle``: ``length``, ``width``, ``pressure = "uniform"`` (the only one), ``axis`` (world
  direction of the length; it sets the contact's axis unless the contact gives the same one);
- ``polygon``: ``vertices = [[x, y], ...]``;
- ``points``: ``xy = [[x, y], ...]``, optional relative ``weights``;
- ``grid``: cell centres ``x``, ``y`` and relative pressures ``values``, one row per ``y``:
  an array of rows or the name of a CSV file, relative to the problem file's folder.
"""

from __future__ import annotations

import csv
import difflib
import functools
import hashlib
import math
import os
import re
import reprlib
import stat
import tomllib
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from datetime import date, datetime, time
from pathlib import Path

import numpy as np

from fixplan import validation
from fixplan.errors import FixplanError, InvalidArgumentError
from fixplan.planner.contact_models import PLANNER_EXACT_ORDER, contact_model
from fixplan.planner.problem import (
    AREA_MODEL_NAMES,
    MODEL_NAMES,
    OBJECTIVES,
    PASSIVE_ROLES,
    ROLES,
    Body,
    Contact,
    Load,
    Problem,
)
from fixplan.surface import pressure
from fixplan.tolerances import (
    MAX_ACCELERATION,
    MAX_ASPECT_RATIO,
    MAX_EXACT_POINTS,
    MAX_FACETS,
    MAX_FORCE,
    MAX_GRID_CELLS,
    MAX_LENGTH,
    MAX_MASS,
    MAX_MU,
    MAX_NAME_LENGTH,
    MAX_POINTS,
    MAX_POLYGON_VERTICES,
    MAX_RELATIVE_VALUE,
    MAX_TORQUE,
    MIN_MU,
    MIN_PATCH_LENGTH,
)

#: The version of the schema this module reads.
SCHEMA_VERSION = 1
KINDS = ("fixture", "grasp")
PATCH_SHAPES = ("disk", "rectangle", "polygon", "points", "grid")
PYRAMID_MODEL_NAMES = ("pyramid", "point-pyramid")
#: The point model a model override gives to contacts without a patch.
POINT_VERSION = {
    "exact": "point-cone",
    "ellipsoid": "point-cone",
    "cone": "point-cone",
    "pyramid": "point-pyramid",
}

#: Largest problem file, and largest CSV file of a grid patch, read [bytes].
MAX_FILE_BYTES = 10_000_000

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
_DEFAULT_KEYS = ("mu", "model", "facets", "inscribed")
_BODY_KEYS = ("mass", "center_of_mass", "gravity")
_CONTACT_KEYS = (
    "name",
    "role",
    "position",
    "normal",
    "mu",
    "model",
    "facets",
    "inscribed",
    "axis",
    "patch",
    "force",
    "max_force",
)
_LOAD_KEYS = ("name", "force", "point", "torque")
_PATCH_KEYS = {
    "disk": ("shape", "radius", "pressure", "inner_radius"),
    "rectangle": ("shape", "length", "width", "pressure", "axis"),
    "polygon": ("shape", "vertices"),
    "points": ("shape", "xy", "weights"),
    "grid": ("shape", "x", "y", "values"),
}

_SHORT = reprlib.Repr()
_SHORT.maxstring = _SHORT.maxother = 40


@dataclass(frozen=True, slots=True, kw_only=True)
class Issue:
    """One mistake in a problem file.

    Attributes
    ----------
    key_path : str
        Where the mistake is, e.g. ``"contacts[2].mu"`` (0-based indices); ``""`` for the file
        as a whole (unreadable, not TOML).
    message : str
        What is wrong and what is expected.
    """

    key_path: str
    message: str

    def __str__(self) -> str:
        return f"{self.key_path}: {self.message}" if self.key_path else self.message


class ProblemFileError(FixplanError, ValueError):
    """A problem file cannot be read or is invalid; lists every issue found.

    ``str(error)`` has one line per issue, ``FILE: key.path: message``.

    Attributes
    ----------
    path : Path
        The problem file.
    issues : list of Issue
        Every mistake found, in the order found.
    """

    def __init__(self, path: str | os.PathLike[str], issues: Sequence[Issue]):
        self.path = Path(path)
        self.issues = list(issues)
        super().__init__(self.path, self.issues)

    def __str__(self) -> str:
        return "\n".join(f"{self.path}: {issue}" for issue in self.issues)


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
    """

    problem: Problem
    name: str
    kind: str
    path: Path
    sha256: str
    model_override: str | None = None


def load_problem(path: str | os.PathLike[str], *, model: str | None = None) -> ProblemFile:
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

    Returns
    -------
    ProblemFile
        The problem with the file's name, kind, path and digest.

    Raises
    ------
    ProblemFileError
        The file cannot be read, is not TOML, or breaks the schema; lists every issue.
    InvalidArgumentError
        ``model`` is not a model name.
    """
    path = Path(path)
    if model is not None:
        model = validation.choice("model", model, MODEL_NAMES)
    try:
        content = _read_regular_file(path, MAX_FILE_BYTES)
    except _InvalidValueError as exc:
        message = f"cannot read the file: {exc}"
        raise ProblemFileError(path, [Issue(key_path="", message=message)]) from None
    document = _parse_toml(path, content)
    reader = _Reader(folder=path.parent, model=model)
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
    )


def _read_regular_file(path: Path, limit: int) -> bytes:
    """The bytes of the regular file ``path`` of at most ``limit`` bytes; the error's message
    says why it cannot be read.

    The file type is checked before the file is opened: reading a FIFO or a device would block
    or never end.
    """
    try:
        status = path.stat()
    except (OSError, ValueError) as exc:
        raise _InvalidValueError(_reason(exc)) from None
    if not stat.S_ISREG(status.st_mode):
        kind = "a folder" if stat.S_ISDIR(status.st_mode) else "not a regular file"
        raise _InvalidValueError(f"it is {kind}")
    if status.st_size > limit:
        raise _InvalidValueError(f"it has {status.st_size} bytes, more than the {limit} accepted")
    try:
        return path.read_bytes()
    except OSError as exc:
        raise _InvalidValueError(_reason(exc)) from None


def _reason(exc: Exception) -> str:
    """Why a file operation failed, without the path (the message names it already)."""
    if isinstance(exc, OSError) and exc.strerror:
        return exc.strerror
    if isinstance(exc, ValueError):
        return "the path is not valid (it holds a NUL character)"
    return str(exc)


def check_problem(path: str | os.PathLike[str], *, model: str | None = None) -> ProblemFile:
    """Read a problem file like :func:`load_problem` and also build every contact's friction
    model, so that every mistake of the input that planning would meet is found, without
    solving.

    Raises
    ------
    ProblemFileError
        As :func:`load_problem`, or a contact's friction model cannot be built from its patch
        (reported at the contact's key path).
    """
    problem_file = load_problem(path, model=model)
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


def _parse_toml(path: Path, content: bytes) -> dict:
    """The TOML document of ``content``; a leading UTF-8 byte-order mark is ignored."""
    try:
        return tomllib.loads(content.decode("utf-8-sig"))
    except UnicodeDecodeError as exc:
        message = f"not UTF-8 text (byte {exc.start} cannot be decoded); save it as UTF-8"
        raise ProblemFileError(path, [Issue(key_path="", message=message)]) from exc
    except tomllib.TOMLDecodeError as exc:
        message = f"TOML syntax error: {exc}"
        raise ProblemFileError(path, [Issue(key_path="", message=message)]) from exc
    except RecursionError:
        message = "tables or arrays are nested too deeply to read (hundreds of levels)"
        raise ProblemFileError(path, [Issue(key_path="", message=message)]) from None


class _InvalidValueError(Exception):
    """A value does not fit its key; the message says what was expected."""


def _describe(value: object) -> str:
    """A value named by its TOML type, e.g. ``string 'abc'`` or ``boolean true``."""
    if isinstance(value, bool):
        return f"boolean {str(value).lower()}"
    if isinstance(value, dict):
        return "a table"
    names = {int: "integer", float: "float", str: "string", list: "array"}
    names.update({datetime: "date-time", date: "date", time: "time"})
    kind = next(name for cls, name in names.items() if isinstance(value, cls))
    text = _SHORT.repr(value) if isinstance(value, str | list) else str(value)
    return f"{kind} {text}"


def _key_text(key: str) -> str:
    """``key`` as written in TOML: bare if it can be, quoted otherwise."""
    return key if re.fullmatch(r"[A-Za-z0-9_-]+", key) else f'"{key}"'


def _suggestion(word: str, allowed: Sequence[str]) -> str | None:
    close = difflib.get_close_matches(word, allowed, n=1)
    return close[0] if close else None


def _finite(value: object) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise _InvalidValueError(f"expected a number, got {_describe(value)}")
    try:
        number = float(value)  # TOML integers have no size limit
    except OverflowError:
        raise _InvalidValueError(
            f"expected a finite number, got an integer too large for a float ({len(str(value))} "
            "digits)"
        ) from None
    if not math.isfinite(number):
        raise _InvalidValueError(f"expected a finite number, got {value}")
    return number


@dataclass(frozen=True, slots=True)
class _Number:
    """A finite number, optionally bounded below (``bound`` is ``"> 0"`` or ``">= 0"``) and in
    size (``limit``, in ``unit``); positive values below ``smallest`` are rejected with
    ``why_smallest``."""

    bound: str = ""
    limit: float | None = None
    unit: str = ""
    smallest: float | None = None
    why_smallest: str = ""

    @property
    def expected(self) -> str:
        return f"a number {self.bound}".rstrip()

    @property
    def accepted_range(self) -> str:
        unit = f" {self.unit}" if self.unit else ""
        if self.bound:
            return f"a number {self.bound} and at most {self.limit:g}{unit}"
        return f"a number within ±{self.limit:g}{unit}"

    def __call__(self, value: object) -> float:
        number = _finite(value)
        if (self.bound == "> 0" and number <= 0.0) or (self.bound == ">= 0" and number < 0.0):
            raise _InvalidValueError(f"expected {self.expected}, got {value}")
        if self.limit is not None and abs(number) > self.limit:
            raise _InvalidValueError(f"expected {self.accepted_range}, got {value}")
        if self.smallest is not None and 0.0 < number < self.smallest:
            raise _InvalidValueError(
                f"expected {self.accepted_range}, got {value}: below {self.smallest:g} "
                f"{self.why_smallest}"
            )
        return number


@dataclass(frozen=True, slots=True)
class _Integer:
    """An integer from ``minimum`` to ``maximum``."""

    minimum: int
    maximum: int

    @property
    def expected(self) -> str:
        return f"an integer >= {self.minimum}"

    def __call__(self, value: object) -> int:
        if isinstance(value, bool) or not isinstance(value, int) or value < self.minimum:
            raise _InvalidValueError(f"expected {self.expected}, got {_describe(value)}")
        if value > self.maximum:
            raise _InvalidValueError(
                f"expected an integer from {self.minimum} to {self.maximum}, got {value}"
            )
        return value


@dataclass(frozen=True, slots=True)
class _Boolean:
    expected: str = "true or false"

    def __call__(self, value: object) -> bool:
        if not isinstance(value, bool):
            raise _InvalidValueError(f"expected {self.expected}, got {_describe(value)}")
        return value


@dataclass(frozen=True, slots=True)
class _Text:
    """A non-empty string; a name (``name=True``) has at most ``MAX_NAME_LENGTH`` characters
    and no control characters (names become headings and file names of reports)."""

    name: bool = False

    @property
    def expected(self) -> str:
        if self.name:
            return f"a name of 1 to {MAX_NAME_LENGTH} characters without control characters"
        return "a non-empty string"

    def __call__(self, value: object) -> str:
        if (
            not isinstance(value, str)
            or not value.strip()
            or (self.name and (len(value) > MAX_NAME_LENGTH or not value.isprintable()))
        ):
            got = f"{len(value)} characters" if isinstance(value, str) and len(value) > 40 else ""
            raise _InvalidValueError(f"expected {self.expected}, got {got or _describe(value)}")
        return value


@dataclass(frozen=True, slots=True)
class _Choice:
    """One of the strings ``allowed``."""

    allowed: tuple[str, ...]

    @property
    def expected(self) -> str:
        return "one of " + ", ".join(repr(a) for a in self.allowed)

    def __call__(self, value: object) -> str:
        if value in self.allowed:
            return str(value)
        message = f"expected {self.expected}; got {_describe(value)}"
        close = _suggestion(value, self.allowed) if isinstance(value, str) else None
        raise _InvalidValueError(message + (f" (did you mean {close!r}?)" if close else ""))


@dataclass(frozen=True, slots=True)
class _Array:
    """Nested non-empty arrays of ``shape`` (``None``: any length, up to ``max_items`` in the
    first dimension) of numbers of the kind ``element``."""

    shape: tuple[int | None, ...]
    element: _Number = _Number()
    max_items: int | None = None

    @property
    def expected(self) -> str:
        text = _shape_text(self.shape)
        return f"{text}, at most {self.max_items} of them" if self.max_items else text

    def __call__(self, value: object) -> list:
        if self.max_items is not None and isinstance(value, list) and len(value) > self.max_items:
            raise _InvalidValueError(f"expected at most {self.max_items} items, got {len(value)}")
        return _nested(value, self.shape, self.element, "")


def _shape_text(shape: tuple[int | None, ...], *, plural: bool = False) -> str:
    """The structure of nested arrays in words (the elements' range is told where one is out
    of it)."""
    if not shape:
        return "numbers" if plural else "a number"
    count = "" if shape[0] is None else f"{shape[0]} "
    head = "arrays" if plural else "an array"
    return f"{head} of {count}{_shape_text(shape[1:], plural=True)}"


def _nested(
    value: object, shape: tuple[int | None, ...], element: _Number, index: str
) -> list | float:
    where = f"element {index}: " if index else ""
    if not shape:
        try:
            return element(value)
        except _InvalidValueError as exc:
            raise _InvalidValueError(f"{where}{exc}") from None
    expected = _shape_text(shape)
    if not isinstance(value, list):
        raise _InvalidValueError(f"{where}expected {expected}, got {_describe(value)}")
    if not value:
        raise _InvalidValueError(f"{where}expected {expected}, got an empty array")
    if shape[0] is not None and len(value) != shape[0]:
        items = "item" if len(value) == 1 else "items"
        raise _InvalidValueError(f"{where}expected {expected}, got {len(value)} {items}")
    return [_nested(item, shape[1:], element, f"{index}[{i}]") for i, item in enumerate(value)]


_Kind = _Number | _Integer | _Boolean | _Text | _Choice | _Array

_LENGTH = _Number(
    "> 0",
    MAX_LENGTH,
    "m",
    smallest=MIN_PATCH_LENGTH,
    why_smallest="m (the limit surface's arithmetic underflows)",
)
_MASS = _Number(">= 0", MAX_MASS, "kg")
_FORCE = _Number(">= 0", MAX_FORCE, "N")
_MU = _Number(
    ">= 0",
    MAX_MU,
    smallest=MIN_MU,
    why_smallest="(friction that small is rounding noise against the forces; give 0 for a "
    "frictionless contact)",
)
_TEXT = _Text()
_NAME = _Text(name=True)
_BOOLEAN = _Boolean()
_FACETS = _Integer(3, MAX_FACETS)
_MODEL = _Choice(MODEL_NAMES)
_POSITION = _Array((3,), _Number("", MAX_LENGTH, "m"))
_FORCE_VECTOR = _Array((3,), _Number("", MAX_FORCE, "N"))
_TORQUE_VECTOR = _Array((3,), _Number("", MAX_TORQUE, "N m"))
_GRAVITY = _Array((3,), _Number("", MAX_ACCELERATION, "m/s^2"))
_DIRECTION = _Array((3,))
_COORDINATES = _Array((None,), _Number("", MAX_LENGTH, "m"), MAX_GRID_CELLS)
_RELATIVE = _Number("", MAX_RELATIVE_VALUE)
_WEIGHTS = _Array((None,), _RELATIVE, MAX_POINTS)
_VERTICES = _Array((None, 2), _Number("", MAX_LENGTH, "m"), MAX_POLYGON_VERTICES)
_POINTS = _Array((None, 2), _Number("", MAX_LENGTH, "m"), MAX_POINTS)
_ROWS = _Array((None, None), _RELATIVE, MAX_GRID_CELLS)


@dataclass(slots=True)
class _Table:
    """A TOML table being read: its contents, its key path and the issue list it reports to."""

    data: dict
    path: str
    issues: list[Issue]

    def key_path(self, key: str) -> str:
        return f"{self.path}.{_key_text(key)}" if self.path else _key_text(key)

    def report(self, key: str | None, message: str) -> None:
        """Record an issue at ``key`` (``None``: the table itself)."""
        where = self.path if key is None else self.key_path(key)
        self.issues.append(Issue(key_path=where, message=message))

    def check_keys(self, allowed: Sequence[str]) -> None:
        for key in self.data:
            if key not in allowed:
                close = _suggestion(key, allowed)
                hint = (
                    f"did you mean {close!r}?" if close else "allowed keys: " + ", ".join(allowed)
                )
                self.report(key, f"unknown key; {hint}")

    def get(self, key: str, kind: _Kind, *, required: bool = False, default: object = None):
        """The value at ``key`` converted by ``kind``; ``default`` if missing, ``None`` if
        invalid."""
        if key not in self.data:
            if required:
                self.report(key, f"missing required key; expected {kind.expected}")
            return default
        try:
            return kind(self.data[key])
        except _InvalidValueError as exc:
            self.report(key, str(exc))
            return None

    def direction(self, key: str, *, required: bool = False) -> list[float] | None:
        """A nonzero 3-vector at ``key``."""
        vector = self.get(key, _DIRECTION, required=required)
        if vector is not None and not any(vector):
            self.report(key, "expected a direction, got the zero vector")
            return None
        return vector

    def table(self, key: str, *, required: bool = False) -> _Table | None:
        if key not in self.data:
            if required:
                self.report(key, f"missing required table; add a [{key}] section")
            return None
        value = self.data[key]
        if not isinstance(value, dict):
            self.report(key, f"expected a table, got {_describe(value)}")
            return None
        return _Table(value, self.key_path(key), self.issues)

    def tables(self, key: str) -> list[_Table]:
        """The required, non-empty array of tables at ``key`` (only its valid items)."""
        value = self.data.get(key)
        if value is None:
            self.report(key, f"missing required key; add at least one [[{key}]] table")
            return []
        if not isinstance(value, list):
            self.report(key, f"expected an array of tables ([[{key}]]), got {_describe(value)}")
            return []
        if not value:
            self.report(key, f"expected at least one [[{key}]] table, got an empty array")
        items = []
        for index, item in enumerate(value):
            where = f"{self.key_path(key)}[{index}]"
            if isinstance(item, dict):
                items.append(_Table(item, where, self.issues))
            else:
                self.issues.append(
                    Issue(key_path=where, message=f"expected a table, got {_describe(item)}")
                )
        return items


@dataclass(frozen=True, slots=True, kw_only=True)
class _Defaults:
    """The valid values of ``[defaults]`` and the keys it gives (valid or not)."""

    values: dict = field(default_factory=dict)
    keys: frozenset = frozenset()


def _given(**values: object) -> dict:
    """The keyword arguments that are not ``None``."""
    return {key: value for key, value in values.items() if value is not None}


class _Reader:
    """Reads a parsed problem file, collecting issues; builds only what is valid."""

    def __init__(self, *, folder: Path, model: str | None):
        self.folder = folder
        self.model = model
        self.issues: list[Issue] = []

    def document(self, data: dict) -> tuple[str | None, str | None, Problem | None]:
        """The file's name, kind and problem (``None`` where invalid)."""
        top = _Table(data, "", self.issues)
        top.check_keys(_TOP_KEYS)
        _check_schema_version(top)
        name = top.get("name", _NAME, required=True)
        kind = top.get("kind", _Choice(KINDS), required=True)
        objective = top.get("objective", _Choice(OBJECTIVES), required=True)
        if "description" in data and not isinstance(data["description"], str):
            top.report("description", f"expected a string, got {_describe(data['description'])}")
        defaults = self._defaults(top.table("defaults"))
        body = self._body(top.table("body", required=True))
        contact_tables = top.tables("contacts")
        contacts = [self._contact(table, defaults) for table in contact_tables]
        _check_unique_names(contact_tables, "contact")
        load_tables = top.tables("loads")
        loads = [self._load(table) for table in load_tables]
        _check_unique_names(load_tables, "load")
        if self.issues:
            return name, kind, None
        # Only the objective's demands on the contacts are left for Problem to find.
        problem = _build(
            top,
            Problem,
            key="objective",
            body=body,
            contacts=contacts,
            loads=loads,
            objective=objective,
        )
        return name, kind, problem

    def _defaults(self, table: _Table | None) -> _Defaults:
        if table is None:
            return _Defaults()
        table.check_keys(_DEFAULT_KEYS)
        kinds = {"mu": _MU, "model": _MODEL, "facets": _FACETS, "inscribed": _BOOLEAN}
        values = {key: table.get(key, kind) for key, kind in kinds.items()}
        return _Defaults(
            values={key: value for key, value in values.items() if value is not None},
            keys=frozenset(table.data),
        )

    def _body(self, table: _Table | None) -> Body | None:
        if table is None:
            return None
        start = len(self.issues)
        table.check_keys(_BODY_KEYS)
        mass = table.get("mass", _MASS, required=True)
        center = table.get("center_of_mass", _POSITION, required=True)
        gravity = table.get("gravity", _GRAVITY)
        if len(self.issues) > start:
            return None
        return _build(table, Body, mass=mass, center_of_mass=center, **_given(gravity=gravity))

    def _load(self, table: _Table) -> Load | None:
        start = len(self.issues)
        table.check_keys(_LOAD_KEYS)
        name = table.get("name", _NAME, required=True)
        force = table.get("force", _FORCE_VECTOR, required=True)
        point = table.get("point", _POSITION, required=True)
        torque = table.get("torque", _TORQUE_VECTOR)
        if len(self.issues) > start:
            return None
        return _build(table, Load, name=name, force=force, point=point, **_given(torque=torque))

    def _contact(self, table: _Table, defaults: _Defaults) -> Contact | None:
        start = len(self.issues)
        table.check_keys(_CONTACT_KEYS)
        name = table.get("name", _NAME, required=True)
        role = table.get("role", _Choice(ROLES), required=True)
        position = table.get("position", _POSITION, required=True)
        normal = _normal(table)
        mu = _with_default(table, "mu", _MU, defaults, required=True)
        file_model = _with_default(table, "model", _MODEL, defaults, required=self.model is None)
        model = self.model or file_model
        if self.model in AREA_MODEL_NAMES and "patch" not in table.data:
            model = POINT_VERSION[self.model]  # an override keeps point contacts point contacts
        facets = self._pyramid_option(table, "facets", _FACETS, defaults, model)
        inscribed = self._pyramid_option(table, "inscribed", _BOOLEAN, defaults, model)
        patch, patch_axis = self._patch(table)
        if model == "exact" and patch is not None:
            _check_exact_size(table, patch)
        if model in AREA_MODEL_NAMES and "patch" not in table.data:
            self._report_missing_patch(table, model, name)
        axis = _contact_axis(table, patch_axis)
        force, max_force = (_active_force(table, key, role) for key in ("force", "max_force"))
        required = (name, role, position, normal, mu, model)
        if len(self.issues) > start or None in required:
            return None
        return _build(
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

    def _pyramid_option(
        self, table: _Table, key: str, kind: _Kind, defaults: _Defaults, model: str | None
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

    def _report_missing_patch(self, table: _Table, model: str, name: str | None) -> None:
        source = f"model {model!r}" if self.model is None else f"the model override {model!r}"
        contact = f"contact {name!r}" if name else "this contact"
        table.report(
            "patch",
            f"missing: {contact} needs a patch (area and pressure) for {source}; add one or use "
            "'point-cone' or 'point-pyramid'",
        )

    def _patch(self, contact: _Table) -> tuple[pressure.PressureField | None, list | None]:
        """The contact's pressure field and its rectangle's ``axis`` (``None`` where absent)."""
        patch = contact.table("patch")
        if patch is None:
            return None, None
        shape = patch.get("shape", _Choice(PATCH_SHAPES), required=True)
        if shape is None:
            return None, None
        patch.check_keys(_PATCH_KEYS[shape])
        axis = patch.direction("axis") if shape == "rectangle" else None
        start = len(self.issues)
        readers = {
            "disk": _disk,
            "rectangle": _rectangle,
            "polygon": _polygon,
            "points": _points,
            "grid": functools.partial(_grid, folder=self.folder),
        }
        build = readers[shape](patch)
        if build is None or len(self.issues) > start:
            return None, axis
        return _build(patch, build), axis


def _build(table: _Table, constructor: Callable, *, key: str | None = None, **arguments: object):
    """``constructor(**arguments)``; its error becomes an issue at ``table`` (or its ``key``)."""
    try:
        return constructor(**arguments)
    except FixplanError as exc:
        table.report(key, str(exc))
        return None


def _check_exact_size(table: _Table, patch: pressure.PressureField) -> None:
    """Report a patch too fine for the planner's exact model (its cost grows with the number
    of friction disks)."""
    disks = len(patch.quadrature(PLANNER_EXACT_ORDER)[0])
    if disks > MAX_EXACT_POINTS:
        table.report(
            "patch",
            f"the exact model would split this patch into {disks} friction disks, more than "
            f"the {MAX_EXACT_POINTS} accepted; give fewer vertices, points or grid cells, or "
            "use another model",
        )


def _check_schema_version(top: _Table) -> None:
    version = top.data.get("schema_version")
    if version is None:
        top.report("schema_version", f"missing required key; expected {SCHEMA_VERSION}")
    elif isinstance(version, bool) or version != SCHEMA_VERSION:
        top.report(
            "schema_version",
            f"expected {SCHEMA_VERSION} (the only schema version this fixplan reads), got "
            f"{_describe(version)}",
        )


def _with_default(table: _Table, key: str, kind: _Kind, defaults: _Defaults, *, required: bool):
    """The contact's ``key``, else ``[defaults]``'s; reports it missing from both if required."""
    if key in table.data:
        return table.get(key, kind)
    if key in defaults.values:
        return defaults.values[key]
    if required and key not in defaults.keys:
        table.report(key, f"missing required key; expected {kind.expected} here or in [defaults]")
    return None


def _normal(table: _Table) -> list[float] | None:
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


def _contact_axis(table: _Table, patch_axis: list | None) -> list | None:
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


def _active_force(table: _Table, key: str, role: str | None) -> float | None:
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


def _disk(patch: _Table) -> Callable | None:
    radius = patch.get("radius", _LENGTH, required=True)
    profile = patch.get("pressure", _Choice(pressure.DISK_PROFILES), default="uniform")
    inner = patch.get("inner_radius", _LENGTH)
    if profile == "annulus" and "inner_radius" not in patch.data:
        patch.report("inner_radius", "missing: pressure 'annulus' needs inner_radius < radius [m]")
    elif profile not in (None, "annulus") and "inner_radius" in patch.data:
        patch.report("inner_radius", f"only for pressure 'annulus', not {profile!r}; remove it")
    return functools.partial(pressure.disk, radius, profile, inner_radius=inner)


def _rectangle(patch: _Table) -> Callable | None:
    length = patch.get("length", _LENGTH, required=True)
    width = patch.get("width", _LENGTH, required=True)
    profile = patch.data.get("pressure", "uniform")
    if profile != "uniform":
        patch.report(
            "pressure",
            f"expected 'uniform' (the only pressure of a rectangle), got {_describe(profile)}; "
            "use a grid for other pressure maps",
        )
    if length is not None and width is not None:
        ratio = max(length, width) / min(length, width)
        if ratio > MAX_ASPECT_RATIO:
            patch.report(
                "width",
                f"the sides' ratio {ratio:.3g} exceeds the {MAX_ASPECT_RATIO:g} accepted; model "
                "so thin a strip as points along a line or widen it",
            )
    return functools.partial(pressure.rectangle, length, width)


def _polygon(patch: _Table) -> Callable | None:
    vertices = patch.get("vertices", _VERTICES, required=True)
    return functools.partial(pressure.polygon, vertices)


def _points(patch: _Table) -> Callable | None:
    xy = patch.get("xy", _POINTS, required=True)
    weights = patch.get("weights", _WEIGHTS)
    return functools.partial(pressure.points, xy, weights)


def _grid(patch: _Table, *, folder: Path) -> Callable | None:
    x = patch.get("x", _COORDINATES, required=True)
    y = patch.get("y", _COORDINATES, required=True)
    values = patch.data.get("values")
    try:
        if isinstance(values, str):
            rows = _csv_rows(folder / values)
        elif isinstance(values, list):
            rows = _ROWS(values)
        else:
            got = "nothing" if values is None else _describe(values)
            raise _InvalidValueError(
                f"expected {_ROWS.expected} (one row per y) or the name of a CSV file, got {got}"
            )
        if x is not None and y is not None:
            _check_grid_shape(rows, len(x), len(y))
    except _InvalidValueError as exc:
        patch.report("values", str(exc))
        return None
    return functools.partial(pressure.grid, x, y, rows)


def _check_grid_shape(rows: list[list[float]], nx: int, ny: int) -> None:
    if nx * ny > MAX_GRID_CELLS:
        raise _InvalidValueError(
            f"a grid of {nx} by {ny} cells; at most {MAX_GRID_CELLS} cells are accepted"
        )
    if len(rows) != ny:
        raise _InvalidValueError(f"expected {ny} rows (one per y), got {len(rows)}")
    for index, row in enumerate(rows):
        if len(row) != nx:
            raise _InvalidValueError(
                f"row {index}: expected {nx} values (one per x), got {len(row)}"
            )


def _csv_rows(file: Path) -> list[list[float]]:
    """The numbers of a CSV file, one list per non-blank row.

    A byte-order mark and empty cells at the end of a row (a trailing comma), which tactile
    array software often writes, are ignored.
    """
    try:
        text = _read_regular_file(file, MAX_FILE_BYTES).decode("utf-8-sig")
    except (_InvalidValueError, UnicodeDecodeError) as exc:
        reason = str(exc) if isinstance(exc, _InvalidValueError) else "not UTF-8 text"
        name = _SHORT.repr(str(file))
        raise _InvalidValueError(f"cannot read the CSV file {name}: {reason}") from None
    rows = []
    reader = csv.reader(text.replace("\0", "\ufffd").splitlines())
    for row in reader:
        if not any(cell.strip() for cell in row):
            continue
        while not row[-1].strip():
            row = row[:-1]
        numbers = []
        for column, cell in enumerate(row, start=1):
            where = f"{file.name} line {reader.line_num}, column {column}"
            try:
                numbers.append(_RELATIVE(float(cell)))
            except ValueError:
                raise _InvalidValueError(
                    f"{where}: expected a finite number, got {_SHORT.repr(cell.strip())}"
                ) from None
            except _InvalidValueError as exc:
                raise _InvalidValueError(f"{where}: {exc}") from None
        rows.append(numbers)
    if not rows:
        raise _InvalidValueError(f"{file.name} holds no numbers")
    return rows


def _check_unique_names(tables: list[_Table], noun: str) -> None:
    """Report every table whose ``name`` an earlier table already uses."""
    first: dict[str, str] = {}
    for table in tables:
        name = table.data.get("name")
        if not isinstance(name, str):
            continue
        if name in first:
            table.report("name", f"duplicate {noun} name {name!r}; {first[name]} already uses it")
        else:
            first[name] = table.path


__all__ = ["Issue", "ProblemFile", "ProblemFileError", "check_problem", "load_problem"]
