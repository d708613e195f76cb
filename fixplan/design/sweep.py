"""Sweeps: the cases of a design solved in parallel with Dask, one row of a tidy table each.

A :class:`CaseSource` turns a case's values into a :class:`~fixplan.planner.problem.Problem`
(:class:`fixplan.io.sweep.FileCases` does it for problem files). The cases are cut into chunks of
:data:`CHUNK_SIZE` consecutive case ids, one Dask task per chunk, so that scheduling costs little
next to the solves; rows stream back chunk by chunk as tasks finish (``on_rows``), so that a sweep
keeps what it finished when it is interrupted. Within a chunk, cases of the same
:meth:`CaseSource.structure` (those that differ only in their loads) re-solve one compiled
:class:`~fixplan.planner.planner.Planner` with new load values.

A case never stops the sweep: input the problem rejects is a row with status ``"invalid
input"`` and the message, any other failure (a worker lost, an unexpected error) a row with
status ``"error"``. Chunks depend only on the case ids, so a chunk gives the same numbers on
any worker, in this process (``client="serial"``) or on a cluster, and when a sweep is resumed.
"""

from __future__ import annotations

import math
import os
import time
import warnings
from collections.abc import Callable, Hashable, Iterator, Mapping, Sequence
from typing import Protocol

import pandas as pd

from fixplan.design.experiment import CASE
from fixplan.errors import FixplanError, InvalidArgumentError
from fixplan.planner.planner import Planner
from fixplan.planner.problem import Problem

#: Cases per Dask task: large enough that a task (about 0.05–0.2 s per case) outweighs the
#: scheduler's few milliseconds, small enough to balance the load and to lose little when a
#: sweep is interrupted. The chunks decide which solves share a planner, so keep it fixed
#: between a sweep and its resumption.
CHUNK_SIZE = 16
#: ``client`` value that solves the cases one after another in this process, without Dask.
SERIAL = "serial"
#: Most workers of a local cluster per core of the machine: each is a process with the solver
#: stack, and more only queue for the cores and fill the memory (100,000 never started).
WORKERS_PER_CORE = 4
STATUS_INVALID = "invalid input"
STATUS_ERROR = "error"
#: Columns of a sweep table after the case id and the varied keys (then one safety factor
#: column per load case, :func:`load_column`, then :data:`TAIL`).
HEAD = ("status", "objective_value", "safety_factor", "critical_load")
TAIL = ("message", "solve_time")
#: Columns of text (``None`` where missing); the others are numbers.
TEXT = ("status", "critical_load", "message")


class CaseSource(Protocol):
    """What a sweep needs to know of the problem it varies; picklable, sent to every worker."""

    #: The varied keys, in the order of a case's values.
    keys: tuple[str, ...]
    #: Names of the problem's load cases (one safety factor column each).
    load_names: tuple[str, ...]

    def problem(self, values: Mapping[str, float]) -> Problem:
        """The problem of a case; raises a :class:`FixplanError` that is a ``ValueError`` for
        values the problem rejects."""

    def structure(self, values: Mapping[str, float]) -> Hashable:
        """Equal for two cases whose problems differ only in their loads."""


def most_workers() -> int:
    """The most workers of a local cluster on this machine (``WORKERS_PER_CORE`` per core)."""
    return WORKERS_PER_CORE * (os.cpu_count() or 1)


def load_column(name: str) -> str:
    """The column of load case ``name``'s safety factor."""
    return f"safety_factor[{name}]"


def columns(source: CaseSource) -> list[str]:
    """The columns of a sweep table of ``source``, in order."""
    return [CASE, *source.keys, *HEAD, *map(load_column, source.load_names), *TAIL]


def typed(table: pd.DataFrame) -> pd.DataFrame:
    """``table`` with the types of a sweep table's columns: integer case ids, text as Python
    strings or ``None``, every other column float (NaN where missing)."""
    types = {c: int if c == CASE else object if c in TEXT else float for c in table.columns}
    table = table.astype(types)
    for column in TEXT:
        table[column] = table[column].where(table[column].notna(), None)
    return table


def solve_chunk(source: CaseSource, cases: Sequence[tuple[int, Sequence[float]]]) -> list[dict]:
    """The rows of ``cases`` (``(case id, values)`` pairs), solved in order (a Dask task)."""
    planners: dict[Hashable, Planner] = {}
    return [_solve_case(source, case, dict(zip(source.keys, values, strict=True)), planners)
            for case, values in cases]  # fmt: skip


