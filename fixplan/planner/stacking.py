r"""The planning problem as one stacked convex program.

Every (contact, load case) pair is a column. Contact ``i`` in case ``j`` has a normal force
``n_ij``, a friction load ``ℓ_ij`` and, for some models, auxiliary variables ``z_ij``; the
friction set of its model is a :class:`~fixplan.models.ConicForm`
``a_i n_ij + B_i ℓ_ij + C_i z_ij ∈ K_i``. The rows of all contacts are stacked into sparse
matrices once, so that the whole problem has one equilibrium constraint block

.. math:: G_n N + G_f F + W \operatorname{diag}(s) + W_g 1^T = 0

and one constraint per cone kind (zero, nonnegative, second-order cones of each size) over all
columns, whatever the numbers of contacts and load cases. cvxpy compiles such a problem in
time and memory that grow linearly with contacts × cases; one constraint per pair grows far
faster (20 contacts × 100 cases ran out of memory).
"""

from __future__ import annotations

import itertools
from collections.abc import Callable
from dataclasses import dataclass, field

import cvxpy as cp
import numpy as np
import scipy.sparse as sp

from fixplan.models.base import FrictionModel
from fixplan.models.conic import ConicForm, soc_columns
from fixplan.planner.cuts import CutPool
from fixplan.planner.exact_contacts import takes_rounds
from fixplan.planner.objectives import objective_expression
from fixplan.planner.osculating import OsculatingPool
from fixplan.planner.parameters import assign, part_values
from fixplan.planner.problem import FIXED_FORCE_OBJECTIVES, PASSIVE_ROLES, Problem
from fixplan.tolerances import MAX_SAFETY_FACTOR

#: Suffix of the second stage of a force objective (clamps given, fingers minimised per case).
REFINE = "|refine"


@dataclass(frozen=True, slots=True)
class ContactLayout:
    """Where each contact's normal force, friction load and auxiliary variables sit.

    Attributes
    ----------
    normal_map : numpy.ndarray
        ``(6, C)``: body wrench per unit normal force of each contact.
    friction_map : numpy.ndarray
        ``(6, D)``: body wrench per unit friction load component, contact after contact.
    slices : tuple of slice
        Rows of each contact's friction load in the stacked friction variable.
    cones : dict
        ``(kind, size) -> (normal, friction, aux)`` sparse row blocks of the friction sets
        (``kind`` ``"zero"``, ``"nonneg"`` or ``"soc"``; ``size`` 0 for the first two).
    aux_size : int
        Auxiliary variables per load case.
    signed : numpy.ndarray
        ``(C,)`` bool: the friction set does not imply a nonnegative normal force (a
        frictionless contact), so the planner states it.
    models : tuple of FrictionModel
        The friction model of each contact (exact models get cuts, :mod:`fixplan.planner.cuts`).
    osculating : bool
        The exact contacts' sets are left out of ``cones``: osculating ellipsoids state them
        (:mod:`fixplan.planner.osculating`).
    """

    normal_map: np.ndarray
    friction_map: np.ndarray
    slices: tuple[slice, ...]
    cones: dict
    aux_size: int
    signed: np.ndarray
    models: tuple[FrictionModel, ...]
    osculating: bool = False

    @classmethod
    def of(
        cls, problem: Problem, models: list[FrictionModel], *, osculating: bool = False
    ) -> ContactLayout:
        """The layout of ``problem``'s contacts with their friction ``models`` (``osculating``:
        see the attribute)."""
        dims = [model.load_dimension for model in models]
        bases = [contact.wrench_basis() for contact in problem.contacts]
        starts = np.concatenate([[0], np.cumsum(dims)])
        slices = tuple(slice(int(a), int(b)) for a, b in itertools.pairwise(starts))
        # (Exact sets stated by ellipsoids, which bound the normal force.)
        elsewhere = [osculating and takes_rounds(model) for model in models]
        forms = [
            _NO_ROWS if e else model.conic_form()
            for e, model in zip(elsewhere, models, strict=True)
        ]
        aux_starts = np.concatenate([[0], np.cumsum([f.aux.shape[1] for f in forms])])
        return cls(
            normal_map=np.column_stack([basis[:, 0] for basis in bases]),
            friction_map=np.hstack(
                [basis[:, 1 : 1 + d] for basis, d in zip(bases, dims, strict=True)]
            ),
            slices=slices,
            cones=_stack_cones(forms, starts, aux_starts),
            aux_size=int(aux_starts[-1]),
            signed=np.array(
                [not (e or form.bounds_normal) for e, form in zip(elsewhere, forms, strict=True)]
            ),
            models=tuple(models),
            osculating=osculating,
        )


#: The form of a contact whose set is stated elsewhere (an osculating ellipsoid).
_NO_ROWS = ConicForm(normal=np.zeros(0), load=np.zeros((0, 3)), aux=np.zeros((0, 0)), cones=())


