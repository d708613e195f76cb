r"""A cheap necessary test of a layout: can its contacts balance the weight and the loads at all?

One linear program (HiGHS) over all load cases, with every contact's friction set replaced by
the box around it (:mod:`fixplan.design.friction_box`, an *outer* approximation),

.. math:: \sum_{i \in S} g_i n_{ij} + F_i \ell_{ij} + k_j W_j + W_g = 0, \qquad
   |\ell_{ijk}| \le b_{ik} n_{ij}, \qquad n_{ij} \ge 0,

with a clamp's normal force shared by the cases, given forces fixed, ``max_force`` bounds kept,
``k_j = 1`` for the force objectives and ``0 <= k_j`` free for the fixed-force ones (their
problem is feasible as soon as the weight alone is held). Every set the planner allows is inside
this one, and the planner's extra rules (no squeeze, the refined stage) only remove solutions, so
an infeasible program proves that the layout cannot hold: it is skipped without a conic solve.
Nothing else is concluded from a feasible program.
"""

from __future__ import annotations

import contextlib
import os
import sys

import highspy
import numpy as np
import scipy.sparse as sp

from fixplan.planner.problem import FIXED_FORCE_OBJECTIVES, Problem


class FeasibilityTest:
    """The necessary feasibility test of subsets of ``problem``'s contacts.

    The program over all contacts is passed to HiGHS once; a subset is tested by fixing the
    normal forces of the other contacts at 0 (their friction follows through the boxes) and
    re-solving from the previous basis.

    Parameters
    ----------
    problem : Problem
        All contacts (fixed and candidates), the loads and the objective.
    boxes : list of numpy.ndarray
        Per contact, the half-widths of its friction box per unit normal force
        (:func:`~fixplan.design.friction_box.friction_box`).
    length_scale : float
        Moments are divided by it [m], so that the rows weigh alike.
    """

    def __init__(self, problem: Problem, boxes: list[np.ndarray], length_scale: float):
        rows = np.array([1.0, 1.0, 1.0, *(3 * [1.0 / length_scale])])
        task = problem.task_wrenches() * rows[:, None]
        lp = _Program(task.shape[1])
        self._normals: list[list[int]] = []  # the normal force columns of each contact
        for contact, box in zip(problem.contacts, boxes, strict=True):
            basis = contact.wrench_basis()[:, : 1 + len(box)] * rows[:, None]
            low = 0.0 if contact.force is None else contact.force
            high = np.inf if contact.force is None else contact.force
            if contact.max_force is not None:
                high = min(high, contact.max_force)
            shared = lp.add(low, high) if contact.role == "clamp" else None
            columns = [] if shared is None else [shared]
            for case in range(lp.cases):
                normal = shared
                if normal is None:
                    normal = lp.add(low, high)
                    columns.append(normal)
                lp.wrench(case, normal, basis[:, 0])
                for k, half in enumerate(box):
                    friction = lp.add(-np.inf, np.inf)
                    lp.wrench(case, friction, basis[:, 1 + k])
                    lp.within(friction, normal, half)
            self._normals.append(columns)
        rhs = -np.tile(problem.body.weight_wrench * rows, lp.cases)
        for case in range(lp.cases):
            if problem.objective in FIXED_FORCE_OBJECTIVES:
                lp.wrench(case, lp.add(0.0, np.inf), task[:, case])
            else:
                rhs[6 * case : 6 * case + 6] -= task[:, case]
        self._bounds = np.array(lp.bounds)
        self._highs = lp.compile(rhs)

    def holds(self, subset) -> bool:
        """Whether the contacts of ``subset`` (indices) may hold (``False``: they cannot)."""
        chosen = set(subset)
        lower, upper = self._bounds[:, 0].copy(), self._bounds[:, 1].copy()
        for i, columns in enumerate(self._normals):
            if i not in chosen:
                lower[columns] = upper[columns] = 0.0
        count = len(lower)
        upper = np.where(np.isinf(upper), highspy.kHighsInf, upper)
        lower = np.where(np.isinf(lower), -highspy.kHighsInf, lower)
        self._highs.changeColsBounds(count, np.arange(count, dtype=np.int32), lower, upper)
        self._highs.run()
        return self._highs.getModelStatus() != highspy.HighsModelStatus.kInfeasible


