"""Semidefinite fits: a cvxpy problem with PSD cones solved with Clarabel, once more with SCS.

Shared by the ellipsoid fit of the models and the limit-surface fits of measurements; a result
that is not optimal (``optimal_inaccurate`` included) is a failure, never silently a success.
"""

from __future__ import annotations

from fixplan.errors import ConvergenceError


def solve_sdp(problem, *, what: str, advice: str) -> str:
    """Solve ``problem`` (a ``cvxpy.Problem``) to optimality; the name of the solver that did.

    Raises
    ------
    ConvergenceError
        Neither Clarabel nor SCS solved it; the message names ``what`` and gives ``advice``.
    """
    import cvxpy as cp

    for solver in (cp.CLARABEL, cp.SCS):
        try:
            problem.solve(solver=solver)
        except cp.error.SolverError:
            continue
        if problem.status == cp.OPTIMAL:
            return solver
    raise ConvergenceError(
        f"{what} did not solve to optimality (status {problem.status!r} with Clarabel and SCS); "
        f"{advice}"
    )
