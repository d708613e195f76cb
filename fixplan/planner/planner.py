r"""The convex fixture and grasp planner.

Every load case ``j`` must be in equilibrium,

.. math:: \sum_i G_i \, (f_{n,ij}, \ell_{ij}) + k_j W_j + W_g = 0,
   \qquad \ell_{ij} \in f_{n,ij} \, \mathcal F_i, \qquad f_{n,ij} \ge 0,

with ``G_i`` the map from contact ``i``'s normal force and friction load ``ℓ`` (``ft1, ft2[, mn]``)
to the body wrench about the world origin, ``F_i`` its friction model at unit normal force,
``W_j`` the task wrench and ``W_g`` gravity. Force objectives fix ``k_j = 1`` and minimise
normal forces; the fixed-force objectives find the interval of multiples ``k_j`` held
(:mod:`fixplan.planner.analysis`), which the analysis of a force objective's forces takes, where
it can, from the force solve itself (:mod:`fixplan.planner.carried`). The problem is stacked
over all contacts and cases (:mod:`fixplan.planner.stacking`), compiled once with Parameters
for the loads and given forces and re-solved with new values (:mod:`fixplan.planner.runner`),
verified in numpy (:mod:`fixplan.planner.verify`); passive contacts may not squeeze each other
(:mod:`fixplan.planner.squeeze`, :mod:`fixplan.planner.unloading`). The dual of the equilibrium
constraint of a case is the twist in which the body starts to slide; for an infeasible problem
it is the motion that nothing resists (:mod:`fixplan.planner.certificate`).
"""

from __future__ import annotations

import time
import warnings
from collections.abc import Callable, Sequence

import numpy as np

from fixplan.errors import InvalidArgumentError
from fixplan.planner.analysis import StayingInContact, analyse_cases
from fixplan.planner.certificate import certificate
from fixplan.planner.contact_models import contact_models
from fixplan.planner.friction_use import FrictionUse
from fixplan.planner.objectives import ActiveForces
from fixplan.planner.plan import Plan
from fixplan.planner.problem import (
    FIXED_FORCE_OBJECTIVES,
    PASSIVE_ROLES,
    SOLVED_AS,
    Load,
    Problem,
)
from fixplan.planner.runner import Runner
from fixplan.planner.solver_calls import SOLVERS
from fixplan.planner.squeeze import squeezing
from fixplan.planner.stacking import REFINE, ContactLayout
from fixplan.planner.unloading import SqueezeFree
from fixplan.planner.verify import Verifier
from fixplan.surface.point_kernel import compiled_scalar
from fixplan.tolerances import HELD_RTOL, MULTIPLE_ATOL


