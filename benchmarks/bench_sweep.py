"""Speed of a sweep: 1,000 fixture cases solved serially, then on local Dask clusters of 1 and
2 worker processes, with the speed-up per worker.

Run: ``python benchmarks/bench_sweep.py [--cases-per-key 10]``. The cases vary three inputs of
``problems/fixture-321.toml`` on a 10 x 10 x 10 grid: the side clamp's x position, the top
clamp's y position and the friction coefficient of every contact. Each changes the problem's
structure, so every case builds its own planner (the slow path; sweeps of loads only re-solve
one planner per chunk). The clusters are started and warmed up (each worker imports the solver
stack once) before the clock starts; their start-up is printed beside. The machine's load
average is printed before and after: other processes share its cores.
"""

from __future__ import annotations

import argparse
import os
import time
from pathlib import Path

import numpy as np

from fixplan.design import SERIAL
from fixplan.io import sweep

PROBLEM = Path(__file__).resolve().parents[1] / "problems" / "fixture-321.toml"


def ranges(count: int) -> list[str]:
    return [
        f"contacts[7].position[0]=-0.06:0.06:{count}",
        f"contacts[6].position[1]=-0.04:0.04:{count}",
        f"defaults.mu=0.15:0.35:{count}",
    ]


def timed_on_cluster(workers: int, variations: list[str]):
    """``(start-up [s], sweep [s], table)`` on a fresh local cluster of ``workers``."""
    from distributed import Client, LocalCluster

    start = time.perf_counter()
    with (
        LocalCluster(
            n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=None
        ) as cluster,
        Client(cluster) as client,
    ):
        client.run(sweep.run, PROBLEM, ranges(2)[:1], client=SERIAL)  # imports, on every worker
        started = time.perf_counter() - start
        start = time.perf_counter()
        table = sweep.run(PROBLEM, variations, client=client)
        return started, time.perf_counter() - start, table


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cases-per-key", type=int, default=10, help="grid values per key")
    args = parser.parse_args()
    variations = ranges(args.cases_per_key)
    cases = args.cases_per_key**3
    print(f"{cases} cases of {PROBLEM.name}; {os.cpu_count()} cores; load average before "
          f"{', '.join(f'{x:.2f}' for x in os.getloadavg())}")  # fmt: skip
    sweep.run(PROBLEM, ranges(2)[:1], client=SERIAL)  # imports and compiled kernels
    start = time.perf_counter()
    serial = sweep.run(PROBLEM, variations, client=SERIAL)
    serial_time = time.perf_counter() - start
    print(f"{'serial':>12s}  {serial_time:7.1f} s  {cases / serial_time:6.1f} cases/s")
    numbers = ["objective_value", "safety_factor"]
    for workers in (1, 2):
        started, elapsed, table = timed_on_cluster(workers, variations)
        speed_up = serial_time / elapsed
        same = table.drop(columns="solve_time").equals(serial.drop(columns="solve_time"))
        print(
            f"{workers:>2d} worker(s)  {elapsed:7.1f} s  {cases / elapsed:6.1f} cases/s  "
            f"speed-up {speed_up:.2f} ({speed_up / workers:.2f} per worker)  start-up "
            f"{started:.1f} s  same table as serial: {same}"
        )
        assert np.array_equal(table[numbers], serial[numbers], equal_nan=True)
    print(f"statuses: {serial['status'].value_counts().to_dict()}; load average after "
          f"{', '.join(f'{x:.2f}' for x in os.getloadavg())}")  # fmt: skip


if __name__ == "__main__":
    main()
