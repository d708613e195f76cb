"""Measured (load, twist) pairs in a CSV file, read for :func:`fixplan.motion.fit`.

The file is UTF-8 text (a byte-order mark is ignored) with comma-separated columns::

    # block 3 on the ABS sheet, 2024-05-02; SI units: N, N m, m/s, rad/s
    fx_N,  fy_N,   m_Nm,   vx_mps, vy_mps, w_radps, normal_force_N
    1.021, 0.113,  0.0031, 0.0100, 0.0011, 0.052,   9.81
    ...

- Lines whose first character other than a blank is ``#`` are comments, and blank lines are
  skipped, anywhere in the file. Comments are not interpreted (units come from the columns); the
  ones above the header are kept and shown in the fit's report.
- The first other line is the header. Each column is named, in any order and case, by one of
  ``fx, fy, m`` (the load [N, N, N m] about the frame origin at which the part slid), ``vx, vy,
  w`` (its twist [m/s, m/s, rad/s], whose direction only matters) and ``normal_force`` [N],
  optionally followed by ``_`` and its SI unit: ``fx_N``, ``fy_N``, ``m_Nm``, ``vx_mps``,
  ``vy_mps``, ``w_radps``, ``normal_force_N`` (``N m``, ``N.m``, ``m/s`` and ``rad/s`` are read
  as ``Nm``, ``mps`` and ``radps``). Any other unit is an error: fixplan reads SI units only and
  never scales silently (``m_Nmm`` says to convert the moments to N m). ``fx, fy, m`` are
  required; ``vx, vy, w`` come all three or not at all (without them only the level set is
  fitted); other columns are errors, with a suggestion for a near miss.
- Every other line is one measurement: one finite number per column (empty cells after the
  last column, a trailing comma, are ignored), a nonzero load, a nonzero twist and a positive
  normal force.

The ``normal_force`` column: where every row has the same value, the loads are fitted as they
are and the surface holds at that normal force. Where the values differ, each load is scaled
to the mean normal force ``N̄`` (``L_i N̄ / N_i``: Coulomb friction makes a contact's loads
proportional to its normal force when its pressure shape stays the same) and the surface holds
at ``N̄``. Without the column the normal force is given separately (the command line's
``--normal-force``, default 1 N).

Mistakes are reported all at once (up to :data:`MAX_ISSUES`) in a
:class:`~fixplan.io.toml_schema.ProblemFileError`, each at ``line L, column C (name)`` of the
file (lines and columns counted from 1).
"""

from __future__ import annotations

import csv
import hashlib
import math
import os
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from fixplan.io.toml_schema import (
    MAX_FILE_BYTES,
    SHORT,
    InvalidValueError,
    Issue,
    Number,
    ProblemFileError,
    read_regular_file,
    suggestion,
)
from fixplan.tolerances import MAX_FORCE, MAX_SPEED, MAX_TORQUE, MIN_PATCH_LENGTH

#: The column names, in the order of the arrays read.
LOAD_COLUMNS = ("fx", "fy", "m")
TWIST_COLUMNS = ("vx", "vy", "w")
NORMAL_FORCE_COLUMN = "normal_force"
COLUMNS = (*LOAD_COLUMNS, *TWIST_COLUMNS, NORMAL_FORCE_COLUMN)

#: Each column's SI unit as a suffix (``fx_N``), and its spelling in messages.
UNITS = {"fx": "N", "fy": "N", "m": "Nm", "vx": "mps", "vy": "mps", "w": "radps",
         "normal_force": "N"}  # fmt: skip
_UNIT_TEXT = {"N": "N", "Nm": "N m", "mps": "m/s", "radps": "rad/s"}

#: Fewest measurements read: the six coefficients of the ellipsoid, the smallest fit (a quartic
#: needs 15 fitted pairs, which :func:`fixplan.motion.fit` checks after holding some out).
MIN_ROWS = 6

#: Most mistakes listed; the count of the rest follows them.
MAX_ISSUES = 20