class Planner:
    """A problem's structure compiled to cvxpy, re-solvable with new load values.

    Parameters
    ----------
    problem : Problem
        The problem; its loads are the default load values.
    solver : str, optional
        ``"CLARABEL"`` (default), ``"OSQP"`` (LP/QP only: pyramid models) or ``"SCS"``.
    allow_squeeze : bool, optional
        Let passive contacts squeeze each other, as a rigid model does (default ``False``; see
        :mod:`fixplan.planner.squeeze`: not conservative, for comparison only).
    switchable : bool, optional
        Compile a switch per contact, so that :meth:`solve` can leave contacts out
        (``disabled``) without recompiling: the layouts of :mod:`fixplan.design.layout`.
    """

    def __init__(
        self,
        problem: Problem,
        *,
        solver: str | None = None,
        allow_squeeze: bool = False,
        switchable: bool = False,
    ):
        if not isinstance(problem, Problem):
            raise InvalidArgumentError(f"problem must be a Problem, got {type(problem).__name__}")
        solver = "CLARABEL" if solver is None else str(solver).upper()
        if solver not in SOLVERS:
            raise InvalidArgumentError(
                f"solver must be one of {', '.join(SOLVERS)}; got {solver!r}"
            )
        self.problem = problem
        self.solver = solver
        self.models = contact_models(problem.contacts)
        self.layout = ContactLayout.of(problem, self.models)
        self.friction_use = FrictionUse(self.models, self.layout.slices)
        positions = np.array([c.position for c in problem.contacts])
        spread = np.linalg.norm(positions - problem.body.center_of_mass, axis=1)
        self.length_scale = float(max(spread.max(), 1e-3))
        self._passive = np.array([c.role in PASSIVE_ROLES for c in problem.contacts])
        self._contact_names = tuple(c.name for c in problem.contacts)
        self._index_of = {name: i for i, name in enumerate(self._contact_names)}
        self._active = ActiveForces(problem.contacts)
        #: The given normal forces [N] by contact index.
        self._given_forces = {
            i: c.force for i, c in enumerate(problem.contacts) if c.force is not None
        }
        free = [(i, c.role) for i, c in enumerate(problem.contacts) if c.force is None]
        self._free_clamps = [i for i, role in free if role == "clamp"]
        self._free_fingers = [i for i, role in free if role == "finger"]
        # Where each row of the stacked friction loads goes in the contact wrenches of a plan.
        self._friction_owner = np.concatenate(
            [np.full(part.stop - part.start, i) for i, part in enumerate(self.layout.slices)]
        ).astype(np.intp)
        self._friction_component = np.concatenate(
            [np.arange(1, 1 + part.stop - part.start) for part in self.layout.slices]
        ).astype(np.intp)
        self._staying = StayingInContact(self.layout.normal_map, self._passive, self.length_scale)
        self._verify = Verifier(problem, self.layout, self.friction_use, self.length_scale)
        passive_map = self.layout.normal_map[:, self._passive]
        squeezable = np.zeros(len(problem.contacts), dtype=bool)
        if not allow_squeeze:
            squeezable[self._passive] = squeezing(passive_map, self.length_scale)
        self.squeeze_contacts = tuple(
            c.name for c, s in zip(problem.contacts, squeezable, strict=True) if s
        )
        self.switchable = switchable
        self._runner = Runner(
            problem, self.layout, solver, squeeze=bool(self.squeeze_contacts), switchable=switchable
        )
        #: Solves whose passive contacts hold no squeeze (see :mod:`fixplan.planner.unloading`).
        self._squeeze_free = SqueezeFree(
            problem, self.layout, self._runner, length_scale=self.length_scale,
            squeezable=bool(self.squeeze_contacts),
        ).solve  # fmt: skip

    def solve(
        self,
        loads: Sequence[Load] | None = None,
        *,
        analyse: bool = True,
        progress: Callable[[int, int], None] | None = None,
        disabled: Sequence[str] = (),
    ) -> Plan:
        """Solve with ``loads`` (default: the problem's); the structure is reused.

        ``disabled`` names contacts left out of this solve (a planner built ``switchable``): they
        carry no force, and the answer is that of the problem without them (the plan still lists
        them, with zero forces).

        ``loads`` must have the problem's number of load cases. With ``analyse`` (default) a
        force objective is followed by the fixed-force analysis of the forces found (held
        intervals, safety factors, impending motions, utilisation). ``progress(done, total)`` is
        called as load cases are solved (the fixed-force objectives solve them in blocks).
        """
        loads = self.problem.loads if loads is None else tuple(loads)
        if len(loads) != len(self.problem.loads) or not all(isinstance(x, Load) for x in loads):
            raise InvalidArgumentError(
                f"loads must be {len(self.problem.loads)} Load objects, one per load case"
            )
        start = time.perf_counter()
        objective = SOLVED_AS.get(self.problem.objective, self.problem.objective)
        names = tuple(x.name for x in loads)
        wrenches = self.problem.task_wrenches(loads)
        off = self._switched_off(disabled)
        given = dict(self._given_forces)
        if off is not None:
            given.update({i: 0.0 for i in given if off[i]})
        squeezed: dict[int, tuple[str, ...]] = {}
        result = self._squeeze_free(
            objective, wrenches, given, squeezed, progress=progress, disabled=off
        )
        if result["status"] == "optimal":
            result = self._refine(objective, result, wrenches, given, squeezed, off)
        notes = list(result["warnings"])
        fields = {"load_names": names, "squeeze_contacts": self.squeeze_contacts}
        status = result["status"]
        if status == "infeasible":
            fixed = objective in FIXED_FORCE_OBJECTIVES
            motions, words = certificate(
                names, result.get("dual"), wrenches, self._applied(wrenches, given, fixed),
                fixed_forces=fixed, length_scale=self.length_scale,
            )  # fmt: skip
            fields.update(certificate=words, infeasible_motions=motions)
        if status not in ("optimal", "inaccurate"):
            notes += self._squeeze_notes(squeezed, names)
            return self._plan(status, None, result["solver"], start, notes, fields)
        residual, problems, use = self._verify(result, wrenches)
        if problems and result["solver"].startswith(("CLARABEL", "dual simplex", "interior point")):
            retry = self._squeeze_free(
                objective, wrenches, given, squeezed, accurate=True, disabled=off
            )
            if retry["status"] == "optimal":
                result = self._refine(objective, retry, wrenches, given, squeezed, off)
                residual, problems, use = self._verify(result, wrenches)
        if problems:
            status = "inaccurate"
            notes += problems
            for note in problems:
                warnings.warn(note, stacklevel=2)
        forces = self._active.forces(result["normal"])
        if objective in FIXED_FORCE_OBJECTIVES:
            extra = self._intervals(names, result, wrenches, given, progress, off)
        elif analyse and status == "optimal":
            extra, note = self._analysis(names, result, use, wrenches, forces, squeezed, progress,
                                         off)  # fmt: skip
            if note is not None:
                notes.append(note)
        else:
            extra = {}
        value = self._active.value(objective, forces, result["scale"])
        if objective in FIXED_FORCE_OBJECTIVES and "safety_factor" in extra:
            value = extra["safety_factor"]
        notes += self._squeeze_notes(squeezed, names)
        fields.update(
            normal_forces=result["normal"], forces=forces, residual=residual,
            contact_wrenches=self._wrenches(result["normal"], result["friction"]), **extra,
        )  # fmt: skip
        return self._plan(status, value, result["solver"], start, notes, fields)

    # -- stages -------------------------------------------------------------------------------

    def _analysis(
        self, names, result, use, wrenches, forces, squeezed, progress, disabled
    ) -> tuple[dict, str | None]:
        """The safety analysis of a force objective's optimum ``result`` (its friction ``use``,
        verified; its active ``forces`` by name): the plan's fields and a note where it failed
        or missed the multiple 1 of a load case.

        The optimum holds every case at multiple 1 (verified: its residuals are within the
        tolerances of its forces), so a case whose held interval misses 1 by more than
        ``HELD_RTOL`` (or a ``check`` found infeasible) misses it by the solver's accuracy: it
        is held, and the note says how sensitive its multiples are."""
        planned = {self._index_of[name]: f for name, f in forces.items()}
        ends = self._carried_ends(wrenches, planned, progress, disabled)
        if "highest" in ends:  # the force solve's loads, verified just now
            ends["highest"].update(normal=result["normal"], friction=result["friction"], use=use)
        checked = ends.get("highest") or ends.get("solved")
        if checked is None:
            checked = self._squeeze_free(
                "check", wrenches, planned, squeezed, progress=progress, disabled=disabled
            )
        if checked["status"] == "infeasible":
            return {}, _sensitive_note(None)
        if checked["status"] != "optimal" and checked["status"] != "inaccurate":
            return {}, f"safety analysis of the forces found: {checked['status']}"
        extra = self._intervals(names, checked, wrenches, planned, progress, disabled,
                                lowest=ends.get("lowest"))  # fmt: skip
        missed = {n: v for n, v in extra["held_intervals"].items() if not extra["held"][n]}
        if not missed:
            return extra, None
        extra["held"].update(dict.fromkeys(missed, True))
        return extra, _sensitive_note(missed)

    def _switched_off(self, disabled: Sequence[str]) -> np.ndarray | None:
        """``(C,)`` bool of the contacts named in ``disabled`` (``None`` for none)."""
        disabled = tuple(disabled)
        if not disabled:
            return None
        names = [c.name for c in self.problem.contacts]
        if not self.switchable:
            raise InvalidArgumentError("disabled needs a planner built with switchable=True")
        unknown = sorted(set(disabled) - set(names))
        if unknown:
            raise InvalidArgumentError(f"disabled names unknown contacts: {', '.join(unknown)}")
        return np.isin(names, disabled)

    def _refine(self, objective, result, wrenches, given, squeezed, disabled=None) -> dict:
        """Second stage of a force objective whose free clamps couple the load cases.

        The first stage leaves the fingers of the non-critical cases anywhere below the
        critical value (the objective is flat there). With the clamp forces it found given,
        the cases are independent and each case's finger forces are minimised on their own.
        """
        if objective in FIXED_FORCE_OBJECTIVES or not self._free_clamps or not self._free_fingers:
            return result
        fixed = dict(given)
        fixed.update({i: float(result["normal"][i, 0]) for i in self._free_clamps})
        refined = self._squeeze_free(
            objective + REFINE, wrenches, fixed, squeezed, disabled=disabled
        )
        return refined if refined["status"] == "optimal" else result

    def _intervals(
        self, names, highest, wrenches, given, progress, disabled=None, lowest=None
    ) -> dict:
        """Held intervals, motions and utilisation of the given forces in the load cases
        ``names`` (``highest``: the maximising fixed-force solve; ``lowest``: the minimising one,
        solved here if ``None``)."""
        if lowest is None:
            lowest = self._lowest(wrenches, given, progress, disabled)
        if lowest["status"] not in ("optimal", "inaccurate"):
            lowest = None
        return analyse_cases(names, self._contact_names, self.friction_use, self._staying,
                             highest, lowest, wrenches, self.length_scale)  # fmt: skip

    def _carried_ends(self, wrenches, given, progress, disabled=None) -> dict:
        """The ends of the held interval of a single load case that the force solve just made
        certifies for its forces ``given``, and its maximising solve where it certifies none (see
        :meth:`~fixplan.planner.runner.Runner.carried_ends`; not with squeezable contacts, whose
        unloading is per solve)."""
        if self.squeeze_contacts:
            return {}
        ends = self._runner.carried_ends(wrenches, given, disabled)
        if ("highest" in ends or "solved" in ends) and progress is not None:
            progress(1, 1)
        return ends

    def _lowest(self, wrenches, given, progress, disabled=None) -> dict:
        """The minimising fixed-force solve: ``scale`` holds ``k_min`` of every case.

        (Its unloaded squeezes stay out of the plan's notes: near ``k = 0`` every choice ties,
        and the notes name the unloadings behind the forces and safety factors reported.)

        At ``k = 0`` the task load drops out, so whether a case is held without it depends only
        on its given forces: one case per distinct column of given forces is solved first, and
        the cases that share a column held at 0 have ``k_min = 0`` without a solve of their own.
        (With squeezable passive contacts every case is solved: their unloading is per case.)
        Where the last direct solve of ``check`` was of these cases and forces (the maximising
        solve just before), only the sense is written into its parameter vector
        (:meth:`~fixplan.planner.runner.Runner.with_sense`).
        """

        def minimised(index, report=None):
            values = {i: v if np.ndim(v) == 0 else np.asarray(v)[index] for i, v in given.items()}
            return self._squeeze_free(
                "check", wrenches[:, index], values, {}, sense=-1.0, progress=report,
                disabled=disabled, cases=index,
            )  # fmt: skip

        cases = wrenches.shape[1]
        if not self.squeeze_contacts:
            if self._runner.held_without_load(wrenches, given, disabled):
                if progress is not None:
                    progress(cases, cases)
                return {"status": "optimal", "scale": np.zeros(cases)}
            found = self._runner.with_sense("check", wrenches, given, -1.0, disabled)
            if found is not None:
                if progress is not None:
                    progress(cases, cases)
                return found
        if self.squeeze_contacts or not given or cases == 1:
            return minimised(np.arange(cases), progress)
        columns = np.vstack([np.broadcast_to(v, (cases,)) for v in given.values()])
        _, first, group = np.unique(columns.T, axis=0, return_index=True, return_inverse=True)
        representatives = minimised(first)
        if representatives["status"] not in ("optimal", "inaccurate"):
            return minimised(np.arange(cases), progress)
        scale = np.zeros(cases)
        rest = np.flatnonzero(representatives["scale"][np.ravel(group)] >= MULTIPLE_ATOL)
        if rest.size:
            solved = minimised(rest)
            if solved["status"] not in ("optimal", "inaccurate"):
                return minimised(np.arange(cases), progress)
            scale[rest] = solved["scale"]
        if progress is not None:
            progress(cases, cases)
        return {"status": "optimal", "scale": scale}

    def _applied(self, wrenches, given, fixed_forces: bool) -> np.ndarray:
        """The wrenches ``(6, K)`` that no contact of the program decides: gravity, the
        ``given`` normal forces and, unless the forces are fixed (then the task load's multiple
        is decided), the task ``wrenches``."""
        cases = wrenches.shape[1]
        applied = np.zeros((6, cases)) if fixed_forces else np.array(wrenches, dtype=float)
        applied += self.problem.body.weight_wrench[:, None]
        for i, force in given.items():
            applied += self.layout.normal_map[:, i, None] * np.broadcast_to(force, (cases,))
        return applied

    # -- reporting ----------------------------------------------------------------------------

    def _squeeze_notes(self, squeezed: dict, names: tuple) -> list[str]:
        """The note on the passive contacts unloaded (``squeezed``: by load case number) in
        the load cases ``names``."""
        if not squeezed:
            return []
        cases = "; ".join(
            f"{names[case]!r}: {', '.join(unloaded)}" for case, unloaded in squeezed.items()
        )
        return [
            f"passive contacts {', '.join(self.squeeze_contacts)} can squeeze each other "
            "(normal forces that cancel, which no active force or load applies); the rigid "
            f"solution relied on such a squeeze, so these contacts were unloaded: {cases}. "
            "The compliant analysis gives the determinate forces."
        ]

    def _plan(self, status, value, solver, start, notes, fields) -> Plan:
        fields.update(status=status, objective=self.problem.objective, objective_value=value,
                      contact_names=self._contact_names, solver=solver, warnings=tuple(notes),
                      solve_time=time.perf_counter() - start)  # fmt: skip
        return Plan._of(fields)

    def _wrenches(self, normal, friction) -> np.ndarray:
        """The contact wrenches ``(C, K, 4)`` of ``normal`` ``(C, K)`` and ``friction``
        ``(D, K)``."""
        out = np.zeros((*normal.shape, 4))
        _PLACED(normal, friction, self._friction_owner, self._friction_component, out)
        return out


