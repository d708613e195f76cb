"""Sweeps of a problem file: ``fixplan.sweep.run(problem, variations)``.

Each case sets numbers of the problem file at key paths (``contacts[1].mu``, ``body.mass``,
``loads[0].force[2]``, as the file's error messages name them) and reads the changed document
exactly as a file is read, so every varied value is checked as the file's own; a value the
file would reject is that case's row (status ``"invalid input"`` and the message). The cases
are solved in parallel by :func:`fixplan.design.run_cases` (Dask); see there for chunks and
streaming.
"""

from __future__ import annotations

import copy
import os
from collections.abc import Callable, Hashable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

import pandas as pd

from fixplan.design import CASE, CHUNK_SIZE, Range, columns, design, run_cases, typed
from fixplan.errors import InvalidArgumentError
from fixplan.io import key_path
from fixplan.io.problem_file import ProblemFile, load_problem, problem_from_document
from fixplan.io.sweep_table import CsvStream, kept_rows, read_table
from fixplan.io.toml_schema import (
    MAX_FILE_BYTES,
    ProblemFileError,
    parse_toml,
    read_regular_file,
)
from fixplan.planner.problem import Problem


@dataclass(frozen=True, slots=True, kw_only=True)
class FileCases:
    """The problems of a sweep of one problem file (a :class:`fixplan.design.CaseSource`).

    Build it with :meth:`read`. A whole-number value is given to the reader as a TOML integer,
    so that integer keys (``facets``, ``cuts``) can be varied too.
    """

    path: Path
    document: dict
    keys: tuple[str, ...]
    parts: tuple[tuple[str | int, ...], ...]
    load_names: tuple[str, ...]
    model: str | None = None
    objective: str | None = None

    @classmethod
    def read(
        cls,
        path: str | os.PathLike[str],
        keys: Sequence[str],
        *,
        model: str | None = None,
        objective: str | None = None,
    ) -> FileCases:
        """The cases of the valid problem file ``path`` varied at ``keys``.

        Raises
        ------
        ProblemFileError
            The file itself is invalid.
        KeyPathError
            A key is malformed or names no number of the file (a missing last key must be one
            the file's table accepts).
        """
        path = Path(path)
        problem_file = load_problem(path, model=model, objective=objective)
        document = parse_toml(path, read_regular_file(path, MAX_FILE_BYTES))
        located = [key_path.locate(document, key) for key in keys]
        cases = cls(
            path=path,
            document=document,
            keys=tuple(keys),
            parts=tuple(parts for parts, _ in located),
            load_names=tuple(load.name for load in problem_file.problem.loads),
            model=model,
            objective=objective,
        )
        missing = [key for key, (_, present) in zip(keys, located, strict=True) if not present]
        if missing:
            cases._check_accepted(missing)
        return cases

    def problem(self, values: Mapping[str, float]) -> Problem:
        """The problem of the file with ``values`` (by key) set; a
        :class:`~fixplan.io.problem_file.ProblemFileError` lists what the file reader rejects."""
        document = copy.deepcopy(self.document)
        for key, parts in zip(self.keys, self.parts, strict=True):
            value = float(values[key])
            key_path.assign(document, parts, int(value) if value.is_integer() else value)
        return problem_from_document(document, self.path, model=self.model,
                                     objective=self.objective)  # fmt: skip

    def structure(self, values: Mapping[str, float]) -> Hashable:
        """The values of the keys outside ``loads`` (cases equal in them share a planner)."""
        return tuple(values[key] for key, parts in zip(self.keys, self.parts, strict=True)
                     if parts[0] != "loads")  # fmt: skip

    def _check_accepted(self, keys: list[str]) -> None:
        """Refuse keys missing from the file that its reader does not know either."""
        try:
            self.problem(dict.fromkeys(self.keys, 1.0))
        except ProblemFileError as exc:
            for issue in exc.issues:
                if issue.key_path in keys and issue.message.startswith("unknown key"):
                    raise key_path.KeyPathError(f"{issue.key_path}: {issue.message}") from None