_KINDS = {
    "fx": Number("", MAX_FORCE, "N"),
    "fy": Number("", MAX_FORCE, "N"),
    "m": Number("", MAX_TORQUE, "N m"),
    "vx": Number("", MAX_SPEED, "m/s"),
    "vy": Number("", MAX_SPEED, "m/s"),
    # A body point at the smallest patch length from the rotation centre moves at most at
    # MAX_SPEED.
    "w": Number("", MAX_SPEED / MIN_PATCH_LENGTH, "rad/s"),
    "normal_force": Number("> 0", MAX_FORCE, "N"),
}


@dataclass(frozen=True, slots=True, kw_only=True, eq=False)
class FitData:
    """The measurements of a CSV file (module docstring), as read.

    Attributes
    ----------
    path : Path
        The file.
    sha256 : str
        SHA-256 of its bytes.
    columns : tuple of str
        The header's cells as written, in file order.
    comments : tuple of str
        The comment lines above the header, without their ``#``.
    lines : numpy.ndarray
        ``(n,)`` line number of each measurement in the file.
    loads : numpy.ndarray
        ``(n, 3)`` ``(fx, fy, m)`` [N, N, N m] as in the file.
    twists : numpy.ndarray or None
        ``(n, 3)`` ``(vx, vy, w)`` [m/s, m/s, rad/s]; ``None`` without twist columns.
    normal_forces : numpy.ndarray or None
        ``(n,)`` normal force [N] of each row; ``None`` without the column.
    """

    path: Path
    sha256: str
    columns: tuple[str, ...]
    comments: tuple[str, ...]
    lines: np.ndarray
    loads: np.ndarray
    twists: np.ndarray | None
    normal_forces: np.ndarray | None
    _fitted: tuple[np.ndarray, float | None] = field(init=False, repr=False)

    def __post_init__(self):
        for name in ("lines", "loads", "twists", "normal_forces"):
            value = getattr(self, name)
            if value is not None:
                value = np.array(value)
                value.setflags(write=False)
                object.__setattr__(self, name, value)
        object.__setattr__(self, "_fitted", _at_one_normal_force(self.loads, self.normal_forces))

    @property
    def rows(self) -> int:
        """Number of measurements."""
        return len(self.loads)

    @property
    def varying_normal_force(self) -> bool:
        """Whether the rows' normal forces differ (the loads are then scaled to their mean)."""
        return self.normal_forces is not None and bool(np.ptp(self.normal_forces) > 0.0)

    @property
    def normal_force(self) -> float | None:
        """Normal force [N] of :attr:`fit_loads`: the rows' common or mean normal force;
        ``None`` without the column (the caller gives it)."""
        return self._fitted[1]

    @property
    def fit_loads(self) -> np.ndarray:
        """``(n, 3)`` loads [N, N, N m] at :attr:`normal_force` (the file's, unless the rows'
        normal forces differ)."""
        return self._fitted[0]


def _at_one_normal_force(loads, normal_forces) -> tuple[np.ndarray, float | None]:
    if normal_forces is None:
        return loads, None
    if np.ptp(normal_forces) == 0.0:
        return loads, float(normal_forces[0])
    mean = float(np.mean(normal_forces))
    scaled = loads * (mean / normal_forces)[:, None]
    scaled.setflags(write=False)
    return scaled, mean


class _Issues:
    """The issues found, up to :data:`MAX_ISSUES`, and a count of the rest."""

    def __init__(self):
        self.issues: list[Issue] = []
        self.more = 0

    def add(self, where: str, message: str) -> None:
        if len(self.issues) < MAX_ISSUES:
            self.issues.append(Issue(key_path=where, message=message))
        else:
            self.more += 1

    def raise_if_any(self, path: Path) -> None:
        if not self.issues:
            return
        issues = list(self.issues)
        if self.more:
            issues.append(Issue(key_path="", message=f"and {self.more} more mistakes not listed"))
        raise ProblemFileError(path, issues)


