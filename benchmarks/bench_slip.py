"""Update rate of the slip-onset estimator, against per-sample exact queries and batch refits.

Run: ``python benchmarks/bench_slip.py``. A stream of slip onsets is drawn from the exact limit
surface of a 10:1 rectangle (3 % force noise, normal forces 2-20 N); estimators start from the
nominal with twice the friction and 0.6 times the patch and take the stream one onset at a time,
as plain lists (the rate of a control loop) and as NumPy rows, with and without twists. Nominals:
the Table 2 ellipsoid of the rectangle and the exact surface itself. Medians of repeated runs of
wall-clock time; the load average is printed with them (on a shared machine other processes
slow a single-threaded loop down by up to the load per core).

Baselines measured in the same run:

- one exact inverse-map query per onset (``LimitSurface.safety_factor`` of one load), the least
  work an update that asks the exact surface would do;
- a batch least-squares refit of ``(log mu, log rho)`` over all onsets so far with
  ``scipy.optimize.least_squares`` (residuals ``log g`` through the exact surface's vectorised
  inverse map), the non-recursive way to use each new onset, at 100 and 1,000 onsets.
"""

from __future__ import annotations

import os
import time

import numpy as np
from scipy.optimize import least_squares

from fixplan import LimitSurface, pressure
from fixplan.models import Ellipsoid
from fixplan.motion import SlipEstimator

LENGTH, WIDTH, MU, NOISE = 0.1, 0.01, 0.5, 0.03
COUNT, RUNS = 20_000, 5


def rectangle(scale: float = 1.0, mu: float = MU) -> LimitSurface:
    return LimitSurface(pressure.rectangle(scale * LENGTH, scale * WIDTH), mu=mu)


def stream(true: LimitSurface, count: int, seed: int = 0):
    """Onsets ``(loads, normal_forces, twists)`` on ``true`` with relative force noise."""
    rng = np.random.default_rng(seed)
    twists = rng.normal(size=(count, 3)) / np.array([1.0, 1.0, true.characteristic_length])
    normal_forces = rng.uniform(2.0, 20.0, count)
    loads = true.load(twists) * normal_forces[:, None]
    return loads * (1.0 + NOISE * rng.normal(size=(count, 3))), normal_forces, twists


def updates_per_second(nominal, samples, *, twists: bool) -> float:
    """Median rate of ``update`` over the samples, a fresh estimator per run."""
    loads, normal_forces, measured = samples
    rates = []
    for _ in range(RUNS):
        estimator = SlipEstimator(nominal, noise=NOISE)
        update = estimator.update
        start = time.perf_counter()
        if twists:
            for load, normal_force, twist in zip(loads, normal_forces, measured, strict=True):
                update(load, normal_force, twist=twist)
        else:
            for load, normal_force in zip(loads, normal_forces, strict=True):
                update(load, normal_force)
        rates.append(len(loads) / (time.perf_counter() - start))
    return float(np.median(rates))


def exact_queries_per_second(surface: LimitSurface, loads: np.ndarray) -> float:
    rates = []
    for _ in range(RUNS):
        start = time.perf_counter()
        for load in loads:
            surface.safety_factor(load)
        rates.append(len(loads) / (time.perf_counter() - start))
    return float(np.median(rates))


def refits_per_second(nominal: LimitSurface, loads: np.ndarray, normal_forces) -> float:
    """Median rate of batch refits of ``(log mu, log rho)`` over all ``loads`` (the rate of
    updates if every new onset triggered one)."""
    mu0 = nominal.max_force / nominal.normal_force
    rho0 = nominal.characteristic_length
    per_unit = loads / normal_forces[:, None]

    def residuals(x):
        force_scale, length_scale = np.exp(x - np.log([mu0, rho0]))
        nominal_loads = per_unit / np.array([force_scale, force_scale, force_scale * length_scale])
        return -np.log(nominal.safety_factor(nominal_loads * nominal.normal_force))

    rates = []
    for _ in range(RUNS):
        start = time.perf_counter()
        least_squares(residuals, np.log([mu0, rho0]), method="lm")
        rates.append(1.0 / (time.perf_counter() - start))
    return float(np.median(rates))


def main() -> None:
    true, exact = rectangle(), rectangle(scale=0.6, mu=2.0 * MU)
    nominals = {"ellipsoid": Ellipsoid.from_limit_surface(exact), "exact": exact}
    samples = stream(true, COUNT)
    as_lists = tuple(values.tolist() for values in samples)
    rho = SlipEstimator(true).rho
    print(f"load average at start: {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores")
    print(f"{COUNT} onsets of a {LENGTH}x{WIDTH} m rectangle, {NOISE:.0%} force noise; "
          f"true mu {MU}, rho {rho:.5f} m; start 2x mu, 0.6x patch")  # fmt: skip
    for name, nominal in nominals.items():
        start = time.perf_counter()
        estimator = SlipEstimator(nominal, noise=NOISE)
        build = time.perf_counter() - start
        for load, normal_force in zip(*as_lists[:2], strict=True):
            estimator.update(load, normal_force)
        print(f"\n{name} nominal: table built in {build:.2f} s; after the stream "
              f"mu {estimator.mu:.4f} ± {estimator.mu_std:.1e}, "
              f"rho {estimator.rho:.5f} ± {estimator.rho_std:.1e} m")  # fmt: skip
        for label, data, twists in (
            ("lists", as_lists, False),
            ("lists + twists", as_lists, True),
            ("numpy rows", samples, False),
        ):
            rate = updates_per_second(nominal, data, twists=twists)
            print(f"  update, {label:15s}: {rate:9.0f} updates/s")
    print("\nbaselines:")
    rate = exact_queries_per_second(exact, samples[0][:200])
    print(f"  one exact safety_factor query per onset: {rate:9.0f} queries/s")
    for count in (100, 1000):
        rate = refits_per_second(exact, samples[0][:count], samples[1][:count])
        print(f"  batch least-squares refit over {count:5d} onsets: {rate:9.1f} refits/s")
    print(f"load average at end: {os.getloadavg()[0]:.1f}")


if __name__ == "__main__":
    main()
