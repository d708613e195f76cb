"""Drake as the independent judge of a plan, with its hydroelastic pressure fields.

Each load case runs in the scene of :class:`~fixplan.sim.drake_scene.DrakeScene` three times, as
MuJoCo's judge (:mod:`fixplan.sim.validate`) does: the active forces times ``1 + margin`` with the
task load ramped to 1× and held (the plan says held, so no contact may slip more than
``HELD_DISPLACEMENT``), times ``1 - margin`` (a case on its limit must slip), and the planned
forces with the load ramped past the safety factor (the multiple at which a contact first slips
faster than ``SLIP_SPEED``). A run stops early once a contact has slipped ``STOP_SLIP``.

In the last run, when the task load reaches 1× (or the part starts to slide, if sooner), the
engine's pressure field of every area contact is read and compared with the profile the plan
assumed (:mod:`fixplan.sim.drake_fields`); the case is then re-planned with objective
``"check"`` at the planned forces, each area contact's model replaced by the exact limit surface
of its engine field, so that Drake's onset is compared both with the plan's safety factor and
with fixplan's exact limit surface of what the engine produced.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace

import numpy as np

from fixplan import validation
from fixplan.errors import ConvergenceError, InvalidArgumentError
from fixplan.planner.problem import Problem
from fixplan.sim.drake_fields import ContactField, contact_field
from fixplan.sim.validate import (
    HELD_DISPLACEMENT,
    SETTLE,
    SLIP_SPEED,
    CaseValidation,
    Run,
    lower_end,
    motion_angle,
    problem_length_scale,
    requested_cases,
)

#: Seconds for the task load to reach 1× in the held and slip runs, and seconds held after that.
RAMP, HOLD = 0.5, 0.5
#: Seconds for the onset run's ramp to ``ONSET_REACH`` times the safety factor.
ONSET_RAMP, ONSET_REACH = 1.0, 1.5
#: A run stops once a contact has slipped this far [m]: the verdict is settled.
STOP_SLIP = 5.0 * HELD_DISPLACEMENT
#: Steps between two samples of a run's history (10 ms at the scene's 1 ms step).
HISTORY_STRIDE = 10


@dataclass(frozen=True, slots=True, kw_only=True)
class DrakeCaseValidation(CaseValidation):
    """What Drake says about one load case of a plan (see :class:`CaseValidation`), with the
    engine's pressure fields.

    Attributes
    ----------
    fields : tuple of ContactField
        Per area contact, the engine's field at the planned forces and the task load (or at slip
        onset, if sooner) against the assumed profile.
    exact_safety_factor : float or None
        The case's safety factor at the planned forces with each area contact's model the exact
        limit surface of its engine field [-]; ``None`` when no multiple of the task load is
        held so (the planned forces do not even hold the part under gravity).
    """

    fields: tuple[ContactField, ...]
    exact_safety_factor: float | None

    @property
    def exact_onset_ratio(self) -> float | None:
        """Drake's slip-onset multiple over ``exact_safety_factor``."""
        if self.onset is None or self.onset.onset_multiple is None:
            return None
        if self.exact_safety_factor is None:
            return None
        return self.onset.onset_multiple / self.exact_safety_factor


def validate(
    problem: Problem,
    plan,
    *,
    margin: float = 0.1,
    loads: list[str] | None = None,
    length_scale: float | None = None,
    progress: Callable[[int, int], None] | None = None,
) -> list[DrakeCaseValidation]:
    """Simulate every load case of ``plan`` (or those named in ``loads``) in Drake;
    ``length_scale`` [m] weighs rotation against translation in the motion angle (default: the
    largest distance of a contact from the centre of mass).

    Raises :class:`~fixplan.errors.InvalidArgumentError` for a request or a problem the scene
    cannot model (see :func:`~fixplan.sim.drake_scene.patch_size`) and
    :class:`~fixplan.errors.MissingExtraError` without the ``drake`` extra.
    """
    from fixplan.sim.drake_scene import patch_size, require_drake

    if not isinstance(problem, Problem):
        raise InvalidArgumentError(f"problem must be a Problem, got {type(problem).__name__}")
    names = requested_cases(plan, margin, loads)
    for contact in problem.contacts:
        patch_size(contact)
    require_drake()
    scale = (
        problem_length_scale(problem)
        if length_scale is None
        else validation.positive_scalar("length_scale", length_scale)
    )
    found = []
    for done, name in enumerate(names):
        found.append(_judge_case(problem, plan, name, margin, scale))
        if progress is not None:
            progress(done + 1, len(names))
    return found


