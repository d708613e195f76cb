"""Fuzzed contact-set surfaces: one to four contacts of every friction model (exact patches of
several shapes and point supports, ellipsoids, pyramids, point cones), with random places,
normals (half of them along an axis) and normal forces, in the planar subspace or three random
wrench components.

For five random loads each, checks that the safety factor ``s`` and motion ``V`` meet the
normality law of the set's support function, ``h(V) = s d·V``, where ``s`` is above 1e-12 (flat
sets, whose friction does not span the subspace, have ``s = 0`` but for rounding). Prints every
set that ends in an error or misses the law by 1e-6 or more, the count of each outcome and the
largest residual. The README's figures on fuzzed contact sets are from
``python fuzz/contact_sets.py 0:400``.
"""

from __future__ import annotations

import collections

import numpy as np
from seeds import seeds, summary

from fixplan import Contact, ContactSetSurface, pressure
from fixplan.errors import FixplanError

COMPONENTS = ("fx", "fy", "fz", "mx", "my", "mz")
MODELS = ("exact", "exact", "ellipsoid", "point-cone", "pyramid")


def _patch(rng):
    kind = rng.integers(0, 4)
    if kind == 3:  # (point supports: an exact model states them exactly, a cone per point)
        return pressure.points(rng.normal(size=(rng.integers(2, 6), 2)) * 0.01)
    if kind == 0:
        profile = ("uniform", "hertz", "parabolic")[rng.integers(0, 3)]
        return pressure.disk(rng.uniform(0.003, 0.02), profile)
    if kind == 1:
        size = rng.uniform([0.005, 0.002], [0.04, 0.02])
        return pressure.rectangle(*size).shifted(*rng.normal(size=2) * 0.003)
    return pressure.polygon(np.array([[0, 0], [0.02, 0], [0.015, 0.01], [0.0, 0.012]]))


def _surface(rng) -> ContactSetSurface:
    contacts, forces = [], []
    for i in range(rng.integers(1, 5)):
        model = MODELS[rng.integers(0, len(MODELS))]
        normal = rng.normal(size=3)
        if rng.uniform() < 0.5:
            normal = np.eye(3)[rng.integers(0, 3)] * rng.choice([-1, 1])
        contacts.append(Contact(name=f"c{i}", role="support", position=rng.normal(size=3) * 0.05,
                                normal=normal, mu=rng.uniform(0.1, 0.9), model=model,
                                patch=None if model.startswith("point") else _patch(rng)))  # fmt: skip
        forces.append(rng.uniform(0.5, 50.0))
    planar = rng.uniform() < 0.5
    subspace = ("fx", "fy", "mz") if planar else tuple(rng.choice(COMPONENTS, 3, replace=False))
    return ContactSetSurface(contacts, forces, subspace)


def _residual(seed: int) -> float:
    """The largest relative miss of the normality law over five loads of the set of ``seed``."""
    rng = np.random.default_rng(seed)
    surface = _surface(rng)
    extents = np.array([surface.support(axis) for axis in np.eye(3)])  # (its size on each axis)
    worst = 0.0
    for _ in range(5):
        load = rng.normal(size=3) * np.where(extents > 0.0, extents, 1.0)
        motion, safety = surface.motion_and_safety_factor(load)
        if safety < 0.0:
            raise AssertionError(f"negative safety factor {safety!r}")
        if not np.isfinite(safety) or safety < 1e-12:
            continue
        support = surface.support(motion)
        worst = max(worst, abs(support - safety * load @ motion) / support)
    return worst


def main() -> None:
    outcomes, worst = collections.Counter(), 0.0
    for seed in seeds(__doc__.splitlines()[0]):
        try:
            residual = _residual(seed)
        except (FixplanError, AssertionError) as exc:
            outcomes[type(exc).__name__] += 1
            print(f"seed {seed}: {type(exc).__name__}: {str(exc)[:150]}", flush=True)
            continue
        worst = max(worst, residual)
        outcomes["ok" if residual < 1e-6 else "off the law"] += 1
        if residual >= 1e-6:
            print(f"seed {seed}: normality missed by {residual:.3g}", flush=True)
    print(f"{summary(outcomes)}; largest residual {worst:.3g}")


if __name__ == "__main__":
    main()
