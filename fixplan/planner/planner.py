r"""The convex fixture and grasp planner.

Every load case ``j`` must be in equilibrium,

.. math:: \sum_i G_i \, (f_{n,ij}, \ell_{ij}) + s_j W_j + W_g = 0,
   \qquad \ell_{ij} \in f_{n,ij} \, \mathcal F_i, \qquad f_{n,ij} \ge 0,

with ``G_i`` the map from contact ``i``'s normal force and friction load ``ℓ`` (``ft1, ft2[, mn]``)
to the body wrench about the world origin, ``F_i`` its friction model at unit normal force,
``W_j`` the task wrench and ``W_g`` gravity. Force objectives fix ``s_j = 1`` and minimise
normal forces; the fixed-force objectives maximise each ``s_j``. The cvxpy problem is built once
per structure with Parameters for the task wrenches, gravity and the fixed forces (it is DPP), so
new load values re-solve without rebuilding; small problems re-solve straight through Clarabel
(:mod:`fixplan.planner.direct_solve`), large ones (the sum-of-disks model) skip cvxpy's DPP compilation,
which costs more there than canonicalising afresh. The dual of the equilibrium constraint of a case is
the twist in which the body starts to slide (maximum power); for an infeasible problem it is the
motion that nothing resists.
"""

from __future__ import annotations

import time
import warnings
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import cvxpy as cp
import numpy as np

from fixplan.errors import FixplanError, InvalidArgumentError
from fixplan.planner.contact_models import contact_model
from fixplan.planner.direct_solve import DirectSolver
from fixplan.planner.plan import Plan
from fixplan.planner.problem import FIXED_FORCE_OBJECTIVES, PASSIVE_ROLES, Load, Problem
from fixplan.planner.screw import Screw
from fixplan.tolerances import (
    EQUILIBRIUM_RTOL,
    FRICTION_SET_RTOL,
    HELD_RTOL,
    MAX_SAFETY_FACTOR,
)

SOLVERS = ("CLARABEL", "OSQP", "SCS")
#: Suffix of the second stage of a force objective (clamps given, fingers minimised per case).
REFINE = "|refine"

#: Above this many scalar variables problems are solved without DPP (see Planner._call).
DPP_MAX_VARIABLES = 10_000

#: Load cases per compiled problem of the fixed-force objectives (their cases are independent).
CASES_PER_BLOCK = 32
_FALLBACK = {"CLARABEL": "SCS", "SCS": "CLARABEL", "OSQP": "CLARABEL"}
_SOLVER_OPTIONS = {
    "CLARABEL": {"tol_gap_abs": 1e-9, "tol_gap_rel": 1e-9, "tol_feas": 1e-9},
    "SCS": {"eps": 1e-9, "max_iters": 200_000},
    "OSQP": {"eps_abs": 1e-8, "eps_rel": 1e-8, "max_iter": 50_000, "polish": True},
}
#: Clarabel settings of the direct re-solves: iterative refinement of the KKT solves is off
#: (a third of the time on the fixture benchmark); every answer is verified in numpy anyway.
_DIRECT_OPTIONS = {**_SOLVER_OPTIONS["CLARABEL"], "iterative_refinement_enable": False}
_STATUS = {
    cp.OPTIMAL: "optimal",
    cp.OPTIMAL_INACCURATE: "inaccurate",
    cp.INFEASIBLE: "infeasible",
    cp.INFEASIBLE_INACCURATE: "infeasible",
    cp.UNBOUNDED: "unbounded",
    cp.UNBOUNDED_INACCURATE: "unbounded",
}


@dataclass(frozen=True, slots=True)
class _Built:
    """A compiled cvxpy problem and its handles."""

    problem: cp.Problem
    task: cp.Parameter
    gravity: cp.Parameter
    fixed: dict  # contact index -> Parameter of its fixed force
    normal: cp.Expression  # (contacts, loads)
    friction: cp.Variable  # (friction dims, loads)
    scale: cp.Expression  # (loads,) task-load scale factors
    balance: cp.Constraint


