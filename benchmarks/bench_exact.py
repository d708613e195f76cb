"""The exact friction model in the planner against the ellipsoid, on the same problems.

Run: ``python benchmarks/bench_exact.py`` (``--cells 200`` is the default grid side). Two
problems, each model timed in a fresh process (peak resident memory of that process):

- a pinch: two fingers with ``cells × cells`` tactile grids (a Hertz-like pressure map over
  20 x 20 mm), holding a weight and a torque about the grasp axis, 4 load cases; build + first
  solve and the median of ``RESOLVES`` re-solves with new loads;
- the fixture of ``bench_planner.py`` (8 area contacts x 20 milling loads), the same figures
  and the number of rounds of the exact model (osculating ellipsoids, or cuts where those do
  not settle), with the time per round of a re-solve spent in Clarabel and in moving the
  ellipsoids or cutting (mostly the exact inverse map's queries).

Before them, the exact surface of one of the pinch's grids alone: the median of an evaluation
with its Hessian and of an inverse-map query, for centres of rotation on the patch (the corner
sums) and far from it (the far rule of blocks of cells), the far evaluation against a Gauss
rule of 3 x 3 points per cell (the rule it replaced) in the same run.

The machine is shared and noisy: compare the ratios of the same run.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import resource
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

from fixplan import Body, Contact, LimitSurface, Load, Problem, pressure
from fixplan.planner.planner import Planner
from fixplan.surface.point_kernel import PointSetKernel

sys.path.insert(0, str(Path(__file__).parent))
from bench_planner import fixture, milling_loads
from performance_rows import emit

#: Re-solves with new loads per problem and model (their median is reported).
RESOLVES = 20

#: Re-solves with new loads per way of stating point supports (:func:`point_support_figures`).
POINT_RESOLVES = 8


#: Evaluations and queries timed per kind of centre of rotation on the grid alone.
GRID_SAMPLES = 30


def tactile_patch(cells: int) -> pressure.GridField:
    """The pinch's Hertz-like map on ``cells x cells`` cells over 20 x 20 mm."""
    side = np.linspace(-0.01, 0.01, cells)
    x, y = np.meshgrid(side, side)
    values = np.sqrt(np.clip(1.0 - (x * x + y * y) / 0.009**2, 0.0, None))
    return pressure.grid(side, side, values)


def tactile_pinch(model: str, cells: int, loads: list[Load]) -> Problem:
    patch = tactile_patch(cells)
    contacts = [
        Contact(name=name, role="finger", position=[0, s * 0.03, 0], normal=[0, -s, 0], mu=0.5,
                model=model, patch=patch)
        for name, s in (("left", -1), ("right", 1))
    ]  # fmt: skip
    return Problem(body=Body(mass=0.0, center_of_mass=[0, 0, 0]), contacts=contacts,
                   loads=loads, objective="min-max-normal-force")  # fmt: skip


def pinch_loads(seed: int) -> list[Load]:
    rng = np.random.default_rng(seed)
    return [
        Load(name=f"hold-{k}", force=[rng.normal(), 0, -rng.uniform(5, 20)],
             point=[rng.normal(0, 0.01), 0, 0], torque=[0, rng.uniform(-0.2, 0.2), 0])
        for k in range(4)
    ]  # fmt: skip