def _judge_case(
    problem: Problem, plan, name: str, margin: float, scale: float
) -> DrakeCaseValidation:
    """The three runs of load case ``name``, its engine fields and its exact re-check."""
    from fixplan.sim.drake_scene import DrakeScene

    case = plan.load_names.index(name)
    planned = _planned_forces(problem, plan, case)
    scene = DrakeScene(problem, _design_forces(plan, case))
    task = _task_about_center(problem, case)
    runs = {}
    for key, factor in (("above", 1 + margin), ("below", 1 - margin)):
        lowest = lower_end(problem, plan, name, factor)
        scene.start(factor * planned, task, lowest)
        runs[key], *_ = _run(scene, RAMP + HOLD, lowest, (1.0 - lowest) / RAMP, 1.0, read_at=None)
    # At the planned forces: the load ramped past the safety factor (to 1x where it is infinite,
    # for the fields only).
    safety = float(plan.safety_factors[name])
    finite = bool(np.isfinite(safety))
    lowest = min(float(plan.held_intervals[name][0]), 1.0)
    reach, seconds = (ONSET_REACH * safety, ONSET_RAMP) if finite else (1.0, RAMP)
    scene.start(planned, task, lowest)
    onset, patches, at_onset = _run(scene, seconds, lowest, (reach - lowest) / seconds, reach,
                                    read_at=1.0)  # fmt: skip
    at_onset = at_onset or [None] * len(problem.contacts)
    fields = tuple(
        contact_field(contact, patch, sliding)
        for contact, patch, sliding in zip(problem.contacts, patches, at_onset, strict=True)
        if patch is not None and contact.patch is not None and contact.has_torsion
    )
    onset = onset if finite else None
    motion = plan.motions.get(name) if plan.motions else None
    twist = onset.onset_twist if onset is not None else None
    twist = runs["below"].onset_twist if twist is None else twist
    angle = None if motion is None or twist is None else motion_angle(twist, motion.twist, scale)
    return DrakeCaseValidation(
        load=name, planned_held=bool(plan.held[name]), safety_factor=safety,
        above=runs["above"], below=runs["below"], onset=onset, motion_angle=angle,
        fields=fields, exact_safety_factor=exact_safety_factor(problem, plan, name, fields),
    )  # fmt: skip


def exact_safety_factor(problem: Problem, plan, load: str, fields) -> float | None:
    """The safety factor of case ``load`` at the plan's forces with each area contact of
    ``fields`` (:class:`ContactField`) modelled by the exact limit surface of its engine
    field; ``None`` if no multiple of the task load is held so.

    Raises :class:`~fixplan.errors.ConvergenceError` if the planner fails on that check."""
    from fixplan.planner.planner import Planner

    case = plan.load_names.index(load)
    engine = {item.contact: item.field for item in fields}
    forces = _planned_forces(problem, plan, case)
    contacts = []
    for contact, force in zip(problem.contacts, forces, strict=True):
        if contact.name in engine:
            contact = replace(contact, model="exact", patch=engine[contact.name], facets=None,
                              inscribed=None)  # fmt: skip
        if contact.is_active:
            contact = replace(contact, force=float(force))
        contacts.append(contact)
    single = replace(problem, contacts=tuple(contacts), loads=(problem.loads[case],),
                     objective="check")  # fmt: skip
    checked = Planner(single).solve()
    if checked.status == "infeasible":
        return None
    if checked.status != "optimal":
        raise ConvergenceError(
            f"load case {load!r}: the check with the exact limit surfaces of Drake's fields "
            f"ended {checked.status}: {'; '.join(checked.warnings) or 'no details'}"
        )
    return float(checked.safety_factors[load])


