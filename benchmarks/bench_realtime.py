"""Grip forces at controller rate: re-solves of an 8-contact grasp with smoothly changing loads.

Run: ``python benchmarks/bench_realtime.py [--count N]``. The fixture of
``bench_planner.py`` (8 area contacts: three support pads, three locators, two clamps) with one
load case, objective ``min-total-clamp-force``, is solved ``N`` times (default 10,000) while its
load turns slowly (a cutting force of 80 N rotating in the plane and a torque varying with it,
as a controller would see it). For each friction model it prints the median and 99th percentile
of

- ``Planner.solve(load, analyse=False)``: the forces, verified in numpy;
- ``Planner.solve(load)``: the same plus the safety analysis (held interval, safety factor and
  impending motion of the forces found), on the first tenth of the path, each step's analysed
  re-solve next to a bare one of the same step (in alternating order), so that both see the
  machine in the same state; and the analysed re-solves of those steps back to back, as the
  bare ones were timed. The two ratios differ: back to back, each kind of re-solve finds its
  own data in the processor's caches, which helps the shorter bare one more (paired, both
  run about a quarter slower, the bare one by more);
- the baseline: cvxpy + Clarabel re-solving the planner's compiled problem (parameters set,
  ``problem.solve``), with nothing else, in the same run.

The exact model (osculating ellipsoids, :mod:`fixplan.planner.osculating`) is timed on the first
twentieth of the path, against the ellipsoid's figures of the same run, with the mean number
of rounds per solve.

The pyramid grasp's linear program (``min q·x``, ``A x = b`` on the equilibrium rows and
``A x <= b`` on the rest; only ``b`` changes with the loads) is then handed, as the planner
states it at every step of the path, to three solvers in the same run, each warm from its last
solve: fixplan's dual simplex (:mod:`fixplan.planner.dual_simplex`), HiGHS through ``highspy``
(the model passed once, the row bounds changed, its simplex hot-started from the kept basis)
and Clarabel (``b`` updated in place; an interior point has no warm start). Their optima must
agree to 1e-6 (relative to the optimum, at least 1). So is the ellipsoid grasp's cone program
(``A x = b`` on the equilibrium rows, second-order cones on the rest; again only ``b``
changes), handed to fixplan's compiled interior-point method
(:mod:`fixplan.planner.cone_interior_point`, which starts from its last optimum) and to
Clarabel.

The machine's load average is printed with the figures (other processes slow these
single-threaded runs).
"""

from __future__ import annotations

import argparse
import os
import time

import clarabel
import cvxpy as cp
import highspy
import numpy as np
import scipy.sparse as sp
from bench_planner import fixture
from performance_rows import emit

from fixplan.planner.dual_simplex import DualSimplex
from fixplan.planner.planner import Planner
from fixplan.planner.problem import Load
from fixplan.planner.solver_calls import SOLVER_OPTIONS

MODELS = ("ellipsoid", "point-cone", "pyramid")


def loads(count: int) -> list[list[Load]]:
    """``count`` single-case load lists along a smooth path."""
    angles = np.linspace(0.0, 4.0 * np.pi, count)
    return [
        [
            Load(
                name="cut",
                force=[80.0 * np.cos(a), 80.0 * np.sin(a), -30.0],
                point=[0.02 * np.cos(a / 2), 0.01, 0.04],
                torque=[0.0, 0.0, 0.8 * np.sin(a)],
            )
        ]
        for a in angles
    ]


def timings(call, arguments) -> np.ndarray:
    out = np.empty(len(arguments))
    for k, argument in enumerate(arguments):
        start = time.perf_counter()
        call(argument)
        out[k] = time.perf_counter() - start
    return out


def paired_timings(planner, path) -> tuple[np.ndarray, np.ndarray]:
    """Times of a bare and of an analysed re-solve at each step of ``path``, in alternating
    order."""
    bare, analysed = np.empty(len(path)), np.empty(len(path))
    for k, load in enumerate(path):
        for analyse in (False, True) if k % 2 else (True, False):
            start = time.perf_counter()
            planner.solve(load, analyse=analyse)
            (analysed if analyse else bare)[k] = time.perf_counter() - start
    return bare, analysed


