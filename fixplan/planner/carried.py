r"""Ends of a held interval that need no solve: the force solve's optimum carried into ``check``.

A force objective finds the least active forces that hold the task load (multiple 1); the
analysis of those forces asks for the held interval ``[k_min, k_max]`` of the load: the fixed-force
program ``check`` (:mod:`fixplan.planner.stacking`), maximised and minimised. Its variables are
the force program's but for the active normal forces, given now, and the multiple ``k``; its
constraints are the force program's rows, role by role. So

- the force solve's point with ``k = 1`` is a point of ``check``;
- its multipliers ``z``, scaled by the ``α > 0`` that makes ``k``'s column stationary
  (``α (Aᵀz)_k + q_k = 0``), are multipliers of ``check`` for one sense: stationarity on the
  shared columns (passive normal forces, friction loads) carries over, as the cost is zero there
  in both programs.

Where the pair is optimal for ``check`` (:meth:`~fixplan.planner.optimality.Pattern.optimal`,
checked on ``check``'s own data), that end of the interval is 1 without a solve, and for ``k_max`` the
multipliers are its impending motion. Which end depends on the sign of ``α``: the forces are
least where the load pushes the part out (``k_max = 1``) or where it holds the part in
(``k_min = 1``); the check fails where the given forces hold more than the least (a clamp left at
its bound, or the load held by the locators alone: then the twist of the force solve is zero).

The other end is solved, but for ``k_min = 0`` where the given forces and the weight alone are
held with no friction at all: the passive normal forces that balance them (least squares on the
equality rows) form a point of ``check`` at ``k = 0`` where they press (:class:`WithoutLoad`):
a fixture whose locators take its clamps' push.
"""

from __future__ import annotations

import numpy as np

from fixplan.planner.direct_solve import DirectSolver
from fixplan.planner.optimality import RESIDUALS, Pattern
from fixplan.planner.stacking import Stacked
from fixplan.surface.point_kernel import compiled_scalar
from fixplan.tolerances import CERTIFICATE_RTOL


class Carried:
    """Where the variables and multipliers of a force program (the source) sit in the
    ``check`` program of the same problem (the target), both solved directly.

    Variables pair by name (the target's multiples, absent from the source, are set), rows by
    the role of their constraint (:attr:`~fixplan.planner.stacking.Stacked.roles`); the target's
    other rows get no multiplier.
    """

    def __init__(self, variables, rows, multiple: int, balance: slice, pattern: Pattern):
        # Target and source positions of the paired variables' entries and multipliers' rows.
        self._x = _positions(variables)
        self._z = _positions(rows)
        #: Where the multiple and the equilibrium's rows sit in the target's x and z.
        self.multiple, self.balance = multiple, balance
        self._pattern = pattern
        #: What :meth:`carry_at` passes its compiled pass besides the solution: the target's
        #: compiled maps they were made for, the arguments (the maps, the arrays it fills and
        #: the pairing) and the arrays ``x``, ``z``, ``q``, A's values and ``b`` among them.
        self._passed: tuple | None = None

    @classmethod
    def between(
        cls, source: Stacked, source_direct: DirectSolver, target: Stacked,
        target_direct: DirectSolver,
    ) -> Carried | None:  # fmt: skip
        """The map from ``source`` to ``target``; ``None`` where a target variable (other than
        the multiples) has no source variable of its name and size, or entries of the target's
        ``x`` belong to no variable."""
        found = {v.name(): (v, source_direct.slot(v)) for v in source.problem.variables()}
        variables, multiple, placed = [], None, 0
        for variable in target.problem.variables():
            slot = target_direct.slot(variable)
            if slot is None:
                return None
            placed += variable.size
            if variable is target.scale:
                multiple = slot
                continue
            other, other_slot = found.get(variable.name(), (None, None))
            if other is None or other_slot is None or other.shape != variable.shape:
                return None
            variables.append((slot, other_slot))
        if (
            multiple is None
            or multiple.stop - multiple.start != 1
            or placed != target_direct.variables
        ):
            return None
        rows = []
        for role, constraint in target.roles.items():
            mine, theirs = target_direct.rows(constraint), None
            if role in source.roles:
                theirs = source_direct.rows(source.roles[role])
            if mine is not None and theirs is not None and _length(mine) == _length(theirs):
                rows.append((mine, theirs))
        balance = target_direct.rows(target.balance)
        return cls(tuple(variables), tuple(rows), multiple.start, balance, target_direct.pattern)

    def carry(
        self, solution: tuple[np.ndarray, np.ndarray], ratio: float, q, values, b
    ) -> tuple[float, float, np.ndarray, np.ndarray]:
        """The target's ``x`` and multipliers ``z`` of the source's ``solution`` ``(x, z)``
        (see the module), for the target's program ``(q, A, b)`` (``A``'s ``values`` in its
        pattern): ``x`` with its forces times ``ratio`` (the source's force unit over the
        target's) and the multiple 1, ``z`` scaled by ``α``. Returns ``α``, the largest of the
        pair's residuals (:meth:`~fixplan.planner.optimality.Pattern.residuals`: optimal where
        at most ``CERTIFICATE_RTOL``; not where ``α <= 0``, when the other sense may hold),
        ``x`` and ``z``."""
        pattern = self._pattern
        x, z = np.zeros(pattern.column_count), np.zeros(pattern.row_count)
        alpha, worst = _CARRIED(
            solution[0], solution[1], *self._x, *self._z, ratio, self.multiple, q, values,
            pattern.rows, pattern.indptr, b, pattern.zero, pattern.nonneg, pattern.heads,
            pattern.sizes, x, z,
        )  # fmt: skip
        return alpha, worst, x, z

    def carry_at(
        self, solution: tuple[np.ndarray, np.ndarray], ratio: float, vector: np.ndarray,
        target: DirectSolver, without: WithoutLoad,
    ) -> tuple:  # fmt: skip
        """:meth:`carry` into the ``target``'s program at its parameter ``vector``, and with it
        :meth:`WithoutLoad.held` (``without``: the target's point without load). Returns ``α``,
        the largest residual, whether the point without load is held (1 or 0; -1 where not
        tested: ``without`` must first see the program), ``x``, ``z`` and the program
        ``(q, A's values, b)``.

        Where ``target`` has compiled maps (:meth:`~fixplan.planner.direct_solve.DirectSolver.compiled_maps`:
        the small programs of a control loop) all of it is one compiled pass, which evaluates
        the program itself into arrays kept for the next call (what it returns holds until
        then: a control loop's analysis reads it at once)."""
        maps = target.compiled_maps()
        if maps is None:
            q, values, b = target.program(vector)
            alpha, worst, x, z = self.carry(solution, ratio, q, values, b)
            return alpha, worst, -1, x, z, (q, values, b)
        if self._passed is None or self._passed[0] is not maps:
            a_map, q_map, split, b_rows = maps
            pattern = self._pattern
            columns, rows = pattern.column_count, pattern.row_count
            filled = (np.zeros(columns), np.zeros(rows), np.empty(columns), np.empty(split),
                      np.zeros(rows))  # fmt: skip
            x, z, q, values, b = filled
            arguments = (
                *a_map, *q_map, split, b_rows, q, values, b, *self._x, *self._z, self.multiple,
                pattern.rows, pattern.indptr, pattern.zero, pattern.nonneg, pattern.heads,
                pattern.sizes, x, z,
            )  # fmt: skip
            self._passed = (maps, arguments, filled)
        _, arguments, (x, z, q, values, b) = self._passed
        alpha, worst, held = _CARRIED_AT(
            vector, solution[0], solution[1], ratio, *arguments, *without.pass_data
        )
        return alpha, worst, held, x, z, (q, values, b)


