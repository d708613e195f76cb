"""MuJoCo as the independent judge of a plan: held or slipped, in which motion, at what load.

For each load case the plan's scene (:func:`~fixplan.sim.mjcf.to_mjcf`) is simulated three
times:

- with the active forces scaled up by the margin, the task load ramped to 1× (from the lower end
  of the held interval of the scaled forces, which the planner gives) and held: the plan
  says *held*, so no contact may slip (``HELD_DISPLACEMENT``, measured as :func:`simulate`
  says);
- scaled down by the margin: a case on its limit (a least-force plan's critical case) must slip;
  the part's twist when it starts to slide is compared with the plan's impending motion;
- at the planned forces with the task load ramped past the plan's safety factor: the multiple at
  which the part starts to slide (its speed passes ``SLIP_SPEED``) against the safety factor.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace

import numpy as np

from fixplan.errors import InvalidArgumentError
from fixplan.planner.problem import Problem
from fixplan.sim.mjcf import to_mjcf

#: Held: no contact slipped by more than this [m] over the whole run (see :func:`simulate`).
HELD_DISPLACEMENT = 1e-3
#: The part slides once a contact slips faster than this [m/s] (tangential speed of its tip
#: against its pad plus spin about its normal times its radius), after ``SETTLE`` seconds in
#: which the soft contacts take up the forces.
SLIP_SPEED = 1e-4
SETTLE = 0.1
#: Steps between two samples of a run's history (10 ms at the scene's 0.5 ms step).
HISTORY_STRIDE = 20
#: Seconds for the task load to reach 1× in the held and slip runs, and seconds held after that.
RAMP, HOLD = 1.0, 0.5
#: Seconds for the onset run's ramp from 0 to ``ONSET_REACH`` times the safety factor.
ONSET_RAMP, ONSET_REACH = 2.0, 1.5


@dataclass(frozen=True, slots=True, kw_only=True)
class Run:
    """One simulation: the largest slip at a contact [m] (held below ``HELD_DISPLACEMENT``) and
    the part's rotation [rad] at the end, and where it started to slide (``None`` if it never did): the task-load multiple then
    and the part's twist ``(v at the world origin [m/s], ω [rad/s])``."""

    displacement: float
    rotation: float
    onset_multiple: float | None
    onset_twist: np.ndarray | None
    #: ``(samples, 4)``: time [s], largest slip at a contact [m], rotation [rad], task multiple.
    history: np.ndarray

    @property
    def held(self) -> bool:
        return bool(self.displacement < HELD_DISPLACEMENT)


@dataclass(frozen=True, slots=True, kw_only=True)
class CaseValidation:
    """What MuJoCo says about one load case of a plan.

    Attributes
    ----------
    load : str
        The load case.
    planned_held, safety_factor : bool, float
        What the plan says.
    above, below : Run
        The runs with the active forces scaled by ``1 + margin`` and ``1 - margin``.
    onset : Run or None
        The run at the planned forces with the load ramped past the safety factor (``None``
        where the safety factor is infinite).
    motion_angle : float or None
        Angle [rad] between the simulated twist at slip onset (of the onset run, else the
        ``below`` run) and the plan's impending motion, both as ``(v, L ω)`` with the plan's length
        scale ``L``; ``None`` where the part did not slide or the plan has no motion.
    """

    load: str
    planned_held: bool
    safety_factor: float
    above: Run
    below: Run
    onset: Run | None
    motion_angle: float | None

    @property
    def contradicts(self) -> bool:
        """Whether the plan calls the case held and the simulation lets it slip."""
        return self.planned_held and not self.above.held

    @property
    def onset_ratio(self) -> float | None:
        """Simulated slip-onset multiple over the plan's safety factor."""
        if self.onset is None or self.onset.onset_multiple is None:
            return None
        return self.onset.onset_multiple / self.safety_factor


