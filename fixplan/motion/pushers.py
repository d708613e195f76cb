"""Pushers that follow a path in the world frame: a round one (a point when its radius is 0) and
a flat one (a segment face that translates with the path and never rotates).

A path is ``(start, velocity)`` for a straight line [m, m/s] or a callable ``t -> (x, y)``
[s -> m]; a callable path's velocity is taken by central differences.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from fixplan import validation
from fixplan.errors import InvalidArgumentError

#: Relative time step [s per s] of the central differences that give a callable path's velocity.
PATH_STEP = 1e-6


@dataclass(frozen=True, slots=True)
class _PathFollower:
    """A pusher whose reference point follows ``path`` (see the module docstring)."""

    path: object

    def _check_path(self) -> None:
        if callable(self.path):
            return
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
        """The reference point at time ``t`` [s], world frame [m]."""
        if callable(self.path):
            return validation.finite_array("path(t)", self.path(t), shape=(2,))
        start, velocity = self.path
        return start + velocity * t

    def velocity(self, t: float) -> np.ndarray:
        """Velocity of the reference point at time ``t`` [m/s] (central differences for a
        callable path)."""
        if not callable(self.path):
            return self.path[1]
        step = PATH_STEP * max(abs(t), 1.0)
        return (self.position(t + step) - self.position(t - step)) / (2 * step)


@dataclass(frozen=True, slots=True)
class PointPusher(_PathFollower):
    """A round pusher of ``radius`` [m] (0: a point) whose centre follows ``path``.

    ``path`` is ``(start, velocity)`` for a straight line [m, m/s] or a callable ``t -> (x, y)``
    [s -> m] in the world frame; ``mu`` is the pusher–part friction coefficient (0 allowed).
    """

    mu: float
    radius: float = 0.0

    def __post_init__(self):
        object.__setattr__(self, "mu", validation.nonnegative_scalar("mu", self.mu))
        object.__setattr__(self, "radius", validation.nonnegative_scalar("radius", self.radius))
        self._check_path()


@dataclass(frozen=True, slots=True)
class LinePusher(_PathFollower):
    """A flat pusher: a face of ``width`` [m] centred on the point that follows ``path``.

    The face is perpendicular to ``normal``, the world direction it pushes in (a nonzero
    2-vector, stored normalised; default the path's velocity direction at ``t = 0``). It
    translates with the path and never rotates. ``path`` is as for :class:`PointPusher`; ``mu``
    is the pusher–part friction coefficient (0 allowed).
    """

    mu: float
    width: float
    normal: np.ndarray | None = None

    def __post_init__(self):
        object.__setattr__(self, "mu", validation.nonnegative_scalar("mu", self.mu))
        object.__setattr__(self, "width", validation.positive_scalar("width", self.width))
        self._check_path()
        if self.normal is None:
            direction = self.velocity(0.0)
            if not np.any(direction):
                raise InvalidArgumentError(
                    "the path does not move at t = 0, so it gives no pushing direction: pass "
                    "normal (the world direction the face pushes in)"
                )
        else:
            direction = validation.finite_array("normal", self.normal, shape=(2,))
            if not np.any(direction):
                raise InvalidArgumentError("normal must be a nonzero 2-vector")
        direction = validation.unit_vector(direction)[0]
        direction.setflags(write=False)
        object.__setattr__(self, "normal", direction)

    @property
    def tangent(self) -> np.ndarray:
        """The face's direction: ``normal`` turned a quarter counter-clockwise."""
        return np.array([-self.normal[1], self.normal[0]])