class Planner:
    """A problem's structure compiled to cvxpy, re-solvable with new load values.

    Parameters
    ----------
    problem : Problem
        The problem; its loads are the default load values.
    solver : str, optional
        ``"CLARABEL"`` (default), ``"OSQP"`` (LP/QP only: pyramid models) or ``"SCS"``.
    """

    def __init__(self, problem: Problem, *, solver: str | None = None):
        if not isinstance(problem, Problem):
            raise InvalidArgumentError(f"problem must be a Problem, got {type(problem).__name__}")
        solver = "CLARABEL" if solver is None else str(solver).upper()
        if solver not in SOLVERS:
            raise InvalidArgumentError(
                f"solver must be one of {', '.join(SOLVERS)}; got {solver!r}"
            )
        self.problem = problem
        self.solver = solver
        self.models = [contact_model(c) for c in problem.contacts]
        dims = [model.load_dimension for model in self.models]
        self._slices = []
        start = 0
        for d in dims:
            self._slices.append(slice(start, start + d))
            start += d
        self._normal_map = np.column_stack([c.wrench_basis()[:, 0] for c in problem.contacts])
        self._friction_map = np.hstack(
            [c.wrench_basis()[:, 1 : 1 + d] for c, d in zip(problem.contacts, dims, strict=True)]
        )
        positions = np.array([c.position for c in problem.contacts])
        spread = np.linalg.norm(positions - problem.body.center_of_mass, axis=1)
        self.length_scale = float(max(spread.max(), 1e-3))
        self._built: dict[str, _Built] = {}
        self._direct: dict[str, DirectSolver | None] = {}
        # The fixed-force objectives scale the task loads from 0: infeasible means the weight
        # (with the given forces) cannot be held.
        self._fixed_forces = problem.objective in FIXED_FORCE_OBJECTIVES
        self._solves: dict[str, int] = {}

    # -- building -----------------------------------------------------------------------------

    def _block_size(self, objective: str) -> int:
        """Load cases per compiled problem: fixed-force objectives split into blocks."""
        cases = len(self.problem.loads)
        return min(cases, CASES_PER_BLOCK) if objective in FIXED_FORCE_OBJECTIVES else cases

    def _build(self, objective: str) -> _Built:
        """The compiled problem of ``objective``; ``objective + REFINE`` is its second stage,
        with the clamp forces given (see :meth:`_refine`)."""
        if objective in self._built:
            return self._built[objective]
        contacts = self.problem.contacts
        cases = self._block_size(objective)
        scaling = objective in FIXED_FORCE_OBJECTIVES
        refine = objective.endswith(REFINE)
        task = cp.Parameter((6, cases), name="task_wrenches")
        gravity = cp.Parameter(6, name="gravity_wrench")
        friction = cp.Variable((self._friction_map.shape[1], cases), name="friction")
        rows, fixed, constraints = [], {}, []
        free_clamps, free_fingers, free = [], [], []
        ones = np.ones(cases)
        for i, contact in enumerate(contacts):
            if contact.role in PASSIVE_ROLES:
                row = cp.Variable(cases, nonneg=True, name=f"fn_{i}")
            elif scaling or contact.force is not None or (refine and contact.role == "clamp"):
                shape = () if contact.role == "clamp" else (cases,)
                fixed[i] = cp.Parameter(shape, nonneg=True, name=f"force_{i}")
                row = fixed[i] * ones if contact.role == "clamp" else fixed[i]
            else:
                if contact.role == "clamp":
                    variable = cp.Variable(nonneg=True, name=f"clamp_{i}")
                    free_clamps.append(variable)
                    row = variable * ones
                else:
                    variable = cp.Variable(cases, nonneg=True, name=f"finger_{i}")
                    free_fingers.append(variable)
                    row = variable
                free.append(i)
                if contact.max_force is not None:
                    constraints.append(variable <= contact.max_force)
            rows.append(cp.reshape(row, (1, cases), order="C"))
        normal = cp.vstack(rows)
        if scaling:
            scale = cp.Variable(cases, name="scale")
            constraints += [scale >= 0.0, scale <= MAX_SAFETY_FACTOR]
            task_term = task @ cp.diag(scale)
        else:
            scale = cp.Constant(ones)
            task_term = task
        gravity_term = cp.reshape(gravity, (6, 1), order="C") @ np.ones((1, cases))
        balance = (
            self._normal_map @ normal + self._friction_map @ friction + task_term + gravity_term
        )
        balance_constraint = balance == 0
        constraints.append(balance_constraint)
        for i, model in enumerate(self.models):
            for j in range(cases):
                constraints += model.constraints(friction[self._slices[i], j], normal[i, j])
        goal = self._objective(
            objective.removesuffix(REFINE), scale, normal[free, :], free_clamps, free_fingers
        )
        problem = cp.Problem(goal, constraints)
        if not problem.is_dcp(dpp=True):  # pragma: no cover - a model broke its contract
            raise FixplanError("internal error: the planning problem is not DPP")
        built = _Built(problem, task, gravity, fixed, normal, friction, scale, balance_constraint)
        self._built[objective] = built
        return built

    def _objective(self, objective, scale, free_forces, free_clamps, free_fingers):
        """The objective over the free active forces ``free_forces`` (rows: contacts).

        Given forces are constants and stay out of it, so that it does not go flat.
        """
        if objective in FIXED_FORCE_OBJECTIVES:
            return cp.Maximize(cp.sum(scale))
        # Without a free clamp the load cases are independent: minimising the sum of the per-case
        # worst values gives every case its own least forces, and the largest of them is the
        # min-max. A free clamp couples the cases, and then the max is minimised directly.
        worst = cp.max if free_clamps else cp.sum
        if objective == "min-total-clamp-force":
            total = cp.sum(cp.hstack(free_clamps)) if free_clamps else 0.0
            if free_fingers:
                total = total + worst(cp.sum(cp.vstack(free_fingers), axis=0))
            return cp.Minimize(total)
        active_forces = free_forces
        if objective == "min-max-normal-force":
            return cp.Minimize(worst(cp.max(active_forces, axis=0)))
        if objective == "min-total-normal-force":
            return cp.Minimize(worst(cp.sum(active_forces, axis=0)))
        return cp.Minimize(cp.sum_squares(active_forces))  # min-squared-normal-force

    # -- solving ------------------------------------------------------------------------------

    def solve(
        self,
        loads: Sequence[Load] | None = None,
        *,
        analyse: bool = True,
        progress: Callable[[int, int], None] | None = None,
    ) -> Plan:
        """Solve with ``loads`` (default: the problem's); the structure is reused.

        ``loads`` must have the problem's number of load cases. With ``analyse`` (default) a
        force objective is followed by the fixed-force analysis of the forces found (safety
        factors, impending motions, utilisation). ``progress(done, total)`` is called as load
        cases are solved (the fixed-force objectives solve them in blocks).
        """
        loads = self.problem.loads if loads is None else tuple(loads)
        if len(loads) != len(self.problem.loads) or not all(isinstance(x, Load) for x in loads):
            raise InvalidArgumentError(
                f"loads must be {len(self.problem.loads)} Load objects, one per load case"
            )
        objective = self.problem.objective
        wrenches = np.column_stack([load.wrench for load in loads])
        start = time.perf_counter()
        fixed_values = {
            i: c.force for i, c in enumerate(self.problem.contacts) if c.force is not None
        }
        result = self._run(objective, wrenches, fixed_values, progress)
        if result["status"] == "optimal":
            result = self._refine(objective, result, wrenches, fixed_values)
        plan_kwargs = {"load_names": tuple(x.name for x in loads)}
        status, solver = result["status"], result["solver"]
        notes = list(result["warnings"])
        if status == "infeasible":
            motions, certificate = self._certificate(result, wrenches, plan_kwargs["load_names"])
            return self._plan(
                status, objective, None, plan_kwargs, solver, start, notes,
                certificate=certificate, infeasible_motions=motions,
            )  # fmt: skip
        if status not in ("optimal", "inaccurate"):
            return self._plan(status, objective, None, plan_kwargs, solver, start, notes)
        normal, friction, scale = result["normal"], result["friction"], result["scale"]
        residual, problems = self._verify(normal, friction, scale, wrenches)
        if problems:
            status = "inaccurate"
            notes += problems
            for note in problems:
                warnings.warn(note, stacklevel=2)
        forces = self._active_forces(normal)
        analysis = result if objective in FIXED_FORCE_OBJECTIVES else None
        if objective not in FIXED_FORCE_OBJECTIVES and analyse and status == "optimal":
            fixed = {i: (f if np.ndim(f) == 0 else np.asarray(f)) for i, f in self._indexed(forces)}
            analysis = self._run("check", wrenches, fixed, progress)
            if analysis["status"] not in ("optimal", "inaccurate"):
                notes.append(f"safety analysis of the forces found: {analysis['status']}")
                analysis = None
        value = self._objective_value(objective, forces, scale)
        extra = self._analysis(analysis, wrenches, plan_kwargs["load_names"]) if analysis else {}
        if objective in FIXED_FORCE_OBJECTIVES and "safety_factor" in extra:
            value = extra["safety_factor"]
        return self._plan(
            status, objective, value, plan_kwargs, solver, start, notes,
            normal_forces=normal, contact_wrenches=self._wrenches(normal, friction),
            forces=forces, residual=residual, **extra,
        )  # fmt: skip

    def _refine(self, objective: str, result: dict, wrenches, fixed_values: dict) -> dict:
        """Second stage of a force objective whose free clamps couple the load cases.

        The first stage leaves the fingers of the non-critical cases anywhere below the
        critical value (the objective is flat there). With the clamp forces it found given,
        the cases are independent and each case's finger forces are minimised on their own.
        """
        contacts = self.problem.contacts
        free_clamps = [i for i, c in enumerate(contacts) if c.role == "clamp" and c.force is None]
        free_fingers = [i for i, c in enumerate(contacts) if c.role == "finger" and c.force is None]
        if objective in FIXED_FORCE_OBJECTIVES or not free_clamps or not free_fingers:
            return result
        given = dict(fixed_values)
        given.update({i: float(result["normal"][i, 0]) for i in free_clamps})
        refined = self._run(objective + REFINE, wrenches, given)
        return refined if refined["status"] == "optimal" else result

    def _indexed(self, forces):
        names = {c.name: i for i, c in enumerate(self.problem.contacts)}
        return [(names[name], value) for name, value in forces.items()]

    def _plan(self, status, objective, value, kwargs, solver, start, notes, **fields) -> Plan:
        return Plan(
            status=status,
            objective=objective,
            objective_value=value,
            contact_names=tuple(c.name for c in self.problem.contacts),
            solver=solver,
            solve_time=time.perf_counter() - start,
            warnings=tuple(notes),
            **kwargs,
            **fields,
        )

    def _run(self, objective: str, wrenches: np.ndarray, fixed_values: dict, progress=None) -> dict:
        """Solve all load cases, block by block for the fixed-force objectives.

        Their load cases are independent (the active forces are given), so a problem compiled
        for ``CASES_PER_BLOCK`` cases serves any number of them: each block only sets new
        Parameter values. The last block is padded with copies of its first case.
        """
        cases = wrenches.shape[1]
        block = self._block_size(objective)
        results = []
        for start in range(0, cases, block):
            index = np.arange(start, min(start + block, cases))
            padded = np.concatenate([index, np.full(block - len(index), index[0])])
            fixed = {
                i: (v if np.ndim(v) == 0 else np.broadcast_to(v, (cases,))[padded])
                for i, v in fixed_values.items()
            }
            result = self._run_block(objective, wrenches[:, padded], fixed)
            results.append((result, len(index)))
            if progress is not None:
                progress(int(index[-1]) + 1, cases)
        return _merge(results)

    def _run_block(self, objective: str, wrenches: np.ndarray, fixed_values: dict) -> dict:
        built = self._build(objective)
        built.task.value = wrenches
        built.gravity.value = self.problem.body.weight_wrench
        for i, parameter in built.fixed.items():
            value = fixed_values[i]
            parameter.value = (
                value if parameter.ndim == 0 else np.broadcast_to(value, parameter.shape)
            )
        direct = self._direct_result(objective, built)
        if direct is not None:
            return direct
        notes = []
        solver = self.solver
        status = self._call(built.problem, solver)
        if status == "optimal":
            self._prepare_direct(objective, built)
        if status in ("solver-error", "inaccurate"):
            fallback = _FALLBACK[solver]
            notes.append(f"{solver} returned {status}; retried with {fallback}")
            solver = fallback
            status = self._call(built.problem, solver)
        result = {"status": status, "solver": solver, "warnings": notes}
        if status in ("optimal", "inaccurate"):
            result["normal"] = np.asarray(built.normal.value, dtype=float)
            result["friction"] = np.asarray(built.friction.value, dtype=float)
            result["scale"] = np.asarray(built.scale.value, dtype=float).ravel()
        if status in ("optimal", "inaccurate", "infeasible"):
            dual = built.balance.dual_value
            result["dual"] = None if dual is None else np.asarray(dual, dtype=float)
        return result

    def _direct_result(self, objective: str, built: _Built) -> dict | None:
        """Solve straight through Clarabel when a direct solver exists for ``objective``.

        ``None`` sends the solve through cvxpy (see :meth:`_prepare_direct`).
        """
        direct = self._direct.get(objective)
        values = None if direct is None else direct.solve()
        if values is None:
            return None
        for variable in built.problem.variables():
            variable.save_value(values[variable.id])
        return {
            "status": "optimal",
            "solver": "CLARABEL (direct)",
            "warnings": [],
            "normal": np.asarray(built.normal.value, dtype=float),
            "friction": np.asarray(built.friction.value, dtype=float),
            "scale": np.asarray(built.scale.value, dtype=float).ravel(),
        }

    def _prepare_direct(self, objective: str, built: _Built) -> None:
        """Build the direct solver of a force objective after its second cvxpy solve.

        It is checked against that solve's answer (same parameters); one-off problems never
        pay for it.
        """
        if self.solver != "CLARABEL" or objective in FIXED_FORCE_OBJECTIVES:
            return
        if objective in self._direct or built.problem.status != cp.OPTIMAL:
            return
        if built.problem.size_metrics.num_scalar_variables > DPP_MAX_VARIABLES:
            return
        self._solves[objective] = self._solves.get(objective, 0) + 1
        if self._solves[objective] >= 2:
            self._direct[objective] = DirectSolver.create(built.problem, _DIRECT_OPTIONS)

    @staticmethod
    def _call(problem: cp.Problem, solver: str) -> str:
        # cvxpy's DPP compilation grows much faster than the problem: past DPP_MAX_VARIABLES
        # (e.g. the sum-of-disks model of many contacts) canonicalising afresh is far quicker.
        large = problem.size_metrics.num_scalar_variables > DPP_MAX_VARIABLES
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                problem.solve(solver=solver, ignore_dpp=large, **_SOLVER_OPTIONS[solver])
        except cp.error.SolverError as exc:
            if solver == "OSQP" and "QP" in str(exc):
                raise InvalidArgumentError(
                    "solver OSQP handles only LP/QP problems: use pyramid models "
                    "('pyramid', 'point-pyramid') or the default solver CLARABEL"
                ) from exc
            return "solver-error"
        except cp.error.DCPError as exc:  # pragma: no cover - guarded when building
            raise FixplanError(f"internal error: {exc}") from exc
        return _STATUS.get(problem.status, "solver-error")

    # -- verification and reporting ---------------------------------------------------------------

    def _verify(self, normal, friction, scale, wrenches) -> tuple[float, list[str]]:
        """Equilibrium residual and friction-set membership, checked in numpy."""
        problems = []
        gravity = self.problem.body.weight_wrench[:, None]
        normal_part = self._normal_map @ normal
        friction_part = self._friction_map @ friction
        task_part = wrenches * scale[None, :]
        residual = normal_part + friction_part + task_part + gravity
        magnitude = (
            np.abs(normal_part) + np.abs(friction_part) + np.abs(task_part) + np.abs(gravity)
        )
        # Per load case: its forces and moments against the wrench terms of that case.
        force_size = np.maximum(magnitude[:3].max(axis=0), 1e-12)
        moment_size = np.maximum(magnitude[3:].max(axis=0), force_size * self.length_scale)
        relative = 0.0
        for rows, unit, size in ((slice(0, 3), "N", force_size), (slice(3, 6), "N m", moment_size)):
            ratio = np.abs(residual[rows]).max(axis=0) / size
            relative = max(relative, float(ratio.max()))
            worst = int(np.argmax(ratio))
            if ratio[worst] > EQUILIBRIUM_RTOL:
                problems.append(
                    f"equilibrium residual of load case {worst + 1}: "
                    f"{ratio[worst] * size[worst]:.3g} {unit}, over {EQUILIBRIUM_RTOL:g} of the "
                    f"wrenches involved ({size[worst]:.3g} {unit})"
                )
        scale_force = max(float(np.abs(normal).max()), 1e-12)
        for i, (contact, model) in enumerate(zip(self.problem.contacts, self.models, strict=True)):
            fn = normal[i]
            if np.any(fn < -FRICTION_SET_RTOL * scale_force):
                problems.append(f"contact {contact.name!r} pulls: normal force {fn.min():.3g} N")
            load = friction[self._slices[i]].T
            pressed = fn > FRICTION_SET_RTOL * scale_force
            loose = ~pressed & (np.abs(load).max(axis=1) > FRICTION_SET_RTOL * scale_force)
            if np.any(loose):
                problems.append(f"contact {contact.name!r} carries friction without normal force")
            if np.any(pressed):
                safety = np.atleast_1d(model.safety_factor(load[pressed] / fn[pressed, None]))
                if np.any(safety < 1.0 - FRICTION_SET_RTOL):
                    problems.append(
                        f"contact {contact.name!r} exceeds its friction set by "
                        f"{1.0 / safety.min() - 1.0:.3g}"
                    )
        return relative, problems

    def _active_forces(self, normal) -> dict:
        forces = {}
        for i, contact in enumerate(self.problem.contacts):
            if contact.role == "clamp":
                forces[contact.name] = float(normal[i, 0])
            elif contact.role == "finger":
                forces[contact.name] = normal[i].copy()
        return forces

    def _objective_value(self, objective, forces, scale) -> float:
        contacts = {c.name: c for c in self.problem.contacts}
        if objective in FIXED_FORCE_OBJECTIVES:
            return float(scale.min())
        clamp = sum(v for k, v in forces.items() if contacts[k].role == "clamp")
        fingers = [v for k, v in forces.items() if contacts[k].role == "finger"]
        finger_total = np.sum(fingers, axis=0) if fingers else 0.0
        if objective == "min-total-clamp-force":
            return float(clamp + np.max(finger_total))
        per_case = [np.broadcast_to(v, scale.shape) for v in forces.values()]
        if objective == "min-max-normal-force":
            return float(np.max(per_case))
        if objective == "min-total-normal-force":
            return float(np.max(np.sum(per_case, axis=0)))
        return float(np.sum(np.square(per_case)))

    def _wrenches(self, normal, friction) -> np.ndarray:
        contacts, cases = normal.shape
        out = np.zeros((contacts, cases, 4))
        out[:, :, 0] = normal
        for i, part in enumerate(self._slices):
            values = friction[part].T
            out[i, :, 1 : 1 + values.shape[1]] = values
        return out

    def _analysis(self, result, wrenches, names) -> dict:
        """Safety factors, motions and utilisation from a fixed-force (scaling) solve."""
        scale = np.maximum(result["scale"], 0.0)  # the solver may return -1e-19 for 0
        safety = np.where(scale >= MAX_SAFETY_FACTOR * (1 - 1e-6), np.inf, scale)
        dual = result.get("dual")
        normal, friction = result["normal"], result["friction"]
        motions = {}
        for j, name in enumerate(names):
            twist = None if dual is None or not np.isfinite(safety[j]) else dual[:, j]
            if twist is not None and np.any(twist):
                twist = self._keep_contact(twist, normal[:, j])
            if twist is None or not np.any(twist):
                motions[name] = None
                continue
            twist = twist if wrenches[:, j] @ twist >= 0.0 else -twist
            motions[name] = Screw.from_twist(twist, self.length_scale)
        utilisation = np.zeros(normal.shape)
        for i, model in enumerate(self.models):
            fn = normal[i]
            pressed = fn > 1e-12 * max(1.0, float(np.abs(normal).max()))
            load = friction[self._slices[i]].T
            if np.any(pressed):
                utilisation[i, pressed] = 1.0 / np.atleast_1d(
                    model.safety_factor(load[pressed] / fn[pressed, None])
                )
        # Cases tied with the smallest safety factor (within solver accuracy): the first.
        critical = int(np.flatnonzero(safety <= safety.min() * (1.0 + HELD_RTOL))[0])
        return {
            "safety_factors": {name: float(s) for name, s in zip(names, safety, strict=True)},
            "safety_factor": float(safety.min()),
            "held": {
                name: bool(s >= 1.0 - HELD_RTOL) for name, s in zip(names, safety, strict=True)
            },
            "motions": motions,
            "utilisation": utilisation,
            "critical_load": names[critical],
            "critical_contact": self.problem.contacts[
                int(np.argmax(utilisation[:, critical]))
            ].name,
        }

    def _keep_contact(self, twist: np.ndarray, normal_forces: np.ndarray) -> np.ndarray:
        """The twist nearest ``twist`` in which every pressed contact stays in contact.

        The dual of the equilibrium is the associated flow of the Coulomb cones, which lifts a
        sliding contact off by ``mu`` times its sliding speed (dilatancy). Real contacts that
        press keep touching, so the normal velocity of the body at each pressed contact is
        projected out — unless that removes most of the motion (when the pressed contacts
        leave no sliding motion at all, one of them must lift off as it starts to slide); then
        the dual twist itself, which lifts no contact into the body, is the answer.
        """
        size = max(float(np.abs(normal_forces).max()), 1e-300)
        pressed = np.flatnonzero(normal_forces > FRICTION_SET_RTOL * size)
        if pressed.size == 0:
            return twist
        # Normal velocity of the body at contact i: n·(v + ω × p) = G_n[:, i] · (v, ω).
        rows = self._normal_map[:, pressed].T
        _, singular, basis = np.linalg.svd(rows)
        rank = int(np.sum(singular > 1e-9 * self.length_scale))
        free = basis[rank:]
        projected = free.T @ (free @ twist)
        kept = np.linalg.norm(projected) >= 0.5 * np.linalg.norm(twist)
        return projected if kept else twist

    def _certificate(self, result, wrenches, names) -> tuple[dict, str]:
        """The unresisted motions of an infeasible problem, in words."""
        dual = result.get("dual")
        if dual is None:
            return {}, "the problem is infeasible (the solver gave no certificate)"
        size = np.abs(dual).max()
        motions, lines = {}, []
        for j, name in enumerate(names):
            twist = dual[:, j]
            if size == 0.0 or np.abs(twist).max() <= 1e-6 * size:
                continue
            gravity = self.problem.body.weight_wrench
            load = wrenches[:, j] + gravity
            twist = twist if load @ twist >= 0.0 else -twist
            screw = Screw.from_twist(twist, self.length_scale)
            motions[name] = screw
            cause = " even without its task load (the weight alone)" if self._fixed_forces else ""
            lines.append(
                f"load case {name!r} cannot be held{cause}: nothing resists the motion in which "
                f"the body {screw.describe()}"
            )
        if not lines:
            return {}, "the problem is infeasible (the certificate is empty)"
        return motions, "; ".join(lines)


