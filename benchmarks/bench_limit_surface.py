"""Speed and accuracy of the exact limit surface, each figure next to a baseline run here.

Run: ``python benchmarks/bench_limit_surface.py`` (add ``--quick`` for a smaller run). Prints
medians of repeated runs; the machines are shared and noisy, so compare ratios.

The inverse map per call is measured against another version of fixplan in the same run
(``--baseline REF``, default :data:`BEFORE_COMPILED_INVERSE`, the last commit before it was
compiled whole): that commit is extracted with ``git archive`` into a temporary folder and the
same measurements run there in a subprocess (its own numba cache).
"""

from __future__ import annotations

import argparse
import contextlib
import json
import os
import resource
import subprocess
import sys
import tempfile
import time
import warnings
from pathlib import Path

import numpy as np
from performance_rows import emit

from fixplan import LimitSurface, pressure

#: The last commit whose inverse map ran Newton from Python (issue 13 §3 measured against it).
BEFORE_COMPILED_INVERSE = "915beafb37c5e1e1b863a49ccea6d0065ac5d6c7"


def median_time(function, repeats: int) -> float:
    """Median wall time [s] of ``repeats`` calls."""
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        function()
        times.append(time.perf_counter() - start)
    return float(np.median(times))


def numpy_forward(points, weights, twists, chunk=64):
    """Baseline: the forward map as a plain NumPy broadcast, chunked to bound memory."""
    loads = np.empty((len(twists), 3))
    x, y = points[:, 0], points[:, 1]
    for start in range(0, len(twists), chunk):
        v = twists[start : start + chunk]
        ux = v[:, 0, None] - v[:, 2, None] * y[None, :]
        uy = v[:, 1, None] + v[:, 2, None] * x[None, :]
        speed = np.hypot(ux, uy)
        gx, gy = weights * ux / speed, weights * uy / speed
        loads[start : start + chunk] = np.column_stack(
            [gx.sum(1), gy.sum(1), (x * gy - y * gx).sum(1)]
        )
    return loads


