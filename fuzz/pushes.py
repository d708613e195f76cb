"""Fuzzed pushes of round pushers: boxes, disks and star-shaped (often concave) polygons pushed
by pushers of radius 0 to 20 mm along straight and wavy paths, in 5 to 100 steps.

Prints every push that does not end normally (an error, a non-finite pose, a step that ends
with the pusher inside the part by more than 1e-12 of its size, or more than 10 s), the count
of each outcome and the deepest overlap found, relative to the part's size. A push refused with
a :class:`~fixplan.errors.GeometryError` (a pusher wedged into a notch of a concave part, which
its single contact does not model) counts as refused, not failed. The README's
figures on fuzzed round-pusher pushes are from ``python fuzz/pushes.py 0:150`` (149 pushes: a
polygon the surface refuses is skipped).
"""

from __future__ import annotations

import collections
import time

import numpy as np
from seeds import seeds, summary

from fixplan import LimitSurface, pressure
from fixplan.errors import FixplanError, GeometryError
from fixplan.motion import Outline, PointPusher, push


def _part(rng):
    """A random outline and its uniform-pressure support surface (``None``: refused)."""
    kind = rng.integers(0, 3)
    if kind == 0:
        length, width = rng.uniform(0.02, 0.2, 2)
        return Outline.rectangle(length, width), pressure.rectangle(length, width)
    if kind == 1:
        radius = rng.uniform(0.01, 0.1)
        return Outline.disk(radius), pressure.disk(radius)
    count = int(rng.integers(3, 9))
    angles = np.sort(rng.uniform(0, 2 * np.pi, count))
    radii = rng.uniform(0.02, 0.1, count)
    vertices = np.stack([radii * np.cos(angles), radii * np.sin(angles)], 1)
    vertices -= vertices.mean(0)
    try:
        return Outline.polygon(vertices), pressure.polygon(vertices)
    except FixplanError:
        return None


def _run(seed: int) -> tuple[str, float] | None:
    """The outcome of the push of ``seed`` and its deepest overlap (``None``: skipped)."""
    rng = np.random.default_rng(seed)
    part = _part(rng)
    if part is None:
        return None
    shape, field = part
    surface = LimitSurface(field, mu=0.3, normal_force=5.0)
    size = shape.size
    radius = float(rng.choice([0.0, rng.uniform(0.001, 0.02)]))
    start = np.array([-size - radius - rng.uniform(0.001, 0.02), rng.uniform(-size, size)])
    velocity = np.array([rng.uniform(0.02, 0.1), rng.uniform(-0.03, 0.03)])
    path = (start, velocity)
    if rng.random() < 0.5:
        frequency, amplitude = rng.uniform(0.5, 5), rng.uniform(0, 0.03)

        def path(t, start=start, velocity=velocity, frequency=frequency, amplitude=amplitude):
            return start + velocity * t + np.array([0.0, amplitude * np.sin(frequency * t)])

    pusher = PointPusher(path, mu=float(rng.uniform(0, 0.8)), radius=radius)
    steps = int(rng.choice([5, 10, 30, 100]))
    try:
        moved = push(surface, pusher, shape=shape, duration=float(rng.uniform(0.5, 3)),
                     steps=steps)  # fmt: skip
    except GeometryError as exc:
        return f"refused: {str(exc)[:120]}", 0.0
    except FixplanError as exc:
        return f"{type(exc).__name__}: {str(exc)[:120]}", 0.0
    if not np.all(np.isfinite(moved.poses)):
        return "non-finite pose", 0.0
    deepest = 0.0
    for pose, centre in zip(moved.poses, moved.pusher_positions, strict=True):
        turn = np.array([[np.cos(pose[2]), np.sin(pose[2])], [-np.sin(pose[2]), np.cos(pose[2])]])
        deepest = min(deepest, (shape.nearest(turn @ (centre - pose[:2]))[2] - radius) / size)
    return ("ok" if deepest >= -1e-12 else f"inside by {-deepest:.3g} of its size"), deepest


def main() -> None:
    outcomes, deepest = collections.Counter(), 0.0
    for seed in seeds(__doc__.splitlines()[0]):
        began = time.perf_counter()
        found = _run(seed)
        if found is None:
            continue
        outcome, overlap = found
        deepest = min(deepest, overlap)
        took = time.perf_counter() - began
        outcomes["failed" if outcome != "ok" and not outcome.startswith("refused") else
                 outcome.split(":")[0]] += 1  # fmt: skip
        if outcome != "ok" or took > 10:
            print(f"seed {seed} ({took:.1f} s): {outcome}", flush=True)
    print(f"{summary(outcomes)}; deepest overlap {0.0 - deepest:.3g} of the part's size")


if __name__ == "__main__":
    main()
