r"""Quasi-static pushing trajectories: a round pusher drives a part across its support.

At every instant the part moves with the quasi-static twist of :func:`~fixplan.motion.push_step`
at the contact between the pusher and the part's outline (or stays at rest when they do not
touch). The part's pose ``(x, y, θ)`` [m, m, rad] in the world is integrated on SE(2) with the
exact exponential of the twist over each step and the explicit midpoint rule (second order in the
step; the twist is taken again at the half step, with the contact where it is then). When the
pusher reaches the part within a step, it first travels to the touching instant (found by
bisection) and pushes for the rest of the step.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from fixplan import validation
from fixplan.errors import InvalidArgumentError
from fixplan.motion.outline import Outline
from fixplan.motion.pushing import PushStep, push_step

#: The pusher counts as touching the outline within this fraction of the part's size.
TOUCH_RTOL = 1e-9

#: Bisection steps that find the touching instant within a step (to 2**-50 of the step).
TOUCH_BISECTIONS = 50

#: Relative time step [s per s] of the central differences that give a callable path's velocity.
PATH_STEP = 1e-6


@dataclass(frozen=True, slots=True)
class PointPusher:
    """A round pusher of ``radius`` [m] (0: a point) whose centre follows ``path``.

    ``path`` is ``(start, velocity)`` for a straight line [m, m/s] or a callable ``t -> (x, y)``
    [s -> m] in the world frame; ``mu`` is the pusher–part friction coefficient (0 allowed).
    """

    path: object
    mu: float
    radius: float = 0.0

    def __post_init__(self):
        object.__setattr__(self, "mu", validation.nonnegative_scalar("mu", self.mu))
        object.__setattr__(self, "radius", validation.nonnegative_scalar("radius", self.radius))
        if not callable(self.path):
            try:
                start, velocity = self.path
            except (TypeError, ValueError):
                raise InvalidArgumentError(
                    "path must be (start, velocity) or a callable t -> (x, y)"
                ) from None
            start = validation.finite_array("path start", start, shape=(2,))
            velocity = validation.finite_array("path velocity", velocity, shape=(2,))
            object.__setattr__(self, "path", (start, velocity))

    def position(self, t: float) -> np.ndarray:
        """Centre of the pusher at time ``t`` [s], world frame [m]."""
        if callable(self.path):
            return validation.finite_array("path(t)", self.path(t), shape=(2,))
        start, velocity = self.path
        return start + velocity * t

    def velocity(self, t: float) -> np.ndarray:
        """Velocity of the centre at time ``t`` [m/s] (central differences for a callable)."""
        if not callable(self.path):
            return self.path[1]
        step = PATH_STEP * max(abs(t), 1.0)
        return (self.position(t + step) - self.position(t - step)) / (2 * step)


@dataclass(frozen=True, slots=True)
class Trajectory:
    """A pushed part over time.

    Attributes
    ----------
    t : numpy.ndarray
        ``(n + 1,)`` times [s].
    poses : numpy.ndarray
        ``(n + 1, 3)`` world poses ``(x, y, θ)`` of the part frame [m, m, rad].
    twists : numpy.ndarray
        ``(n, 3)`` the part's twist in each step, in the part frame [m/s, m/s, rad/s].
    modes : tuple of str
        Contact mode of each step (``"separated"`` where the pusher does not touch).
    forces : numpy.ndarray
        ``(n, 2)`` the pusher's force on the part, world frame [N].
    contact_points : numpy.ndarray
        ``(n, 2)`` the contact point in the world frame at the start of each step (or when the
        pusher touches within it) [m]; NaN where not touching.
    """

    t: np.ndarray
    poses: np.ndarray
    twists: np.ndarray
    modes: tuple[str, ...]
    forces: np.ndarray
    contact_points: np.ndarray


def push(
    surface,
    pusher: PointPusher,
    *,
    shape: Outline,
    pose=(0.0, 0.0, 0.0),
    duration: float,
    steps: int,
    progress: Callable[[int, int], None] | None = None,
) -> Trajectory:
    """Integrate the part's quasi-static motion under ``pusher`` for ``duration`` [s].

    ``surface`` is the support's limit surface in the part frame (see
    :func:`~fixplan.motion.push_step`); ``shape`` the part's outline in the same frame; ``pose``
    its initial world pose ``(x, y, θ)``; ``steps`` the number of integration steps;
    ``progress(done, total)`` is called after each step.
    """
    if not isinstance(pusher, PointPusher):
        raise InvalidArgumentError(f"pusher must be a PointPusher, got {type(pusher).__name__}")
    if not isinstance(shape, Outline):
        raise InvalidArgumentError(f"shape must be an Outline, got {type(shape).__name__}")
    duration = validation.positive_scalar("duration", duration)
    if isinstance(steps, bool) or not isinstance(steps, int | np.integer) or steps < 1:
        raise InvalidArgumentError(f"steps must be a positive integer, got {steps!r}")
    pose = validation.finite_array("pose", pose, shape=(3,)).copy()
    size = float(np.abs(shape.vertices).max()) if len(shape.vertices) else shape.radius
    tolerance = TOUCH_RTOL * max(size, pusher.radius)
    dt = duration / steps
    times, poses = [0.0], [pose.copy()]
    twists, modes, forces, points = [], [], [], []
    for k in range(steps):
        start = k * dt
        touch = _touching_time(shape, pusher, pose, start, dt, tolerance)
        if touch is None:
            step, contact = PushStep.separated(), None
        else:
            rest = start + dt - touch
            step, contact = _step(surface, shape, pusher, pose, touch)
            if step.mode != "separated":
                half = _compose(pose, step.twist, rest / 2)
                midpoint, _ = _step(surface, shape, pusher, half, touch + rest / 2)
                pose = _compose(pose, midpoint.twist, rest)
        twists.append(step.twist)
        modes.append(step.mode)
        rotation = _rotation(poses[-1][2])
        forces.append(rotation @ step.force)
        points.append(np.full(2, np.nan) if contact is None else poses[-1][:2] + rotation @ contact)
        times.append(start + dt)
        poses.append(pose.copy())
        if progress is not None:
            progress(k + 1, steps)
    return Trajectory(
        t=np.array(times), poses=np.array(poses), twists=np.array(twists), modes=tuple(modes),
        forces=np.array(forces), contact_points=np.array(points),
    )  # fmt: skip


def _local(pose: np.ndarray, point: np.ndarray) -> np.ndarray:
    """A world point in the part frame of ``pose``."""
    return _rotation(pose[2]).T @ (point - pose[:2])


def _gap(shape: Outline, pusher: PointPusher, pose: np.ndarray, t: float) -> float:
    """Distance between the pusher's surface and the outline at time ``t`` [m] (part at rest)."""
    return shape.nearest(_local(pose, pusher.position(t)))[2] - pusher.radius


