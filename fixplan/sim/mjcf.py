r"""A planning problem as a self-contained MuJoCo scene (MJCF), with a plan's forces and a ramped
task load.

The scene follows what makes MuJoCo a faithful judge of a friction plan (README, "Simulators"):

- the part is a free body with the problem's mass, centre of mass and inertia; its shape (a box
  of ``Body.size`` or its mesh) is drawn but does not collide;
- each contact is an explicit ``<pair>`` with its own friction (:func:`mujoco_contact`): a thin
  pad fixed to the part, whose outer face holds the contact point, against a sphere outside it
  (one contact point per pair; box fingertips would make several);
- locators and supports are spheres fixed in the world; clamps and fingers are spheres on slide
  joints along the contact normal (with added inertia, so that hundreds of newtons do not fling
  a light sphere through the soft contact), pushed by motors whose control is the planned normal
  force (gravity compensated, so the force reaching the part is the control);
- the elliptic cone with no-slip iterations, a stiff soft contact and a 0.5 ms implicit step
  (``OPTIONS``): a sticking contact does not creep, torsion included;
- the task wrench of a chosen load case enters through an integrator actuator on the part's free
  joint: its activation grows at ``1 / ramp`` per second up to ``max_multiple``, so the load is a
  ramp ``k(t) W`` from a starting multiple; keyframe ``"plan"`` holds the controls, that
  multiple and the starting pose.

The free joint's rotational degrees of freedom act in the part's frame, aligned with the world
at the start; over the small motions of a slip test the task moment stays within that rotation
of its direction.
"""

from __future__ import annotations

from dataclasses import dataclass
from xml.sax.saxutils import quoteattr

import numpy as np

from fixplan.errors import InvalidArgumentError
from fixplan.planner.problem import Problem
from fixplan.sim.mujoco_contact import mujoco_contact

#: Simulation options of the scene (MJCF ``<option>`` attributes).
OPTIONS = {
    "timestep": "0.0005",
    "integrator": "implicitfast",
    "cone": "elliptic",
    "impratio": "100",
    "noslip_iterations": "20",
}
#: Soft-contact parameters of every pair: a 5 ms time constant, nearly rigid impedance.
SOLREF = "0.001 1"
SOLIMP = "0.99 0.999 0.0005"
#: Radius [m] of the spheres and half side of the pads of point contacts (patches: their radius).
POINT_RADIUS = 0.004
#: Half thickness of a pad [m] relative to its half side.
PAD_THICKNESS = 1.0
#: Mass [kg] of each finger or clamp sphere (gravity compensated).
FINGER_MASS = 0.01
#: Added inertia [kg] of each slide joint: a light sphere under hundreds of newtons would hit the
#: part too fast for the soft contact to catch it.
FINGER_ARMATURE = 0.05
#: Mass [kg] given to a massless part (MuJoCo needs one for a free body); gravity then is off.
MASSLESS = 1e-3


@dataclass(frozen=True, slots=True)
class Scene:
    """An MJCF scene and what it was made of.

    Attributes
    ----------
    xml : str
        The MJCF document.
    load : str
        The load case whose task wrench is ramped.
    forces : dict
        The normal force [N] of each active contact (the motors' controls).
    ramp : float
        Seconds for the task load to reach 1× (the actuator's activation rate is ``1 / ramp``).
    """

    xml: str
    load: str
    forces: dict
    ramp: float


