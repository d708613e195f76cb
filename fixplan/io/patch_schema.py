"""Contact patches in input files: ``patch = { shape = ..., ... }`` read into a pressure field.

Shapes (lengths [m], coordinates in the patch frame):

- ``disk``: ``radius``, ``pressure`` (``uniform`` default, ``hertz``, ``parabolic``,
  ``annulus`` with ``inner_radius``, ``ring``);
- ``rectangle``: ``length``, ``width``, ``pressure = "uniform"`` (the only one), ``axis`` (world
  direction of the length);
- ``polygon``: ``vertices = [[x, y], ...]``;
- ``points``: ``xy = [[x, y], ...]``, optional relative ``weights``;
- ``grid``: cell centres ``x``, ``y`` and relative pressures ``values``, one row per ``y``:
  an array of rows or the name of a CSV file, relative to the input file's folder.
"""

from __future__ import annotations

import csv
import functools
from collections.abc import Callable
from pathlib import Path

from fixplan.io.toml_schema import (
    MAX_FILE_BYTES,
    SHORT,
    Array,
    Choice,
    InvalidValueError,
    Number,
    Table,
    build,
    describe,
    read_regular_file,
)
from fixplan.surface import pressure
from fixplan.tolerances import (
    MAX_ASPECT_RATIO,
    MAX_GRID_CELLS,
    MAX_LENGTH,
    MAX_POINTS,
    MAX_POLYGON_VERTICES,
    MAX_RELATIVE_VALUE,
    MIN_PATCH_LENGTH,
)

PATCH_SHAPES = ("disk", "rectangle", "polygon", "points", "grid")
_PATCH_KEYS = {
    "disk": ("shape", "radius", "pressure", "inner_radius"),
    "rectangle": ("shape", "length", "width", "pressure", "axis"),
    "polygon": ("shape", "vertices"),
    "points": ("shape", "xy", "weights"),
    "grid": ("shape", "x", "y", "values"),
}

LENGTH = Number(
    "> 0",
    MAX_LENGTH,
    "m",
    smallest=MIN_PATCH_LENGTH,
    why_smallest="m (the limit surface's arithmetic underflows)",
)
_COORDINATES = Array((None,), Number("", MAX_LENGTH, "m"), MAX_GRID_CELLS)
RELATIVE = Number("", MAX_RELATIVE_VALUE)
_WEIGHTS = Array((None,), RELATIVE, MAX_POINTS)
_VERTICES = Array((None, 2), Number("", MAX_LENGTH, "m"), MAX_POLYGON_VERTICES)
_POINTS = Array((None, 2), Number("", MAX_LENGTH, "m"), MAX_POINTS)
_ROWS = Array((None, None), RELATIVE, MAX_GRID_CELLS)


def _disk(patch: Table) -> Callable | None:
    radius = patch.get("radius", LENGTH, required=True)
    profile = patch.get("pressure", Choice(pressure.DISK_PROFILES), default="uniform")
    inner = patch.get("inner_radius", LENGTH)
    if profile == "annulus" and "inner_radius" not in patch.data:
        patch.report("inner_radius", "missing: pressure 'annulus' needs inner_radius < radius [m]")
    elif profile not in (None, "annulus") and "inner_radius" in patch.data:
        patch.report("inner_radius", f"only for pressure 'annulus', not {profile!r}; remove it")
    return functools.partial(pressure.disk, radius, profile, inner_radius=inner)


def _rectangle(patch: Table) -> Callable | None:
    length = patch.get("length", LENGTH, required=True)
    width = patch.get("width", LENGTH, required=True)
    profile = patch.data.get("pressure", "uniform")
    if profile != "uniform":
        patch.report(
            "pressure",
            f"expected 'uniform' (the only pressure of a rectangle), got {describe(profile)}; "
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


def _polygon(patch: Table) -> Callable | None:
    vertices = patch.get("vertices", _VERTICES, required=True)
    return functools.partial(pressure.polygon, vertices)


def _points(patch: Table) -> Callable | None:
    xy = patch.get("xy", _POINTS, required=True)
    weights = patch.get("weights", _WEIGHTS)
    return functools.partial(pressure.points, xy, weights)


def _grid(patch: Table, *, folder: Path) -> Callable | None:
    x = patch.get("x", _COORDINATES, required=True)
    y = patch.get("y", _COORDINATES, required=True)
    values = patch.data.get("values")
    try:
        if isinstance(values, str):
            rows = _csv_rows(folder / values)
        elif isinstance(values, list):
            rows = _ROWS(values)
        else:
            got = "nothing" if values is None else describe(values)
            raise InvalidValueError(
                f"expected {_ROWS.expected} (one row per y) or the name of a CSV file, got {got}"
            )
        if x is not None and y is not None:
            _check_grid_shape(rows, len(x), len(y))
    except InvalidValueError as exc:
        patch.report("values", str(exc))
        return None
    return functools.partial(pressure.grid, x, y, rows)


def _check_grid_shape(rows: list[list[float]], nx: int, ny: int) -> None:
    if nx * ny > MAX_GRID_CELLS:
        raise InvalidValueError(
            f"a grid of {nx} by {ny} cells; at most {MAX_GRID_CELLS} cells are accepted"
        )
    if len(rows) != ny:
        raise InvalidValueError(f"expected {ny} rows (one per y), got {len(rows)}")
    for index, row in enumerate(rows):
        if len(row) != nx:
            raise InvalidValueError(
                f"row {index}: expected {nx} values (one per x), got {len(row)}"
            )


def _csv_rows(file: Path) -> list[list[float]]:
    """The numbers of a CSV file, one list per non-blank row.

    A byte-order mark and empty cells at the end of a row (a trailing comma), which tactile
    array software often writes, are ignored.
    """
    try:
        text = read_regular_file(file, MAX_FILE_BYTES).decode("utf-8-sig")
    except (InvalidValueError, UnicodeDecodeError) as exc:
        reason = str(exc) if isinstance(exc, InvalidValueError) else "not UTF-8 text"
        name = SHORT.repr(str(file))
        raise InvalidValueError(f"cannot read the CSV file {name}: {reason}") from None
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
                numbers.append(RELATIVE(float(cell)))
            except ValueError:
                raise InvalidValueError(
                    f"{where}: expected a finite number, got {SHORT.repr(cell.strip())}"
                ) from None
            except InvalidValueError as exc:
                raise InvalidValueError(f"{where}: {exc}") from None
        rows.append(numbers)
    if not rows:
        raise InvalidValueError(f"{file.name} holds no numbers")
    return rows


def read_patch(
    contact: Table, *, folder: Path
) -> tuple[pressure.PressureField | None, list | None]:
    """The pressure field at ``contact``'s ``patch`` key and its rectangle's ``axis`` (``None`` where absent)."""
    patch = contact.table("patch")
    if patch is None:
        return None, None
    shape = patch.get("shape", Choice(PATCH_SHAPES), required=True)
    if shape is None:
        return None, None
    patch.check_keys(_PATCH_KEYS[shape])
    axis = patch.direction("axis") if shape == "rectangle" else None
    start = len(contact.issues)
    readers = {
        "disk": _disk,
        "rectangle": _rectangle,
        "polygon": _polygon,
        "points": _points,
        "grid": functools.partial(_grid, folder=folder),
    }
    constructor = readers[shape](patch)
    if constructor is None or len(contact.issues) > start:
        return None, axis
    return build(patch, constructor), axis