def bench_forward(n_points: int, n_twists: int, repeats: int) -> None:
    rng = np.random.default_rng(0)
    xy = rng.uniform(-0.05, 0.05, size=(n_points, 2))
    surface = LimitSurface(pressure.points(xy), mu=0.5, normal_force=100.0)
    twists = rng.normal(size=(n_twists, 3)) * np.array([1.0, 1.0, 20.0])
    rss_before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    surface.load(twists[:8])  # compile
    fast = median_time(lambda: surface.load(twists), repeats)
    rss_after = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    points, weights = surface.field.quadrature()
    weights = weights * 0.5 * 100.0
    base_twists = twists[: max(1, n_twists // 10)]
    base = median_time(lambda: numpy_forward(points, weights, base_twists), 1) * 10
    check = numpy_forward(points, weights, twists[:50])
    error = np.max(np.abs(surface.load(twists[:50]) - check)) / np.max(np.abs(check))
    pairs = n_points * n_twists
    print(f"forward map, {n_points} points x {n_twists} twists")
    print(f"  fixplan (numba, parallel)  {pairs / fast / 1e6:9.1f} M evaluations/s  ({fast:.3f} s)")
    print(f"  NumPy broadcast baseline   {pairs / base / 1e6:9.1f} M evaluations/s")
    print(f"  speed-up                   {base / fast:9.1f} x")
    print(f"  agreement                  {error:9.1e} (max relative difference)")
    print(f"  peak resident memory       {rss_after / 1024:9.0f} MB (whole process, incl. numba)")
    emit(
        f"forward map, {n_points:,} points × {n_twists:,} twists",
        f"{pairs / fast / 1e6:,.0f} M evaluations/s (peak memory {rss_after / 1024:.0f} MB)",
        f"NumPy broadcast {pairs / base / 1e6:,.0f} M/s",
        f"{base / fast:.0f}×",
    )
    del rss_before


def socp_safety(points, friction, load):
    """Baseline: safety factor and sliding twist of one load as a cvxpy + Clarabel SOCP."""
    import cvxpy as cp

    forces = cp.Variable((len(points), 2))
    scale = cp.Variable()
    moment = cp.sum(
        cp.multiply(points[:, 0], forces[:, 1]) - cp.multiply(points[:, 1], forces[:, 0])
    )
    balance = [cp.sum(forces[:, 0]) == scale * load[0], cp.sum(forces[:, 1]) == scale * load[1]]
    balance.append(moment == scale * load[2])
    cones = [cp.norm(forces, 2, axis=1) <= friction]
    problem = cp.Problem(cp.Maximize(scale), balance + cones)
    # Tolerances far below Clarabel's defaults, so that the baseline is accurate enough to check
    # 1e-8 agreement; Clarabel then reports "almost solved", which cvxpy warns about.
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        problem.solve(
            solver=cp.CLARABEL,
            tol_gap_abs=1e-13,
            tol_gap_rel=1e-13,
            tol_feas=1e-13,
            tol_ktratio=1e-11,
        )
    # The sliding twist from the primal: every sliding point's force is parallel to its
    # velocity v_i(V), so f_i × v_i(V) = 0 is linear in V; its null vector is the motion (more
    # accurate than the dual of the balance constraints).
    f = forces.value
    sliding = np.linalg.norm(f, axis=1) >= 0.999 * friction
    fx, fy = (f[sliding] / np.linalg.norm(f[sliding], axis=1, keepdims=True)).T
    x, y = points[sliding, 0], points[sliding, 1]
    rows = np.column_stack([-fy, fx, fx * x + fy * y])
    twist = np.linalg.svd(rows)[2][-1]
    return scale.value, twist * np.sign(twist @ load)


def bench_inverse(n_points: int, n_queries: int, n_socp: int, repeats: int) -> None:
    rng = np.random.default_rng(1)
    xy = rng.uniform(-0.05, 0.05, size=(n_points, 2))
    surface = LimitSurface(pressure.points(xy), mu=0.5, normal_force=100.0)
    twists = rng.normal(size=(n_queries, 3)) * np.array([1.0, 1.0, 20.0])
    loads = surface.load(twists) * rng.uniform(0.3, 2.0, size=(n_queries, 1))
    surface.motion_and_safety_factor(loads[:4])  # compile
    fast = median_time(lambda: surface.motion_and_safety_factor(loads), repeats)
    motions, safety = surface.motion_and_safety_factor(loads[:n_socp])
    points, weights = surface.field.quadrature()
    friction = weights * 0.5 * 100.0
    start = time.perf_counter()
    results = [socp_safety(points, friction, load) for load in loads[:n_socp]]
    socp = (time.perf_counter() - start) / n_socp
    safety_gap = max(abs(s - r[0]) / r[0] for s, r in zip(safety, results, strict=True))
    rho = surface.characteristic_length
    angles = []
    for motion, (_, twist) in zip(motions, results, strict=True):
        a, b = motion * [1, 1, rho], twist * [1, 1, rho]
        angles.append(np.arctan2(np.linalg.norm(np.cross(a, b)), a @ b))
    print(f"inverse map (safety factor + motion), {n_points}-point field")
    print(f"  fixplan (Newton, batched)  {n_queries / fast:9.0f} queries/s  ({fast:.3f} s)")
    print(f"  cvxpy + Clarabel SOCP      {1.0 / socp:9.1f} queries/s  ({n_socp} queries)")
    print(f"  speed-up                   {socp * n_queries / fast:9.0f} x")
    print(f"  safety factor agreement    {safety_gap:9.1e} (max relative difference)")
    print(f"  motion agreement           {max(angles):9.1e} rad (max angle)")
    emit(
        f"inverse map (safety factor + motion), {n_points:,}-point field, batched",
        f"{n_queries / fast:,.0f} queries/s (agreement: safety {safety_gap:.1e}, motion "
        f"{max(angles):.1e} rad)",
        f"cvxpy + Clarabel SOCP {1.0 / socp:.1f} queries/s",
        f"{socp * n_queries / fast:,.0f}×",
    )


def bench_accuracy() -> None:
    """Error of point-quadrature surfaces against the closed forms, versus point count."""
    rng = np.random.default_rng(2)
    fields = {
        "uniform disk": pressure.disk(0.01),
        "Hertz disk": pressure.disk(0.01, "hertz"),
        "10:1 rectangle": pressure.rectangle(0.1, 0.01),
    }
    print("accuracy vs cost: max relative load error of a quadrature of n points")
    print(f"  {'field':16s} {'order':>5s} {'points':>8s} {'error':>9s}")
    for name, field in fields.items():
        exact = LimitSurface(field, mu=1.0)
        cors = rng.uniform(-2.0, 2.0, size=(400, 2)) * field.radius
        reference = exact.load_at_cor(cors)
        for order in (4, 8, 16, 32, 64):
            xy, w = field.quadrature(order)
            approx = LimitSurface(pressure.points(xy, w, centered=False), mu=1.0)
            error = np.linalg.norm(approx.load_at_cor(cors) - reference, axis=1)
            error = np.max(error / np.linalg.norm(reference, axis=1))
            print(f"  {name:16s} {order:5d} {len(xy):8d} {error:9.1e}")


def per_call_surfaces() -> dict:
    """The surfaces of the per-call benchmark: point supports (facets), a polygon, disks."""
    xy = np.random.default_rng(1).uniform(-0.05, 0.05, size=(4096, 2))
    triangle = 0.05 * np.array([[0.0, 1.0], [-0.866, -0.5], [0.866, -0.5]])
    return {
        "4,096 points": LimitSurface(pressure.points(xy), mu=0.5, normal_force=100.0),
        "3 points": LimitSurface(pressure.points(triangle), mu=0.5, normal_force=30.0),
        "rectangle 10:1": LimitSurface(pressure.rectangle(0.1, 0.01), mu=0.25, normal_force=200.0),
        "uniform disk": LimitSurface(pressure.disk(0.01), mu=0.5, normal_force=10.0),
        "Hertz disk": LimitSurface(pressure.disk(0.01, "hertz"), mu=0.5, normal_force=10.0),
        "annulus": LimitSurface(
            pressure.disk(0.01, "annulus", inner_radius=0.006), mu=0.5, normal_force=10.0
        ),
    }


def load_distributions(surface, count: int, rng, points=None) -> dict:
    """name: loads ``(count, 3)`` [N, N m] of each distribution of the per-call benchmark (near
    the facets of the ``points`` ``(P, 2)`` [m], default the field's points, where any)."""
    rho = surface.characteristic_length
    twists = rng.normal(size=(count, 3)) * [1.0, 1.0, 1.0 / rho]
    directions = rng.normal(size=(count, 3)) * [1.0, 1.0, rho]
    on_surface = surface.load(twists)
    loads = {
        "from twists (h's gradient)": on_surface,
        "random directions and sizes": directions
        * surface.max_force
        * rng.uniform(0.01, 100.0, (count, 1)),
        "near pure moment": surface.load([0.0, 0.0, 1.0]) * rng.uniform(0.5, 2.0, (count, 1))
        + directions * 1e-6 * surface.max_force,
        "far outside (x 1e6)": on_surface * 1e6,
        "deep inside (x 1e-6)": on_surface * 1e-6,
    }
    points = getattr(surface.field, "xy", None) if points is None else points
    if points is not None and len(points):
        k = rng.integers(0, len(points), count)
        offsets = rng.normal(size=(count, 2)) * 1e-7 * rho
        near = surface.load_at_cor(points[k] + offsets) * rng.uniform(0.5, 1.5, (count, 1))
        loads["near facets (COR 1e-7 rho off a point)"] = near
    return loads


def per_call_times(surface, loads) -> tuple[np.ndarray, np.ndarray]:
    """Times [s] and safety factors (NaN where the version raised ConvergenceError) of single
    ``motion_and_safety_factor`` calls, after one to compile and warm up."""
    from fixplan import ConvergenceError

    surface.motion_and_safety_factor(loads[0])
    times, safety = np.empty(len(loads)), np.full(len(loads), np.nan)
    for i, load in enumerate(loads):
        start = time.perf_counter()
        with contextlib.suppress(ConvergenceError):
            safety[i] = surface.motion_and_safety_factor(load)[1]
        times[i] = time.perf_counter() - start
    return times, safety


def measure_per_call(count: int, batch_repeats: int) -> dict:
    """Single-call median and p99 [s], batched throughput [queries/s], the safety factors (NaN
    where the version raised ConvergenceError) and the number of such failures, per surface and
    load distribution (public API only: it runs on other versions too). Single calls are timed
    before any batch: the threads of a parallel batch keep spinning for a while afterwards."""
    from fixplan import ConvergenceError

    results = {}
    batches = []
    for name, surface in per_call_surfaces().items():
        rng = np.random.default_rng(2)
        for distribution, loads in load_distributions(surface, count, rng).items():
            times, safety = per_call_times(surface, loads)
            key = f"{name} | {distribution}"
            solved = loads[~np.isnan(safety)]
            batches.append((key, surface, solved))
            results[key] = {
                "median": float(np.median(times)),
                "p99": float(np.percentile(times, 99)),
                "safety": safety.tolist(),
                "failed": int(count - len(solved)),
            }
    for key, surface, solved in batches:
        try:
            batch = median_time(
                lambda s=surface, x=solved: s.motion_and_safety_factor(x), batch_repeats
            )
        except ConvergenceError:  # a batch may fail on a load that single calls solve
            batch = np.nan
        results[key]["throughput"] = len(solved) / batch
    return results


def baseline_per_call(ref: str, count: int, batch_repeats: int) -> dict | None:
    """:func:`measure_per_call` run on commit ``ref`` of this repository (``None`` if it cannot
    be extracted)."""
    root = Path(__file__).resolve().parent.parent
    with tempfile.TemporaryDirectory() as folder:
        try:
            archive = subprocess.run(["git", "-C", str(root), "archive", ref], check=True,
                                     capture_output=True).stdout  # fmt: skip
        except (OSError, subprocess.CalledProcessError) as exc:
            print(f"  (no baseline: git archive {ref} failed: {exc})", file=sys.stderr)
            return None
        subprocess.run(["tar", "-x", "-C", folder], input=archive, check=True)
        env = {**os.environ, "PYTHONPATH": folder, "NUMBA_CACHE_DIR": f"{folder}/numba-cache"}
        command = [sys.executable, __file__, "--measure-per-call", str(count), str(batch_repeats)]
        output = subprocess.run(command, env=env, cwd=folder, capture_output=True, text=True)
        if output.returncode:
            print(f"  (no baseline: the run on {ref} failed)\n{output.stderr}", file=sys.stderr)
            return None
        return json.loads(output.stdout)


def bench_per_call(count: int, batch_repeats: int, ref: str) -> None:
    """The inverse map per call and batched, per load distribution, against commit ``ref``."""
    new = measure_per_call(count, batch_repeats)
    old = baseline_per_call(ref, count, batch_repeats)
    print(f"inverse map per call (motion_and_safety_factor), {count} loads per distribution;")
    print(f"  this version against {ref} in the same run (median | p99 per call; batch of {count})")
    header = f"  {'surface | loads':58s} {'median':>8s} {'p99':>8s} {'batch q/s':>10s}"
    if old is not None:
        header += f" {'was median':>10s} {'p99':>8s} {'batch q/s':>10s} {'x median':>8s} {'safety diff':>11s}"
    print(header)
    for key, row in new.items():
        line = (f"  {key:58s} {row['median'] * 1e6:6.1f}us {row['p99'] * 1e6:6.1f}us "
                f"{row['throughput']:10.0f}")  # fmt: skip
        if old is not None and key in old:
            was = old[key]
            a, b = np.array(row["safety"]), np.array(was["safety"])
            finite = np.isfinite(a) & np.isfinite(b)
            gap = np.max(np.abs(a[finite] - b[finite]) / b[finite]) if finite.any() else 0.0
            line += (f" {was['median'] * 1e6:8.1f}us {was['p99'] * 1e6:6.1f}us "
                     f"{was['throughput']:10.0f} {was['median'] / row['median']:8.1f} {gap:11.1e}")  # fmt: skip
            if was["failed"]:
                line += f"  (was: {was['failed']} ConvergenceError)"
            if np.isnan(was["throughput"]):
                line += "  (was: the batch raised ConvergenceError)"
        if row["failed"]:
            line += f"  ({row['failed']} ConvergenceError)"
        print(line)
    _emit_per_call(new, old, ref)


def _emit_per_call(new: dict, old: dict | None, ref: str) -> None:
    """One performance-table row per surface: medians and p99 over its load distributions."""
    surfaces = dict.fromkeys(key.split(" | ")[0].strip() for key in new)
    for surface in surfaces:
        keys = [key for key in new if key.split(" | ")[0].strip() == surface]
        medians = [new[key]["median"] * 1e6 for key in keys]
        tails = [new[key]["p99"] * 1e6 for key in keys]
        baseline, ratio = "", ""
        if old is not None and all(key in old for key in keys):
            was = [old[key]["median"] * 1e6 for key in keys]
            baseline = f"{ref[:7]}: {min(was):,.1f}–{max(was):,.1f} µs"
            ratios = [w / m for w, m in zip(was, medians, strict=True)]
            ratio = f"{min(ratios):.1f}–{max(ratios):.1f}×"
        emit(
            f"inverse map per call, {surface} ({len(keys)} load distributions)",
            f"median {min(medians):.1f}–{max(medians):.1f} µs, p99 {min(tails):.0f}–"
            f"{max(tails):.0f} µs",
            baseline,
            ratio,
        )


def summed_surfaces() -> dict:
    """Surfaces summed from parts (:meth:`LimitSurface.combine`): a contact set's exact form and
    placed pads."""
    from fixplan import Contact, ContactSetSurface
    from fixplan.surface.geometry import Pose

    pad = pressure.rectangle(0.03, 0.01).rotated(0.3)
    contacts = [
        Contact(name="pin", role="support", position=[-0.03, 0.0, 0.0], normal=[0, 0, 1],
                mu=0.5, model="point-cone"),
        Contact(name="pin 2", role="support", position=[0.01, 0.04, 0.0], normal=[0, 0, 1],
                mu=0.5, model="point-cone"),
        Contact(name="pad", role="support", position=[0.02, 0.01, 0.0], normal=[0, 0, 1],
                mu=0.4, model="exact", patch=pad),
        Contact(name="disk", role="support", position=[0.0, -0.03, 0.0], normal=[0, 0, 1],
                mu=0.3, model="ellipsoid", patch=pressure.disk(0.01)),
    ]  # fmt: skip
    placed = [
        LimitSurface(pad, mu=0.4, normal_force=30.0).placed(Pose(angle=0.3, offset=(0.02, 0.0))),
        LimitSurface(pressure.disk(0.01, "hertz"), mu=0.5, normal_force=20.0).placed(
            Pose(angle=0.0, offset=(-0.03, 0.01), mirrored=True)
        ),
    ]
    return {
        "2 pins, exact pad, ellipsoid pad": ContactSetSurface(
            contacts, [3.0, 2.0, 5.0, 4.0]
        ).as_limit_surface(),
        "rectangle and Hertz disk, placed": LimitSurface.combine(placed),
    }


def bench_summed_surfaces(count: int, batch_repeats: int) -> None:
    """The inverse map per call and batched on summed surfaces, compiled against the NumPy path
    that summed them before (each part's own kernel per Newton step; restored in this run by
    dropping the compiled kernel)."""
    print(f"inverse map per call on summed surfaces, {count} loads per distribution; compiled "
          "against the NumPy path (median | p99 per call; batch)")  # fmt: skip
    for name, surface in summed_surfaces().items():
        rng = np.random.default_rng(2)
        distributions = load_distributions(surface, count, rng, surface.point_supports[0])
        compiled, numpy, gaps = [], [], []
        batch = {}
        for way in ("compiled", "NumPy"):
            if way == "NumPy":
                surface._compiled = None
            for loads in distributions.values():
                times, safety = per_call_times(surface, loads)
                (compiled if way == "compiled" else numpy).append((times, safety))
            every = np.vstack(list(distributions.values()))
            batch[way] = len(every) / median_time(
                lambda s=surface, x=every: s.motion_and_safety_factor(x), batch_repeats
            )
        medians = [np.median(t) * 1e6 for t, _ in compiled]
        tails = [np.percentile(t, 99) * 1e6 for t, _ in compiled]
        ratios = [np.median(t) / np.median(c) for (t, _), (c, _) in zip(numpy, compiled,
                                                                            strict=True)]  # fmt: skip
        was = [np.median(t) * 1e6 for t, _ in numpy]
        for (_, a), (_, b) in zip(compiled, numpy, strict=True):
            finite = np.isfinite(a) & np.isfinite(b)
            gaps.append(np.max(np.abs(a[finite] - b[finite]) / b[finite]))
        print(f"  {name:36s} median {min(medians):.1f}-{max(medians):.1f} us, p99 "
              f"{min(tails):.0f}-{max(tails):.0f} us; NumPy path median {min(was):,.0f}-"
              f"{max(was):,.0f} us: x{min(ratios):.0f}-{max(ratios):.0f}; batch "
              f"{batch['compiled']:,.0f} q/s against {batch['NumPy']:,.0f}; safety factors "
              f"agree to {max(gaps):.1e}")  # fmt: skip
        emit(
            f"inverse map per call, summed: {name} ({len(distributions)} load distributions)",
            f"median {min(medians):.1f}–{max(medians):.1f} µs, p99 {min(tails):.0f}–"
            f"{max(tails):.0f} µs; batch {batch['compiled']:,.0f} queries/s",
            f"NumPy path: median {min(was):,.0f}–{max(was):,.0f} µs; batch "
            f"{batch['NumPy']:,.0f} queries/s",
            f"{min(ratios):.0f}–{max(ratios):.0f}× (safety factors within {max(gaps):.0e})",
        )


def function_fields() -> dict:
    """Surfaces of users' pressure functions (integrated by adapted rules, not closed forms)."""
    return {
        "disk, p = 1 + 40 x": pressure.from_function(pressure.disk(0.01), lambda x, y: 1 + 40 * x),
        "rectangle 4:1, p = exp(-(x/a)²)": pressure.from_function(
            pressure.rectangle(0.04, 0.01), lambda x, y: np.exp(-((x / 0.01) ** 2))
        ),
    }


def bench_function_fields(count: int) -> None:
    """The inverse map per call on function fields, Newton steered by the analytic Hessians
    against central differences of the gradient (the Hessians it had before, six more
    evaluations per step; restored in this run by calling the base class's methods)."""
    from fixplan.surface.function_kernel import FunctionKernel
    from fixplan.surface.kernels import SupportKernel

    print(f"inverse map per call on function fields, {count} loads from twists (x 0.5-1.5)")
    for name, field in function_fields().items():
        surface = LimitSurface(field, mu=0.5, normal_force=10.0)
        rng = np.random.default_rng(2)
        twists = rng.normal(size=(count, 3)) * [1.0, 1.0, 1.0 / surface.characteristic_length]
        loads = surface.load(twists) * rng.uniform(0.5, 1.5, (count, 1))
        analytic, safety = per_call_times(surface, loads)
        with contextlib.ExitStack() as stack:
            for method in ("newton_terms", "hessian"):
                stack.callback(setattr, FunctionKernel, method, getattr(FunctionKernel, method))
                setattr(FunctionKernel, method, getattr(SupportKernel, method))
            differences, reference = per_call_times(surface, loads)
        gap = float(np.max(np.abs(safety - reference) / reference))
        ratio = np.median(differences) / np.median(analytic)
        print(f"  {name:32s} analytic Hessians {figures_us(analytic)}; central differences "
              f"{figures_us(differences)}; x{ratio:.1f}; safety factors agree to {gap:.1e}")  # fmt: skip
        emit(
            f"inverse map per call, function field: {name} ({count} loads)",
            figures_us(analytic),
            f"Hessians by central differences: {figures_us(differences)}",
            f"{ratio:.1f}× (safety factors within {gap:.0e})",
        )


def figures_us(times: np.ndarray) -> str:
    return f"median {np.median(times) * 1e6:,.0f} µs, p99 {np.percentile(times, 99) * 1e6:,.0f} µs"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--quick", action="store_true", help="smaller sizes (for CI)")
    parser.add_argument(
        "--baseline", default=BEFORE_COMPILED_INVERSE, help="git ref of the per-call baseline"
    )
    parser.add_argument("--measure-per-call", nargs=2, type=int, help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.measure_per_call:
        json.dump(measure_per_call(*args.measure_per_call), sys.stdout)
        return
    if args.quick:
        bench_forward(2000, 2000, 3)
        bench_inverse(4096, 500, 3, 3)
        bench_per_call(200, 3, args.baseline)
        bench_summed_surfaces(100, 3)
        bench_function_fields(50)
    else:
        bench_forward(10_000, 10_000, 5)
        bench_inverse(4096, 4000, 20, 5)
        bench_per_call(1000, 5, args.baseline)
        bench_summed_surfaces(300, 3)
        bench_function_fields(300)
    bench_accuracy()


if __name__ == "__main__":
    main()
