"""Speed of one quasi-static push step, against the same step solved as a cvxpy SOCP.

Run: ``python benchmarks/bench_pushing.py``. The part rests on a 10:1 rectangle of uniform
pressure; the pusher pushes at random points of its long side with random velocities (sticking
and sliding steps mixed). fixplan's step uses the ellipsoid's closed form or, for the exact
surface, root finding on the force angle through the exact inverse map; the baseline solves the
sticking step as a minimum-dissipation SOCP (cvxpy + Clarabel) over a 2,000-point quadrature of
the same rectangle. Medians of repeated runs.
"""

from __future__ import annotations

import time

import cvxpy as cp
import numpy as np

from fixplan import LimitSurface, pressure
from fixplan.models import Ellipsoid
from fixplan.motion import push_step

LENGTH, WIDTH, MU, PUSHER_MU = 0.2, 0.02, 0.4, 0.3


def pushes(count: int, seed: int = 0):
    rng = np.random.default_rng(seed)
    for x, turn in zip(rng.uniform(-0.09, 0.09, count), rng.uniform(-0.6, 0.6, count),
                       strict=True):  # fmt: skip
        yield [x, -WIDTH / 2], [0.0, 1.0], [np.sin(turn), np.cos(turn)]


def steps_per_second(surface, count: int) -> tuple[float, dict]:
    cases = list(pushes(count))
    modes: dict[str, int] = {}
    start = time.perf_counter()
    for contact, normal, velocity in cases:
        step = push_step(surface, contact=contact, normal=normal, velocity=velocity, mu=PUSHER_MU)
        modes[step.mode] = modes.get(step.mode, 0) + 1
    return count / (time.perf_counter() - start), modes


def socp_steps_per_second(count: int) -> float:
    nx, ny = 200, 10
    xs = (np.arange(nx) + 0.5) / nx * LENGTH - LENGTH / 2
    ys = (np.arange(ny) + 0.5) / ny * WIDTH - WIDTH / 2
    points = np.array([(x, y) for x in xs for y in ys])
    jacobians = np.vstack([[[1.0, 0.0, -y], [0.0, 1.0, x]] for x, y in points])
    twist = cp.Variable(3)
    contact_map = cp.Parameter((2, 3))
    velocity = cp.Parameter(2)
    speeds = cp.norm(cp.reshape(jacobians @ twist, (len(points), 2), order="C"), axis=1)
    problem = cp.Problem(
        cp.Minimize(cp.sum(speeds) / len(points)), [contact_map @ twist == velocity]
    )
    cases = list(pushes(count))
    start = time.perf_counter()
    for contact, _, push in cases:
        contact_map.value = np.array([[1.0, 0.0, -contact[1]], [0.0, 1.0, contact[0]]])
        velocity.value = np.asarray(push)
        problem.solve(solver=cp.CLARABEL)
    return count / (time.perf_counter() - start)


def main() -> None:
    exact = LimitSurface(pressure.rectangle(LENGTH, WIDTH), mu=MU, normal_force=1.0)
    ellipsoid = Ellipsoid.from_limit_surface(exact)
    push_step(exact, contact=[0.0, -WIDTH / 2], normal=[0, 1], velocity=[0, 1], mu=PUSHER_MU)
    rates = {}
    for name, surface, count in (("ellipsoid", ellipsoid, 20_000), ("exact", exact, 2_000)):
        runs = [steps_per_second(surface, count) for _ in range(3)]
        rates[name] = float(np.median([rate for rate, _ in runs]))
        print(f"push step, {name:9s}: {rates[name]:9.0f} steps/s  modes {runs[0][1]}")
    baseline = float(np.median([socp_steps_per_second(50) for _ in range(3)]))
    print(
        f"baseline: minimum-dissipation SOCP (cvxpy + Clarabel, 2,000 points): {baseline:.0f} steps/s"
    )
    for name, rate in rates.items():
        print(f"  {name} / baseline: x{rate / baseline:.0f}")


if __name__ == "__main__":
    main()