def validate(
    problem: Problem,
    plan,
    *,
    margin: float = 0.1,
    loads: list[str] | None = None,
    length_scale: float | None = None,
    progress: Callable[[int, int], None] | None = None,
) -> list[CaseValidation]:
    """Simulate every load case of ``plan`` (or those named in ``loads``) in MuJoCo;
    ``length_scale`` [m] weighs rotation against translation in the motion angle (default: the
    largest distance of a contact from the centre of mass)."""
    names = requested_cases(plan, margin, loads)
    scale = problem_length_scale(problem) if length_scale is None else length_scale
    found = []
    for done, name in enumerate(names):
        safety = float(plan.safety_factors[name])
        runs = {}
        for key, factor in (("above", 1 + margin), ("below", 1 - margin)):
            lowest = lower_end(problem, plan, name, factor)  # where the ramp starts
            ramp = RAMP / (1.0 - lowest) if lowest < 1.0 else RAMP
            scene = to_mjcf(problem, plan, load=name, scale=factor, ramp=ramp, max_multiple=1.0,
                            start=lowest)  # fmt: skip
            runs[key] = simulate(scene, RAMP + HOLD, problem, scale)
        above, below = runs["above"], runs["below"]
        onset = None
        lowest = min(float(plan.held_intervals[name][0]), 1.0)
        if np.isfinite(safety):
            reach = ONSET_REACH * safety
            scene = to_mjcf(problem, plan, load=name, ramp=ONSET_RAMP / (reach - lowest),
                            max_multiple=reach, start=lowest)  # fmt: skip
            onset = simulate(scene, ONSET_RAMP, problem, scale)
        motion = plan.motions.get(name) if plan.motions else None
        # The plan's motion is that at the top of the held interval: the onset run's slide.
        twist = onset.onset_twist if onset is not None else None
        twist = below.onset_twist if twist is None else twist
        angle = (
            None if motion is None or twist is None else motion_angle(twist, motion.twist, scale)
        )
        found.append(CaseValidation(load=name, planned_held=bool(plan.held[name]),
                                    safety_factor=safety, above=above, below=below, onset=onset,
                                    motion_angle=angle))  # fmt: skip
        if progress is not None:
            progress(done + 1, len(names))
    return found


def requested_cases(plan, margin: float, loads: list[str] | None) -> list[str]:
    """The load cases to simulate (all of ``plan``'s, or ``loads``), once ``margin`` and the plan
    are checked: an optimal plan with forces, a margin between 0 and 1, known case names."""
    if not 0.0 < margin < 1.0:
        raise InvalidArgumentError(f"margin must be between 0 and 1, got {margin!r}")
    if plan.status != "optimal" or plan.forces is None:
        raise InvalidArgumentError(
            f"only an optimal plan can be simulated; this one is {plan.status}"
        )
    names = list(plan.load_names) if loads is None else list(loads)
    unknown = [name for name in names if name not in plan.load_names]
    if unknown:
        raise InvalidArgumentError(
            f"unknown load case {unknown[0]!r}; the plan's are {', '.join(map(repr, plan.load_names))}"
        )
    return names


def lower_end(problem: Problem, plan, load: str, factor: float) -> float:
    """Where a run with the active forces of case ``load`` scaled by ``factor`` starts its ramp:
    the lower end of the held interval of those forces (at most 1), from the planner (a part
    that the forces alone push out, like a squeezed nose cone, is held only from there on)."""
    from fixplan.planner.planner import Planner

    case = plan.load_names.index(load)
    contacts = []
    for contact in problem.contacts:
        if contact.is_active:
            force = np.atleast_1d(plan.forces[contact.name])
            contact = replace(
                contact, force=factor * float(force[case] if force.size > 1 else force[0])
            )
        contacts.append(contact)
    single = replace(problem, contacts=tuple(contacts), loads=(problem.loads[case],),
                     objective="check")  # fmt: skip
    interval = (Planner(single).solve().held_intervals or {}).get(load)
    return 0.0 if interval is None else min(float(interval[0]), 1.0)  # none held: from 0


