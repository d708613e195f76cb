"""Key paths into a parsed TOML document, written as the problem file reader reports them:
``body.mass``, ``defaults.mu``, ``contacts[1].mu``, ``loads[0].force[2]``,
``contacts[6].patch.radius`` (0-based indices).
"""

from __future__ import annotations

import re

from fixplan.errors import InvalidArgumentError

_NAME = r"[A-Za-z_][A-Za-z0-9_-]*"
_PATH = re.compile(rf"^{_NAME}(?:\[\d+\])*(?:\.{_NAME}(?:\[\d+\])*)*$")
_PART = re.compile(rf"({_NAME})|\[(\d+)\]")


class KeyPathError(InvalidArgumentError):
    """A key path is malformed or names no number of the document."""


def parse(path: str) -> tuple[str | int, ...]:
    """The parts of ``path``: table keys (str) and array indices (int)."""
    if not isinstance(path, str) or not _PATH.match(path):
        raise KeyPathError(
            f"{path!r}: not a key path; write it as the file's error messages do, e.g. "
            "body.mass, contacts[1].mu, loads[0].force[2]"
        )
    return tuple(name if name else int(index) for name, index in _PART.findall(path))


def locate(document: dict, path: str) -> tuple[tuple[str | int, ...], bool]:
    """The parts of ``path`` and whether its value is in ``document`` (then a number: an
    integer or a float). The last key may be missing from an existing table (a value its
    ``[defaults]`` gives, or an optional key), nothing else."""
    parts = parse(path)
    node = document
    for depth, part in enumerate(parts):
        where = _join(parts[: depth + 1])
        last = depth == len(parts) - 1
        if isinstance(part, int):
            if not isinstance(node, list):
                raise KeyPathError(f"{where}: {_join(parts[:depth])} is not an array")
            if part >= len(node):
                raise KeyPathError(
                    f"{where}: {_join(parts[:depth])} has {len(node)} entries "
                    f"(indices 0–{len(node) - 1})"
                )
        else:
            if not isinstance(node, dict):
                raise KeyPathError(f"{where}: {_join(parts[:depth]) or 'the file'} is not a table")
            if part not in node:
                if last:
                    return parts, False
                raise KeyPathError(f"{where}: the file has no such table or array")
        node = node[part]
    if isinstance(node, bool) or not isinstance(node, int | float):
        raise KeyPathError(f"{path}: holds {type(node).__name__} {node!r}; only numbers vary")
    return parts, True


def assign(document: dict, parts: tuple[str | int, ...], value: float) -> None:
    """Set the value at ``parts`` (from :func:`locate`) in ``document``, in place."""
    node = document
    for part in parts[:-1]:
        node = node[part]
    node[parts[-1]] = value


def _join(parts: tuple[str | int, ...]) -> str:
    text = ""
    for part in parts:
        text += f"[{part}]" if isinstance(part, int) else f".{part}" if text else part
    return text


__all__ = ["KeyPathError", "assign", "locate", "parse"]