def run_cases(
    source: CaseSource,
    cases: pd.DataFrame,
    *,
    client=None,
    workers: int | None = None,
    chunk_size: int = CHUNK_SIZE,
    on_rows: Callable[[pd.DataFrame], None] | None = None,
    progress: Callable[[int, int], None] | None = None,
) -> pd.DataFrame:
    """Solve every case of ``cases`` and return their rows, sorted by case id.

    Parameters
    ----------
    source : CaseSource
        Builds each case's problem.
    cases : DataFrame
        One row per case: index the case ids, columns ``source.keys``.
    client : distributed.Client or "serial", optional
        Where to solve: a client of an existing Dask cluster; ``"serial"``: in this process,
        chunk after chunk; ``None`` (default): a ``LocalCluster`` of ``workers`` single-threaded
        worker processes, started and closed here.
    workers : int, optional
        Worker processes of the default local cluster (default: one per core).
    chunk_size : int
        Consecutive case ids per task (default :data:`CHUNK_SIZE`).
    on_rows : callable, optional
        Called with the rows of each chunk as it finishes (in order of completion).
    progress : callable, optional
        ``progress(done, total)`` in cases, as chunks finish.
    """
    if list(cases.columns) != list(source.keys):
        raise InvalidArgumentError(
            f"cases must have the columns {list(source.keys)}, got {list(cases.columns)}"
        )
    if isinstance(chunk_size, bool) or not isinstance(chunk_size, int) or chunk_size < 1:
        raise InvalidArgumentError(f"chunk_size must be a positive integer, got {chunk_size!r}")
    if client is not None and workers is not None:
        raise InvalidArgumentError("workers is for the default local cluster; give no client")
    chunks = _chunks(cases, chunk_size)
    if isinstance(client, str) and client == SERIAL:
        results = (solve_chunk(source, chunk) for chunk in chunks)
        return _collect(source, results, len(cases), on_rows, progress)
    if client is not None:
        return _collect(source, _stream(client, source, chunks), len(cases), on_rows, progress)
    from distributed import Client, LocalCluster

    workers = (os.cpu_count() or 1) if workers is None else workers
    if (
        isinstance(workers, bool)
        or not isinstance(workers, int)
        or not 1 <= workers <= most_workers()
    ):
        raise InvalidArgumentError(
            f"workers must be an integer from 1 to {most_workers()} ({WORKERS_PER_CORE} per core "
            f"of this machine), got {workers!r}"
        )
    with (
        LocalCluster(  # its web server on a free port: several sweeps may run side by side
            n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=":0"
        ) as cluster,
        Client(cluster) as local,
    ):
        return _collect(source, _stream(local, source, chunks), len(cases), on_rows, progress)


def _chunks(cases: pd.DataFrame, size: int) -> list[list[tuple[int, tuple[float, ...]]]]:
    """The cases grouped by ``case id // size``: the same chunks whichever cases are left."""
    groups: dict[int, list] = {}
    for case, values in zip(cases.index, cases.itertuples(index=False, name=None), strict=True):
        groups.setdefault(int(case) // size, []).append((int(case), values))
    return list(groups.values())


def _stream(client, source: CaseSource, chunks: list) -> Iterator[list[dict]]:
    """The rows of each chunk, solved on ``client``'s cluster, as their tasks finish; a task
    that fails (its worker lost) gives error rows for its cases."""
    from distributed import as_completed

    shared = client.scatter(source, broadcast=True, hash=False)
    futures = {client.submit(solve_chunk, shared, chunk, pure=False): chunk for chunk in chunks}
    for future in as_completed(futures):
        chunk = futures.pop(future)
        if future.status == "error":
            yield [_failed_row(source, case, values, future.exception()) for case, values in chunk]
        else:
            yield future.result()
        future.release()


def _collect(source, results, total, on_rows, progress) -> pd.DataFrame:
    names = columns(source)
    tables = []
    done = 0
    for rows in results:
        table = typed(pd.DataFrame(rows, columns=names))
        tables.append(table)
        if on_rows is not None:
            on_rows(table)
        done += len(rows)
        if progress is not None:
            progress(done, total)
    if not tables:
        return typed(pd.DataFrame(columns=names))
    return pd.concat(tables, ignore_index=True).sort_values(CASE, ignore_index=True)


def _solve_case(source: CaseSource, case: int, values: dict, planners: dict) -> dict:
    """One case's row; reuses the chunk's planner of the same structure."""
    start = time.perf_counter()
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # an inaccurate solve is its row's status
            problem = source.problem(values)
            structure = source.structure(values)
            planner = planners.get(structure)
            if planner is None:
                planner = planners[structure] = Planner(problem)
            plan = planner.solve(problem.loads)
    except FixplanError as exc:
        status = STATUS_INVALID if isinstance(exc, ValueError) else STATUS_ERROR
        return {CASE: case, **values, "status": status, "message": str(exc),
                "solve_time": time.perf_counter() - start}  # fmt: skip
    except Exception as exc:  # a case never stops the sweep: its row says what happened
        return _failed_row(source, case, values.values(), exc, start)
    row = {
        CASE: case,
        **values,
        "status": plan.status,
        "objective_value": _number(plan.objective_value),
        "safety_factor": _number(plan.safety_factor),
        "critical_load": plan.critical_load,
        "message": plan.certificate or "; ".join(plan.warnings) or None,
        "solve_time": time.perf_counter() - start,
    }
    row.update({load_column(name): _number(plan.safety_factors.get(name))
                for name in source.load_names})  # fmt: skip
    return row


def _failed_row(source, case, values, exc: BaseException, start: float | None = None) -> dict:
    elapsed = math.nan if start is None else time.perf_counter() - start
    return {CASE: case, **dict(zip(source.keys, values, strict=True)), "status": STATUS_ERROR,
            "message": f"{type(exc).__name__}: {exc}", "solve_time": elapsed}  # fmt: skip


def _number(value) -> float:
    return math.nan if value is None else float(value)


__all__ = [
    "CHUNK_SIZE",
    "SERIAL",
    "STATUS_ERROR",
    "STATUS_INVALID",
    "CaseSource",
    "columns",
    "load_column",
    "run_cases",
    "solve_chunk",
    "typed",
]