def to_mjcf(
    problem: Problem,
    plan=None,
    *,
    load: str | None = None,
    forces: dict | None = None,
    scale: float = 1.0,
    ramp: float = 1.0,
    max_multiple: float = 2.0,
    start: float = 0.0,
) -> Scene:
    """The MuJoCo scene of ``problem`` with its active forces times ``scale``, and the task load
    of case ``load`` (default the first) ramped from ``start`` at ``1 / ramp`` per second [1/s]
    up to ``max_multiple`` (start at the lower end of a held interval that does not reach 0).

    The active forces [N] are ``forces`` (by contact name) where given, else the plan's for that
    case, else the contacts' own ``force``.
    """
    if not isinstance(problem, Problem):
        raise InvalidArgumentError(f"problem must be a Problem, got {type(problem).__name__}")
    names = [item.name for item in problem.loads]
    load = names[0] if load is None else load
    if load not in names:
        raise InvalidArgumentError(
            f"load must be one of {', '.join(map(repr, names))}; got {load!r}"
        )
    case = names.index(load)
    for key, value in (("scale", scale), ("ramp", ramp), ("max_multiple", max_multiple)):
        if not np.isfinite(value) or value <= 0.0:
            raise InvalidArgumentError(f"{key} must be a positive number, got {value!r}")
    if not 0.0 <= start <= max_multiple:
        raise InvalidArgumentError(f"start must be from 0 to max_multiple, got {start!r}")
    active = [c.name for c in problem.contacts if c.is_active]
    for name, value in (forces or {}).items():
        if name not in active:
            raise InvalidArgumentError(
                f"forces: {name!r} is not an active contact (clamp or finger); those are "
                f"{', '.join(map(repr, active)) or 'none'}"
            )
        if not np.isfinite(value) or value < 0.0:
            raise InvalidArgumentError(
                f"forces[{name!r}] must be a finite force >= 0 N, got {value!r}"
            )
    chosen = _active_forces(problem, plan, case, forces or {})
    forces = {name: scale * force for name, force in chosen.items()}
    body = problem.body
    center = np.asarray(body.center_of_mass, dtype=float)
    task = problem.task_wrenches()[:, case]
    task_about_center = np.r_[task[:3], task[3:] - np.cross(center, task[:3])]
    gravity = body.gravity if body.mass > 0.0 else np.zeros(3)
    lines = [
        f"<mujoco model={quoteattr('fixplan ' + load)}>",
        '  <compiler angle="radian" autolimits="true"/>',
        "  <option " + _attributes(OPTIONS, gravity=_numbers(gravity)) + "/>",
        *_assets(body),
        "  <worldbody>",
        f'    <body name="part" pos="{_numbers(center)}">',
        '      <freejoint name="part"/>',
        "      " + _inertial(problem),
        *("      " + line for line in _part_shape(body, center)),
        *("      " + line for line in _pads(problem, center)),
        "    </body>",
        *("    " + line for line in _contact_bodies(problem)),
        "  </worldbody>",
        "  <contact>",
        *("    " + line for line in _pairs(problem)),
        "  </contact>",
        "  <actuator>",
        *_motors(problem),
        '    <general name="task-load" joint="part" dyntype="integrator" gainprm="1" '
        f'actlimited="true" actrange="0 {max_multiple:.9g}" '
        f'gear="{_numbers(task_about_center)}"/>',
        "  </actuator>",
        "  <keyframe>",
        f'    <key name="plan" ctrl="{_controls(problem, forces, ramp)}" act="{start:.9g}"/>',
        "  </keyframe>",
        "</mujoco>",
    ]
    return Scene(xml="\n".join(lines) + "\n", load=load, forces=forces, ramp=ramp)


def _active_forces(problem: Problem, plan, case: int, given: dict) -> dict:
    """Normal force [N] of each active contact in load case ``case``."""
    forces = {}
    for contact in problem.contacts:
        if not contact.is_active:
            continue
        if contact.name in given:
            forces[contact.name] = float(given[contact.name])
        elif plan is not None and plan.forces is not None and contact.name in plan.forces:
            value = np.atleast_1d(plan.forces[contact.name])
            forces[contact.name] = float(value[case] if value.size > 1 else value[0])
        elif contact.force is not None:
            forces[contact.name] = float(contact.force)
        else:
            raise InvalidArgumentError(
                f"contact {contact.name!r} has no force: give a plan with forces, the contact's "
                "force or forces={name: newtons}"
            )
    return forces


def _size(contact) -> float:
    """Half side of a contact's pad and radius of its sphere [m]."""
    return POINT_RADIUS if contact.patch is None else float(contact.patch.radius)


def _pads(problem: Problem, center: np.ndarray) -> list[str]:
    """A thin box on the part per contact, its outer face through the contact point."""
    lines = []
    for contact in problem.contacts:
        half = _size(contact)
        thickness = PAD_THICKNESS * half
        middle = contact.position + thickness * contact.normal - center
        lines.append(
            f'<geom name={_named("pad", contact.name)} type="box" size="{half:.9g} {half:.9g} '
            f'{thickness:.9g}" pos="{_numbers(middle)}" zaxis="{_numbers(contact.normal)}" '
            'contype="0" conaffinity="0" mass="0" rgba="0.9 0.6 0.2 1"/>'
        )
    return lines


