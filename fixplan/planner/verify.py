"""Every answer checked in numpy before it is reported: equilibrium and friction sets."""

from __future__ import annotations

import numpy as np

from fixplan.planner.friction_use import FrictionUse
from fixplan.planner.problem import Problem
from fixplan.planner.stacking import ContactLayout
from fixplan.tolerances import EQUILIBRIUM_RTOL, FRICTION_SET_RTOL


class Verifier:
    """Checks every answer of one problem's planner: equilibrium and friction sets.

    Parameters
    ----------
    problem : Problem
        The problem (its contact names and weight).
    layout : ContactLayout
        Where each contact's normal force and friction load sit.
    friction_use : FrictionUse
        The friction use of every contact load.
    length_scale : float
        Moments are compared with at least force × ``length_scale`` [m].
    """

    def __init__(
        self,
        problem: Problem,
        layout: ContactLayout,
        friction_use: FrictionUse,
        length_scale: float,
    ):
        self._names = [contact.name for contact in problem.contacts]
        self._gravity = problem.body.weight_wrench[:, None]
        self._maps = (layout.normal_map, layout.friction_map)
        self._sizes = (np.abs(layout.normal_map), np.abs(layout.friction_map))
        self._use = friction_use
        self._length_scale = length_scale

    def __call__(self, answer: dict, wrenches: np.ndarray) -> tuple[float, list[str]]:
        """The largest relative equilibrium residual of ``answer`` and what failed, in words.

        ``answer`` holds ``normal`` ``(C, K)`` [N], ``friction`` ``(D, K)`` and ``scale``
        ``(K,)``; ``wrenches`` ``(6, K)`` are the task wrenches. Forces are compared with the
        forces of each case's wrench terms and moments with their moments; a contact's friction
        may exceed its set by ``FRICTION_SET_RTOL`` of the largest normal force.
        """
        normal, friction, scale = answer["normal"], answer["friction"], answer["scale"]
        normal_map, friction_map = self._maps
        task = wrenches * scale
        residual = normal_map @ normal + friction_map @ friction + task + self._gravity
        # The size of every term, not of their sums: opposed contacts cancel in the sums.
        normal_size, friction_size = self._sizes
        magnitude = (
            normal_size @ np.abs(normal)
            + friction_size @ np.abs(friction)
            + np.abs(task)
            + np.abs(self._gravity)
        )
        force_size = np.maximum(magnitude[:3].max(axis=0), 1e-12)
        moment_size = np.maximum(magnitude[3:].max(axis=0), force_size * self._length_scale)
        problems = []
        relative = 0.0
        for rows, unit, size in (
            (slice(0, 3), "N", force_size),
            (slice(3, 6), "N m", moment_size),
        ):
            ratio = np.abs(residual[rows]).max(axis=0) / size
            worst = int(np.argmax(ratio))
            relative = max(relative, float(ratio[worst]))
            if ratio[worst] > EQUILIBRIUM_RTOL:
                problems.append(
                    f"equilibrium residual of load case {worst + 1}: "
                    f"{ratio[worst] * size[worst]:.3g} {unit}, over {EQUILIBRIUM_RTOL:g} of the "
                    f"wrenches involved ({size[worst]:.3g} {unit})"
                )
        known = answer.get("known_use")
        return relative, problems + self._friction_problems(normal, friction, known)

    def _friction_problems(self, normal, friction, known) -> list[str]:
        """Pulling contacts, friction without normal force and friction outside its set
        (``known``: the uses already computed for some contacts, see :class:`FrictionUse`)."""
        scale_force = max(float(np.abs(normal).max()), 1e-12)
        noise = FRICTION_SET_RTOL * scale_force
        problems = [
            f"contact {self._names[i]!r} pulls: normal force {normal[i].min():.3g} N"
            for i in np.flatnonzero((normal < -noise).any(axis=1))
        ]
        use = self._use(friction, normal, noise=noise, known=known)
        pressed = normal > noise
        problems += [
            f"contact {self._names[i]!r} carries friction without normal force"
            for i in np.flatnonzero((np.isinf(use) & ~pressed).any(axis=1))
        ]
        # The excess of a contact's friction over its set, as a force, against the largest
        # normal force: solver accuracy is absolute, so a lightly pressed contact may exceed its
        # own set by more than FRICTION_SET_RTOL in relative terms and still be exact enough.
        excess = np.where(pressed, use - 1.0, -np.inf)
        excess[pressed] *= normal[pressed]
        for i in np.flatnonzero((excess > noise).any(axis=1)):
            worst = int(np.argmax(excess[i]))
            problems.append(
                f"contact {self._names[i]!r} exceeds its friction set by "
                f"{excess[i, worst]:.3g} N (over {FRICTION_SET_RTOL:g} of the largest normal "
                f"force, {scale_force:.3g} N)"
            )
        return problems
