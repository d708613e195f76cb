"""Fuzzing the command line with mutated problem files: whatever the file holds, ``fixplan plan``
and ``fixplan check`` end in a result or a clear message, never a traceback or an unexpected
error, and ``check`` rejects everything that ``plan`` rejects for the input's sake.

The bundled problems are mutated by replacing values with extreme or odd ones, deleting keys,
nesting values and repeating array items; each mutated document is written back as TOML.
"""

import contextlib
import copy
import io
import json
import math
import os
import random
import tempfile
import tomllib
from dataclasses import dataclass
from datetime import datetime
from pathlib import Path

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from fixplan.io.cli import EXIT_INVALID_INPUT, EXIT_NOT_HELD, EXIT_OK, EXIT_SOLVER, main

PROBLEMS = Path(__file__).resolve().parents[1] / "problems"
#: The bundled problems that solve in well under a second (the fuzz test runs many of them).
QUICK_PROBLEMS = ("hertz-pinch", "point-grasp", "three-finger-grasp", "three-pads", "unholdable")
EXPECTED_CODES = {EXIT_OK, EXIT_INVALID_INPUT, EXIT_NOT_HELD, EXIT_SOLVER}


def _circle(count: int) -> list[list[float]]:
    angles = [2 * math.pi * k / count for k in range(count)]
    return [[0.01 * math.cos(a), 0.01 * math.sin(a)] for a in angles]


@dataclass(frozen=True)
class _Raw:
    """TOML text written as is (values nested too deeply to serialise recursively)."""

    text: str


def _deep(depth: int, table: bool) -> _Raw:
    if table:
        return _Raw("{a = " * depth + "1.0" + "}" * depth)
    return _Raw("[" * depth + "1.0" + "]" * depth)


#: Odd values a mutation puts in place of a value (functions: each call builds a fresh one).
ODD_VALUES = (
    lambda: 1e308,
    lambda: -1e308,
    lambda: 1e-300,
    lambda: -1e-300,
    lambda: 0,
    lambda: -1,
    lambda: 1e300,
    lambda: 10**400,
    lambda: math.inf,
    lambda: math.nan,
    lambda: 10_000_000,
    lambda: 10_000,
    lambda: 2.5,
    lambda: True,
    lambda: "",
    lambda: "x" * 250,
    lambda: "x" * 100_000,
    lambda: "line\nbreak",
    lambda: "nul\x00",
    lambda: "fifo",
    lambda: "folder.csv",
    lambda: "missing.csv",
    lambda: "/dev/null",
    lambda: [],
    lambda: [[]],
    lambda: {},
    lambda: [1e308, 1e308, 1e308],
    lambda: [-1e308, 0.0, 1e308],
    lambda: [0.0, 0.0, 0.0],
    lambda: [1e-300, 0.0, 0.0],
    lambda: _deep(400, table=False),
    lambda: _deep(400, table=True),
    lambda: datetime(2024, 1, 1, 12, 0),
    lambda: _circle(300),
    lambda: _circle(2000),
    lambda: [[0.0, 0.0]] * 5000,
)


def _paths(node: object, path: tuple = ()):
    """Every key path of a parsed document (the root excluded)."""
    if path:
        yield path
    if isinstance(node, dict):
        for key, value in node.items():
            yield from _paths(value, (*path, key))
    elif isinstance(node, list) and len(node) < 100:
        for index, value in enumerate(node):
            yield from _paths(value, (*path, index))


def _scaled(value: object, factor: float) -> object:
    if isinstance(value, bool) or not isinstance(value, int | float | list):
        return value
    if isinstance(value, list):
        return [_scaled(item, factor) for item in value]
    try:
        return float(value) * factor
    except OverflowError:  # an integer too large for a float
        return value