def _stack_cones(forms: list[ConicForm], starts, aux_starts) -> dict:
    """Row blocks of every contact's friction set, grouped by cone kind and size."""
    contacts, width, aux_width = len(forms), int(starts[-1]), int(aux_starts[-1])
    groups = {("zero", 0), ("nonneg", 0)}
    groups |= {("soc", size) for form in forms for kind, size in form.cones if kind == "soc"}
    stacked = {}
    for kind, size in sorted(groups):
        normal, friction, aux = [], [], []
        for i, form in enumerate(forms):
            rows = form.rows_of(kind, size or None)
            if rows.size == 0:
                continue
            count = rows.size
            normal.append(sp.coo_array((form.normal[rows], (np.arange(count), np.full(count, i))),
                                       shape=(count, contacts)))  # fmt: skip
            friction.append(_placed(form.load[rows], int(starts[i]), width))
            aux.append(_placed(form.aux[rows], int(aux_starts[i]), aux_width))
        if normal:
            stacked[kind, size] = tuple(
                sp.vstack(part, format="csr") for part in (normal, friction, aux)
            )
    return stacked


def _placed(block: np.ndarray, start: int, width: int) -> sp.coo_array:
    """``block`` as the sparse columns ``start ...`` of a matrix ``width`` columns wide."""
    sparse = sp.coo_array(block)
    return sp.coo_array((sparse.data, (sparse.row, sparse.col + start)),
                        shape=(block.shape[0], width))  # fmt: skip


@dataclass(frozen=True, slots=True)
class Stacked:
    """A compiled cvxpy problem of one objective over a block of load cases, and its handles.

    Attributes
    ----------
    problem : cvxpy.Problem
    task, gravity : cvxpy.Parameter
        Task wrenches ``(6, K)`` and the gravity wrench ``(6,)``.
    given : dict
        Contact index -> ``("finger" | "clamp", row)``: where its given normal force sits in
        ``given_fingers`` ``(m, K)`` or ``given_clamps`` ``(m,)`` (see :func:`set_given`).
    given_fingers, given_clamps : cvxpy.Parameter or None
    sense : cvxpy.Parameter or None
        +1 to maximise the task-load multiples, -1 to minimise them (fixed-force objectives).
    unloaded : cvxpy.Parameter or None
        ``(passive contacts, K)``: 1 where a passive contact is held without normal force.
    normal : cvxpy.Expression
        ``(C, K)`` normal forces.
    normal_parts : tuple
        ``(contact indices, variable or parameter)`` pairs that make up ``normal`` (a 1-D one
        is the same in every case): :func:`normal_forces` evaluates it in numpy.
    friction : cvxpy.Variable
        ``(D, K)`` friction loads.
    scale : cvxpy.Expression
        ``(K,)`` task-load multiples (1 for the force objectives).
    balance : cvxpy.Constraint
        The equilibrium block; its dual is the twist of impending motion per case.
    decided : numpy.ndarray
        ``(C,)`` bool: the contact's normal force is a decision variable (passive, or an active
        contact whose force is free in this objective).
    exact : CutPool or OsculatingPool or None
        The rounds that bring the exact contacts' loads inside their sets: tangent-plane cuts,
        or osculating ellipsoids in an ``osculating`` layout (``None`` without exact models).
    limits : tuple
        ``(parameter, forces)`` pairs: the ``max_force`` bounds [N] of the free finger and clamp
        forces that have one, and the Parameter that states them (see :func:`set_units`).
    disabled : cvxpy.Parameter or None
        ``(C,)``: 1 where a contact is switched off (its normal force held at 0, so its friction
        load too), for layouts that use some of the contacts (``switchable`` in :func:`build`).
    roles : dict
        The problem's constraints by what they state: ``"balance"``, ``"friction-<cone>"`` (the
        friction sets, one per cone kind and size), ``"sign-<piece>"``, ``"limit-<piece>"``,
        ``"disabled-<piece>"`` (``<piece>``: passive, finger or clamp), ``"multiple-lower"``,
        ``"multiple-upper"``, ``"unloaded"``, ``"exact-<n>"``. Programs of other objectives
        built for the same problem state each role alike (:mod:`fixplan.planner.carried`).
    """

    problem: cp.Problem
    task: cp.Parameter
    gravity: cp.Parameter
    given: dict
    given_fingers: cp.Parameter | None
    given_clamps: cp.Parameter | None
    sense: cp.Parameter | None
    unloaded: cp.Parameter | None
    normal: cp.Expression
    normal_parts: tuple
    friction: cp.Variable
    scale: cp.Expression
    balance: cp.Constraint
    decided: np.ndarray
    exact: CutPool | OsculatingPool | None
    limits: tuple = ()
    disabled: cp.Parameter | None = None
    roles: dict = field(default_factory=dict)


