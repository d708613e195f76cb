"""Every answer checked in numpy before it is reported: equilibrium and friction sets."""

from __future__ import annotations

import numpy as np

from fixplan.planner.friction_use import FrictionUse
from fixplan.planner.problem import Problem
from fixplan.planner.stacking import ContactLayout
from fixplan.tolerances import EQUILIBRIUM_RTOL, FRICTION_SET_RTOL


def verify(
    problem: Problem,
    layout: ContactLayout,
    friction_use: FrictionUse,
    answer: dict,
    wrenches: np.ndarray,
    length_scale: float,
) -> tuple[float, list[str]]:
    """The largest relative equilibrium residual of ``answer`` and what failed, in words.

    ``answer`` holds ``normal`` ``(C, K)`` [N], ``friction`` ``(D, K)`` and ``scale`` ``(K,)``;
    ``wrenches`` ``(6, K)`` are the task wrenches. Forces are compared with the forces of each
    case's wrench terms and moments with their moments (at least force × ``length_scale``);
    a contact's friction may exceed its set by ``FRICTION_SET_RTOL`` of the largest normal
    force.
    """
    normal, friction, scale = answer["normal"], answer["friction"], answer["scale"]
    problems = []
    gravity = problem.body.weight_wrench[:, None]
    normal_part = layout.normal_map @ normal
    friction_part = layout.friction_map @ friction
    task_part = wrenches * scale[None, :]
    residual = normal_part + friction_part + task_part + gravity
    # The size of every term, not of their sums: opposed contacts cancel in the sums.
    magnitude = (
        np.abs(layout.normal_map) @ np.abs(normal)
        + np.abs(layout.friction_map) @ np.abs(friction)
        + np.abs(task_part)
        + np.abs(gravity)
    )
    force_size = np.maximum(magnitude[:3].max(axis=0), 1e-12)
    moment_size = np.maximum(magnitude[3:].max(axis=0), force_size * length_scale)
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
    noise = FRICTION_SET_RTOL * scale_force
    for i in np.flatnonzero((normal < -noise).any(axis=1)):
        name = problem.contacts[i].name
        problems.append(f"contact {name!r} pulls: normal force {normal[i].min():.3g} N")
    use = friction_use(friction, normal, noise=noise)
    pressed = normal > noise
    for i in np.flatnonzero((np.isinf(use) & ~pressed).any(axis=1)):
        problems.append(
            f"contact {problem.contacts[i].name!r} carries friction without normal force"
        )
    # The excess of a contact's friction over its set, as a force, against the largest normal
    # force: solver accuracy is absolute, so a lightly pressed contact may exceed its own set by
    # more than FRICTION_SET_RTOL in relative terms and still be exact enough.
    excess = np.full(normal.shape, -np.inf)
    excess[pressed] = (use[pressed] - 1.0) * normal[pressed]
    for i in np.flatnonzero((excess > noise).any(axis=1)):
        worst = int(np.argmax(excess[i]))
        problems.append(
            f"contact {problem.contacts[i].name!r} exceeds its friction set by "
            f"{excess[i, worst]:.3g} N (over {FRICTION_SET_RTOL:g} of the largest normal force, "
            f"{scale_force:.3g} N)"
        )
    return relative, problems