def cases_of(
    variations, *, method: str = "grid", samples: int | None = None, seed: int = 0
) -> pd.DataFrame:
    """The design of ``variations`` (see :func:`run`): one row per case, indexed by case id."""
    if isinstance(variations, pd.DataFrame):
        if method != "grid" or samples is not None:
            raise InvalidArgumentError("a table of cases takes no method or samples")
        cases = variations.astype(float).reset_index(drop=True)
        cases.columns = [str(key) for key in cases.columns]
        cases.index.name = CASE
        return cases
    if isinstance(variations, str | Range):
        variations = [variations]
    ranges = [Range.parse(v) if isinstance(v, str) else v for v in variations]
    return design(ranges, method=method, samples=samples, seed=seed)


def run(
    problem: str | os.PathLike[str] | ProblemFile,
    variations,
    *,
    method: str = "grid",
    samples: int | None = None,
    seed: int = 0,
    client=None,
    workers: int | None = None,
    table: str | os.PathLike[str] | None = None,
    resume: str | os.PathLike[str] | None = None,
    chunk_size: int = CHUNK_SIZE,
    progress: Callable[[int, int], None] | None = None,
) -> pd.DataFrame:
    """Solve a problem file for every case of a design, in parallel; one row per case.

    Parameters
    ----------
    problem : path or ProblemFile
        The problem file (a :class:`~fixplan.io.problem_file.ProblemFile` stands for its file,
        read again, with its model override and objective).
    variations : sequence of Range or str, or DataFrame
        Ranges of key paths (``Range(key="contacts[1].mu", start=0.2, stop=0.4, count=5)`` or
        ``"contacts[1].mu=0.2:0.4:5"``), combined by ``method``; or a table of explicit cases
        with one column per key path.
    method : {"grid", "lhs"}
        The Cartesian product of the ranges, or a Latin hypercube of ``samples`` cases drawn
        with ``seed`` (ranges without counts).
    client : distributed.Client or "serial", optional
        An existing Dask cluster's client (``Client("tcp://host:8786")``); ``"serial"`` solves
        in this process; default: a ``LocalCluster`` of ``workers`` processes (one per core).
    table : path, optional
        A CSV file the rows stream into as chunks finish (replaced if it exists).
    resume : path, optional
        The table (CSV or Parquet) of an interrupted run of the same sweep: its cases are kept
        and not solved again. It may be ``table`` itself.
    chunk_size : int
        Cases per Dask task; keep it between a sweep and its resumption.
    progress : callable, optional
        ``progress(done, total)`` in cases.

    Returns
    -------
    DataFrame
        Columns ``case``, the keys, ``status``, ``objective_value``, ``safety_factor`` (the
        smallest), ``critical_load``, ``safety_factor[<load>]`` per load case, ``message``
        and ``solve_time`` [s], sorted by case.
    """
    model = objective = None
    if isinstance(problem, ProblemFile):
        model, objective = problem.model_override, problem.problem.objective
        problem = problem.path
    cases = cases_of(variations, method=method, samples=samples, seed=seed)
    source = FileCases.read(problem, list(cases.columns), model=model, objective=objective)
    names = columns(source)
    kept = typed(pd.DataFrame(columns=names))
    if resume is not None:
        kept = kept_rows(read_table(resume), cases, names, resume)
    stream = None if table is None else CsvStream(table, kept)
    rows = run_cases(
        source,
        cases.drop(index=kept[CASE]),
        client=client,
        workers=workers,
        chunk_size=chunk_size,
        on_rows=None if stream is None else stream.append,
        progress=progress,
    )
    if kept.empty:
        return rows
    return pd.concat([kept, rows], ignore_index=True).sort_values(CASE, ignore_index=True)


__all__ = ["FileCases", "cases_of", "run"]