def _positions(pairs) -> tuple[np.ndarray, np.ndarray]:
    """The entries of ``(target slice, source slice)`` pairs as two index arrays."""
    target = [np.arange(mine.start, mine.stop) for mine, _ in pairs]
    source = [np.arange(theirs.start, theirs.stop) for _, theirs in pairs]
    empty = np.zeros(0, dtype=np.intp)
    return (np.concatenate([empty, *target]).astype(np.intp),
            np.concatenate([empty, *source]).astype(np.intp))  # fmt: skip


def carried_pair(
    source_x,
    source_z,
    x_target,
    x_source,
    z_target,
    z_source,
    ratio,
    multiple,
    q,
    values,
    rows,
    indptr,
    b,
    zero,
    nonneg,
    heads,
    sizes,
    x,
    z,
):  # pragma: no cover - compiled
    """:meth:`Carried.carry` into ``x`` and ``z`` (zeros): returns ``α`` and the largest
    residual (``inf`` where ``α`` is not positive and finite)."""
    for k in range(x_target.shape[0]):
        x[x_target[k]] = source_x[x_source[k]] * ratio
    x[multiple] = 1.0
    for k in range(z_target.shape[0]):
        z[z_target[k]] = source_z[z_source[k]]
    pull = 0.0
    for k in range(indptr[multiple], indptr[multiple + 1]):
        pull += values[k] * z[rows[k]]
    alpha = -q[multiple] / pull if pull != 0.0 else 0.0
    if not (alpha > 0.0 and alpha < np.inf):
        return alpha, np.inf
    for i in range(z.shape[0]):
        z[i] *= alpha
    primal, dual, gap = RESIDUALS(q, values, rows, indptr, b, x, z, zero, nonneg, heads, sizes)
    return alpha, max(primal, dual, gap)


_CARRIED = compiled_scalar(carried_pair)


def held_without_load(
    values, b, inverse, passive, rows, indptr, zero, nonneg, heads, sizes, columns
):  # pragma: no cover - compiled
    """Whether the point of :class:`WithoutLoad` is feasible for the program of ``A``'s
    ``values`` and ``b`` (``columns`` variables): its passive normal forces (columns from
    ``passive`` on) are ``inverse`` (the block's pseudo-inverse) times the equality rows of
    ``b``, everything else 0."""
    free = np.zeros(columns)
    for c in range(inverse.shape[0]):
        total = 0.0
        for r in range(zero):
            total += inverse[c, r] * b[r]
        free[passive + c] = total
    empty = np.zeros(0)  # (no cost and no multipliers: the primal residual alone)
    primal = RESIDUALS(empty, values, rows, indptr, b, free, empty, zero, nonneg, heads, sizes)[0]
    return primal <= CERTIFICATE_RTOL


