"""What both ways of stating exact friction models in a stacked problem share.

:mod:`fixplan.planner.cuts` (tangent-plane cuts on a seed polytope) and
:mod:`fixplan.planner.osculating` (osculating ellipsoids) both keep the exact contacts and where
their loads sit, the friction use of the last solve they checked, the contacts' twists in that
solve's impending motion, and a pool of tangent-plane cut rows ``a · ℓ <= n`` in cvxpy
Parameters (``slots`` per exact contact and load case; an empty slot has ``a = 0``).
"""

from __future__ import annotations

import cvxpy as cp
import numpy as np
import scipy.sparse as sp

from fixplan.models.exact import Exact
from fixplan.planner.parameters import assign, part_values


def takes_rounds(model) -> bool:
    """Whether ``model`` is an exact model whose constraints hold its set only from outside
    (not :attr:`~fixplan.models.Exact.stated_exactly`): cuts or ellipsoids bring its loads in."""
    return isinstance(model, Exact) and not model.stated_exactly


class ExactContacts:
    """The exact contacts of a stacked problem, and their cut rows.

    Parameters
    ----------
    models : dict
        Contact index -> its :class:`~fixplan.models.Exact` model (frictionless ones excluded).
    slices : tuple of slice
        Rows of each contact's friction load in the stacked friction variable.
    normal : cvxpy.Expression
        ``(C, K)`` normal forces [N].
    normal_parts : tuple
        The ``(contact indices, variable or parameter)`` pairs that make up ``normal`` (see
        :class:`~fixplan.planner.stacking.Stacked`), whose values are read after a solve.
    friction : cvxpy.Variable
        ``(D, K)`` friction loads.
    wrenches : numpy.ndarray
        ``(6, D)`` body wrench per unit friction load component (the equilibrium's ``G``).
    balance : cvxpy.Constraint
        The equilibrium; its multipliers ``(6, K)`` are the impending motion of each case.
    slots : int
        Cut rows per (exact contact, load case).
    name : str
        Prefix of the cut Parameters' names.
    """

    def __init__(
        self,
        models: dict,
        slices,
        normal: cp.Expression,
        friction: cp.Variable,
        *,
        normal_parts: tuple,
        wrenches: np.ndarray,
        balance: cp.Constraint,
        slots: int,
        name: str,
    ):
        self._contacts = np.array(sorted(models), dtype=int)
        self._models = [models[i] for i in self._contacts]
        #: The distinct model objects (contacts may share one: see
        #: :func:`~fixplan.planner.contact_models.contact_models`) and each contact's among them.
        index: dict[int, int] = {}
        self._model_of = np.array([index.setdefault(id(m), len(index)) for m in self._models])
        self._distinct = list({id(m): m for m in self._models}.values())
        self._rows = np.array([np.arange(slices[i].start, slices[i].stop) for i in self._contacts])
        self._normal, self._friction, self._balance = normal, friction, balance
        self._normal_parts = normal_parts
        self._wrenches = np.array([wrenches[:, rows] for rows in self._rows])  # (E, 6, 3)
        count, cases = len(self._contacts), friction.shape[1]
        #: ``(C, K)`` friction use ``1 / s`` of every exact contact's load in the last solve the
        #: rounds checked (NaN for other contacts and unpressed ones): the solve's final loads,
        #: whose exact safety factors verification need not ask for again.
        self.use = np.full((normal.shape[0], cases), np.nan)
        self._planes = np.zeros((3, slots, count, cases))  # (axis, slot, contact, case)
        self._cut_parameters = [
            cp.Parameter((slots * count, cases), name=f"{name}_{axis}")
            for axis in ("fx", "fy", "m")
        ]
        tile = sp.vstack([sp.eye_array(count)] * slots, format="csr")
        lhs = sum(
            cp.multiply(parameter, tile @ friction[self._rows[:, axis], :])
            for axis, parameter in enumerate(self._cut_parameters)
        )
        self._cuts = lhs <= tile @ normal[self._contacts, :]
        self._assign_cuts()

    @classmethod
    def of(cls, models, slices, normal, friction, **options):
        """The pool of the exact models among ``models`` (one per contact), or ``None``."""
        exact = {i: m for i, m in enumerate(models) if takes_rounds(m)}
        return cls(exact, slices, normal, friction, **options) if exact else None

    def _by_model(self, owner: np.ndarray):
        """``(model, rows)`` per distinct model of the exact contacts ``owner`` ``(P,)``: the rows
        of ``owner`` whose contact has that model, in order (their loads are queried in one
        call). (A test per distinct model: with ``np.unique`` a call took 13.5 µs against 5.9 µs
        on the two models of the grasp of benchmarks/bench_realtime.py.)"""
        which = self._model_of[owner]
        for index, model in enumerate(self._distinct):
            rows = np.flatnonzero(which == index)
            if rows.size:
                yield model, rows

    def _normal_values(self) -> np.ndarray:
        """``(C, K)`` normal forces [N] of the last solve."""
        return part_values(self._normal_parts, self._normal.shape)

    def _assign_cuts(self) -> None:
        shape = self._cut_parameters[0].shape
        for axis, parameter in enumerate(self._cut_parameters):
            assign(parameter, self._planes[axis].reshape(shape))

    def _twists(self) -> np.ndarray | None:
        """``(E, K, 3)`` twists ``(vx, vy, w)`` of the exact contacts in the last solve's
        impending motion, ``-G_iᵀ y``; ``None`` without multipliers."""
        dual = self._balance.dual_value
        if dual is None:
            return None
        return -np.einsum("exr,xk->ekr", self._wrenches, np.asarray(dual, dtype=float))