def mutate(document: dict, rnd: random.Random) -> dict:
    """``document`` with one to three random mutations."""
    document = copy.deepcopy(document)
    for _ in range(rnd.randint(1, 3)):
        paths = list(_paths(document))
        if not paths:
            break
        path = rnd.choice(paths)
        parent = document
        for key in path[:-1]:
            parent = parent[key]
        key = path[-1]
        operation = rnd.choice(
            ("replace", "replace", "replace", "delete", "nest", "scale", "repeat")
        )
        if operation == "replace":
            parent[key] = rnd.choice(ODD_VALUES)()
        elif operation == "delete":
            del parent[key]
        elif operation == "nest":
            parent[key] = rnd.choice(([parent[key]], {"a": parent[key]}))
        elif operation == "scale":
            parent[key] = _scaled(parent[key], rnd.choice((1e300, -1.0, 0.0, 1e-300, 1e6)))
        elif isinstance(parent[key], list) and parent[key]:
            parent[key] = parent[key] * rnd.choice((2, 100, 3000))
    return document


def toml_text(document: dict) -> str:
    """``document`` as TOML, every table and array written inline."""
    return "".join(
        f"{_toml_string(key)} = {_toml_value(value)}\n" for key, value in document.items()
    )


def _toml_string(text: str) -> str:
    return json.dumps(text, ensure_ascii=False).replace("\x7f", "\\u007f")


def _toml_value(value: object) -> str:
    if isinstance(value, _Raw):
        return value.text
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float):
        return "nan" if math.isnan(value) else repr(value)
    if isinstance(value, int):
        return str(value)
    if isinstance(value, str):
        return _toml_string(value)
    if isinstance(value, datetime):
        return value.isoformat()
    if isinstance(value, list):
        return "[" + ", ".join(_toml_value(item) for item in value) + "]"
    items = ", ".join(f"{_toml_string(k)} = {_toml_value(v)}" for k, v in value.items())
    return "{" + items + "}"


def prepare_folder(folder: Path) -> None:
    """Files a mutated problem may name: a FIFO, a folder named like a CSV file, the tactile
    CSV of the bundled problems."""
    os.mkfifo(folder / "fifo")
    (folder / "folder.csv").mkdir()
    (folder / "tactile-pinch.csv").write_bytes((PROBLEMS / "tactile-pinch.csv").read_bytes())


def run(argv: list[str]) -> tuple[int, str, str]:
    """``main(argv)`` in this process: exit code, stdout and stderr."""
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main(argv)
    return code, out.getvalue(), err.getvalue()


def check_run(argv: list[str], file: Path) -> int:
    """Run the command line and assert the contract of its outputs; returns the exit code."""
    code, out, err = run(argv)
    assert code in EXPECTED_CODES, (argv, code, err)
    assert "Traceback" not in err, err
    if "--json" in argv and (code != EXIT_INVALID_INPUT or argv[0] == "check"):
        json.loads(out)
    if code == EXIT_INVALID_INPUT:
        assert file.name in err, err
    return code


def _base_documents() -> dict[str, dict]:
    return {name: tomllib.loads((PROBLEMS / f"{name}.toml").read_text()) for name in QUICK_PROBLEMS}


BASES = _base_documents()


@settings(
    max_examples=25,
    deadline=None,
    derandomize=True,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large],
)
@given(name=st.sampled_from(sorted(BASES)), rnd=st.randoms(use_true_random=False))
def test_mutated_problem_files_end_in_a_result_or_a_clear_message(name, rnd):
    with tempfile.TemporaryDirectory() as folder:
        folder = Path(folder)
        prepare_folder(folder)
        file = folder / f"{name}.toml"
        file.write_text(toml_text(mutate(BASES[name], rnd)), encoding="utf-8")
        checked = check_run(["check", str(file), "--json"], file)
        report = folder / "report"
        planned = check_run(["plan", str(file), "--json", "-q", "--report", str(report)], file)
        assert (checked == EXIT_INVALID_INPUT) == (planned == EXIT_INVALID_INPUT)
        if planned == EXIT_INVALID_INPUT:
            assert not report.exists()