def _touching_time(shape, pusher, pose, start, dt, tolerance) -> float | None:
    """When within ``[start, start + dt]`` the pusher touches the resting part (``None``: not)."""
    if _gap(shape, pusher, pose, start) <= tolerance:
        return start
    if _gap(shape, pusher, pose, start + dt) > tolerance:
        return None
    low, high = start, start + dt
    for _ in range(TOUCH_BISECTIONS):
        middle = 0.5 * (low + high)
        if _gap(shape, pusher, pose, middle) > tolerance:
            low = middle
        else:
            high = middle
    return high


def _step(surface, shape, pusher, pose, t) -> tuple[PushStep, np.ndarray]:
    """The push step at time ``t`` with the part at ``pose`` and the pusher touching it (to
    within the step's accuracy), and the contact point in the part frame."""
    centre = _local(pose, pusher.position(t))
    point, outward, _ = shape.nearest(centre)
    velocity = _rotation(pose[2]).T @ pusher.velocity(t)
    step = push_step(surface, contact=point, normal=-outward, velocity=velocity, mu=pusher.mu)
    return step, point


def _rotation(angle: float) -> np.ndarray:
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[c, -s], [s, c]])


def _compose(pose: np.ndarray, twist: np.ndarray, time: float) -> np.ndarray:
    """``pose`` moved by the body twist ``twist`` (part frame) for ``time``: the exact SE(2)
    exponential."""
    vx, vy, w = twist * time
    if abs(w) < 1e-12:
        displacement = np.array([vx, vy])
    else:
        s, c = math.sin(w), math.cos(w)
        displacement = np.array([[s, -(1 - c)], [1 - c, s]]) @ np.array([vx, vy]) / w
    moved = pose.copy()
    moved[:2] += _rotation(pose[2]) @ displacement
    moved[2] += w
    return moved
