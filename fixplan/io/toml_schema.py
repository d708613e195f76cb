"""Reading TOML input files: values checked against what a key allows, every mistake collected.

A :class:`Table` wraps one TOML table with its key path and the list of :class:`Issue` it reports
to; the value kinds (:class:`Number`, :class:`Integer`, :class:`Boolean`, :class:`Text`,
:class:`Choice`, :class:`Array`) convert a value or say what was expected. Readers of problem
files (:mod:`fixplan.io.problem_file`, :mod:`fixplan.io.push_file`) are built from them, so that a
file's mistakes are all reported at once, each at its key path, before anything is built.
"""

from __future__ import annotations

import difflib
import math
import os
import re
import reprlib
import stat
import tomllib
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from datetime import date, datetime, time
from pathlib import Path

from fixplan.errors import FixplanError
from fixplan.tolerances import MAX_NAME_LENGTH

#: The version of the schema the problem-file readers read.
SCHEMA_VERSION = 1

#: Largest input file (a problem file, a grid patch's CSV file) read [bytes].
MAX_FILE_BYTES = 10_000_000

SHORT = reprlib.Repr()
SHORT.maxstring = SHORT.maxother = 40


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


def read_regular_file(path: Path, limit: int) -> bytes:
    """The bytes of the regular file ``path`` of at most ``limit`` bytes; the error's message
    says why it cannot be read.

    The file type is checked before the file is opened: reading a FIFO or a device would block
    or never end.
    """
    try:
        status = path.stat()
    except (OSError, ValueError) as exc:
        raise InvalidValueError(_reason(exc)) from None
    if not stat.S_ISREG(status.st_mode):
        kind = "a folder" if stat.S_ISDIR(status.st_mode) else "not a regular file"
        raise InvalidValueError(f"it is {kind}")
    if status.st_size > limit:
        raise InvalidValueError(f"it has {status.st_size} bytes, more than the {limit} accepted")
    try:
        return path.read_bytes()
    except OSError as exc:
        raise InvalidValueError(_reason(exc)) from None


def _reason(exc: Exception) -> str:
    """Why a file operation failed, without the path (the message names it already)."""
    if isinstance(exc, OSError) and exc.strerror:
        return exc.strerror
    if isinstance(exc, ValueError):
        return "the path is not valid (it holds a NUL character)"
    return str(exc)


def parse_toml(path: Path, content: bytes) -> dict:
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


class InvalidValueError(Exception):
    """A value does not fit its key; the message says what was expected."""


def describe(value: object) -> str:
    """A value named by its TOML type, e.g. ``string 'abc'`` or ``boolean true``."""
    if isinstance(value, bool):
        return f"boolean {str(value).lower()}"
    if isinstance(value, dict):
        return "a table"
    names = {int: "integer", float: "float", str: "string", list: "array"}
    names.update({datetime: "date-time", date: "date", time: "time"})
    kind = next(name for cls, name in names.items() if isinstance(value, cls))
    text = SHORT.repr(value) if isinstance(value, str | list) else str(value)
    return f"{kind} {text}"


def _key_text(key: str) -> str:
    """``key`` as written in TOML: bare if it can be, quoted otherwise."""
    return key if re.fullmatch(r"[A-Za-z0-9_-]+", key) else f'"{key}"'


def suggestion(word: str, allowed: Sequence[str]) -> str | None:
    close = difflib.get_close_matches(word, allowed, n=1)
    return close[0] if close else None


def _finite(value: object) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise InvalidValueError(f"expected a number, got {describe(value)}")
    try:
        number = float(value)  # TOML integers have no size limit
    except OverflowError:
        raise InvalidValueError(
            f"expected a finite number, got an integer too large for a float ({len(str(value))} "
            "digits)"
        ) from None
    if not math.isfinite(number):
        raise InvalidValueError(f"expected a finite number, got {value}")
    return number


@dataclass(frozen=True, slots=True)
class Number:
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
            raise InvalidValueError(f"expected {self.expected}, got {value}")
        if self.limit is not None and abs(number) > self.limit:
            raise InvalidValueError(f"expected {self.accepted_range}, got {value}")
        if self.smallest is not None and 0.0 < number < self.smallest:
            raise InvalidValueError(
                f"expected {self.accepted_range}, got {value}: below {self.smallest:g} "
                f"{self.why_smallest}"
            )
        return number


@dataclass(frozen=True, slots=True)
class Integer:
    """An integer from ``minimum`` to ``maximum``."""

    minimum: int
    maximum: int

    @property
    def expected(self) -> str:
        return f"an integer >= {self.minimum}"

    def __call__(self, value: object) -> int:
        if isinstance(value, bool) or not isinstance(value, int) or value < self.minimum:
            raise InvalidValueError(f"expected {self.expected}, got {describe(value)}")
        if value > self.maximum:
            raise InvalidValueError(
                f"expected an integer from {self.minimum} to {self.maximum}, got {value}"
            )
        return value


@dataclass(frozen=True, slots=True)
class Boolean:
    expected: str = "true or false"

    def __call__(self, value: object) -> bool:
        if not isinstance(value, bool):
            raise InvalidValueError(f"expected {self.expected}, got {describe(value)}")
        return value


@dataclass(frozen=True, slots=True)
class Text:
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
            raise InvalidValueError(f"expected {self.expected}, got {got or describe(value)}")
        return value


