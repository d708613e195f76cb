"""Speed of one quasi-static push step, against the same step solved as a cvxpy SOCP.

Run: ``python benchmarks/bench_pushing.py``. The part rests on a 10:1 rectangle of uniform
pressure (and, as for simulating measured pushes without a fit, on the 99-gon inscribed in the
ellipse of the same extent); the pusher pushes at random points of its long side with random
velocities (sticking and sliding steps mixed). fixplan's step uses the ellipsoid's closed form or,
for the exact surface, root finding on the line of sticking twists through the forward map and,
for sliding steps, the inverse map at the edge of the friction cone; the baseline solves the
sticking step as a minimum-dissipation SOCP (cvxpy + Clarabel) over a 2,000-point quadrature of
the rectangle. Medians of repeated runs. Then where the time of an exact step goes (forward map,
inverse map, the rest) and single calls of ``LimitSurface.load`` and ``.motion``.
"""

from __future__ import annotations

import time

import cvxpy as cp
import numpy as np
from performance_rows import emit

from fixplan import LimitSurface, pressure
from fixplan.models import Ellipsoid
from fixplan.motion import push_step

LENGTH, WIDTH, MU, PUSHER_MU = 0.2, 0.02, 0.4, 0.3
RUNS = 3


def pushes(count: int, seed: int = 0):
    rng = np.random.default_rng(seed)
    for x, turn in zip(rng.uniform(-0.09, 0.09, count), rng.uniform(-0.6, 0.6, count),
                       strict=True):  # fmt: skip
        yield [x, -WIDTH / 2], [0.0, 1.0], [np.sin(turn), np.cos(turn)]


def ellipse_outline(vertices: int = 99) -> np.ndarray:
    """The polygon inscribed in the ellipse with the rectangle's extent (counter-clockwise)."""
    angles = 2 * np.pi * np.arange(vertices) / vertices
    return np.column_stack([LENGTH / 2 * np.cos(angles), WIDTH / 2 * np.sin(angles)])


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


class TimedSurface:
    """A limit surface whose forward and inverse maps add their time [s] and calls to counters."""

    def __init__(self, surface: LimitSurface):
        self.surface = surface
        self.frictionless = surface.frictionless
        self.seconds = {"forward map (load)": 0.0, "inverse map (motion, safety factor)": 0.0}
        self.calls = dict.fromkeys(self.seconds, 0)

    def _timed(self, key, method, argument):
        start = time.perf_counter()
        result = method(argument)
        self.seconds[key] += time.perf_counter() - start
        self.calls[key] += 1
        return result

    def load(self, twist):
        return self._timed("forward map (load)", self.surface.load, twist)

    def motion(self, load):
        return self._timed("inverse map (motion, safety factor)", self.surface.motion, load)

    def safety_factor(self, load):
        key = "inverse map (motion, safety factor)"
        return self._timed(key, self.surface.safety_factor, load)

    def motion_and_safety_factor(self, load):
        key = "inverse map (motion, safety factor)"
        return self._timed(key, self.surface.motion_and_safety_factor, load)


def where_the_time_goes(surface: LimitSurface, count: int) -> None:
    timed = TimedSurface(surface)
    start = time.perf_counter()
    steps_per_second(timed, count)
    total = time.perf_counter() - start
    for name, seconds in timed.seconds.items():
        calls = timed.calls[name]
        print(f"    {name}: {seconds / total:.0%} ({calls / count:.1f} calls per step, "
              f"{seconds / calls * 1e6:.1f} us each)")  # fmt: skip
    rest = total - sum(timed.seconds.values())
    print(f"    the rest (push_step's own Python, root finding, timers): {rest / total:.0%}")


def single_call_microseconds(method, arguments) -> float:
    """Median time [us] of one call over ``arguments`` (each called a few times)."""
    times = []
    for argument in arguments:
        method(argument)
        for _ in range(5):
            start = time.perf_counter()
            method(argument)
            times.append(time.perf_counter() - start)
    return float(np.median(times)) * 1e6


def main() -> None:
    rectangle = LimitSurface(pressure.rectangle(LENGTH, WIDTH), mu=MU, normal_force=1.0)
    outline = LimitSurface(pressure.polygon(ellipse_outline()), mu=MU, normal_force=1.0)
    surfaces = (
        ("ellipsoid", Ellipsoid.from_limit_surface(rectangle), 20_000),
        ("exact 10:1 rectangle", rectangle, 2_000),
        ("exact 99-gon ellipse outline", outline, 1_000),
    )
    rates = {}
    for name, surface, count in surfaces:
        steps_per_second(surface, 10)  # compile and warm up
        runs = [steps_per_second(surface, count) for _ in range(RUNS)]
        rates[name] = float(np.median([rate for rate, _ in runs]))
        print(f"push step, {name:28s}: {rates[name]:7.0f} steps/s  modes {runs[0][1]}")
    baseline = float(np.median([socp_steps_per_second(50) for _ in range(RUNS)]))
    print(
        f"baseline: minimum-dissipation SOCP (cvxpy + Clarabel, 2,000 points): {baseline:.0f} steps/s"
    )
    for name, rate in rates.items():
        print(f"  {name} / baseline: x{rate / baseline:.0f}")
    emit(
        "push step, 10:1 rectangle: ellipsoid; exact",
        f"{rates['ellipsoid']:,.0f}; {rates['exact 10:1 rectangle']:,.0f} steps/s",
        f"cvxpy + Clarabel SOCP, 2,000 points: {baseline:.0f} steps/s",
        f"{rates['ellipsoid'] / baseline:,.0f}×; {rates['exact 10:1 rectangle'] / baseline:,.0f}×",
    )
    print("where the time of an exact step goes:")
    for name, surface, count in surfaces[1:]:
        print(f"  {name}:")
        where_the_time_goes(surface, count)
    rng = np.random.default_rng(1)
    twists = rng.normal(size=(40, 3)) * [1.0, 1.0, 20.0]
    loads = rng.normal(size=(40, 3)) * [1.0, 1.0, 0.02]
    print("single calls (median):")
    for name, surface, _ in surfaces[1:]:
        load = single_call_microseconds(surface.load, twists)
        motion = single_call_microseconds(surface.motion, loads)
        print(f"  {name}: load {load:.1f} us, motion {motion:.1f} us")


if __name__ == "__main__":
    main()