def measure(case: str, model: str, cells: int) -> dict:
    """Figures of one model on one problem (run in a fresh process)."""
    if case == "pinch":
        problem, new_loads = tactile_pinch(model, cells, pinch_loads(0)), pinch_loads
    else:
        problem = fixture(model, "min-total-clamp-force", milling_loads(20, 0))
        new_loads = lambda seed: milling_loads(20, seed)  # noqa: E731
    rounds, spent = [], {"cuts": 0.0, "solver": 0.0}
    if model == "exact":
        from fixplan.planner import cuts, direct_solve, osculating

        def timed(owner, name, key):
            method = getattr(owner, name)

            def wrapper(self, *args, **kwargs):
                start = time.perf_counter()
                try:
                    return method(self, *args, **kwargs)
                finally:
                    spent[key] += time.perf_counter() - start

            setattr(owner, name, wrapper)

        timed(cuts.CutPool, "add_cuts", "cuts")
        timed(osculating.OsculatingPool, "move", "cuts")
        timed(direct_solve.DirectSolver, "solve", "solver")
        add_cuts, move = cuts.CutPool.add_cuts, osculating.OsculatingPool.move
        cuts.CutPool.add_cuts = lambda pool: rounds.append(1) or add_cuts(pool)
        osculating.OsculatingPool.move = lambda pool: rounds.append(1) or move(pool)
    start = time.perf_counter()
    planner = Planner(problem)
    plan = planner.solve(analyse=False)
    first = time.perf_counter() - start
    assert plan.status == "optimal", plan.status
    first_rounds, times = len(rounds), []
    spent.update(cuts=0.0, solver=0.0)
    for seed in range(1, RESOLVES + 1):
        loads = new_loads(seed)
        start = time.perf_counter()
        again = planner.solve(loads, analyse=False)
        times.append(time.perf_counter() - start)
        assert again.status == "optimal", again.status
    return {
        "first": first,
        "resolve": float(np.median(times)),
        "peak_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024,
        "rounds": (first_rounds, (len(rounds) - first_rounds) / RESOLVES),
        "per_round": {
            key: value / max(len(rounds) - first_rounds, 1) for key, value in spent.items()
        },
        "objective": plan.objective_value,
    }


def median_ms(call, arguments) -> float:
    """Median time [ms] of ``call`` on each of ``arguments``, after one call to warm up."""
    call(arguments[0])
    times = []
    for argument in arguments:
        start = time.perf_counter()
        call(argument)
        times.append(time.perf_counter() - start)
    return float(np.median(times)) * 1e3


def grid_figures(cells: int) -> None:
    """Evaluations and queries of one pinch grid's exact surface (see the module)."""
    field = tactile_patch(cells)
    surface = LimitSurface(field, mu=0.5, normal_force=10.0)
    kernel = surface._kernel
    cell_rule = PointSetKernel(*field._local_quadrature(3))
    rng = np.random.default_rng(0)
    print(f"exact surface of one {cells} x {cells} grid ({kernel.table.shape[1]:,} loaded corners)")
    for where, spin in (("on the patch", 300.0), ("far from it", 1.0)):
        twists = rng.normal(size=(GRID_SAMPLES, 1, 3)) * [1.0, 1.0, spin]
        loads = surface.load(twists[:, 0]) * rng.uniform(0.5, 1.5, (GRID_SAMPLES, 1))
        evaluation = median_ms(kernel.newton_terms, twists)
        query = median_ms(surface.motion_and_safety_factor, loads)
        line = f"  centres of rotation {where}: evaluation with Hessian {evaluation:.3f} ms"
        baseline, ratio = "", ""
        if spin == 1.0:
            gauss = median_ms(cell_rule.newton_terms, twists)
            line += (f" ({len(kernel.far.weights):,} points) against {gauss:.3f} ms for 3 x 3 "
                     f"Gauss points per cell ({len(cell_rule.weights):,})")  # fmt: skip
            baseline = f"3 × 3 Gauss points per cell: evaluation {gauss:.3f} ms"
            ratio = f"{gauss / evaluation:.1f}×"
        print(f"{line}; inverse-map query {query:.3f} ms")
        emit(
            f"exact surface of a {cells} × {cells} tactile grid, centres of rotation {where} "
            "(median): evaluation with Hessian; inverse-map query",
            f"{evaluation:.3f} ms; {query:.3f} ms",
            baseline,
            ratio,
        )


