"""Speed of the friction models on a million loads, next to the exact limit surface.

Run: ``python benchmarks/bench_models.py`` (``--quick`` for 100,000 loads). Each model's
``contains`` and ``safety_factor`` are timed on the same loads (medians of ``--repeats`` runs);
the exact limit surface is timed once on the same loads (``--exact-loads`` times it on the
first loads only and scales up). The machines are shared and noisy: compare the ratios.
"""

from __future__ import annotations

import argparse
import time

import numpy as np
from performance_rows import emit

from fixplan import LimitSurface, pressure
from fixplan.models import Cone, Ellipsoid, FittedEllipsoid, PointCone, PointPyramid, Pyramid


def median_time(function, repeats: int) -> float:
    """Median wall time [s] of ``repeats`` calls."""
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        function()
        times.append(time.perf_counter() - start)
    return float(np.median(times))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--loads", type=int, default=1_000_000, help="number of loads")
    parser.add_argument("--repeats", type=int, default=7, help="runs per model (median)")
    parser.add_argument(
        "--exact-loads", type=int, default=None, help="time the exact surface on this many"
    )
    parser.add_argument("--quick", action="store_true", help="100,000 loads, 3 repeats")
    args = parser.parse_args()
    count = 100_000 if args.quick else args.loads
    repeats = 3 if args.quick else args.repeats
    exact_count = min(count, args.exact_loads or count)

    surface = LimitSurface(pressure.disk(0.01), mu=0.5, normal_force=10.0)
    units = np.array([surface.max_force, surface.max_force, surface.max_moment])
    loads = np.random.default_rng(0).normal(size=(count, 3)) * units
    models = {
        "Ellipsoid (Table 2)": Ellipsoid.from_limit_surface(surface),
        "FittedEllipsoid": FittedEllipsoid.from_limit_surface(surface),
        "Cone": Cone.from_limit_surface(surface),
        "Pyramid k=4 (eq. 11)": Pyramid.from_limit_surface(surface),
        "Pyramid k=16": Pyramid.from_limit_surface(surface, facets=16),
        "PointCone": PointCone.from_limit_surface(surface),
        "PointPyramid k=8": PointPyramid.from_limit_surface(surface, facets=8),
    }

    surface.safety_factor(loads[:100])  # warm up (numba caches, first allocation)
    start = time.perf_counter()
    surface.safety_factor(loads[:exact_count])
    exact = (time.perf_counter() - start) * count / exact_count
    note = "" if exact_count == count else f" (timed on {exact_count:,}, scaled)"

    print(f"friction models on {count:,} loads, uniform disk contact; medians of {repeats} runs")
    print(f"exact LimitSurface.safety_factor: {exact:.3f} s{note}")
    print()
    print("| model | contains [s] | safety_factor [s] | loads/s | faster than exact |")
    print("|---|---:|---:|---:|---:|")
    factors = {}
    for name, model in models.items():
        model.safety_factor(loads[:100])
        held = median_time(lambda m=model: m.contains(loads), repeats)
        factors[name] = median_time(lambda m=model: m.safety_factor(loads), repeats)
        print(
            f"| {name} | {held:.3f} | {factors[name]:.3f} | {count / factors[name] / 1e6:.1f} M "
            f"| {exact / factors[name]:,.0f}x |"
        )
    shown = ("Ellipsoid (Table 2)", "Cone", "Pyramid k=4 (eq. 11)")
    emit(
        f"`safety_factor` of {count:,} loads, uniform disk: ellipsoid, cone, pyramid (eq. 11)",
        ", ".join(f"{factors[name]:.3f} s" for name in shown),
        f"exact surface {exact:.1f} s",
        ", ".join(f"{exact / factors[name]:,.0f}×" for name in shown),
    )


if __name__ == "__main__":
    main()