def build(
    problem: Problem,
    layout: ContactLayout,
    objective: str,
    cases: int,
    *,
    squeeze: bool,
    switchable: bool = False,
) -> Stacked:
    """The stacked problem of ``objective`` (``objective + REFINE``: its second stage, with the
    clamp forces given) over ``cases`` load cases.

    ``squeeze`` adds the ``unloaded`` Parameter (see :mod:`fixplan.planner.squeeze`);
    ``switchable`` the ``disabled`` one, ``disabled_i * n_ij == 0`` on the decided normal forces
    (DPP; a given force of a disabled contact is set to 0 by its caller).
    """
    contacts = problem.contacts
    scaling = objective in FIXED_FORCE_OBJECTIVES
    refine = objective.endswith(REFINE)
    count = len(contacts)

    def given(contact) -> bool:
        if contact.role in PASSIVE_ROLES:
            return False
        return scaling or contact.force is not None or (refine and contact.role == "clamp")

    groups = {"passive": [], "finger": [], "clamp": [], "given-finger": [], "given-clamp": []}
    for i, contact in enumerate(contacts):
        role = "passive" if contact.role in PASSIVE_ROLES else contact.role
        groups[f"given-{role}" if given(contact) else role].append(i)
    ones = np.ones((1, cases))
    # Normal forces are nonnegative; most friction sets imply it (a cone's first row), and only
    # the others get a sign constraint, which keeps the conic problem small.
    pieces = {
        "passive": cp.Variable((len(groups["passive"]), cases), name="passive"),
        "finger": cp.Variable((len(groups["finger"]), cases), name="fingers"),
        "clamp": cp.Variable(len(groups["clamp"]), name="clamps"),
        "given-finger": cp.Parameter((len(groups["given-finger"]), cases), nonneg=True),
        "given-clamp": cp.Parameter(len(groups["given-clamp"]), nonneg=True),
    }
    normal, normal_parts = 0, []
    for key, index in groups.items():
        if not index:
            continue
        normal_parts.append((np.asarray(index), pieces[key]))
        piece = pieces[key]
        if piece.ndim == 1:
            piece = cp.reshape(piece, (len(index), 1), order="F") @ ones
        select = sp.csr_array((np.ones(len(index)), (index, np.arange(len(index)))),
                              shape=(count, len(index)))  # fmt: skip
        normal = normal + select @ piece
    friction = cp.Variable((layout.friction_map.shape[1], cases), name="friction")
    aux = cp.Variable((layout.aux_size, cases), name="aux") if layout.aux_size else None

    constraints = {}  # by role (see Stacked.roles)
    for key in ("passive", "finger", "clamp"):
        rows = [k for k, i in enumerate(groups[key]) if layout.signed[i]]
        if rows:
            constraints[f"sign-{key}"] = pieces[key][rows] >= 0.0
    task = cp.Parameter((6, cases), name="task_wrenches")
    gravity = cp.Parameter(6, name="gravity_wrench")
    sense = None
    if scaling:
        scale = cp.Variable(cases, name="scale")
        constraints["multiple-lower"] = scale >= 0.0
        constraints["multiple-upper"] = scale <= MAX_SAFETY_FACTOR
        task_term = task @ cp.diag(scale)
        sense = cp.Parameter(name="sense", value=1.0)
    else:
        scale = cp.Constant(np.ones(cases))
        task_term = task
    gravity_term = cp.reshape(gravity, (6, 1), order="F") @ ones
    balance = (
        layout.normal_map @ normal + layout.friction_map @ friction + task_term + gravity_term == 0
    )
    constraints["balance"] = balance
    for (kind, size), (on_normal, on_friction, on_aux) in layout.cones.items():
        rows = on_normal @ normal + on_friction @ friction
        if aux is not None and on_aux.nnz:
            rows = rows + on_aux @ aux
        if kind == "zero":
            constraints[f"friction-{kind}"] = rows == 0
        elif kind == "nonneg":
            constraints[f"friction-{kind}"] = rows >= 0
        else:
            constraints[f"friction-{kind}-{size}"] = soc_columns(rows, size)
    limits = []
    for key in ("finger", "clamp"):
        bounded = [(k, contacts[i].max_force) for k, i in enumerate(groups[key])
                   if contacts[i].max_force is not None]  # fmt: skip
        if bounded:
            rows, forces = zip(*bounded, strict=True)
            bound = cp.Parameter(len(rows), nonneg=True, name=f"max_{key}_forces")
            limits.append((bound, np.asarray(forces, dtype=float)))
            variable = pieces[key][list(rows)]
            if key == "finger":
                bound = cp.reshape(bound, (len(rows), 1), order="F") @ ones
            constraints[f"limit-{key}"] = variable <= bound
    if layout.osculating:
        exact = OsculatingPool.of(layout.models, layout.slices, normal, friction,
                                  normal_parts=tuple(normal_parts), wrenches=layout.friction_map,
                                  balance=balance, scale=scale if scaling else None)  # fmt: skip
    else:
        exact = CutPool.of(layout.models, layout.slices, normal, friction,
                           normal_parts=tuple(normal_parts), wrenches=layout.friction_map,
                           balance=balance)  # fmt: skip
    if exact is not None:
        constraints.update({f"exact-{n}": c for n, c in enumerate(exact.constraints)})
    unloaded = None
    if squeeze and groups["passive"]:
        unloaded = cp.Parameter((len(groups["passive"]), cases), nonneg=True, name="unloaded")
        unloaded.value = np.zeros(unloaded.shape)
        constraints["unloaded"] = cp.multiply(unloaded, pieces["passive"]) == 0
    disabled = None
    if switchable:
        disabled = cp.Parameter(count, nonneg=True, name="disabled", value=np.zeros(count))
        for key in ("passive", "finger", "clamp"):
            if groups[key]:
                switch = disabled[np.asarray(groups[key])]
                if key != "clamp":
                    switch = cp.reshape(switch, (len(groups[key]), 1), order="F") @ ones
                constraints[f"disabled-{key}"] = cp.multiply(switch, pieces[key]) == 0

    free_index = groups["finger"] + groups["clamp"]
    goal = objective_expression(
        objective.removesuffix(REFINE),
        scale=scale,
        sense=sense,
        clamps=pieces["clamp"] if groups["clamp"] else None,
        fingers=pieces["finger"] if groups["finger"] else None,
        free_forces=normal[sorted(free_index), :] if free_index else None,
    )
    compiled = cp.Problem(goal, list(constraints.values()))
    decided = np.ones(count, dtype=bool)
    decided[groups["given-finger"] + groups["given-clamp"]] = False
    return Stacked(
        problem=compiled,
        task=task,
        gravity=gravity,
        given={
            i: (key.removeprefix("given-"), row)
            for key in ("given-finger", "given-clamp")
            for row, i in enumerate(groups[key])
        },
        given_fingers=pieces["given-finger"] if groups["given-finger"] else None,
        given_clamps=pieces["given-clamp"] if groups["given-clamp"] else None,
        sense=sense,
        unloaded=unloaded,
        normal=normal,
        normal_parts=tuple(normal_parts),
        friction=friction,
        scale=scale,
        balance=balance,
        decided=decided,
        exact=exact,
        limits=tuple(limits),
        disabled=disabled,
        roles=constraints,
    )


