"""Re-solving a compiled DPP problem straight through Clarabel, for control loops.

cvxpy re-solves a DPP problem without recompiling it, but still spends a few milliseconds per
solve mapping parameters, building the solver and unpacking the answer. When the parameters only
move the constraint offsets ``b`` (the planner's load wrenches and fixed forces do, for the force
objectives), the conic data ``A`` and ``c`` are fixed: this module probes the affine map from
parameter values to ``b`` once, keeps one Clarabel solver whose ``b`` is updated in place, and
reads the variables from the solution vector. It checks itself against cvxpy's answer when it is
built and refuses (returns ``None``) where its assumptions do not hold.
"""

from __future__ import annotations

import cvxpy as cp
import numpy as np
import scipy.sparse as sp

#: Largest relative difference from cvxpy's own answer accepted when the direct path is built.
AGREEMENT_RTOL = 1e-6


class DirectSolver:
    """Clarabel on the fixed conic data of ``problem``, with ``b`` an affine map of parameters.

    Build with :meth:`create` after ``problem`` was solved once by cvxpy with Clarabel.
    """

    def __init__(self, problem, solver, offset, jacobian, offsets, constant):
        self._problem = problem
        self._solver = solver
        self._offset = offset
        self._jacobian = jacobian
        self._offsets = offsets
        self._constant = constant
        self.objective_value = float("nan")

    @classmethod
    def create(cls, problem: cp.Problem, settings: dict) -> DirectSolver | None:
        """A direct solver for ``problem``, or ``None`` when its parameters move ``A`` or ``c``."""
        import clarabel

        data, _, inverse = problem.get_problem_data(cp.CLARABEL, solver_opts={})
        program = data[cp.settings.PARAM_PROB]
        parameters = problem.parameters()
        saved = [p.value for p in parameters]
        try:
            for p in parameters:
                p.value = np.zeros(p.shape)
            c0, d0, a0, b0 = program.apply_parameters()
            columns = []
            for p in parameters:
                for index in range(p.size):
                    unit = np.zeros(p.size)
                    unit[index] = 1.0
                    p.value = unit.reshape(p.shape, order="F")
                    c, _, a, b = program.apply_parameters()
                    if not np.array_equal(c, c0) or (a != a0).nnz:
                        return None
                    columns.append(b - b0)
                    p.value = np.zeros(p.shape)
        finally:
            for p, value in zip(parameters, saved, strict=True):
                p.value = value
        jacobian = sp.csc_array(np.column_stack(columns)) if columns else None
        dims = data["dims"]
        cones = [clarabel.ZeroConeT(dims.zero), clarabel.NonnegativeConeT(dims.nonneg)]
        cones += [clarabel.SecondOrderConeT(k) for k in dims.soc]
        if dims.exp or dims.psd or dims.p3d:
            return None
        options = clarabel.DefaultSettings()
        options.verbose = False
        for key, value in settings.items():
            setattr(options, key, value)
        size = a0.shape[1]
        solver = clarabel.DefaultSolver(
            sp.csc_matrix((size, size)), np.asarray(c0), sp.csc_matrix(-a0), np.asarray(b0), cones,
            options,
        )  # fmt: skip
        offsets = inverse[0].var_offsets
        direct = cls(problem, solver, np.asarray(b0), jacobian, offsets, float(d0))
        if not direct._agrees_with_cvxpy():
            return None
        return direct

    def _parameter_vector(self) -> np.ndarray:
        return np.concatenate(
            [
                np.ravel(np.asarray(p.value, dtype=float), order="F")
                for p in self._problem.parameters()
            ]
        )

    def solve(self) -> dict | None:
        """Variable values by id after a solve with the parameters' current values.

        ``None`` when Clarabel does not report the problem solved (use cvxpy then: it turns
        infeasibility into certificates).
        """
        b = self._offset
        if self._jacobian is not None:
            b = b + self._jacobian @ self._parameter_vector()
        self._solver.update(b=b)
        solution = self._solver.solve()
        if str(solution.status) != "Solved":
            return None
        self.objective_value = float(solution.obj_val) + self._constant
        x = np.asarray(solution.x)
        values = {}
        for variable in self._problem.variables():
            start = self._offsets[variable.id]
            chunk = x[start : start + variable.size]
            values[variable.id] = chunk.reshape(variable.shape, order="F")
        return values

    def _agrees_with_cvxpy(self) -> bool:
        """Same optimal value as cvxpy, and the variables feasible for cvxpy's constraints.

        (Optimal points need not be unique, so the values themselves are not compared.)
        """
        expected = self._problem.value
        saved = {v.id: v.value for v in self._problem.variables()}
        values = self.solve()
        if values is None:
            return False
        try:
            for variable in self._problem.variables():
                variable.save_value(values[variable.id])
            feasible = all(
                np.all(np.asarray(c.violation()) <= AGREEMENT_RTOL * max(1.0, abs(expected)))
                for c in self._problem.constraints
            )
        finally:
            for variable in self._problem.variables():
                variable.save_value(saved[variable.id])
        scale = max(1.0, abs(expected))
        return feasible and abs(self.objective_value - expected) <= AGREEMENT_RTOL * scale