def read_fit_data(path: str | os.PathLike[str], *, min_rows: int = MIN_ROWS) -> FitData:
    """Read and check a CSV file of measurements (format in the module docstring).

    Parameters
    ----------
    path : path-like
        The CSV file.
    min_rows : int
        Fewest measurements accepted.

    Raises
    ------
    ProblemFileError
        The file cannot be read or breaks the format; lists every mistake, each at its line
        and column.
    """
    path = Path(path)
    try:
        content = read_regular_file(path, MAX_FILE_BYTES)
        text = content.decode("utf-8-sig")
    except (InvalidValueError, UnicodeDecodeError) as exc:
        reason = str(exc) if isinstance(exc, InvalidValueError) else (
            f"not UTF-8 text (byte {exc.start} cannot be decoded); save it as UTF-8")  # fmt: skip
        message = f"cannot read it: {reason}"
        raise ProblemFileError(path, [Issue(key_path="", message=message)]) from None
    issues = _Issues()
    lines = text.replace("\0", "\ufffd").splitlines()
    comments, header_line = _comments(lines)
    if header_line is None:
        message = (f"no header line: name the columns ({', '.join(COLUMNS)}) on the first line "
                   "that is not a comment, then one measurement per line")  # fmt: skip
        issues.add("", message)
        issues.raise_if_any(path)
    header = _cells(lines[header_line - 1])
    columns = _columns(header, header_line, issues)
    issues.raise_if_any(path)
    values, numbers = _rows(lines, header_line, header, columns, issues)
    if not issues.issues and len(numbers) < min_rows:
        what = "no measurement" if not numbers else f"only {len(numbers)} measurements"
        issues.add("", f"{what} below the header; a fit needs at least {min_rows}")
    issues.raise_if_any(path)
    array = np.array(values, dtype=float)
    return FitData(
        path=path,
        sha256=hashlib.sha256(content).hexdigest(),
        columns=tuple(cell.strip() for cell in header),
        comments=tuple(comments),
        lines=np.array(numbers, dtype=int),
        loads=array[:, [columns[name] for name in LOAD_COLUMNS]],
        twists=array[:, [columns[n] for n in TWIST_COLUMNS]] if "vx" in columns else None,
        normal_forces=array[:, columns[NORMAL_FORCE_COLUMN]] if NORMAL_FORCE_COLUMN in columns
        else None,
    )  # fmt: skip


def _skipped(line: str) -> bool:
    """Whether ``line`` is blank or a comment."""
    stripped = line.strip()
    return not stripped or stripped.startswith("#")


def _comments(lines: list[str]) -> tuple[list[str], int | None]:
    """The comments above the header and the header's line number (``None``: no header)."""
    comments = []
    for number, line in enumerate(lines, start=1):
        if not _skipped(line):
            return comments, number
        if line.strip():
            comments.append(line.strip()[1:].strip())
    return comments, None


def _cells(line: str) -> list[str]:
    """The cells of one CSV line, without the empty cells at its end (a trailing comma)."""
    cells = next(csv.reader([line]), [])
    while cells and not cells[-1].strip():
        cells.pop()
    return cells


def _where(line: int, column: int, header: list[str]) -> str:
    name = header[column - 1].strip() if column <= len(header) else ""
    return f"line {line}, column {column}" + (f" ({name})" if name else "")


def _column_name(cell: str) -> tuple[str | None, str | None]:
    """``(name, unit)`` of a header cell: the name if it is a column's, the unit suffix as
    written (``None``: none)."""
    text = cell.strip()
    lowered = text.lower()
    for name in sorted(COLUMNS, key=len, reverse=True):
        if lowered == name:
            return name, None
        if lowered.startswith(name + "_"):
            return name, text[len(name) + 1 :]
    return None, None


def _unit_key(unit: str) -> str:
    """A unit's spelling reduced to the suffix form: ``N m``, ``N.m`` → ``nm``; ``m/s`` →
    ``mps``."""
    return re.sub(r"[\s.*·]", "", unit).replace("/", "p").lower()