_HELD = compiled_scalar(held_without_load)


def carried_at(
    vector, source_x, source_z, ratio, a_indptr, a_indices, a_data, q_indptr, q_indices, q_data,
    split, b_rows, q, values, b, x_target, x_source, z_target, z_source, multiple, rows, indptr,
    zero, nonneg, heads, sizes, x, z, entries, found, inverse, passive,
):  # pragma: no cover - compiled  # fmt: skip
    """:meth:`Carried.carry_at` with compiled maps (each ``(indptr, indices, data)``): the
    program ``q``, ``values`` (A's) and ``b`` (zeros but for ``b_rows``) evaluated at ``vector``,
    then :func:`carried_pair` into ``x`` and ``z`` (set to zeros first) and, where A's
    ``entries`` on the passive columns still hold the values ``found`` that ``inverse`` was made
    from, the point without load (:meth:`WithoutLoad.held`; its passive columns start at
    ``passive``). Returns ``α``, the largest residual and whether that point is held (-1: not
    tested)."""
    for i in range(a_indptr.shape[0] - 1):
        total = 0.0
        for k in range(a_indptr[i], a_indptr[i + 1]):
            total += a_data[k] * vector[a_indices[k]]
        if i < split:
            values[i] = -total
        else:
            b[b_rows[i - split]] = total
    for i in range(q.shape[0]):
        total = 0.0
        for k in range(q_indptr[i], q_indptr[i + 1]):
            total += q_data[k] * vector[q_indices[k]]
        q[i] = total
    x[:] = 0.0
    z[:] = 0.0
    alpha, worst = _CARRIED(
        source_x, source_z, x_target, x_source, z_target, z_source, ratio, multiple, q, values,
        rows, indptr, b, zero, nonneg, heads, sizes, x, z,
    )  # fmt: skip
    if found.shape[0] != entries.shape[0]:
        return alpha, worst, -1
    for k in range(entries.shape[0]):
        if values[entries[k]] != found[k]:
            return alpha, worst, -1
    held = _HELD(values, b, inverse, passive, rows, indptr, zero, nonneg, heads, sizes, x.shape[0])
    return alpha, worst, 1 if held else 0


_CARRIED_AT = compiled_scalar(carried_at)


def _length(rows: slice) -> int:
    return rows.stop - rows.start


class WithoutLoad:
    """The point of a ``check`` program at multiple 0 with no friction: its passive normal
    forces balance the weight and the given forces (least squares on the equality rows).

    Parameters
    ----------
    target : Stacked
        The ``check`` program of one load case.
    direct : DirectSolver
        Its direct solver.
    """

    def __init__(self, target: Stacked, direct: DirectSolver):
        self._pattern = pattern = direct.pattern
        passive = [v for v in target.problem.variables() if v.name() == "passive"]
        self._passive = direct.slot(passive[0]) if passive else slice(0, 0)
        # The passive columns' values on the equality rows: their positions among A's values,
        # and their rows and columns in the block.
        first, last = pattern.indptr[self._passive.start], pattern.indptr[self._passive.stop]
        entries = np.arange(first, last)
        columns = np.repeat(np.arange(self._passive.stop - self._passive.start),
                            np.diff(pattern.indptr[self._passive.start : self._passive.stop + 1]))  # fmt: skip
        on_zero = pattern.rows[entries] < pattern.zero
        self._entries = entries[on_zero]
        self._block = (pattern.rows[self._entries], columns[on_zero])
        #: What :func:`carried_at` tests the point with: the block's entries among A's values,
        #: the values its pseudo-inverse was made from (none yet), that pseudo-inverse and where
        #: the passive columns start.
        self.pass_data = (self._entries, np.zeros(0), np.zeros((0, pattern.zero)),
                          self._passive.start)  # fmt: skip

    def held(self, values: np.ndarray, b: np.ndarray) -> bool:
        """Whether that point lies in the cones of the program of ``A``'s ``values`` and ``b``
        (then ``k_min = 0``: the given forces and the weight are held without task load)."""
        found = values[self._entries]
        entries, kept, inverse, start = self.pass_data
        if found.shape != kept.shape or found.tobytes() != kept.tobytes():
            block = np.zeros((self._pattern.zero, self._passive.stop - self._passive.start))
            block[self._block] = found
            inverse = np.linalg.pinv(block)
            self.pass_data = (entries, found, inverse, start)
        pattern = self._pattern
        return _HELD(values, b, inverse, start, pattern.rows, pattern.indptr, pattern.zero,
                     pattern.nonneg, pattern.heads, pattern.sizes, pattern.column_count)  # fmt: skip