def _sensitive_note(intervals: dict | None) -> str:
    """The note on the load cases whose held ``intervals`` in the analysis of a force
    objective's optimum miss 1 by more than ``HELD_RTOL`` (``None``: the analysis found the
    forces held at no multiple), though its verified forces hold them at 1."""
    if intervals is None:
        found = "at no multiple of the loads"
    else:
        found = "only at " + "; ".join(
            f"{name!r}: {low:.9g} to {high:.9g} times its load"
            for name, (low, high) in intervals.items()
        )
    return (
        f"the safety analysis of the forces found holds them {found}, which misses 1 by more "
        f"than {HELD_RTOL:g}; the force solve holds every load case at 1 within the solver's "
        "accuracy (about 1e-9 of the largest force), so they count as held: their multiples "
        "are that sensitive to the forces here (forces far larger than the loads they hold, or "
        "that must cancel a load component exactly). Give the loads a margin or the contacts "
        "more friction for a safety factor that means something."
    )


def placed_wrenches(normal, friction, owner, component, out):  # pragma: no cover - compiled
    """Put ``normal`` ``(C, K)`` and ``friction`` ``(D, K)`` into the contact wrenches ``out``
    ``(C, K, 4)``: row ``d`` of ``friction`` is component ``component[d]`` of contact
    ``owner[d]``."""
    for i in range(normal.shape[0]):
        for k in range(normal.shape[1]):
            out[i, k, 0] = normal[i, k]
    for d in range(friction.shape[0]):
        for k in range(friction.shape[1]):
            out[owner[d], k, component[d]] = friction[d, k]


_PLACED = compiled_scalar(placed_wrenches)


def solve(problem: Problem, *, solver: str | None = None) -> Plan:
    """Solve ``problem`` (see :class:`Planner`); returns a verified :class:`Plan`."""
    return Planner(problem, solver=solver).solve()