@dataclass(frozen=True, slots=True)
class Choice:
    """One of the strings ``allowed``."""

    allowed: tuple[str, ...]

    @property
    def expected(self) -> str:
        return "one of " + ", ".join(repr(a) for a in self.allowed)

    def __call__(self, value: object) -> str:
        if value in self.allowed:
            return str(value)
        message = f"expected {self.expected}; got {describe(value)}"
        close = suggestion(value, self.allowed) if isinstance(value, str) else None
        raise InvalidValueError(message + (f" (did you mean {close!r}?)" if close else ""))


@dataclass(frozen=True, slots=True)
class Array:
    """Nested non-empty arrays of ``shape`` (``None``: any length, up to ``max_items`` in the
    first dimension) of numbers of the kind ``element``."""

    shape: tuple[int | None, ...]
    element: Number = Number()
    max_items: int | None = None

    @property
    def expected(self) -> str:
        text = _shape_text(self.shape)
        return f"{text}, at most {self.max_items} of them" if self.max_items else text

    def __call__(self, value: object) -> list:
        if self.max_items is not None and isinstance(value, list) and len(value) > self.max_items:
            raise InvalidValueError(f"expected at most {self.max_items} items, got {len(value)}")
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
    value: object, shape: tuple[int | None, ...], element: Number, index: str
) -> list | float:
    where = f"element {index}: " if index else ""
    if not shape:
        try:
            return element(value)
        except InvalidValueError as exc:
            raise InvalidValueError(f"{where}{exc}") from None
    expected = _shape_text(shape)
    if not isinstance(value, list):
        raise InvalidValueError(f"{where}expected {expected}, got {describe(value)}")
    if not value:
        raise InvalidValueError(f"{where}expected {expected}, got an empty array")
    if shape[0] is not None and len(value) != shape[0]:
        items = "item" if len(value) == 1 else "items"
        raise InvalidValueError(f"{where}expected {expected}, got {len(value)} {items}")
    return [_nested(item, shape[1:], element, f"{index}[{i}]") for i, item in enumerate(value)]


Kind = Number | Integer | Boolean | Text | Choice | Array

DIRECTION = Array((3,))


@dataclass(slots=True)
class Table:
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
                close = suggestion(key, allowed)
                hint = (
                    f"did you mean {close!r}?" if close else "allowed keys: " + ", ".join(allowed)
                )
                self.report(key, f"unknown key; {hint}")

    def get(self, key: str, kind: Kind, *, required: bool = False, default: object = None):
        """The value at ``key`` converted by ``kind``; ``default`` if missing, ``None`` if
        invalid."""
        if key not in self.data:
            if required:
                self.report(key, f"missing required key; expected {kind.expected}")
            return default
        try:
            return kind(self.data[key])
        except InvalidValueError as exc:
            self.report(key, str(exc))
            return None

    def read(self, constructor: Callable, kinds: dict[str, Kind], *, required: Sequence[str]):
        """``constructor(**values)`` of this table's keys, each converted by its kind in
        ``kinds`` (the keys allowed); ``None`` if a key is unknown, invalid or ``required`` and
        missing, or the constructor rejects the values (every issue reported)."""
        start = len(self.issues)
        self.check_keys(tuple(kinds))
        values = {key: self.get(key, kind, required=key in required) for key, kind in kinds.items()}
        if len(self.issues) > start:
            return None
        return build(self, constructor, **given(**values))

    def direction(self, key: str, *, required: bool = False) -> list[float] | None:
        """A nonzero 3-vector at ``key``."""
        vector = self.get(key, DIRECTION, required=required)
        if vector is not None and not any(vector):
            self.report(key, "expected a direction, got the zero vector")
            return None
        return vector

    def table(self, key: str, *, required: bool = False) -> Table | None:
        if key not in self.data:
            if required:
                self.report(key, f"missing required table; add a [{key}] section")
            return None
        value = self.data[key]
        if not isinstance(value, dict):
            self.report(key, f"expected a table, got {describe(value)}")
            return None
        return Table(value, self.key_path(key), self.issues)

    def tables(self, key: str) -> list[Table]:
        """The required, non-empty array of tables at ``key`` (only its valid items)."""
        value = self.data.get(key)
        if value is None:
            self.report(key, f"missing required key; add at least one [[{key}]] table")
            return []
        if not isinstance(value, list):
            self.report(key, f"expected an array of tables ([[{key}]]), got {describe(value)}")
            return []
        if not value:
            self.report(key, f"expected at least one [[{key}]] table, got an empty array")
        items = []
        for index, item in enumerate(value):
            where = f"{self.key_path(key)}[{index}]"
            if isinstance(item, dict):
                items.append(Table(item, where, self.issues))
            else:
                self.issues.append(
                    Issue(key_path=where, message=f"expected a table, got {describe(item)}")
                )
        return items


def given(**values: object) -> dict:
    """The keyword arguments that are not ``None``."""
    return {key: value for key, value in values.items() if value is not None}


def build(table: Table, constructor: Callable, *, key: str | None = None, **arguments: object):
    """``constructor(**arguments)``; its error becomes an issue at ``table`` (or its ``key``)."""
    try:
        return constructor(**arguments)
    except FixplanError as exc:
        table.report(key, str(exc))
        return None


def check_schema_version(top: Table) -> None:
    version = top.data.get("schema_version")
    if version is None:
        top.report("schema_version", f"missing required key; expected {SCHEMA_VERSION}")
    elif isinstance(version, bool) or version != SCHEMA_VERSION:
        top.report(
            "schema_version",
            f"expected {SCHEMA_VERSION} (the only schema version this fixplan reads), got "
            f"{describe(version)}",
        )


def check_unique_names(tables: list[Table], noun: str) -> None:
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
