r"""Quasi-static pivoting under a load that depends on the pose: where a part settles.

A part held by a support — soft fingers pinching it, in the in-hand pivoting of Kao & Cutkosky
and of Costanzo et al. — carries a load that changes as it moves (the gravity torque of a rod
turning in the pinch). The support is fixed and its limit surface is given in its own frame
(any surface with the LS interface: the exact :class:`~fixplan.LimitSurface`, a planar
:class:`~fixplan.ContactSetSurface`, or a friction model with a motion map). The part's pose
``g = (x, y, θ)`` [m, m, rad] is that of its frame in the support's frame, and
``load_of_pose(g)`` is the load ``(fx, fy, m)`` [N, N, N m] applied to the part about the
support frame's origin (docs/conventions.md). The part slides with the twist ``V`` (velocity of
the part point at the support's origin and rate of turn, in the support's frame) normal to the
limit surface at the load scaled onto it (normality, maximum power):

.. math:: \frac{dg}{ds} = \hat V(g), \quad \hat V = \frac{\nabla H(L / g_H(L))}
          {\|(\nabla H_x, \nabla H_y, \rho \nabla H_\theta)\|}, \qquad
          \dot x = V_x - V_\theta y, \quad \dot y = V_y + V_\theta x, \quad \dot θ = V_\theta,

until the load falls inside the surface (its safety factor reaches 1). The path parameter
``s`` [m] is arc length: the distance moved by the part point at the origin, with rotation
counted at the surface's characteristic length ``ρ`` (its largest pure moment over its largest
pure force along ``x``, so ``ds² = |v|² dt² + ρ² dθ²``).

**Quasi-static** means the part moves slowly enough that inertia plays no part: the load leaves
the limit surface only by what keeps the part sliding slowly, so at every instant the friction
load is the applied load scaled onto the surface and the part moves along its normal there, the
speed being left open (only the path is found). A load far outside the surface would instead
accelerate the part (see :func:`~fixplan.motion.slide` for that dynamics); the path found here
is then the one of a load applied slowly, e.g. a grip force released gradually.

The pose is integrated in its SE(2) coordinates ``(x, y, θ)``, which describe a rigid motion
exactly whatever the step (there is no constraint to drift), by scipy's adaptive Runge–Kutta
method in ``s``; where the part stops is found as the root of ``safety factor − 1`` on the
solver's dense output (an event), not at a step boundary. Facets of point supports are followed
as the surface's motion map gives them (the part pivots about a support point).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from scipy.integrate import solve_ivp

from fixplan import validation
from fixplan.errors import InvalidArgumentError, ModelError

#: Relative tolerance of the adaptive integration; the absolute tolerance is this fraction of
#: the characteristic length for positions and this many radians for the angle.
INTEGRATION_RTOL = 1e-10

#: Default sliding distance, in characteristic lengths, after which a part whose load stayed
#: outside the surface is taken to slide out of the support.
SLIDE_OUT_LENGTHS = 20.0

#: Reasons a settling ends.
INSIDE = "the load is inside the limit surface"
TURNED = "turned by max_angle without stopping"
SLID_OUT = "the load stayed outside the limit surface over max_distance: the part slides out"


@dataclass(frozen=True, slots=True)
class Settling:
    """Where a part under a pose-dependent load comes to rest, and the path it took.

    Attributes
    ----------
    pose : numpy.ndarray
        The last pose ``(x, y, θ)`` [m, m, rad] in the support's frame: where the part stops
        when :attr:`stopped`.
    poses : numpy.ndarray
        ``(n, 3)`` poses along the path, from the start to :attr:`pose` (at the integrator's
        steps).
    distance : numpy.ndarray
        ``(n,)`` path parameter at the poses [m]: arc length, rotation counted at the surface's
        characteristic length.
    loads : numpy.ndarray
        ``(n, 3)`` applied loads ``(fx, fy, m)`` [N, N, N m] at the poses.
    safety_factors : numpy.ndarray
        ``(n,)`` safety factors of the loads (below 1 while sliding, 1 where it stops).
    stopped : bool
        Whether the part came to rest.
    reason : str
        Why the settling ended: :data:`INSIDE`, :data:`TURNED` or :data:`SLID_OUT`.
    """

    pose: np.ndarray
    poses: np.ndarray
    distance: np.ndarray
    loads: np.ndarray
    safety_factors: np.ndarray
    stopped: bool
    reason: str


def settle(
    surface,
    load_of_pose: Callable,
    pose,
    *,
    max_angle: float = math.pi,
    max_distance: float | None = None,
) -> Settling:
    """Quasi-static sliding from ``pose`` until the load falls inside the surface (see the
    module docstring).

    Parameters
    ----------
    surface
        The support's limit surface in its own frame: anything with ``motion(load)`` and
        ``safety_factor(load)`` (or ``motion_and_safety_factor``); not frictionless.
    load_of_pose : callable
        ``load_of_pose(pose)`` -> ``(fx, fy, m)`` [N, N, N m], the load applied to the part about
        the support's origin when the part is at ``pose``.
    pose : array_like
        Starting pose ``(x, y, θ)`` [m, m, rad] of the part in the support's frame.
    max_angle : float
        The settling ends (not stopped) when the part has turned by this much [rad], > 0.
    max_distance : float, optional
        The settling ends (not stopped: the part slides out) after this path length [m], > 0;
        default ``SLIDE_OUT_LENGTHS`` characteristic lengths.
    """
    response = _Response(surface, load_of_pose)
    start = validation.finite_array("pose", pose, shape=(3,))
    max_angle = validation.positive_scalar("max_angle", max_angle)
    length = response.length
    if max_distance is None:
        max_distance = SLIDE_OUT_LENGTHS * length
    max_distance = validation.positive_scalar("max_distance", max_distance)
    if response.at(start)[2] >= 1.0:
        return response.settling([0.0], [start], stopped=True, reason=INSIDE)

    def rate(s, pose):
        vx, vy, w = response.at(pose)[1]
        return [vx - w * pose[1], vy + w * pose[0], w]

    def inside(s, pose):
        return response.at(pose)[2] - 1.0

    def turned(s, pose):
        return abs(pose[2] - start[2]) - max_angle

    for event in (inside, turned):
        event.terminal, event.direction = True, 1
    atol = INTEGRATION_RTOL * np.array([length, length, 1.0])
    result = solve_ivp(rate, (0.0, max_distance), start, events=(inside, turned),
                       rtol=INTEGRATION_RTOL, atol=atol)  # fmt: skip
    if result.status == -1:  # pragma: no cover - the right-hand side is bounded
        raise ModelError(f"the settling integration failed: {result.message}")
    # A terminal event ends the solution at its root.
    reason = SLID_OUT
    if result.t_events[0].size:
        reason = INSIDE
    elif result.t_events[1].size:
        reason = TURNED
    return response.settling(result.t, result.y.T, stopped=reason == INSIDE, reason=reason)


class _Response:
    """The load at a pose, its unit twist and safety factor (the last pose asked remembered:
    the integrator asks for the same pose for its rate and its events)."""

    __slots__ = ("_last", "length", "load_of_pose", "surface")

    def __init__(self, surface, load_of_pose: Callable):
        if not (hasattr(surface, "motion") and hasattr(surface, "safety_factor")):
            raise InvalidArgumentError(
                "surface must have the limit-surface interface (motion, safety_factor), got "
                f"{type(surface).__name__}"
            )
        if getattr(surface, "frictionless", False):
            raise InvalidArgumentError(
                "a part on a frictionless support has no quasi-static motion: any load slides "
                "it (give the support friction)"
            )
        if not callable(load_of_pose):
            raise InvalidArgumentError(
                f"load_of_pose must be a function of the pose (x, y, θ), got {load_of_pose!r}"
            )
        force = float(surface.safety_factor(np.array([1.0, 0.0, 0.0])))
        moment = float(surface.safety_factor(np.array([0.0, 0.0, 1.0])))
        if not (0.0 < force < math.inf and 0.0 < moment < math.inf):
            raise InvalidArgumentError(
                f"{type(surface).__name__} must hold a bounded, nonzero force and moment "
                f"(largest pure force {force!r} N, moment {moment!r} N m)"
            )
        self.surface = surface
        self.load_of_pose = load_of_pose
        self.length = moment / force
        self._last: tuple[bytes, tuple] | None = None

    def at(self, pose: np.ndarray) -> tuple[np.ndarray, np.ndarray, float]:
        """``(load, unit twist, safety factor)`` at ``pose``."""
        key = np.asarray(pose, dtype=float).tobytes()
        if self._last is None or self._last[0] != key:
            load = validation.finite_array("load_of_pose(pose)", self.load_of_pose(pose.copy()),
                                           shape=(3,))  # fmt: skip
            self._last = (key, (load, *self._motion(load)))
        return self._last[1]

    def _motion(self, load: np.ndarray) -> tuple[np.ndarray, float]:
        if not np.any(load):
            return np.zeros(3), math.inf
        if hasattr(self.surface, "motion_and_safety_factor"):
            twist, safety = self.surface.motion_and_safety_factor(load)
        else:
            twist, safety = self.surface.motion(load), self.surface.safety_factor(load)
        twist = np.asarray(twist, dtype=float)
        size = math.hypot(twist[0], twist[1], self.length * twist[2])
        if not (np.all(np.isfinite(twist)) and size > 0.0):
            raise ModelError(f"the surface gives no motion for the load {load}")
        return twist / size, float(safety)

    def settling(self, distance, poses, *, stopped: bool, reason: str) -> Settling:
        poses = np.array(poses, dtype=float)
        answers = [self.at(pose) for pose in poses]
        return Settling(
            pose=poses[-1].copy(),
            poses=poses,
            distance=np.array(distance, dtype=float),
            loads=np.array([load for load, _, _ in answers]),
            safety_factors=np.array([safety for _, _, safety in answers]),
            stopped=stopped,
            reason=reason,
        )
