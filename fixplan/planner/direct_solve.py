"""Re-solving a compiled DPP problem straight through Clarabel, for control loops.

cvxpy re-solves a DPP problem without recompiling it, but still spends a few milliseconds per
solve mapping parameters, building the solver and unpacking the answer. Its compiled program
keeps the problem data as linear maps of the parameter vector with fixed sparsity patterns:
``A`` and ``b`` (the planner's load wrenches, given forces and load multiples; the references,
loads and friction bounds of the contact-spring steps of :mod:`fixplan.motion.contact_springs`)
and the linear cost ``q``. This module applies those maps itself, keeps one Clarabel solver whose
``A``, ``b`` and ``q`` are updated in place, and reads the variables and the multipliers of
equality constraints from the solution vectors. Linear programs (pyramid models) are solved by a
warm-started dual simplex (:mod:`fixplan.planner.dual_simplex`) instead, and small cone programs
(ellipsoid and cone models, the osculating rounds of exact ones) by a compiled interior-point method
(:mod:`fixplan.planner.cone_interior_point`), with Clarabel where either gives up. It checks
itself against cvxpy's answer when it is built and refuses (returns ``None``) where its
assumptions do not hold (a parametric ``P``, cones Clarabel's direct path does not cover, cvxpy
internals it does not recognise).
"""

from __future__ import annotations

import cvxpy as cp
import numpy as np
import scipy.sparse as sp

from fixplan.planner.cone_interior_point import ConeInteriorPoint
from fixplan.planner.dual_simplex import DualSimplex
from fixplan.planner.optimality import Pattern

#: Largest relative difference from cvxpy's own answer accepted when the direct path is built.
AGREEMENT_RTOL = 1e-6

#: Maps of the parameter vector up to this many entries are applied dense: a sparse product costs
#: about 10 µs of overhead, as much as a dense one of this size.
DENSE_MAX_ENTRIES = 20_000

#: Linear programs up to this many constraint-matrix entries go to the dual simplex.
SIMPLEX_MAX_ENTRIES = 100_000
#: ... and, where ``A`` changes between solves (fixed-force objectives), up to this many
#: variables (one load case of an 8-contact fixture has 28-35).
SIMPLEX_MAX_CHANGING_VARIABLES = 64

#: Cone programs up to this many constraint-matrix entries go to the compiled interior-point
#: method where they fit it: its dense steps grow faster than Clarabel's sparse ones. (Against
#: Clarabel on the 8-contact fixture with ellipsoid models, from Mehrotra's start and from the
#: last optimum of similar loads: 0.71 and 0.39 of its time at 1 load case, 38 x 32 entries;
#: 1.08 and 0.46 at 2 cases, 76 x 62; 1.47 and 0.60 at 3 cases, 114 x 92.)
INTERIOR_MAX_ENTRIES = 2_500

#: What :meth:`DirectSolver.gather` reads at position -1.
_ZERO = np.zeros(1)

#: Clarabel's statuses of a problem without a feasible point.
INFEASIBLE = ("PrimalInfeasible", "AlmostPrimalInfeasible")