def _contact_bodies(problem: Problem) -> list[str]:
    """Fixed spheres for passive contacts; spheres on slide joints for active ones."""
    lines = []
    for contact in problem.contacts:
        radius = _size(contact)
        place = contact.position - radius * contact.normal
        geom = (
            f'<geom name={_named("tip", contact.name)} type="sphere" size="{radius:.9g}" '
            'contype="0" conaffinity="0" rgba="0.3 0.5 0.9 1"'
        )
        if not contact.is_active:
            lines.append(f'{geom} pos="{_numbers(place)}"/>')
            continue
        lines += [
            f'<body name={_named("finger", contact.name)} pos="{_numbers(place)}" gravcomp="1">',
            f'  <joint name={_named("slide", contact.name)} type="slide" '
            f'axis="{_numbers(contact.normal)}" armature="{FINGER_ARMATURE:.9g}"/>',
            f'  {geom} mass="{FINGER_MASS:.9g}"/>',
            "</body>",
        ]
    return lines


def _pairs(problem: Problem) -> list[str]:
    lines = []
    for contact in problem.contacts:
        attributes = mujoco_contact(contact).attributes()
        lines.append(
            f"<pair name={_named('contact', contact.name)} geom1={_named('tip', contact.name)} "
            f'geom2={_named("pad", contact.name)} condim="{attributes["condim"]}" '
            f'friction="{attributes["friction"]}" solref="{SOLREF}" solimp="{SOLIMP}"/>'
        )
    return lines


def _inertial(problem: Problem) -> str:
    """The part's mass and inertia about its centre of mass (a sphere's where none is given)."""
    body = problem.body
    mass = body.mass if body.mass > 0.0 else MASSLESS
    if body.inertia is not None and body.mass > 0.0:
        inertia = np.asarray(body.inertia, dtype=float)
    else:
        spread = max(
            float(
                np.max([np.linalg.norm(c.position - body.center_of_mass) for c in problem.contacts])
            ),
            POINT_RADIUS,
        )
        inertia = 0.4 * mass * spread**2 * np.eye(3)
    full = [
        inertia[0, 0],
        inertia[1, 1],
        inertia[2, 2],
        inertia[0, 1],
        inertia[0, 2],
        inertia[1, 2],
    ]
    return f'<inertial pos="0 0 0" mass="{mass:.9g}" fullinertia="{_numbers(full)}"/>'


def _assets(body) -> list[str]:
    if body.mesh is None:
        return []
    vertices = _numbers(np.asarray(body.mesh.vertices).ravel())
    faces = " ".join(str(int(i)) for i in np.asarray(body.mesh.faces).ravel())
    return [
        "  <asset>",
        f'    <mesh name="part" vertex="{vertices}" face="{faces}"/>',
        "  </asset>",
    ]


def _part_shape(body, center: np.ndarray) -> list[str]:
    """The drawn (non-colliding) shape of the part: its mesh or its box."""
    drawn = 'contype="0" conaffinity="0" mass="0" rgba="0.7 0.7 0.7 0.4"'
    if body.mesh is not None:
        return [f'<geom type="mesh" mesh="part" pos="{_numbers(-center)}" {drawn}/>']
    if body.size is not None:
        return [f'<geom type="box" size="{_numbers(0.5 * np.asarray(body.size))}" {drawn}/>']
    return []


def _motors(problem: Problem) -> list[str]:
    return [
        f'    <motor name={_named("push", c.name)} joint={_named("slide", c.name)} gear="1"/>'
        for c in problem.contacts
        if c.is_active
    ]


def _controls(problem: Problem, forces: dict, ramp: float) -> str:
    values = [forces[c.name] for c in problem.contacts if c.is_active] + [1.0 / ramp]
    return _numbers(values)


def _named(prefix: str, name: str) -> str:
    """The quoted MJCF attribute value ``prefix-name`` (contact names may hold any printable
    character)."""
    return quoteattr(f"{prefix}-{name}")


def _attributes(values: dict, **more: str) -> str:
    return " ".join(f'{key}="{value}"' for key, value in {**values, **more}.items())


def _numbers(values) -> str:
    return " ".join(f"{float(v):.9g}" for v in np.ravel(values))
