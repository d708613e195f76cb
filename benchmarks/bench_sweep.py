"""Speed of a sweep: 1,000 fixture cases solved serially and on local Dask clusters of 1 and 2
worker processes, with the speed-up per worker.

Run: ``python benchmarks/bench_sweep.py [--cases-per-key 10] [--rounds 4]``. The cases vary three
inputs of ``problems/fixture-321.toml`` on a 10 x 10 x 10 grid: the side clamp's x position, the
top clamp's y position and the friction coefficient of every contact. Each changes the problem's
structure, so every case builds its own planner (the slow path; sweeps of loads only re-solve one
planner per chunk). The machine is shared, and its load drifts over minutes: the cases are split
into ``rounds`` blocks, each block solved by the three set-ups in turn (rotating who goes first),
and each set-up's times are summed over the blocks. A cluster is started for each block and
warmed up (each worker imports the solver stack) before the clock starts; its start-up is printed
beside. The load average is printed before and after.
"""

from __future__ import annotations

import argparse
import functools
import itertools
import os
import time
from pathlib import Path

import numpy as np
import pandas as pd

from fixplan.design import SERIAL
from fixplan.io import sweep

PROBLEM = Path(__file__).resolve().parents[1] / "problems" / "fixture-321.toml"
WORKERS = (1, 2)


def ranges(count: int) -> list[str]:
    return [
        f"contacts[7].position[0]=-0.06:0.06:{count}",
        f"contacts[6].position[1]=-0.04:0.04:{count}",
        f"defaults.mu=0.15:0.35:{count}",
    ]


def on_cluster(workers: int, block: pd.DataFrame) -> tuple[float, float, pd.DataFrame]:
    """``(start-up [s], sweep [s], table)`` of ``block`` on a new, warmed-up local cluster of
    ``workers`` (one cluster alive at a time: idle schedulers still take their share)."""
    from distributed import Client, LocalCluster

    start = time.perf_counter()
    with (
        LocalCluster(
            n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=":0"
        ) as cluster,
        Client(cluster) as client,
    ):
        client.run(sweep.run, PROBLEM, ranges(2)[:1], client=SERIAL)  # imports, on every worker
        started = time.perf_counter() - start
        start = time.perf_counter()
        table = sweep.run(PROBLEM, block, client=client)
        return started, time.perf_counter() - start, table


def in_process(block: pd.DataFrame) -> tuple[float, float, pd.DataFrame]:
    start = time.perf_counter()
    table = sweep.run(PROBLEM, block, client=SERIAL)
    return 0.0, time.perf_counter() - start, table


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cases-per-key", type=int, default=10, help="grid values per key")
    parser.add_argument("--rounds", type=int, default=4, help="blocks of cases, see above")
    args = parser.parse_args()
    cases = sweep.cases_of(ranges(args.cases_per_key))
    bounds = np.linspace(0, len(cases), args.rounds + 1).astype(int)
    blocks = [cases.iloc[low:high] for low, high in itertools.pairwise(bounds)]
    print(f"{len(cases)} cases of {PROBLEM.name} in {args.rounds} blocks; {os.cpu_count()} "
          f"cores; load average before {', '.join(f'{x:.2f}' for x in os.getloadavg())}")  # fmt: skip
    sweep.run(PROBLEM, ranges(2)[:1], client=SERIAL)  # imports and compiled kernels here
    setups = {"serial": in_process, **{f"{n} worker(s)": functools.partial(on_cluster, n)
                                       for n in WORKERS}}  # fmt: skip
    startup = dict.fromkeys(setups, 0.0)
    times = dict.fromkeys(setups, 0.0)
    tables = {name: [] for name in setups}
    for index, block in enumerate(blocks):
        names = list(setups)
        for name in names[index % 3 :] + names[: index % 3]:
            started, elapsed, table = setups[name](block)
            startup[name] = max(startup[name], started)
            times[name] += elapsed
            tables[name].append(table)
    serial = pd.concat(tables["serial"]).drop(columns="solve_time")
    for name, elapsed in times.items():
        workers = 1 if name == "serial" else int(name.split()[0])
        speed_up = times["serial"] / elapsed
        same = pd.concat(tables[name]).drop(columns="solve_time").equals(serial)
        print(
            f"{name:>12s}  {elapsed:7.1f} s  {len(cases) / elapsed:6.1f} cases/s  speed-up "
            f"{speed_up:.2f} ({speed_up / workers:.2f} per worker)  start-up at most "
            f"{startup[name]:.1f} s  same table as serial: {same}"
        )
    print(f"statuses: {serial['status'].value_counts().to_dict()}; load average after "
          f"{', '.join(f'{x:.2f}' for x in os.getloadavg())}")  # fmt: skip


if __name__ == "__main__":
    main()
