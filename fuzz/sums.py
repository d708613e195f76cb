"""Fuzzed summed surfaces: one to four parts (disks of every profile, annuli, rectangles, point
supports, pressure grids and ellipsoids) with random friction and normal forces, each placed by a
random pose (half of them mirrored), summed with ``LimitSurface.combine``.

For 20 random loads each, and where the sum has point supports 10 next to their facets, checks
the compiled inverse map against the NumPy path, which evaluates each part's kernel and sums
them: safety factors to 1e-12 and motions to 1e-9 (unit twists in normalised coordinates).
Prints every sum that ends in an error or misses, the count of each outcome and the largest
differences. The README's figures on fuzzed sums are from ``python fuzz/sums.py 0:150``.
"""

from __future__ import annotations

import collections

import numpy as np
from seeds import seeds, summary

from fixplan import LimitSurface, pressure
from fixplan.errors import FixplanError
from fixplan.surface.geometry import Pose
from fixplan.surface.inverse import solve


def _pose(rng) -> Pose:
    return Pose(angle=rng.uniform(-3, 3), offset=tuple(rng.normal(size=2) * 0.03),
                mirrored=bool(rng.integers(0, 2)))  # fmt: skip


def _part(rng) -> LimitSurface:
    kind = rng.integers(0, 6)
    if kind == 4:
        matrix = np.diag([1.0, 1.0, 1e4] / rng.uniform(0.1, 1.0, 3) ** 2)
        return LimitSurface.ellipsoid(matrix, normal_force=rng.uniform(0.5, 5.0)).placed(_pose(rng))
    if kind == 0:
        profile = ("uniform", "hertz", "parabolic")[rng.integers(0, 3)]
        field = pressure.disk(rng.uniform(0.003, 0.02), profile)
    elif kind == 1:
        field = pressure.rectangle(*rng.uniform([0.005, 0.002], [0.04, 0.02]))
    elif kind == 2:
        field = pressure.points(rng.normal(size=(rng.integers(2, 6), 2)) * 0.02)
    elif kind == 3:
        field = pressure.disk(0.02, "annulus", inner_radius=rng.uniform(0.002, 0.015))
    else:
        values = rng.uniform(0.2, 1.0, (5, 6))
        field = pressure.grid(np.linspace(-0.01, 0.01, 6), np.linspace(-0.008, 0.008, 5), values)
    surface = LimitSurface(field, mu=rng.uniform(0.1, 0.9), normal_force=rng.uniform(0.5, 20.0))
    return surface.placed(_pose(rng))


def _unit(surface: LimitSurface, twists: np.ndarray) -> np.ndarray:
    normalised = twists * np.array([surface.max_force, surface.max_force, surface.max_moment])
    return normalised / np.linalg.norm(normalised, axis=1, keepdims=True)


def _differences(seed: int) -> tuple[float, float]:
    """The largest relative safety-factor and unit-motion differences of the sum of ``seed``."""
    rng = np.random.default_rng(seed)
    surface = LimitSurface.combine([_part(rng) for _ in range(rng.integers(1, 5))])
    if surface._compiled is None:
        raise AssertionError("the sum has no compiled form")
    loads = rng.normal(size=(20, 3)) * surface._units
    points = surface.point_supports[0]
    if len(points):
        near = points[rng.integers(len(points), size=10)] + rng.normal(size=(10, 2)) * 1e-8
        loads = np.vstack([loads, surface.load_at_cor(near)])
    motions, safety = surface.motion_and_safety_factor(loads)
    size = np.max(np.abs(loads / surface._units), axis=1)
    numpy = solve(surface._kernel, surface._scale, loads / size[:, None], surface._units)
    gap = np.abs(safety / (numpy.safety_factor / size) - 1.0).max()
    turn = np.linalg.norm(_unit(surface, motions) - _unit(surface, numpy.twist), axis=1).max()
    return float(gap), float(turn)


def main() -> None:
    outcomes, worst = collections.Counter(), np.zeros(2)
    for seed in seeds(__doc__.splitlines()[0]):
        try:
            found = np.array(_differences(seed))
        except (FixplanError, AssertionError) as exc:
            outcomes[type(exc).__name__] += 1
            print(f"seed {seed}: {type(exc).__name__}: {str(exc)[:150]}", flush=True)
            continue
        worst = np.maximum(worst, found)
        missed = found[0] > 1e-12 or found[1] > 1e-9
        outcomes["missed" if missed else "ok"] += 1
        if missed:
            print(f"seed {seed}: safety factors {found[0]:.3g}, motions {found[1]:.3g}")
    print(f"{summary(outcomes)}; largest differences: safety factors {worst[0]:.3g}, motions "
          f"{worst[1]:.3g}")  # fmt: skip


if __name__ == "__main__":
    main()