class _Program:
    """A feasibility LP built column by column: equilibrium rows per case, box rows."""

    def __init__(self, cases: int):
        self.cases = cases
        self.bounds: list[tuple[float, float]] = []
        self._equal: list[tuple[int, int, float]] = []  # (row, column, value)
        self._boxes: list[tuple[int, int, float]] = []  # (friction, normal, half-width)

    def add(self, low: float, high: float) -> int:
        """A new variable within ``[low, high]``; its column."""
        self.bounds.append((low, high))
        return len(self.bounds) - 1

    def wrench(self, case: int, column: int, wrench: np.ndarray) -> None:
        """Column ``column`` adds ``wrench`` per unit to the equilibrium of ``case``."""
        self._equal += [(6 * case + r, column, float(v)) for r, v in enumerate(wrench) if v]

    def within(self, friction: int, normal: int, half: float) -> None:
        """``|x_friction| <= half * x_normal``: two rows ``∓x_friction + half x_normal >= 0``."""
        self._boxes.append((friction, normal, half))

    def compile(self, rhs: np.ndarray) -> highspy.Highs:
        """HiGHS with the program: equilibrium rows equal to ``rhs``, box rows ``>= 0``."""
        count, equal = len(self.bounds), 6 * self.cases
        entries = list(self._equal)
        for k, (friction, normal, half) in enumerate(self._boxes):
            entries += [(equal + 2 * k, friction, -1.0), (equal + 2 * k, normal, half)]
            entries += [(equal + 2 * k + 1, friction, 1.0), (equal + 2 * k + 1, normal, half)]
        rows, columns, values = (np.array(x) for x in zip(*entries, strict=True))
        matrix = sp.csc_array((values, (rows, columns)), shape=(equal + 2 * len(self._boxes),
                                                                count))  # fmt: skip
        matrix.sort_indices()
        inf = highspy.kHighsInf
        lp = highspy.HighsLp()
        lp.num_col_, lp.num_row_ = count, matrix.shape[0]
        lp.col_cost_ = np.zeros(count)
        lp.col_lower_ = np.array([-inf if np.isinf(a) else a for a, _ in self.bounds])
        lp.col_upper_ = np.array([inf if np.isinf(b) else b for _, b in self.bounds])
        lp.row_lower_ = np.concatenate([rhs, np.zeros(2 * len(self._boxes))])
        lp.row_upper_ = np.concatenate([rhs, np.full(2 * len(self._boxes), inf)])
        lp.a_matrix_.format_ = highspy.MatrixFormat.kColwise
        lp.a_matrix_.start_ = matrix.indptr.astype(np.int32)
        lp.a_matrix_.index_ = matrix.indices.astype(np.int32)
        lp.a_matrix_.value_ = matrix.data
        with _silenced_streams():  # (its constructor prints a banner, once per process)
            highs = highspy.Highs()
        highs.setOptionValue("output_flag", False)
        highs.passModel(lp)
        return highs


@contextlib.contextmanager
def _silenced_streams():
    """The process's standard output and error (file descriptors 1 and 2, where compiled code
    writes) sent to the null device for the duration."""
    sys.stdout.flush()
    sys.stderr.flush()
    saved = os.dup(1), os.dup(2)
    null = os.open(os.devnull, os.O_WRONLY)
    try:
        os.dup2(null, 1)
        os.dup2(null, 2)
        yield
    finally:
        os.dup2(saved[0], 1)
        os.dup2(saved[1], 2)
        for descriptor in (*saved, null):
            os.close(descriptor)
