"""What the planner reports: a verified :class:`Plan`."""

from __future__ import annotations

from dataclasses import MISSING, dataclass, field, fields

import numpy as np

from fixplan.planner.screw import Screw
from fixplan.tolerances import HELD_RTOL

STATUSES = ("optimal", "infeasible", "unbounded", "inaccurate", "solver-error")


@dataclass(frozen=True, kw_only=True)
class Plan:
    """The answer to a :class:`~fixplan.Problem`, verified in numpy before it is reported.

    Attributes
    ----------
    status : str
        ``"optimal"``, ``"infeasible"``, ``"unbounded"``, ``"inaccurate"`` (the solver's answer
        failed verification or the solver said so) or ``"solver-error"``.
    objective : str
        The objective solved.
    objective_value : float or None
        Total or largest force [N] for the force objectives; the smallest safety factor over
        the load cases for ``"max-safety-factor"``, ``"check"`` and ``"check-compliant"``.
    load_names, contact_names : tuple of str
        Order of the load cases and contacts in the arrays below.
    normal_forces : array (contacts, loads)
        Normal force of every contact in every load case [N] (at the task loads, or at the
        state of impending slip for the fixed-force objectives).
    contact_wrenches : array (contacts, loads, 4)
        ``(fn, ft1, ft2, mn)`` of every contact in its own frame [N, N m], same state.
    forces : dict
        Active contacts' normal forces [N]: a float for a clamp, an array over the load cases
        for a finger.
    safety_factors : dict
        Per load case: the largest factor by which its task load (not gravity) can be scaled
        while held with these active forces (``inf`` when no scale breaks the hold): the upper
        end of ``held_intervals``.
    safety_factor : float
        The smallest of ``safety_factors``.
    held_intervals : dict
        Per load case: ``(k_min, k_max)``, the multiples of its task load that are held with
        these active forces. ``k_min > 0`` when the active forces and the weight alone are not
        held (fingers or clamps that do not balance each other push the part out unless enough
        task load pushes back).
    held : dict
        Per load case: whether the task load itself is held (``k_min <= 1 <= k_max``).
    utilisation : array (contacts, loads)
        At the state of impending slip, the fraction of each contact's friction set its wrench
        uses (1 on the limit).
    motions : dict
        Per load case: the :class:`~fixplan.planner.screw.Screw` in which the body starts to slide when
        the task load exceeds its margin (``None`` when unbounded), from the dual of the
        equilibrium constraints.
    critical_load, critical_contact : str or None
        The load case with the smallest safety factor and its most used contact.
    certificate : str or None
        For an infeasible problem: which load case cannot be held and along which motion
        nothing resists it.
    infeasible_motions : dict
        For an infeasible problem: the unresisted motion per load case that cannot be held.
    squeeze_contacts : tuple of str
        Passive contacts that can squeeze each other (normal forces that cancel); the planner
        keeps them from doing so (:mod:`fixplan.planner.squeeze`) and says in ``warnings`` where
        the rigid solution relied on it.
    residual : float
        Largest relative equilibrium residual found by the verification.
    warnings : tuple of str
        Why the status is ``"inaccurate"``, and other caveats.
    solver : str
        The solver that produced the answer, with its method in parentheses where it matters:
        ``"dual simplex (direct)"``, ``"interior point (direct)"``, ``"CLARABEL (direct)"``,
        and for exact friction models ``"CLARABEL (osculating ellipsoids)"`` or
        ``"CLARABEL (cutting planes)"`` (once a planner has solved a program twice, its rounds
        are solved directly: by the compiled interior point where the program is small, else
        by Clarabel); blocks solved differently are listed, separated by commas.
    solve_time : float
        Wall time of the solve(s) [s].
    """

    status: str
    objective: str
    objective_value: float | None
    load_names: tuple[str, ...]
    contact_names: tuple[str, ...]
    normal_forces: np.ndarray | None = None
    contact_wrenches: np.ndarray | None = None
    forces: dict = field(default_factory=dict)
    safety_factors: dict = field(default_factory=dict)
    safety_factor: float | None = None
    held_intervals: dict = field(default_factory=dict)
    held: dict = field(default_factory=dict)
    utilisation: np.ndarray | None = None
    motions: dict = field(default_factory=dict)
    critical_load: str | None = None
    critical_contact: str | None = None
    certificate: str | None = None
    infeasible_motions: dict = field(default_factory=dict)
    squeeze_contacts: tuple[str, ...] = ()
    residual: float | None = None
    warnings: tuple[str, ...] = ()
    solver: str = ""
    solve_time: float = 0.0

    @classmethod
    def _of(cls, values: dict) -> Plan:
        """The plan of ``values`` by field name (the planner's, already checked), the others
        at their defaults: filled in at once rather than by the frozen ``__init__``, one
        ``object.__setattr__`` per field (2.7 µs instead of 8.5 for each plan of a control
        loop's re-solves)."""
        plan = object.__new__(cls)
        filled = plan.__dict__
        filled.update(_DEFAULTS)
        for name in _MADE_FRESH:
            filled[name] = {}
        filled.update(values)
        return plan

    @property
    def succeeded(self) -> bool:
        """Whether the status is ``"optimal"``."""
        return self.status == "optimal"

    def describe_held(self, load_name: str) -> str:
        """Whether load case ``load_name`` is held, and for which multiples of its task load,
        in words (e.g. ``"held for 0–2.05 × the task load"``)."""
        if load_name not in self.held_intervals:
            return "not analysed"
        low, high = self.held_intervals[load_name]
        span = (
            f"{_multiple(low)} × the task load and above"
            if np.isinf(high)
            else f"{_multiple(low)}–{_multiple(high)} × the task load"
        )
        if self.held.get(load_name):
            if np.isfinite(high) and high - low <= HELD_RTOL * high:
                return "held at the task load only, with no margin either way"
            return f"held for {span}"
        if low > 0.0:
            return (
                "not held even without the task load: the active forces themselves push the "
                f"part out (held only for {span})"
            )
        return f"not held: slides above {_multiple(high)} × the task load"

    def as_dict(self) -> dict:
        """JSON-ready description of the plan."""

        def number(x):
            x = float(x)
            return x if np.isfinite(x) else ("inf" if x > 0 else "-inf" if x < 0 else "nan")

        forces = {
            name: (number(v) if np.ndim(v) == 0 else [number(x) for x in v])
            for name, v in self.forces.items()
        }
        return {
            "status": self.status,
            "objective": self.objective,
            "objective_value": None
            if self.objective_value is None
            else number(self.objective_value),
            "forces_N": forces,
            "safety_factors": {k: number(v) for k, v in self.safety_factors.items()},
            "safety_factor": None if self.safety_factor is None else number(self.safety_factor),
            "held_intervals": {
                k: [number(low), number(high)] for k, (low, high) in self.held_intervals.items()
            },
            "held": dict(self.held),
            "held_descriptions": {name: self.describe_held(name) for name in self.held_intervals},
            "critical_load": self.critical_load,
            "critical_contact": self.critical_contact,
            "motions": {k: (None if m is None else m.as_dict()) for k, m in self.motions.items()},
            "certificate": self.certificate,
            "infeasible_motions": {k: m.as_dict() for k, m in self.infeasible_motions.items()},
            "contact_wrenches": None
            if self.contact_wrenches is None
            else {
                contact: {
                    load: [number(x) for x in self.contact_wrenches[i, j]]
                    for j, load in enumerate(self.load_names)
                }
                for i, contact in enumerate(self.contact_names)
            },
            "utilisation": None
            if self.utilisation is None
            else {
                contact: {
                    load: number(self.utilisation[i, j]) for j, load in enumerate(self.load_names)
                }
                for i, contact in enumerate(self.contact_names)
            },
            "squeeze_contacts": list(self.squeeze_contacts),
            "residual": self.residual,
            "warnings": list(self.warnings),
            "solver": self.solver,
        }


#: The fields of :class:`Plan` with a default value, and those with a new dict each.
_DEFAULTS = {f.name: f.default for f in fields(Plan) if f.default is not MISSING}
_MADE_FRESH = tuple(f.name for f in fields(Plan) if f.default_factory is dict)


def _multiple(value: float) -> str:
    """A multiple of a task load for words: 3 significant digits, 0 as 0."""
    return "0" if value == 0.0 else f"{value:.3g}"


__all__ = ["STATUSES", "Plan", "Screw"]