class DirectSolver:
    """Clarabel on the compiled conic data of ``problem``, with ``A``, ``b`` and ``q`` linear
    maps of the parameter vector.

    Build with :meth:`create` after ``problem`` was solved once by cvxpy with Clarabel.
    """

    def __init__(
        self, problem, solver, program, offsets, rows, pattern, simplex=None, interior=None
    ):
        self._problem = problem
        self._solver = solver
        self._simplex = simplex
        self._interior = interior
        #: The last parameter vector's ``(vector, A values, b)``, kept until :meth:`write` puts
        #: a parameter of ``A`` or ``b`` into it (a sense writes only ``q``), and the dense A of
        #: the simplex or the interior-point method with the values it was made from.
        self._constraints = (None, None, None)
        self._dense = (None, None)
        #: By parameter id, what :meth:`write` needs: its entries in the parameter vector
        #: (``None``: not used), its shape and whether it enters ``A`` or ``b``.
        self._placed: dict[int, tuple] = {}
        #: (column of the load multiple, its simplex) where only that column of A changes,
        #: and the last matrix of that simplex with its b.
        self._scaled = None
        self._scaled_matrix = (None, None)
        #: What solved the last problem: ``"dual simplex"``, ``"interior point"`` or
        #: ``"CLARABEL"``.
        self.method = ""
        self._program = program
        #: Where each variable sits in Clarabel's x: (id, start, stop, shape).
        self._placement = [
            (v.id, offsets[v.id], offsets[v.id] + v.size, v.shape) for v in problem.variables()
        ]
        #: Where each constraint's rows sit in ``z``: id -> (start, size, shape).
        self._rows = rows
        #: The cones of the rows and the pattern of ``A`` (its values: :meth:`program`).
        self.pattern = pattern
        self._sign = -1.0 if isinstance(problem.objective, cp.Maximize) else 1.0  # of the value
        #: The last solve's value: ``(q, x, constant)`` of a linear program (its value taken
        #: when asked), or ``(None, None, value)`` from Clarabel (see :attr:`objective_value`).
        self._optimum = (None, None, float("nan"))
        #: Clarabel's status of the last solve.
        self.status = ""
        self._dual = np.zeros(0)
        #: The last solution and the parameter vector it was solved with (the caller's array,
        #: not a copy: :meth:`gather` reads it before the caller writes new values into it).
        self._last = (np.zeros(0), np.zeros(0))

    @classmethod
    def create(cls, problem: cp.Problem, settings: dict) -> DirectSolver | None:
        """A direct solver for ``problem``, or ``None`` where its assumptions do not hold."""
        import clarabel

        data, _, inverse = problem.get_problem_data(cp.CLARABEL, solver_opts={})
        try:
            program = _Program(data[cp.settings.PARAM_PROB], problem.parameters())
            rows = _constraint_rows(inverse[-1].inverse_data)
        except (AttributeError, KeyError, TypeError, ValueError):
            return None  # cvxpy internals this module does not know
        dims = data["dims"]
        if dims.exp or dims.psd or dims.p3d or program.parametric_p:
            return None
        kinds = [clarabel.ZeroConeT(dims.zero), clarabel.NonnegativeConeT(dims.nonneg)]
        kinds += [clarabel.SecondOrderConeT(k) for k in dims.soc]
        options = clarabel.DefaultSettings()
        options.verbose = False
        options.presolve_enable = False  # keeps the rows of b, so that it can be updated
        for key, value in settings.items():
            setattr(options, key, value)
        vector = program.parameter_vector()
        q, _ = program.cost(vector)
        a, b = program.constraints(vector)
        solver = clarabel.DefaultSolver(program.quadratic, q, program.matrix(a), b, kinds, options)
        # The offsets of the variables in Clarabel's x: those of the matrix stuffing, the last
        # reduction that sees variables (canonicalisation may add auxiliary ones before them).
        offsets = [d.var_offsets for d in inverse if hasattr(d, "var_offsets")][-1]
        simplex = None
        small = len(b) * len(q) <= SIMPLEX_MAX_ENTRIES
        if not program.fixed_a:  # cold starts cost more than Clarabel beyond this size
            small = small and len(q) <= SIMPLEX_MAX_CHANGING_VARIABLES
        if not dims.soc and program.quadratic.nnz == 0 and small:
            simplex = DualSimplex(dims.zero, changing=not program.fixed_a)
        interior = None
        if (
            simplex is None
            and program.quadratic.nnz == 0
            and len(b) * len(q) <= INTERIOR_MAX_ENTRIES
        ):
            pattern = program.dense(np.ones_like(a))
            if ConeInteriorPoint.fits(dims.zero, dims.nonneg, pattern):
                interior = ConeInteriorPoint(dims.zero, dims.nonneg, dims.soc, pattern, settings)
        pattern = Pattern.of(*program.pattern, dims.zero, dims.nonneg, dims.soc)
        direct = cls(problem, solver, program, offsets, rows, pattern, simplex, interior)
        columns = program.parametric_columns()
        if simplex is not None and len(columns) == 1:  # one load multiple times the loads
            direct._scaled = (int(columns[0]), DualSimplex(dims.zero, changing=True))
        if not direct._agrees_with_cvxpy():
            return None
        return direct

    def parameter_vector(self) -> np.ndarray:
        """The parameter vector of the parameters' current values (the last entry 1)."""
        return self._program.parameter_vector()

    @property
    def objective_value(self) -> float:
        """The objective's value at the last solve (NaN before one)."""
        q, x, value = self._optimum  # (value: the constant of the minimisation cvxpy compiled)
        return self._sign * (value if x is None else float(q @ x) + value)

    def write(self, vector: np.ndarray, parameter: cp.Parameter, value) -> None:
        """Put ``parameter``'s ``value`` (broadcast to its shape) into the parameter ``vector``
        (:meth:`parameter_vector`'s layout) instead of into ``parameter``; a parameter that the
        compiled program does not use is left out."""
        placed = self._placed.get(parameter.id)
        if placed is None:
            program = self._program
            placed = (program.entries(parameter), parameter.shape,
                      program.in_constraints(parameter))  # fmt: skip
            self._placed[parameter.id] = placed
        entries, shape, in_constraints = placed
        if entries is None:
            return
        value = np.asarray(value, dtype=float)
        if value.shape != shape:  # (broadcast_to costs 5-8 µs; most fit)
            value = np.broadcast_to(value, shape)
        vector[entries] = value.ravel(order="F")
        if in_constraints and vector is self._constraints[0]:
            self._constraints = (None, None, None)

    def solve(
        self, *, accept_inaccurate: bool = False, vector: np.ndarray | None = None
    ) -> dict | None:
        """Variable values by id after a solve with the parameters' current values (or those
        of the parameter ``vector``, :meth:`parameter_vector`'s layout); ``None`` where
        :meth:`solved` fails."""
        if not self.solved(accept_inaccurate=accept_inaccurate, vector=vector):
            return None
        return self.values()

    def values(self) -> dict:
        """The variable values of the last solve, by id."""
        x = self._last[0]
        return {
            key: x[start:stop].reshape(shape, order="F")
            for key, start, stop, shape in self._placement
        }

    def solved(self, *, accept_inaccurate: bool = False, vector: np.ndarray | None = None) -> bool:
        """Solve with the parameters' current values (or those of the parameter ``vector``);
        the answer is then read with :meth:`values` or :meth:`gather`.

        A linear program goes to the warm-started dual simplex first, a cone program in
        standard form to the compiled interior-point method, and to Clarabel where either gives
        up (:mod:`fixplan.planner.dual_simplex`, :mod:`fixplan.planner.cone_interior_point`).
        ``False`` when Clarabel does not report the problem solved (or almost solved, with ``accept_inaccurate``); :attr:`status`
        says why (use cvxpy then: it turns infeasibility into certificates).
        """
        if vector is None:
            vector = self._program.parameter_vector()
        q, constant = self._program.cost(vector)
        a, b = self._constraints_at(vector)
        found = self._simplex_solve(q, a, b)
        method = "dual simplex"
        if found is None and self._interior is not None:
            found, method = self._interior.solve(q, self._dense_matrix(a), b), "interior point"
        if found is not None:
            x, self._dual = found
            self._optimum = (q, x, constant)
            self.status, self.method = "Solved", method
        else:
            update = {"q": q, "b": b}
            if not self._program.fixed_a:
                update["A"] = a  # the same pattern, so only the values change
            self._solver.update(**update)
            solution = self._solver.solve()
            self.status, self.method = str(solution.status), "CLARABEL"
            solved = self.status == "Solved"
            if not (solved or (accept_inaccurate and self.status == "AlmostSolved")):
                if self.infeasible:  # (its multipliers: the certificate, see dual())
                    self._dual = np.asarray(solution.z)
                return False
            x, self._dual = np.asarray(solution.x), np.asarray(solution.z)
            self._optimum = (None, None, float(solution.obj_val) + constant)
        self._last = (x, vector)
        return True

    @property
    def variables(self) -> int:
        """The size of the solution vector: :meth:`positions` below it are variables'."""
        return self._program.variables

    @property
    def solution(self) -> tuple[np.ndarray, np.ndarray]:
        """The last solve's ``x`` and multipliers ``z`` (``Aᵀz + q = 0``, ``z`` in the dual
        cones), not copies."""
        return self._last[0], self._dual

    def program(self, vector: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``q``, ``A``'s values (in :attr:`pattern`) and ``b`` of the program at the parameter
        ``vector`` (:meth:`parameter_vector`'s layout)."""
        a, b = self._constraints_at(vector)
        return self._program.cost(vector)[0], a, b

    def compiled_maps(self) -> tuple | None:
        """The program of a small problem as maps of the parameter vector, for compiled passes
        that evaluate it themselves: ``(a_map, q_map, split, b_rows)``, each map compressed by
        rows (``(indptr, indices, data)``), where ``a_map @ vector`` holds minus ``A``'s values
        (its first ``split`` entries) and then ``b``'s nonzero entries, at rows ``b_rows``
        (zeros elsewhere), and ``(q_map @ vector)[:n]`` is ``q``; ``None`` for large programs
        (whose maps numpy applies faster) or where ``A`` or ``q`` does not depend on the
        parameters."""
        return self._program.compiled_maps()

    def _constraints_at(self, vector: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``A``'s values and ``b`` at ``vector``, kept while the same ``vector`` object holds
        them (:meth:`write` drops them when it puts a parameter of ``A`` or ``b`` into it)."""
        kept, a, b = self._constraints
        if kept is not vector:
            a, b = self._program.constraints(vector)
            self._constraints = (vector, a, b)
        return a, b

    def slot(self, variable: cp.Variable) -> slice | None:
        """Where ``variable``'s entries (column-major) sit in ``x``; ``None`` if not there."""
        for key, start, stop, _ in self._placement:
            if key == variable.id:
                return slice(start, stop)
        return None

    def rows(self, constraint: cp.Constraint) -> slice | None:
        """Where ``constraint``'s rows sit in ``A``, ``b`` and ``z``; ``None`` if not there."""
        found = self._rows.get(constraint.id)
        return None if found is None else slice(found[0], found[0] + found[1])

    def positions(self, piece: cp.Variable | cp.Parameter) -> np.ndarray | None:
        """Where the entries of ``piece`` (column-major) sit in what :meth:`gather` reads: a
        variable's in the solution, a parameter's in the parameter vector after it; ``None``
        for a parameter the compiled program does not use."""
        found = self.slot(piece)
        if found is not None:
            return np.arange(found.start, found.stop)
        entries = self._program.entries(piece)
        if entries is None:
            return None
        return self._program.variables + np.arange(entries.start, entries.stop)

    def gather(
        self, positions: np.ndarray, *, solution_only: bool = False, point: tuple | None = None
    ) -> np.ndarray:
        """The last solve's values at ``positions`` (from :meth:`positions`; ``-1`` reads 0),
        or those of ``point`` (``x`` and its parameter vector); ``solution_only`` where every
        position is a variable's (read without joining the parameter vector to ``x``)."""
        x, vector = self._last if point is None else point
        if solution_only:
            return x[positions]
        return np.concatenate((x, vector, _ZERO))[positions]

    def _simplex_solve(self, q, a, b) -> tuple[np.ndarray, np.ndarray] | None:
        """``(x, z)`` from the dual simplex of a linear program, or ``None`` (not a linear
        program, or the simplex gave up: Clarabel then solves it)."""
        if self._simplex is None:
            return None
        matrix = self._dense_matrix(a)
        if self._scaled is not None:
            column = self._scaled[0]
            if q[column] < 0.0 and np.count_nonzero(q) == 1:
                return self._scaled_solve(matrix, q, b)
        return self._simplex.solve(matrix, q, b)

    def _dense_matrix(self, a) -> np.ndarray:
        """Clarabel's ``A`` from its values ``a``, dense (kept while ``a`` is the same object)."""
        values, matrix = self._dense
        if values is not a:
            matrix = self._program.dense(a)
            self._dense = (a, matrix)
        return matrix

    def _scaled_solve(self, matrix, q, b) -> tuple[np.ndarray, np.ndarray] | None:
        r"""The largest load multiple ``k`` (column ``c``, cost ``q_c < 0``), through the
        program in ``t = 1/k`` and ``y = x / k`` (Charnes and Cooper): dividing ``A x (=, <=) b``
        by ``k`` gives ``A_rest y - b t (=, <=) -a_c``, whose matrix does not change with the
        loads (they move to the right-hand side), so the basis of the last case starts the
        next. Minimising ``|q_c| t`` gives ``k = 1/t``, ``x = y k``, and multipliers ``z' k``
        (the same stationarity: ``a_c^T z' = |q_c| t``)."""
        column, simplex = self._scaled
        scaled, last = self._scaled_matrix
        if not same_values(b, last):  # (the same b: no refactoring)
            scaled = matrix.copy()
            scaled[:, column] = -b
            self._scaled_matrix = (scaled, b.copy())
        cost = np.zeros_like(q)
        cost[column] = -q[column]
        found = simplex.solve(scaled, cost, -matrix[:, column])
        if found is None or found[0][column] <= 0.0:
            return None
        y, z = found
        k = 1.0 / y[column]
        x = y * k
        x[column] = k
        return x, z * k

    @property
    def infeasible(self) -> bool:
        """Whether Clarabel found the last problem primal infeasible (then :meth:`dual` gives
        the Farkas certificate's part)."""
        return self.status == "PrimalInfeasible"

    def dual(self, constraint: cp.Constraint) -> np.ndarray | None:
        """The multipliers of equality ``constraint`` after :meth:`solve`, as cvxpy gives them
        (``constraint.dual_value``: after an infeasible solve, the certificate's); ``None`` if
        it is not one of the problem's equalities."""
        found = self._rows.get(constraint.id)
        if found is None or found[0] + found[1] > self.pattern.zero:
            return None
        start, size, shape = found
        return self._dual[start : start + size].reshape(shape, order="F")

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
            with np.errstate(divide="ignore", invalid="ignore"):  # cones at their apex
                feasible = all(
                    np.all(np.asarray(c.violation()) <= AGREEMENT_RTOL * max(1.0, abs(expected)))
                    for c in self._problem.constraints
                )
        finally:
            for variable in self._problem.variables():
                variable.save_value(saved[variable.id])
        scale = max(1.0, abs(expected))
        return feasible and abs(self.objective_value - expected) <= AGREEMENT_RTOL * scale


class _Program:
    """cvxpy's compiled conic program as linear maps of the parameter vector, applied in numpy
    (``P`` constant; the patterns of ``A`` and ``b`` fixed)."""

    def __init__(self, program, parameters):
        self._columns = [(p, program.param_id_to_col[p.id], p.size) for p in parameters]
        self._entries = {p.id: slice(column, column + size) for p, column, size in self._columns}
        self._size = program.total_param_size + 1  # the last entry is the constant 1
        #: The size of the solution vector x.
        self.variables = program.x.size
        # The parameter vector with every parameter 0: a map applied to it is its constant part.
        constant = np.r_[np.zeros(self._size - 1), 1.0]
        q_map = sp.csr_array(program.q)
        self._q = _for_products(q_map)
        #: ``(q, constant)`` where the cost does not depend on the parameters, else ``None``.
        self._fixed_cost = None
        if q_map[:, : self._size - 1].nnz == 0:
            full = q_map @ constant
            self._fixed_cost = (full[: self.variables], float(full[self.variables]))
        program.reduced_A.cache()
        a_map = sp.csr_array(program.reduced_A.reduced_mat)
        indices, indptr, shape = program.reduced_A.problem_data_index
        self._a_rows = np.asarray(indices)
        self._split = int(indptr[-2])  # entries of A; the rest are b's, in the last column
        self._a_shape = (int(shape[0]), int(shape[1]) - 1)
        self._a_indptr = np.asarray(indptr[:-1])
        self._dense_index = None  # (rows, columns) of A's entries, once dense() is asked
        #: Whether ``A`` does not depend on the parameters (only ``b`` and ``q`` change).
        parametric = a_map[: self._split][:, : self._size - 1]
        self._parametric_entries = np.diff(parametric.tocsr().indptr) > 0
        self.fixed_a = not self._parametric_entries.any()
        self._a_map = _for_products(a_map)
        used = np.diff(a_map[:, : self._size - 1].tocsc().indptr) > 0  # by vector entry
        self._constraint_parameters = {
            p.id for p, column, size in self._columns if used[column : column + size].any()
        }
        #: Where ``A`` is fixed: its values, and the map of ``b`` alone.
        self._fixed_values = None
        if self.fixed_a:
            self._fixed_values = -(a_map[: self._split] @ constant)
            # b's map with a row for every row of A, so that one product gives b.
            placed = a_map[self._split :].tocoo()
            rows = self._a_rows[self._split :][placed.row]
            self._b_map = _for_products(
                sp.csr_array(
                    (placed.data, (rows, placed.col)), shape=(self._a_shape[0], self._size)
                )
            )
        self._compiled_maps = None
        small = isinstance(self._a_map, np.ndarray) and isinstance(self._q, np.ndarray)
        if small and self._fixed_values is None and self._fixed_cost is None:
            self._compiled_maps = (_by_rows(a_map), _by_rows(q_map), self._split,
                                   self._a_rows[self._split :])  # fmt: skip
        if program.reduced_P is None or program.reduced_P.matrix_data is None:
            self.quadratic = sp.csc_matrix((self.variables, self.variables))
            self.parametric_p = False
        else:
            program.reduced_P.cache()
            p_map = sp.csr_array(program.reduced_P.reduced_mat)
            self.parametric_p = p_map[:, :-1].nnz > 0
            p_indices, p_indptr, p_shape = program.reduced_P.problem_data_index
            values = p_map @ constant
            full = sp.csc_matrix((values, p_indices, p_indptr), shape=p_shape)
            self.quadratic = sp.csc_matrix(sp.triu(full))

    def parameter_vector(self) -> np.ndarray:
        vector = np.zeros(self._size)
        vector[-1] = 1.0
        for parameter, column, size in self._columns:
            vector[column : column + size] = np.ravel(parameter.value, order="F")
        return vector

    def entries(self, parameter) -> slice | None:
        """Where ``parameter``'s values sit in the parameter vector (``None``: not used)."""
        return self._entries.get(parameter.id)

    def in_constraints(self, parameter) -> bool:
        """Whether ``parameter`` enters ``A`` or ``b`` (else only the cost, or nothing)."""
        return parameter.id in self._constraint_parameters

    def cost(self, vector) -> tuple[np.ndarray, float]:
        """``q`` and the constant of the cost."""
        if self._fixed_cost is not None:
            return self._fixed_cost
        full = self._q.dot(vector)
        return full[: self.variables], float(full[self.variables])

    def compiled_maps(self) -> tuple | None:
        """See :meth:`DirectSolver.compiled_maps`."""
        return self._compiled_maps

    def constraints(self, vector) -> tuple[np.ndarray, np.ndarray]:
        """Clarabel's ``A`` as its values in the fixed pattern (:meth:`matrix`) and ``b``:
        cvxpy's ``A x + b`` in the cones is ``b_C - A_C x`` with ``A_C = -A``, ``b_C = b``."""
        if self._fixed_values is not None:
            return self._fixed_values, self._b_map.dot(vector)
        b = np.zeros(self._a_shape[0])
        values = self._a_map.dot(vector)
        b[self._a_rows[self._split :]] = values[self._split :]
        return -values[: self._split], b

    def parametric_columns(self) -> np.ndarray:
        """The columns of ``A`` with entries that depend on the parameters."""
        entries = np.flatnonzero(self._parametric_entries)
        columns = np.repeat(np.arange(self._a_shape[1]), np.diff(self._a_indptr))
        return np.unique(columns[entries])

    @property
    def pattern(self) -> tuple[np.ndarray, np.ndarray]:
        """``A``'s compressed-column pattern: the row of each value, and where each column's
        values start."""
        return self._a_rows[: self._split], self._a_indptr

    def dense(self, values) -> np.ndarray:
        """Clarabel's ``A`` from its ``values``, as a dense array."""
        if self._dense_index is None:
            columns = np.repeat(np.arange(self._a_shape[1]), np.diff(self._a_indptr))
            self._dense_index = (self._a_rows[: self._split], columns)
        out = np.zeros(self._a_shape)
        out[self._dense_index] = values
        return out

    def matrix(self, values) -> sp.csc_matrix:
        """Clarabel's ``A`` from its ``values``."""
        return sp.csc_matrix((values, *self.pattern), shape=self._a_shape)


def same_values(a: np.ndarray | None, b: np.ndarray | None) -> bool:
    """Whether arrays ``a`` and ``b`` (or ``None``) hold the same values bit for bit: a sixth
    of the time of ``np.array_equal`` on small arrays (0.7-0.9 µs against 5.2)."""
    return a is not None and b is not None and a.shape == b.shape and a.tobytes() == b.tobytes()


def _for_products(matrix: sp.csr_array):
    """``matrix`` as it is fastest to multiply (with ``.dot``, 1 µs less than ``@`` on small
    arrays): dense up to ``DENSE_MAX_ENTRIES`` entries."""
    return matrix.toarray() if matrix.shape[0] * matrix.shape[1] <= DENSE_MAX_ENTRIES else matrix


def _by_rows(matrix: sp.csr_array) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``matrix``'s ``(indptr, indices, data)``, its explicit zeros left out."""
    matrix = sp.csr_array(matrix, copy=True)
    matrix.eliminate_zeros()
    return (matrix.indptr.astype(np.intp), matrix.indices.astype(np.intp),
            matrix.data.astype(float))  # fmt: skip


def _constraint_rows(inverse_data: dict) -> dict:
    """Row offset, size and shape of each constraint (by id) in Clarabel's rows: the equality
    constraints in its zero cone, then the others in its nonnegative and second-order cones."""
    rows, start = {}, 0
    for constraint in [*inverse_data["eq_constr"], *inverse_data["other_constr"]]:
        rows[constraint.id] = (start, constraint.size, constraint.shape)
        start += constraint.size
    return rows
