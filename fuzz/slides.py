"""Fuzzed slides on point supports: random parts on two to five points (a third of them with a
disk patch too), spinning and sliding or pushed by pulsing loads, each run to its end.

Prints every run that does not end normally (an error, a non-finite pose, a point that drifts
while the body turns about it, or more than 10 s) and the count of each outcome. The README's
figures on fuzzed slides are from ``python fuzz/slides.py 0:150 1000:1150`` (247 runs: seeds
whose points are fewer than two distinct ones are skipped, as the surface refuses them).
"""

from __future__ import annotations

import collections
import signal
import time

import numpy as np
from seeds import seeds, summary

from fixplan import LimitSurface, pressure
from fixplan.errors import FixplanError
from fixplan.motion import slide

#: A run is stopped after this long [s].
TIME_LIMIT = 60


def _run(seed: int) -> str | None:
    """The outcome of the slide of ``seed`` (``None``: skipped)."""
    rng = np.random.default_rng(seed)
    count = int(rng.integers(1, 6))
    points, weights = rng.normal(0, 0.05, (count, 2)), rng.uniform(0.2, 2, count)
    kind = rng.integers(0, 3)
    try:
        surface = LimitSurface(pressure.points(points, weights), mu=rng.uniform(0.1, 1),
                               normal_force=rng.uniform(1, 20))  # fmt: skip
    except FixplanError:
        return None
    if kind == 2:
        disk = LimitSurface(pressure.disk(rng.uniform(0.005, 0.03)), mu=0.3,
                            normal_force=rng.uniform(0.5, 5))  # fmt: skip
        surface = LimitSurface.combine([surface, disk])
    mass = rng.uniform(0.1, 2)
    inertia = mass * rng.uniform(0.0005, 0.005)
    twist = rng.normal(0, 1, 3) * [0.2, 0.2, 5]
    load = None
    if kind >= 1 and rng.random() < 0.7:
        amplitude = rng.normal(0, 1, 3) * [2, 2, 0.1] * rng.uniform(0.2, 3)
        frequency = rng.uniform(0, 20)

        def load(t, pose, amplitude=amplitude, frequency=frequency):
            return amplitude * (1 + 0.5 * np.sin(frequency * t))

        if rng.random() < 0.5:
            twist = np.zeros(3)
    if load is None and not np.any(twist):
        return None
    try:
        moved = slide(surface, mass=mass, inertia=inertia, twist0=twist, load=load,
                      duration=float(rng.uniform(0.05, 1.0)),
                      samples=int(rng.integers(5, 300)))  # fmt: skip
    except FixplanError as exc:
        return f"{type(exc).__name__}: {str(exc)[:120]}"
    if not np.all(np.isfinite(moved.poses)):
        return "non-finite pose"
    anchors = surface.point_supports[0]
    for start, end, index in moved.pivots:
        turning = (moved.t >= start) & (moved.t <= end)
        angles = moved.poses[turning, 2]
        x, y = anchors[index]
        still = moved.poses[turning, :2] + np.stack(
            [np.cos(angles) * x - np.sin(angles) * y, np.sin(angles) * x + np.cos(angles) * y], 1
        )
        if np.ptp(still, axis=0).max() > 1e-12:
            return f"the still point drifted {np.ptp(still, axis=0).max():.2e} m"
    return "ok"


def _time_up(*_) -> None:
    raise TimeoutError


def main() -> None:
    signal.signal(signal.SIGALRM, _time_up)
    outcomes = collections.Counter()
    for seed in seeds(__doc__.splitlines()[0]):
        began = time.perf_counter()
        signal.alarm(TIME_LIMIT)
        try:
            outcome = _run(seed)
        except TimeoutError:
            outcome = f"stopped after {TIME_LIMIT} s"
        finally:
            signal.alarm(0)
        if outcome is None:
            continue
        took = time.perf_counter() - began
        outcomes["ok" if outcome == "ok" else "failed"] += 1
        if outcome != "ok" or took > 10:
            print(f"seed {seed} ({took:.1f} s): {outcome}", flush=True)
    print(summary(outcomes))


if __name__ == "__main__":
    main()