def simulate(scene, seconds: float, problem: Problem, length_scale: float) -> Run:
    """Run ``scene`` from its keyframe for ``seconds``; watch for the onset of sliding.

    Sliding is measured at each contact, between the part and what presses on it: the
    tangential displacement of the contact's tip against its pad on the part (a finger may
    follow the part along its normal, which is no slip) plus, for contacts with torsional
    friction, the part's turn about the contact normal times the patch radius. A point contact
    may spin freely about its normal, as a part pinched by two of them turns about the grasp
    axis: that is no slip.
    """
    import mujoco

    model = mujoco.MjModel.from_xml_string(scene.xml)
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, 0)
    mujoco.mj_forward(model, data)
    part = model.body("part").id
    tips = [model.geom(f"tip-{c.name}").id for c in problem.contacts]
    pads = [model.geom(f"pad-{c.name}").id for c in problem.contacts]
    normals = np.array([c.normal for c in problem.contacts])  # in the part's frame at the start
    pairs = [model.pair(f"contact-{c.name}").id for c in problem.contacts]
    torsional = np.array([model.pair_dim[pair] == 4 for pair in pairs])
    radii = np.where(torsional, [model.geom_size[pad][0] for pad in pads], 0.0)
    turn = data.qpos[3:7].copy()

    def slips() -> np.ndarray:
        """Each contact's tangential offset of its tip from its pad (part frame) [m] and, as a
        last column, its turn about its normal times its radius [m]."""
        rotation = data.xmat[part].reshape(3, 3)
        relative = (data.geom_xpos[tips] - data.geom_xpos[pads]) @ rotation
        tangential = relative - np.sum(relative * normals, axis=1)[:, None] * normals
        return np.column_stack([tangential, (normals @ _turned(data, turn)) * radii])

    start = previous = slips()
    onset_multiple, onset_twist = None, None
    history = []
    settle, step_time = round(SETTLE / model.opt.timestep), model.opt.timestep
    for step in range(round(seconds / step_time)):
        mujoco.mj_step(model, data)
        if onset_multiple is None:
            now = slips()
            speed = np.linalg.norm(now[:, :3] - previous[:, :3], axis=1) + np.abs(
                now[:, 3] - previous[:, 3]
            )
            previous = now
            if step >= settle and np.max(speed) / step_time > SLIP_SPEED:
                onset_multiple, onset_twist = float(data.act[-1]), _twist(data)
        if step % HISTORY_STRIDE == 0:
            history.append(_sample(data, slips() - start, turn))
    history.append(_sample(data, slips() - start, turn))
    return Run(displacement=float(history[-1][1]), rotation=_rotation(data, turn),
               onset_multiple=onset_multiple, onset_twist=onset_twist,
               history=np.array(history))  # fmt: skip


def _sample(data, slipped: np.ndarray, turn: np.ndarray) -> tuple[float, float, float, float]:
    """A history row: time, largest slip at a contact, rotation, task multiple."""
    largest = float(np.max(np.linalg.norm(slipped[:, :3], axis=1) + np.abs(slipped[:, 3])))
    return (data.time, largest, _rotation(data, turn), float(data.act[-1]))


def _turned(data, start: np.ndarray) -> np.ndarray:
    """The part's rotation vector [rad] since orientation ``start``, in its starting frame."""
    import mujoco

    inverse, relative, vector = np.zeros(4), np.zeros(4), np.zeros(3)
    mujoco.mju_negQuat(inverse, start)
    mujoco.mju_mulQuat(relative, inverse, data.qpos[3:7])
    mujoco.mju_quat2Vel(vector, relative, 1.0)
    return vector


def _rotation(data, start: np.ndarray) -> float:
    """Angle [rad] the part turned since its orientation ``start`` (a quaternion)."""
    return 2.0 * np.arccos(min(1.0, abs(float(data.qpos[3:7] @ start))))


def _twist(data) -> np.ndarray:
    """The part's twist: velocity of the body point at the world origin and angular velocity,
    world frame (the free joint's angular velocity is in the part's frame)."""
    import mujoco

    rotation = np.zeros(9)
    mujoco.mju_quat2Mat(rotation, data.qpos[3:7])
    omega = rotation.reshape(3, 3) @ data.qvel[3:6]
    return np.r_[data.qvel[:3] - np.cross(omega, data.qpos[:3]), omega]


def motion_angle(simulated: np.ndarray, planned: np.ndarray, length_scale: float) -> float:
    """Angle [rad] between two twists ``(v, ω)`` compared as ``(v, length_scale ω)``."""
    weights = np.r_[np.ones(3), np.full(3, length_scale)]
    a, b = simulated * weights, np.asarray(planned, dtype=float) * weights
    cosine = float(a @ b / (np.linalg.norm(a) * np.linalg.norm(b)))
    return float(np.arccos(np.clip(cosine, -1.0, 1.0)))


def problem_length_scale(problem: Problem) -> float:
    """The largest distance of a contact from the centre of mass [m] (at least 1 mm)."""
    spread = [np.linalg.norm(c.position - problem.body.center_of_mass) for c in problem.contacts]
    return float(max(max(spread), 1e-3))
