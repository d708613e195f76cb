"""Re-solving a compiled DPP problem straight through Clarabel, for control loops.

cvxpy re-solves a DPP problem without recompiling it, but still spends a few milliseconds per
solve mapping parameters, building the solver and unpacking the answer. When the parameters only
move the constraint offsets ``b`` and the linear cost ``q`` (the planner's load wrenches and
fixed forces do, for the force objectives; so do the references, loads and friction bounds of
the contact-spring steps of :mod:`fixplan.motion.contact_springs`), the conic data ``A`` and
``P`` are fixed: this module probes the affine maps from parameter values to ``b`` and ``q``
once, keeps one Clarabel solver whose ``b`` and ``q`` are updated in place, and reads the
variables (and the multipliers of equality constraints) from the solution vectors. It checks
itself against cvxpy's answer when it is built and refuses (returns ``None``) where its
assumptions do not hold.
"""

from __future__ import annotations

import cvxpy as cp
import numpy as np
import scipy.sparse as sp

#: Largest relative difference from cvxpy's own answer accepted when the direct path is built.
AGREEMENT_RTOL = 1e-6

#: Clarabel's statuses of a problem without a feasible point.
INFEASIBLE = ("PrimalInfeasible", "AlmostPrimalInfeasible")


class DirectSolver:
    """Clarabel on the fixed conic data of ``problem``, with ``b`` and ``q`` affine maps of
    parameters.

    Build with :meth:`create` after ``problem`` was solved once by cvxpy with Clarabel.
    """

    def __init__(self, problem, solver, offsets, constant, data_maps):
        self._problem = problem
        self._columns = _parameter_columns(problem.parameters())
        self._solver = solver
        self._offsets = offsets
        self._constant = constant
        self._q0, self._q_jacobian, self._b0, self._b_jacobian = data_maps
        self.objective_value = float("nan")
        #: Clarabel's status of the last solve.
        self.status = ""
        self._dual = np.zeros(0)
        self._dual_rows: dict = {}

    @classmethod
    def create(cls, problem: cp.Problem, settings: dict) -> DirectSolver | None:
        """A direct solver for ``problem``, or ``None`` when its parameters move ``A`` or
        ``P``."""
        import clarabel

        data, _, inverse = problem.get_problem_data(cp.CLARABEL, solver_opts={})
        program = data[cp.settings.PARAM_PROB]
        quadratic = program.P is not None
        parameters = problem.parameters()
        saved = [p.value for p in parameters]

        def conic_data():
            if quadratic:
                return program.apply_parameters(quad_obj=True)
            return (None, *program.apply_parameters())

        try:
            for p in parameters:
                p.value = np.zeros(p.shape)
            p0, q0, d0, a0, b0 = conic_data()
            q_columns, b_columns = [], []
            for p in parameters:
                for index in range(p.size):
                    unit = np.zeros(p.size)
                    unit[index] = 1.0
                    p.value = unit.reshape(p.shape, order="F")
                    pp, q, _, a, b = conic_data()
                    if (a != a0).nnz or (quadratic and (pp != p0).nnz):
                        return None
                    q_columns.append(q - q0)
                    b_columns.append(b - b0)
                    p.value = np.zeros(p.shape)
        finally:
            for p, value in zip(parameters, saved, strict=True):
                p.value = value
        dims = data["dims"]
        cones = [clarabel.ZeroConeT(dims.zero), clarabel.NonnegativeConeT(dims.nonneg)]
        cones += [clarabel.SecondOrderConeT(k) for k in dims.soc]
        if dims.exp or dims.psd or dims.p3d:
            return None
        options = clarabel.DefaultSettings()
        options.verbose = False
        options.presolve_enable = False  # keeps the rows of b, so that it can be updated
        for key, value in settings.items():
            setattr(options, key, value)
        size = a0.shape[1]
        objective = sp.csc_matrix((size, size)) if p0 is None else sp.csc_matrix(sp.triu(p0))
        solver = clarabel.DefaultSolver(
            objective, np.asarray(q0), sp.csc_matrix(-a0), np.asarray(b0), cones, options
        )
        maps = (np.asarray(q0), _jacobian(q_columns), np.asarray(b0), _jacobian(b_columns))
        # The offsets of the variables in Clarabel's x: those of the matrix stuffing, the last
        # reduction that sees variables (canonicalisation may add auxiliary ones before them).
        offsets = [d.var_offsets for d in inverse if hasattr(d, "var_offsets")][-1]
        direct = cls(problem, solver, offsets, float(d0), maps)
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

    def solve(self, *, accept_inaccurate: bool = False) -> dict | None:
        """Variable values by id after a solve with the parameters' current values.

        ``None`` when Clarabel does not report the problem solved (or almost solved, with
        ``accept_inaccurate``); :attr:`status` says why (use cvxpy then: it turns infeasibility
        into certificates).
        """
        vector = self._parameter_vector()
        update = {
            "b": self._b0 if self._b_jacobian is None else self._b0 + self._b_jacobian @ vector
        }
        if self._q_jacobian is not None:
            update["q"] = self._q0 + self._q_jacobian @ vector
        self._solver.update(**update)
        solution = self._solver.solve()
        self.status = str(solution.status)
        if self.status != "Solved" and not (accept_inaccurate and self.status == "AlmostSolved"):
            return None
        self.objective_value = float(solution.obj_val) + self._constant
        self._dual = np.asarray(solution.z)
        x = np.asarray(solution.x)
        values = {}
        for variable in self._problem.variables():
            start = self._offsets[variable.id]
            chunk = x[start : start + variable.size]
            values[variable.id] = chunk.reshape(variable.shape, order="F")
        return values

    def equality_dual(self, parameter: cp.Parameter) -> np.ndarray:
        """Multipliers, after :meth:`solve`, of the equality constraint ``expression +
        parameter == 0`` in which ``parameter`` (a vector) appears alone, as cvxpy gives them
        (``constraint.dual_value``)."""
        if parameter.id not in self._dual_rows:
            block = self._b_jacobian[:, self._columns[parameter.id]].toarray()
            rows = np.argmax(np.abs(block), axis=0)
            # Clarabel's row a·x + s = b with b = c p_j (s = 0) is cvxpy's (a/c)·x + ... == 0
            # scaled by c: cvxpy's multiplier is the row's times -c.
            self._dual_rows[parameter.id] = rows, -block[rows, np.arange(len(rows))]
        rows, coefficients = self._dual_rows[parameter.id]
        return coefficients * self._dual[rows]

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


def _jacobian(columns) -> sp.csc_array | None:
    """The sparse matrix of probed columns, or ``None`` when every column is zero."""
    if not columns:
        return None
    matrix = sp.csc_array(np.column_stack(columns))
    return matrix if matrix.nnz else None


def _parameter_columns(parameters) -> dict:
    """Column indices of each parameter (by id) in the probed parameter vector."""
    columns, start = {}, 0
    for p in parameters:
        columns[p.id] = np.arange(start, start + p.size)
        start += p.size
    return columns