def _columns(header: list[str], line: int, issues: _Issues) -> dict[str, int]:
    """Index of each named column; issues for unknown, duplicated, mis-united and missing
    columns."""
    columns: dict[str, int] = {}
    if len(header) == 1 and re.search(r"[;\t]", header[0]):
        issues.add(f"line {line}", "the header has a single column: separate the columns with "
                                   "commas (not semicolons or tabs)")  # fmt: skip
        return columns
    for index, cell in enumerate(header):
        where = _where(line, index + 1, header)
        name, unit = _column_name(cell)
        if name is None:
            if not cell.strip():
                issues.add(f"line {line}, column {index + 1}", "empty column name; name every "
                           f"column, one of {', '.join(COLUMNS)}")  # fmt: skip
                continue
            close = suggestion(cell.strip().lower().split("_")[0], COLUMNS)
            hint = f"did you mean {close!r}?" if close else f"allowed: {', '.join(COLUMNS)}"
            issues.add(where, f"unknown column {SHORT.repr(cell.strip())}; {hint}")
            continue
        if unit is not None and _unit_key(unit) != UNITS[name].lower():
            si = UNITS[name]
            issues.add(where, f"unit {SHORT.repr(unit)} is not {_UNIT_TEXT[si]}: fixplan reads SI "
                              f"units only; convert the column to {_UNIT_TEXT[si]} and name it "
                              f"{name} or {name}_{si}")  # fmt: skip
        if name in columns:
            issues.add(where, f"column {name!r} again (column {columns[name] + 1} is {name!r} "
                              "already); keep one")  # fmt: skip
            continue
        columns[name] = index
    if issues.issues:
        return columns
    missing = [name for name in LOAD_COLUMNS if name not in columns]
    if missing:
        issues.add(f"line {line}", f"missing column{'s' if len(missing) > 1 else ''} "
                   f"{', '.join(missing)}: the loads need fx, fy and m (columns found: "
                   f"{', '.join(cell.strip() for cell in header)})")  # fmt: skip
    twist = [name for name in TWIST_COLUMNS if name in columns]
    if twist and len(twist) < 3:
        absent = [name for name in TWIST_COLUMNS if name not in columns]
        issues.add(f"line {line}", f"twist columns {', '.join(twist)} without "
                   f"{', '.join(absent)}: give all of vx, vy and w, or none (then only the "
                   "level set is fitted)")  # fmt: skip
    return columns


def _number(cell: str, kind: Number) -> float:
    text = cell.strip()
    if not text:
        raise InvalidValueError("expected a number, got an empty cell")
    try:
        value = float(text)
    except ValueError:
        raise InvalidValueError(f"expected a number, got {SHORT.repr(text)}") from None
    if not math.isfinite(value):
        raise InvalidValueError(f"expected a finite number, got {SHORT.repr(text)}")
    try:
        return kind(value)
    except InvalidValueError:
        raise InvalidValueError(f"expected {kind.accepted_range}, got {SHORT.repr(text)}") from None


def _rows(lines, header_line, header, columns, issues) -> tuple[list[list[float]], list[int]]:
    """The numbers of every measurement line (in file order of the columns) and its line."""
    width = len(header)
    values, numbers = [], []
    for number in range(header_line + 1, len(lines) + 1):
        line = lines[number - 1]
        if _skipped(line):
            continue
        cells = _cells(line)
        if len(cells) != width:
            hint = " (a decimal comma? write decimal points)" if len(cells) > width else ""
            issues.add(f"line {number}", f"{len(cells)} cells, but the header names {width} "
                                         f"columns{hint}")  # fmt: skip
            continue
        row, valid = [], True
        for index, cell in enumerate(cells):
            name = next(n for n, i in columns.items() if i == index)
            try:
                row.append(_number(cell, _KINDS[name]))
            except InvalidValueError as exc:
                issues.add(_where(number, index + 1, header), str(exc))
                row.append(math.nan)
                valid = False
        if valid:
            _check_row(row, columns, number, issues)
        values.append(row)
        numbers.append(number)
    return values, numbers


def _check_row(row: list[float], columns: dict[str, int], number: int, issues: _Issues) -> None:
    """Issues for a zero load or a zero twist."""
    for names, what in ((LOAD_COLUMNS, "load (fx, fy, m)"), (TWIST_COLUMNS, "twist (vx, vy, w)")):
        if names[0] in columns and not any(row[columns[name]] for name in names):
            issues.add(f"line {number}", f"the {what} is zero: every measurement needs a nonzero "
                                         f"{what.split()[0]}")  # fmt: skip