def normal_forces(stacked: Stacked, solved: dict | None = None) -> np.ndarray:
    """The normal forces ``(C, K)`` [N] of the last solve, from the values of their parts (the
    variables' from ``solved``, by id, where given)."""
    shape = (len(stacked.decided), stacked.task.shape[1])
    return part_values(stacked.normal_parts, shape, solved)


def set_units(
    stacked: Stacked, weight_wrench: np.ndarray, unit: float = 1.0, put: Callable = assign
) -> None:
    """Set the gravity wrench ``(6,)`` [N, N m] and the ``max_force`` bounds, both divided by
    the force ``unit`` [N] in which the program is solved (see :mod:`fixplan.planner.runner`),
    through ``put(parameter, value)`` (default :func:`~fixplan.planner.parameters.assign`)."""
    put(stacked.gravity, np.asarray(weight_wrench, dtype=float) / unit)
    for parameter, forces in stacked.limits:
        put(parameter, forces / unit)


def set_given(stacked: Stacked, values: dict, unit: float = 1.0, put: Callable = assign) -> None:
    """Set the given normal forces [N] in the force ``unit`` [N] of the program: ``values``
    maps contact index -> float or ``(K,)`` (one per load case); through ``put(parameter,
    value)`` (default :func:`~fixplan.planner.parameters.assign`)."""
    fingers, clamps = stacked.given_fingers, stacked.given_clamps
    finger_values = None if fingers is None else np.zeros(fingers.shape)
    # (The clamps' in floats: numpy's calls cost more than the arithmetic.)
    clamp_values = None if clamps is None else [0.0] * clamps.shape[0]
    for i, (kind, row) in stacked.given.items():
        # A planned force may come back from the solver as -1e-12 N: given forces are >= 0.
        value = values[i]
        if kind == "finger":
            finger_values[row] = np.maximum(value, 0.0) / unit
        else:
            first = value if isinstance(value, float) else float(np.ravel(value)[0])
            clamp_values[row] = max(first, 0.0) / unit
    if fingers is not None:
        put(fingers, finger_values)
    if clamps is not None:
        put(clamps, np.array(clamp_values))
