"""The table of a sweep on disk: CSV streamed chunk by chunk (so an interrupted sweep keeps
every chunk it finished), Parquet once complete, and the rows of an earlier table that a
resumed sweep keeps.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pandas as pd

from fixplan.design import CASE, STATUS_ERROR, STATUS_INVALID, typed
from fixplan.errors import InvalidArgumentError

#: Statuses a finished row may have (the planner's and the sweep's own).
STATUSES = ("optimal", "infeasible", "unbounded", "inaccurate", "solver-error",
            STATUS_INVALID, STATUS_ERROR)  # fmt: skip


def read_table(path: str | os.PathLike[str]) -> pd.DataFrame:
    """A sweep table from a ``.csv`` or ``.parquet`` file; rows left incomplete by an
    interruption (no status, or no solve time) are dropped."""
    path = Path(path)
    try:
        if path.suffix == ".parquet":
            table = pd.read_parquet(path)
        else:
            table = pd.read_csv(path, keep_default_na=False,
                                na_values=[""])  # fmt: skip
    except (OSError, ValueError, ImportError) as exc:
        raise InvalidArgumentError(f"{path}: cannot read the sweep table: {exc}") from exc
    for column in (CASE, "status", "solve_time"):
        if column not in table.columns:
            raise InvalidArgumentError(f"{path}: not a sweep table (no column {column!r})")
    finished = table["status"].isin(STATUSES) & table["solve_time"].notna()
    return typed(table[finished & table[CASE].notna()])


def kept_rows(table: pd.DataFrame, cases: pd.DataFrame, columns: list[str], path) -> pd.DataFrame:
    """The rows of an earlier ``table`` that belong to this sweep's ``cases``; refuses a table
    of another sweep (other columns, or a case whose values differ)."""
    if list(table.columns) != columns:
        raise InvalidArgumentError(
            f"{path}: its columns {list(table.columns)} are not this sweep's {columns}; resume "
            "with the same file, keys and options"
        )
    table = table.drop_duplicates(CASE).set_index(CASE)
    unknown = table.index.difference(cases.index)
    if len(unknown):
        raise InvalidArgumentError(
            f"{path}: case {unknown[0]} is not in this sweep's design of {len(cases)} cases"
        )
    design = cases.loc[table.index]
    differ = ~np.isclose(table[cases.columns].to_numpy(float), design.to_numpy(float),
                         rtol=1e-12, atol=0.0).all(axis=1)  # fmt: skip
    if differ.any():
        case = table.index[differ][0]
        raise InvalidArgumentError(
            f"{path}: case {case} has {table.loc[case, cases.columns].tolist()} where this "
            f"sweep's design has {design.loc[case].tolist()}; resume with the same ranges, "
            "method, samples and seed"
        )
    return table.reset_index()[columns].sort_values(CASE, ignore_index=True)


class CsvStream:
    """A CSV sweep table that grows chunk by chunk; starts with the ``kept`` rows of a resumed
    sweep (rewritten whole, so ``path`` may be the table being resumed)."""

    def __init__(self, path: str | os.PathLike[str], kept: pd.DataFrame):
        self.path = Path(path)
        _replace(self.path, kept.to_csv(index=False))

    def append(self, rows: pd.DataFrame) -> None:
        """Add ``rows`` at the end, in one write."""
        with self.path.open("a", encoding="utf-8", newline="") as stream:
            stream.write(rows.to_csv(index=False, header=False))
            stream.flush()


def write_tables(folder: Path, table: pd.DataFrame) -> list[Path]:
    """``sweep.csv`` (sorted by case) and ``sweep.parquet`` in ``folder``."""
    csv, parquet = folder / "sweep.csv", folder / "sweep.parquet"
    _replace(csv, table.to_csv(index=False))
    table.to_parquet(parquet, index=False)
    return [csv, parquet]


def _replace(path: Path, text: str) -> None:
    """Write ``path`` whole, through a temporary file beside it."""
    partial = path.with_name(path.name + ".partial")
    partial.write_text(text, encoding="utf-8", newline="")
    partial.replace(path)


__all__ = ["STATUSES", "CsvStream", "kept_rows", "read_table", "write_tables"]
