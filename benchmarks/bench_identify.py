"""Time of the limit-surface fits against the number of (load, twist) pairs.

Run: ``python benchmarks/bench_identify.py [--repeats N]``. The pairs are synthetic, from the
exact limit surface of the paper's 10:1 rectangle with 5 % force noise and 5° twist noise
(:func:`fixplan.motion.synthetic`); each fit (:func:`fixplan.motion.fit`, twists weighted 1,
nothing held out) is the ellipsoid or the SOS-convex quartic, two solves of the convex program
with Clarabel each (the second reweighted). Medians of ``--repeats`` runs, after one warm-up fit
that imports cvxpy.
"""

from __future__ import annotations

import argparse
import math
import statistics
import time

from fixplan import LimitSurface, pressure
from fixplan.motion import fit, synthetic

COUNTS = (100, 300, 1000, 3000, 10_000)
RECTANGLE = LimitSurface(pressure.rectangle(0.1, 0.01), mu=0.25, normal_force=200.0)


def seconds(loads, twists, model: str, repeats: int) -> float:
    """Median wall time [s] of a fit."""
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        fit(loads, twists, model=model, normal_force=RECTANGLE.normal_force, holdout=0.0)
        times.append(time.perf_counter() - start)
    return statistics.median(times)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3, help="runs per cell (median)")
    repeats = parser.parse_args().repeats
    loads, twists = synthetic(
        RECTANGLE, max(COUNTS), noise_force=0.05, noise_angle=math.radians(5.0), seed=0
    )
    seconds(loads[:100], twists[:100], "ellipsoid", 1)
    print(f"fit time [s], median of {repeats} runs (10:1 rectangle, 5 % / 5° noise)")
    print(f"{'pairs':>8} {'ellipsoid':>10} {'quartic':>10}")
    for count in COUNTS:
        cells = [seconds(loads[:count], twists[:count], model, repeats)
                 for model in ("ellipsoid", "quartic")]  # fmt: skip
        print(f"{count:>8} {cells[0]:>10.3f} {cells[1]:>10.3f}")


if __name__ == "__main__":
    main()
