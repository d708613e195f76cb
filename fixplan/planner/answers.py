"""What a solve of a stacked problem answers: normal forces, friction loads, multiples and the
equilibrium's multipliers, read from the direct solver or the cvxpy variables, put back in
newtons, and joined across the blocks of load cases."""

from __future__ import annotations

from dataclasses import dataclass

import cvxpy as cp
import numpy as np

from fixplan.planner.direct_solve import DirectSolver
from fixplan.planner.problem import FIXED_FORCE_OBJECTIVES
from fixplan.planner.stacking import REFINE, Stacked, normal_forces

#: Statuses from best to worst: results joined across blocks take the worst.
SEVERITY = ("optimal", "inaccurate", "unbounded", "infeasible", "solver-error")


def in_newtons(result: dict, unit: float, objective: str) -> dict:
    """``result`` of a program solved in the force ``unit`` [N], in newtons.

    The equilibrium multipliers scale as the objective over the wrenches: by ``1 / unit`` for
    the fixed-force objectives (dimensionless multiples) and the squared forces, not at all for
    the force objectives linear in the forces."""
    if unit == 1.0:
        return result
    for key in ("normal", "friction"):
        if result.get(key) is not None:
            result[key] = result[key] * unit
    if result.get("dual") is not None:
        objective = objective.removesuffix(REFINE)
        if objective in FIXED_FORCE_OBJECTIVES or objective == "min-squared-normal-force":
            result["dual"] = result["dual"] / unit
    return result


def values_of(stacked: Stacked, solved: dict | None = None) -> dict:
    """Normal forces, friction loads and multiples of the last solve: from the cvxpy variables,
    or from the direct solver's values by variable id (``solved``)."""
    if solved is None:
        friction, scale = stacked.friction.value, stacked.scale.value
    else:
        friction = solved[stacked.friction.id]
        scale = stacked.scale.value  # (a constant for force objectives)
        if isinstance(stacked.scale, cp.Variable):
            scale = solved[stacked.scale.id]
    return {
        "normal": normal_forces(stacked, solved),
        "friction": np.asarray(friction, dtype=float),
        "scale": np.ravel(scale).astype(float),
    }


@dataclass(frozen=True, slots=True)
class Reader:
    """Where a direct solve's answer sits, for
    :meth:`~fixplan.planner.direct_solve.DirectSolver.gather`: the normal forces ``(C, K)``,
    friction loads ``(D, K)`` and, where they are variables, the multiples ``(K,)``, flattened
    in that order (``scale``: the constant multiples of a force objective instead); whether all
    are variables' (``solution_only``: no given normal force read from the parameters). Read so
    in about 5.5 µs, where the values by variable id take 17."""

    positions: np.ndarray
    normal_shape: tuple[int, int]
    friction_shape: tuple[int, int]
    scale: np.ndarray | None
    solution_only: bool

    @classmethod
    def of(cls, stacked: Stacked, direct: DirectSolver) -> Reader | None:
        """The reader of ``stacked``'s answer; ``None`` where a part is unknown to ``direct``."""
        normal = np.full((len(stacked.decided), stacked.task.shape[1]), -1)
        for index, piece in stacked.normal_parts:
            found = direct.positions(piece)
            if found is None:
                return None
            normal[index] = found.reshape((len(index), -1), order="F")  # (a clamp's: every case)
        variables = [stacked.friction]
        constant = None
        if isinstance(stacked.scale, cp.Variable):
            variables.append(stacked.scale)
        else:
            constant = np.ravel(stacked.scale.value).astype(float)
        flat = [normal.ravel()]
        for variable in variables:
            found = direct.positions(variable)
            if found is None:
                return None
            flat.append(found.reshape(variable.shape, order="F").ravel())
        positions = np.concatenate(flat)
        solution_only = bool(np.all((positions >= 0) & (positions < direct.variables)))
        return cls(positions, normal.shape, stacked.friction.shape, constant, solution_only)

    def __call__(self, direct: DirectSolver, point: tuple | None = None) -> dict:
        """Normal forces, friction loads and multiples of ``direct``'s last solve (or of
        ``point``, an ``x`` of its program and the parameter vector it was found at)."""
        values = direct.gather(self.positions, solution_only=self.solution_only, point=point)
        normal_size = self.normal_shape[0] * self.normal_shape[1]
        friction_end = normal_size + self.friction_shape[0] * self.friction_shape[1]
        return {
            "normal": values[:normal_size].reshape(self.normal_shape),
            "friction": values[normal_size:friction_end].reshape(self.friction_shape),
            "scale": values[friction_end:] if self.scale is None else self.scale.copy(),
        }


def joined(solvers) -> str:
    """Solver names (each possibly a comma-separated list) as one list without repeats."""
    return ", ".join(dict.fromkeys(name for names in solvers for name in names.split(", ")))


def merge_blocks(results: list[tuple[dict, int]]) -> dict:
    """One result from the results of consecutive blocks (``(result, cases used)`` pairs)."""
    if len(results) == 1:
        result, used = results[0]
        return trim_padding(result, used)
    status = max((r["status"] for r, _ in results), key=SEVERITY.index)
    merged = {
        "status": status,
        "solver": joined(r["solver"] for r, _ in results),
        "warnings": [note for r, _ in results for note in r["warnings"]],
    }
    trimmed = [trim_padding(r, used) for r, used in results]
    for key in ("normal", "friction", "scale", "dual", "known_use"):
        parts = [r.get(key) for r in trimmed]
        if status == "infeasible" and key == "dual":
            parts = [
                p if r["status"] == "infeasible" else np.zeros((6, used))
                for p, r, (_, used) in zip(parts, trimmed, results, strict=True)
            ]
        if all(p is not None for p in parts):
            merged[key] = np.concatenate(parts, axis=-1)
    return merged


def trim_padding(result: dict, used: int) -> dict:
    """Drop the padding columns of a block's result."""
    trimmed = dict(result)
    for key in ("normal", "friction", "dual", "known_use"):
        if trimmed.get(key) is not None:
            trimmed[key] = trimmed[key][:, :used]
    if "scale" in trimmed:
        trimmed["scale"] = trimmed["scale"][:used]
    return trimmed