_SEVERITY = ("optimal", "inaccurate", "unbounded", "infeasible", "solver-error")


def _merge(results: list[tuple[dict, int]]) -> dict:
    """One result from the results of consecutive blocks (``(result, cases used)`` pairs)."""
    if len(results) == 1:
        result, used = results[0]
        return _trim(result, used)
    status = max((r["status"] for r, _ in results), key=_SEVERITY.index)
    merged = {
        "status": status,
        "solver": ", ".join(dict.fromkeys(r["solver"] for r, _ in results)),
        "warnings": [note for r, _ in results for note in r["warnings"]],
    }
    trimmed = [_trim(r, used) for r, used in results]
    keys = ("normal", "friction", "scale", "dual")
    for key in keys:
        parts = [r.get(key) for r in trimmed]
        if status == "infeasible" and key == "dual":
            parts = [
                p if r["status"] == "infeasible" else np.zeros((6, used))
                for p, r, (_, used) in zip(parts, trimmed, results, strict=True)
            ]
        if all(p is not None for p in parts):
            merged[key] = np.concatenate(parts, axis=-1)
    return merged


def _trim(result: dict, used: int) -> dict:
    """Drop the padding columns of a block's result."""
    trimmed = dict(result)
    for key in ("normal", "friction", "dual"):
        if trimmed.get(key) is not None:
            trimmed[key] = trimmed[key][:, :used]
    if "scale" in trimmed:
        trimmed["scale"] = trimmed["scale"][:used]
    return trimmed


def solve(problem: Problem, *, solver: str | None = None) -> Plan:
    """Solve ``problem`` (see :class:`Planner`); returns a verified :class:`Plan`."""
    return Planner(problem, solver=solver).solve()