def figures(times: np.ndarray) -> str:
    return f"median {np.median(times) * 1e3:6.3f} ms, p99 {np.percentile(times, 99) * 1e3:6.3f} ms"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--count", type=int, default=10_000)
    count = parser.parse_args().count
    path = loads(count)
    print(f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores; {count} re-solves")
    medians = {}
    for model in MODELS:
        problem = fixture(model, "min-total-clamp-force", path[0])
        planner = Planner(problem)
        for warm in path[:3]:  # compile, then build the direct solvers
            planner.solve(warm)
        bare = timings(lambda x, planner=planner: planner.solve(x, analyse=False), path)
        tenth = path[: max(count // 10, 10)]
        paired, analysed = paired_timings(planner, tenth)
        alone = timings(planner.solve, tenth)  # (back to back, as bare was)
        stacked = planner._runner.stacked(problem.objective)

        def baseline(x, stacked=stacked):
            stacked.task.value = np.column_stack([load.wrench for load in x])
            stacked.problem.solve(solver=cp.CLARABEL)

        raw = timings(baseline, tenth)
        plan = planner.solve(path[-1])
        print(f"{model:10s} solve {figures(bare)}; with analysis {figures(analysed)}")
        ratio = np.median(analysed) / np.median(paired)
        in_a_row = np.median(alone) / np.median(bare[: len(tenth)])
        print(
            f"{'':10s} cvxpy + Clarabel {figures(raw)}; solve / baseline "
            f"{np.median(bare) / np.median(raw):.2f}, with analysis / solve {ratio:.2f} "
            f"(bare solves of the same steps: median {np.median(paired) * 1e3:.3f} ms; solver "
            f"{plan.solver}, {plan.status}); each back to back: {in_a_row:.2f} "
            f"(analysed median {np.median(alone) * 1e3:.3f} ms)"
        )
        medians[model] = (np.median(bare), np.median(analysed))
        emit(
            f"grasp re-solve, 8 contacts × 1 case, {model}, {count:,} smoothly changing loads "
            "(median, p99): bare; with the safety analysis",
            f"{figures(bare)}; {figures(analysed)}",
            f"cvxpy + Clarabel re-solve {figures(raw)}",
            f"{np.median(bare) / np.median(raw):.2f}×; analysis / bare {ratio:.2f}× paired, "
            f"{in_a_row:.2f}× back to back",
        )

    exact_row(path[: max(count // 20, 10)], medians["ellipsoid"])
    linear_program_row(path)
    cone_program_row(path)


def linear_program_row(path: list) -> None:
    """The pyramid grasp's linear program at every step of ``path``, solved by the dual
    simplex, HiGHS and Clarabel, each warm from its last solve (see the module)."""
    direct, q, matrix, steps = _program_steps("pyramid", path)
    equalities = direct._simplex._equalities
    solvers = {
        "dual simplex": _simplex_steps(matrix, q, equalities),
        "HiGHS (hot start)": _highs_steps(matrix, q, equalities),
        "Clarabel": _clarabel_steps(matrix, q, equalities),
    }
    _compare_solvers("pyramid", "linear program", q, matrix, steps, solvers)


def cone_program_row(path: list) -> None:
    """The ellipsoid grasp's cone program at every step of ``path``, solved by the compiled
    interior-point method and by Clarabel (``b`` updated in place; see the module)."""
    direct, q, matrix, steps = _program_steps("ellipsoid", path)
    interior = direct._interior
    cones = (interior._zero, interior._nonneg, interior._dimensions)
    solvers = {
        "interior point": lambda b: interior.solve(q, matrix, b)[0],
        "Clarabel": _clarabel_steps(matrix, q, *cones),
    }
    _compare_solvers("ellipsoid", "cone program", q, matrix, steps, solvers)


def _program_steps(model: str, path: list) -> tuple:
    """The direct solver of ``model``'s grasp, its cost, constraint matrix (dense) and the
    ``b`` of every step of ``path``, as the planner states them (only ``b`` changes)."""
    problem = fixture(model, "min-total-clamp-force", path[0])
    planner = Planner(problem)
    for warm in path[:3]:
        planner.solve(warm, analyse=False)
    direct = planner._runner._direct[(problem.objective, False)]
    program = direct._program
    steps = []
    for load in path:
        planner.solve(load, analyse=False)  # sets the parameters as the planner states them
        vector = program.parameter_vector()
        q, _ = program.cost(vector)
        a, b = program.constraints(vector)
        steps.append(b)
    return direct, q, program.dense(a), steps


def _compare_solvers(grasp: str, kind: str, q, matrix, steps, solvers: dict) -> None:
    """Time each of ``solvers`` (``b -> x``, the first fixplan's) on every ``b`` of ``steps``
    of the ``grasp``'s program, after a cold first solve; their optima must agree to 1e-6
    (relative, at least 1)."""
    times, optima = {}, {}
    for name, step in solvers.items():
        step(steps[0])  # first solve: cold
        times[name] = np.empty(len(steps))
        optima[name] = np.empty(len(steps))
        for k, b in enumerate(steps):
            start = time.perf_counter()
            x = step(b)
            times[name][k] = time.perf_counter() - start
            optima[name][k] = q @ x
    ours, *others = solvers
    scale = np.maximum(np.abs(optima["Clarabel"]), 1.0)
    disagreement = {
        name: float(np.max(np.abs(optima[name] - optima[ours]) / scale)) for name in others
    }
    assert max(disagreement.values()) <= 1e-6, disagreement
    differences = ", ".join(f"{name} {value:.1e}" for name, value in disagreement.items())
    print(f"{kind} of the {grasp} grasp ({matrix.shape[0]} rows, {matrix.shape[1]} variables), {len(steps):,} "
          f"right-hand sides; largest relative difference of the optima from the {ours}'s: "
          f"{differences}")  # fmt: skip
    median = np.median(times[ours])
    for name, measured in times.items():
        print(f"  {name:18s} {figures(measured)}; / {ours} {np.median(measured) / median:5.1f}")
    emit(
        f"the {grasp} grasp's {kind} alone ({matrix.shape[0]} rows × "
        f"{matrix.shape[1]} variables), {len(steps):,} right-hand sides (median, p99): "
        f"fixplan's {ours}",
        figures(times[ours]),
        "; ".join(f"{name} {figures(times[name])}" for name in others),
        "; ".join(f"{np.median(times[name]) / median:.1f}× slower" for name in others),
    )


def _simplex_steps(matrix, q, equalities):
    simplex = DualSimplex(equalities)
    return lambda b: simplex.solve(matrix, q, b)[0]


def _highs_steps(matrix, q, equalities):
    """HiGHS with the program passed once; each step changes the row bounds to ``b``."""
    inf = highspy.kHighsInf
    rows, columns = matrix.shape
    sparse = sp.csc_array(matrix)
    lp = highspy.HighsLp()
    lp.num_col_, lp.num_row_ = columns, rows
    lp.col_cost_ = q
    lp.col_lower_, lp.col_upper_ = np.full(columns, -inf), np.full(columns, inf)
    lp.row_lower_, lp.row_upper_ = np.zeros(rows), np.zeros(rows)
    lp.a_matrix_.format_ = highspy.MatrixFormat.kColwise
    lp.a_matrix_.start_ = sparse.indptr.astype(np.int32)
    lp.a_matrix_.index_ = sparse.indices.astype(np.int32)
    lp.a_matrix_.value_ = sparse.data
    highs = highspy.Highs()
    highs.setOptionValue("output_flag", False)
    highs.passModel(lp)
    index = np.arange(rows, dtype=np.int32)
    lower = np.full(rows, -inf)

    def step(b):
        lower[:equalities] = b[:equalities]
        highs.changeRowsBounds(rows, index, lower, b)
        highs.run()
        return np.asarray(highs.getSolution().col_value)

    return step


def _clarabel_steps(matrix, q, equalities, nonneg=None, dimensions=()):
    """Clarabel with the planner's settings; each step updates ``b`` in place. The rows after
    the ``equalities`` are ``nonneg`` nonnegative ones (default: all) and then second-order
    cones of ``dimensions``."""
    options = clarabel.DefaultSettings()
    options.verbose, options.presolve_enable = False, False
    for key, value in SOLVER_OPTIONS["CLARABEL"].items():
        setattr(options, key, value)
    rows, columns = matrix.shape
    nonneg = rows - equalities if nonneg is None else nonneg
    cones = [clarabel.ZeroConeT(equalities), clarabel.NonnegativeConeT(nonneg)]
    cones += [clarabel.SecondOrderConeT(int(d)) for d in dimensions]
    zero = sp.csc_matrix((columns, columns))
    solver = clarabel.DefaultSolver(zero, q, sp.csc_matrix(matrix), np.zeros(rows), cones, options)

    def step(b):
        solver.update(b=b)
        return np.asarray(solver.solve().x)

    return step


def exact_row(path: list, ellipsoid: tuple[float, float]) -> None:
    """The exact model on the same grasp, against the ellipsoid's medians (bare, analysed)."""
    from fixplan.planner import osculating

    rounds = []
    move = osculating.OsculatingPool.move
    osculating.OsculatingPool.move = lambda pool: rounds.append(1) or move(pool)
    planner = Planner(fixture("exact", "min-total-clamp-force", path[0]))
    for warm in path[:3]:
        planner.solve(warm)
    rounds.clear()
    bare = timings(lambda x: planner.solve(x, analyse=False), path)
    per_bare = len(rounds) / len(path)
    rounds.clear()
    analysed = timings(planner.solve, path)
    per_analysed = len(rounds) / len(path)
    osculating.OsculatingPool.move = move
    ratios = np.median(bare) / ellipsoid[0], np.median(analysed) / ellipsoid[1]
    print(f"{'exact':10s} solve {figures(bare)} ({per_bare:.1f} rounds); with analysis "
          f"{figures(analysed)} ({per_analysed:.1f} rounds); / ellipsoid {ratios[0]:.1f}, "
          f"{ratios[1]:.1f}")  # fmt: skip
    emit(
        f"grasp re-solve, 8 contacts × 1 case, exact, {len(path):,} smoothly changing loads "
        "(median, p99): bare; with the safety analysis (rounds of osculating ellipsoids)",
        f"{figures(bare)} ({per_bare:.1f}); {figures(analysed)} ({per_analysed:.1f})",
        f"ellipsoid of the same run: median {ellipsoid[0] * 1e3:.3f} ms; {ellipsoid[1] * 1e3:.3f} ms",
        f"{ratios[0]:.0f}×; {ratios[1]:.0f}×",
    )


if __name__ == "__main__":
    main()