def point_support_figures() -> None:
    """The fixture with every patch point supports (3, 9, 64 and 256 per pad): re-solves with the
    exact model stating them exactly (a cone per point, whatever ``MAX_STATED_POINTS`` says)
    against the cutting planes on the same supports (``MAX_STATED_POINTS`` set to 0), in the
    same process, and how far apart their optima are: where the first is faster is where the
    model states them by default."""
    from fixplan.models import exact

    print("fixture, 8 contacts x 20 milling loads, every patch point supports (exact model)")
    stated = exact.MAX_STATED_POINTS
    for side in (None, 3, 8, 16):
        if side is None:
            patch = pressure.points([[0.006, 0.0], [-0.003, 0.005], [-0.003, -0.005]])
        else:
            grid = [[x, y] for x in np.linspace(-0.01, 0.01, side)
                    for y in np.linspace(-0.005, 0.005, side)]  # fmt: skip
            patch = pressure.points(grid)
        count = len(patch.xy)
        base = fixture("exact", "min-total-clamp-force", milling_loads(20, 1))
        contacts = tuple(dataclasses.replace(c, patch=patch) for c in base.contacts)
        problem = dataclasses.replace(base, contacts=contacts)
        times, values = {}, {}
        for way, most in (("stated", count), ("cuts", 0)):
            exact.MAX_STATED_POINTS = most
            planner = Planner(problem)
            planner.solve()
            found, spent = [], []
            for seed in range(2, 2 + POINT_RESOLVES):
                start = time.perf_counter()
                found.append(planner.solve(milling_loads(20, seed)).objective_value)
                spent.append(time.perf_counter() - start)
            times[way], values[way] = float(np.median(spent)) * 1e3, np.array(found)
        exact.MAX_STATED_POINTS = stated
        gap = float(np.max(np.abs(values["stated"] / values["cuts"] - 1.0)))
        ratio = times["cuts"] / times["stated"]
        default = "stated" if count <= stated else "cutting planes"
        print(f"  {count:3d} points per pad: re-solve {times['stated']:.1f} ms stated exactly, "
              f"{times['cuts']:.1f} ms by cutting planes: x{ratio:.1f}; optima within {gap:.1e} "
              f"(by default: {default})")  # fmt: skip
        emit(
            f"exact model on point supports, fixture (8 contacts × 20 milling loads), {count} "
            "points per pad: re-solve stated exactly (a cone per point)",
            f"{times['stated']:,.1f} ms",
            f"cutting planes {times['cuts']:,.1f} ms (optima within {gap:.0e})",
            f"{ratio:.1f}× faster" if ratio >= 1.0 else f"{1.0 / ratio:.1f}× slower",
        )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--cells", type=int, default=200, help="grid side of the pinch")
    parser.add_argument("--child", nargs=2, help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.child:
        print(json.dumps(measure(*args.child, args.cells)))
        return
    grid_figures(args.cells)
    for case, title in (
        ("pinch", f"pinch, 2 tactile grids of {args.cells} x {args.cells} cells, 4 load cases"),
        ("fixture", "fixture, 8 area contacts x 20 milling loads (bench_planner.py)"),
    ):
        figures = {}
        for model in ("ellipsoid", "exact"):
            command = [sys.executable, __file__, "--cells", str(args.cells), "--child", case, model]
            output = subprocess.run(command, check=True, capture_output=True, text=True).stdout
            figures[model] = json.loads(output)
        print(title)
        for model, f in figures.items():
            cutting = ""
            if model == "exact":
                cutting = (
                    f", rounds {f['rounds'][0]} then {f['rounds'][1]:.1f} per re-solve "
                    f"(per round: Clarabel {f['per_round']['solver'] * 1e3:.1f} ms, ellipsoids or "
                    f"cuts with their inverse-map queries {f['per_round']['cuts'] * 1e3:.1f} ms)"
                )
            print(
                f"  {model:9s}: build + first solve {f['first']:7.3f} s, median re-solve "
                f"{f['resolve'] * 1e3:8.1f} ms, peak memory {f['peak_mb']:6.0f} MB, objective "
                f"{f['objective']:.6f} N{cutting}"
            )
        e, x = figures["ellipsoid"], figures["exact"]
        print(
            f"  exact / ellipsoid: build + first solve x{x['first'] / e['first']:.1f}, re-solve "
            f"x{x['resolve'] / e['resolve']:.1f}, memory x{x['peak_mb'] / e['peak_mb']:.2f}"
        )
        emit(
            f"exact model, {title}: build + first solve; re-solve ({x['rounds'][1]:.1f} rounds); "
            "peak memory",
            f"{x['first']:.2f} s; {x['resolve'] * 1e3:,.0f} ms; {x['peak_mb']:,.0f} MB",
            f"ellipsoid {e['first']:.2f} s; {e['resolve'] * 1e3:,.1f} ms; {e['peak_mb']:,.0f} MB",
            f"{x['first'] / e['first']:.1f}×; {x['resolve'] / e['resolve']:,.0f}×; "
            f"{x['peak_mb'] / e['peak_mb']:.2f}×",
        )
    # (Last: a child's peak memory starts from this process's at the fork, and these problems
    # take 230 MB more.)
    point_support_figures()


if __name__ == "__main__":
    main()
