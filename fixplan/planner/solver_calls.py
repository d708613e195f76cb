"""Solving a stacked problem through cvxpy: the solvers, their options, statuses and fallbacks.

Clarabel is the default; where it fails a solve is retried once with the fallback solver. Large
problems are compiled without DPP (see ``DPP_MAX_WORK``).
"""

from __future__ import annotations

import warnings

import cvxpy as cp

from fixplan.errors import FixplanError, InvalidArgumentError

#: The solvers a planner can be built with.
SOLVERS = ("CLARABEL", "OSQP", "SCS")

#: Problems whose scalar variables times parameter entries exceed this are compiled without
#: DPP. cvxpy's DPP compilation builds a map from every parameter entry to the problem data, and
#: its cost grows with that product: with DPP the first solve costs more and every re-solve less.
#: On the plate fixture of benchmarks/bench_scaling.py: 200 contacts x 20 cases (15k variables,
#: 127 parameter entries) 0.25 s then 0.13 s against 0.26 s and 0.15 s without; 50 x 100 (19k,
#: 607) 0.56 s then 0.27 s against 0.28 s each; 8 x 500 (16k, 3k) peaks at 1.1-2.0 GB. Large
#: problems are mostly solved once, so there DPP does not pay.
DPP_MAX_WORK = 5_000_000

#: The solver a failed solve is retried with.
FALLBACK = {"CLARABEL": "SCS", "SCS": "CLARABEL", "OSQP": "CLARABEL"}

#: Clarabel's iterative refinement of the KKT solves is off: it takes about half of the solve
#: time (a 200-contact x 200-case fixture: 6.5 s with it, 3.5 s without, the same iterations),
#: and every answer is verified in numpy anyway (a failed verification retries with SCS).
SOLVER_OPTIONS = {
    "CLARABEL": {
        "tol_gap_abs": 1e-9,
        "tol_gap_rel": 1e-9,
        "tol_feas": 1e-9,
        "iterative_refinement_enable": False,
    },
    "SCS": {"eps": 1e-9, "max_iters": 200_000},
    "OSQP": {"eps_abs": 1e-8, "eps_rel": 1e-8, "max_iter": 50_000, "polish": True},
}

#: cvxpy's statuses in the planner's words.
STATUS = {
    cp.OPTIMAL: "optimal",
    cp.OPTIMAL_INACCURATE: "inaccurate",
    cp.INFEASIBLE: "infeasible",
    cp.INFEASIBLE_INACCURATE: "infeasible",
    cp.UNBOUNDED: "unbounded",
    cp.UNBOUNDED_INACCURATE: "unbounded",
}


def uses_dpp(problem: cp.Problem) -> bool:
    """Whether ``problem`` is small enough for DPP to pay (see ``DPP_MAX_WORK``)."""
    entries = sum(parameter.size for parameter in problem.parameters())
    return problem.size_metrics.num_scalar_variables * max(entries, 1) <= DPP_MAX_WORK


def call(problem: cp.Problem, solver: str, *, accurate: bool = False) -> str:
    large = not uses_dpp(problem)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            options = dict(SOLVER_OPTIONS[solver])
            if accurate and solver == "CLARABEL":
                options["iterative_refinement_enable"] = True
            problem.solve(solver=solver, ignore_dpp=large, **options)
    except cp.error.SolverError as exc:
        if solver == "OSQP" and "QP" in str(exc):
            raise InvalidArgumentError(
                "solver OSQP handles only LP/QP problems: use pyramid models "
                "('pyramid', 'point-pyramid') or the default solver CLARABEL"
            ) from exc
        return "solver-error"
    except cp.error.DCPError as exc:  # pragma: no cover - a model broke its contract
        raise FixplanError(f"internal error: {exc}") from exc
    return STATUS.get(problem.status, "solver-error")