def _run(scene, seconds: float, start: float, rate: float, reach: float, *, read_at):
    """Ramp the task load from ``start`` at ``rate`` [1/s] up to ``reach`` for ``seconds``;
    returns the :class:`Run` and, with ``read_at``, the engine's patches when the load reaches
    that multiple or the part starts to slide, and when it starts to slide (``None`` if it
    does not)."""
    from fixplan.sim.drake_scene import TIME_STEP

    origin = previous = scene.slips()
    onset_multiple = onset_twist = patches = at_onset = None
    history = [_sample(0.0, origin - origin, scene.rotation(), start)]
    settle = round(SETTLE / TIME_STEP)
    for step in range(1, round(seconds / TIME_STEP) + 1):
        multiple = min(start + rate * step * TIME_STEP, reach)
        scene.load(multiple)
        time = scene.step()
        now = scene.slips()
        if onset_multiple is None:
            speed = np.linalg.norm(now[:, :3] - previous[:, :3], axis=1) + np.abs(
                now[:, 3] - previous[:, 3]
            )
            if step >= settle and np.max(speed) / TIME_STEP > SLIP_SPEED:
                onset_multiple, onset_twist = multiple, scene.twist()
                at_onset = scene.patches() if read_at is not None else None
        previous = now
        if (
            read_at is not None
            and patches is None
            and (multiple >= read_at or onset_multiple is not None)
        ):
            patches = scene.patches()
        slipped = now - origin
        largest = float(np.max(np.linalg.norm(slipped[:, :3], axis=1) + np.abs(slipped[:, 3])))
        if step % HISTORY_STRIDE == 0 or largest > STOP_SLIP:
            history.append(_sample(time, slipped, scene.rotation(), multiple))
        if largest > STOP_SLIP and (read_at is None or patches is not None):
            break
    if read_at is not None and patches is None:
        patches = scene.patches()
    history = np.array(history)
    run = Run(displacement=float(history[-1, 1]), rotation=float(history[-1, 2]),
              onset_multiple=onset_multiple, onset_twist=onset_twist, history=history)  # fmt: skip
    return run, patches, at_onset


def _sample(time: float, slipped: np.ndarray, rotation: float, multiple: float) -> tuple:
    """A history row: time [s], largest slip at a contact [m], rotation [rad], task multiple."""
    largest = float(np.max(np.linalg.norm(slipped[:, :3], axis=1) + np.abs(slipped[:, 3])))
    return (time, largest, rotation, multiple)


def _planned_forces(problem: Problem, plan, case: int) -> np.ndarray:
    """Each contact's planned normal force in case ``case`` [N] (0 for passive contacts)."""
    forces = np.zeros(len(problem.contacts))
    for index, contact in enumerate(problem.contacts):
        if contact.is_active:
            value = np.atleast_1d(plan.forces[contact.name])
            forces[index] = float(value[case] if value.size > 1 else value[0])
    return forces


def _design_forces(plan, case: int) -> np.ndarray:
    """The normal force [N] each contact's sphere is sized for: the plan's in that case, at
    least ``FORCE_FLOOR`` times the case's largest."""
    from fixplan.sim.drake_scene import FORCE_FLOOR

    forces = np.asarray(plan.normal_forces[:, case], dtype=float)
    largest = float(forces.max())
    if largest <= 0.0:
        raise InvalidArgumentError(
            f"load case {plan.load_names[case]!r}: the plan presses no contact, so no sphere "
            "can be sized from its normal forces"
        )
    return np.maximum(forces, FORCE_FLOOR * largest)


def _task_about_center(problem: Problem, case: int) -> np.ndarray:
    """Task wrench of case ``case``: force [N] and moment about the centre of mass [N m]."""
    task = problem.task_wrenches()[:, case]
    center = np.asarray(problem.body.center_of_mass, dtype=float)
    return np.r_[task[:3], task[3:] - np.cross(center, task[:3])]
