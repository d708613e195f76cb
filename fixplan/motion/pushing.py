r"""One quasi-static pushing step: how a part on a support moves when a pusher drives it.

A part rests on a support whose friction is the limit surface ``H`` (any surface with the LS
interface: ``motion(load)`` and ``safety_factor(load)`` — the exact
:class:`~fixplan.LimitSurface`, a planar :class:`~fixplan.ContactSetSurface`, or a friction model
with a motion map). A pusher touches the part at ``c = (cx, cy)`` in the surface's frame with
inward unit normal ``n`` and moves with velocity ``v_p``; the pusher–part friction coefficient is
``mu_p`` (0 allowed). Conventions as in ``docs/conventions.md``: twists ``V = (vx, vy, w)``, loads
``(fx, fy, m)`` about the frame origin. The part's contact point moves with ``J V`` and the
pusher's force ``F`` applies the load ``B F``:

.. math:: J = \begin{pmatrix} 1 & 0 & -c_y \\ 0 & 1 & c_x \end{pmatrix}, \qquad B = J^T .

Quasi-static motion with maximum power (Mason; Lynch & Mason): the load ``B F`` lies on the
limit surface and the part's twist is normal to it there, ``V = k \nabla H(B F)``, ``k >= 0``;
``F`` lies in the pusher's friction cone ``|F·t| <= mu_p F·n`` (``t`` is ``n`` turned a quarter
counter-clockwise).

- **Sticking**: the contact point moves with the pusher, ``J V = v_p``. Among such twists the
  quasi-static one minimises the dissipation ``h(V)``; its multiplier is the pusher force
  (``∇h(V) = J^T F = B F``). The twists with ``J V = v_p`` form the line ``V_0 + s N``
  (``N = (c_y, -c_x, 1)``, rotation about the contact point), along which ``h`` is convex: for a
  surface with a forward map (``load(twist) = ∇h``) the minimum is one root of
  ``∇h(V_0 + s N) · N`` (at a facet, a kink of ``h``, the load is the subgradient of the
  one-sided loads that annuls it). Surfaces with only the inverse map are solved on the force
  angle instead: as the force turns across the friction cone the contact velocity ``J V(F)``
  turns the same way (``J ∇²H J^T`` is positive definite). An ellipsoid ``H(L) = L^T A L`` has
  the closed form ``F ∝ (J A J^T)^{-1} v_p``. The sticking force found, in the friction cone the
  pusher sticks; outside it, it slides on that side.
- **Sliding**: when ``v_p`` lies outside the *motion cone* (the contact velocities that the cone's
  two edge forces produce), the force lies on the edge on that side, the twist follows from
  normality there and is scaled so that the normal velocities of pusher and part match; the
  pusher slides along the contact tangent.
- **Separated**: a pusher that does not move into the part (``v_p · n <= 0``) leaves it at rest.

Facets of point-supported parts are exact: a part pivoting about a support point has its twist on
the facet, as the surface's ``motion`` returns it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.optimize import brentq

from fixplan import validation
from fixplan.errors import InvalidArgumentError, ModelError
from fixplan.models.ellipsoid import Ellipsoid, FittedEllipsoid

MODES = ("sticking", "sliding-left", "sliding-right", "separated")

#: Root finding on the force angle stops at this many radians, and on the line of sticking
#: twists at this fraction of the pusher's speed over the contact's lever (double precision).
ANGLE_XTOL = 1e-15

#: A sticking force may exceed the friction cone by this fraction (rounding) and still stick.
CONE_RTOL = 1e-12


@dataclass(frozen=True, slots=True)
class PushStep:
    """The part's response to a pusher velocity.

    Attributes
    ----------
    twist : numpy.ndarray
        ``(vx, vy, w)`` of the part [m/s, m/s, rad/s] in the surface's frame.
    mode : str
        ``"sticking"``, ``"sliding-left"`` (the pusher slides along ``+t``, ``n`` turned a
        quarter counter-clockwise), ``"sliding-right"`` or ``"separated"``.
    slip : float
        Slip speed of the pusher along ``t`` relative to the part's contact point [m/s].
    force : numpy.ndarray
        The pusher's force on the part [N], per the support's normal force (the load is on the
        surface as given).
    load : numpy.ndarray
        ``(fx, fy, m)`` [N, N, N m] the pusher applies about the frame origin.
    """

    twist: np.ndarray
    mode: str
    slip: float
    force: np.ndarray
    load: np.ndarray

    @classmethod
    def separated(cls, slip: float = 0.0) -> PushStep:
        """The part at rest, the pusher not pressing on it (moving by ``slip`` [m/s] along ``t``)."""
        return cls(twist=np.zeros(3), mode="separated", slip=slip, force=np.zeros(2),
                   load=np.zeros(3))  # fmt: skip


@dataclass(frozen=True, slots=True)
class MotionCone:
    """The twists at the two edges of the pusher's friction cone, scaled to unit normal speed
    of the contact point [m/s]; the part follows a sticking pusher with a positive combination
    of the contact velocities ``J @ right`` and ``J @ left``."""

    left: np.ndarray
    right: np.ndarray


def push_step(surface, *, contact, normal, velocity, mu: float) -> PushStep:
    """The quasi-static step of a part pushed at ``contact`` (see the module docstring).

    Parameters
    ----------
    surface
        The support's limit surface: anything with ``motion(load)`` and ``safety_factor(load)``
        for loads ``(fx, fy, m)`` (a frictionless support has no quasi-static motion).
    contact : array_like
        Contact point ``(x, y)`` on the part [m], in the surface's frame.
    normal : array_like
        Inward normal of the part at the contact (the direction the pusher pushes); normalised.
    velocity : array_like
        Velocity of the pusher point [m/s].
    mu : float
        Pusher–part friction coefficient, >= 0.
    """
    geometry = _Geometry.of(surface, contact, normal, mu)
    velocity = validation.finite_array("velocity", velocity, shape=(2,))
    push = float(velocity @ geometry.normal)
    if push <= 0.0:
        return PushStep.separated(float(velocity @ geometry.tangent))
    # Sticking: through the forward map where the surface has one (then the force found tells
    # the side it slides on if it lies outside the cone), else from the motion cone.
    sticking = geometry.sticking_by_forward_map(velocity)
    if sticking is None:
        side = _side(geometry.normal, *geometry.edge_velocities(), velocity)
        if side == 0:
            sticking = geometry.sticking_in_cone(velocity)
    elif geometry.in_cone(sticking[1]):
        side = 0
    else:
        side = 1 if sticking[1] @ geometry.tangent > 0.0 else -1
    if side == 0:
        twist, force, load = sticking
        return PushStep(twist=twist, mode="sticking", slip=0.0, force=force, load=load)
    force = geometry.edge(side)
    load = geometry.jacobian.T @ force
    twist, scale = geometry.twist_and_scale(load)
    normal_speed = float(geometry.normal @ geometry.jacobian @ twist)
    if normal_speed <= 0.0:  # pragma: no cover - normality makes it positive
        raise ModelError("the edge force does not drive the part away from the pusher")
    twist = twist * push / normal_speed
    slip = float(geometry.tangent @ (velocity - geometry.jacobian @ twist))
    return PushStep(twist=twist, mode="sliding-left" if side > 0 else "sliding-right", slip=slip,
                    force=force * scale, load=load * scale)  # fmt: skip


def motion_cone(surface, *, contact, normal, mu: float) -> MotionCone:
    """The motion cone of a pusher at ``contact`` (Mason; Lynch, Maekawa & Tanie 1992): the
    twists of the two edge forces of its friction cone, each at unit normal speed of the contact
    point. Arguments as for :func:`push_step`."""
    geometry = _Geometry.of(surface, contact, normal, mu)
    twists = []
    for side in (1, -1):
        twist = geometry.unit_twist(geometry.edge(side))
        twists.append(twist / float(geometry.normal @ geometry.jacobian @ twist))
    return MotionCone(left=twists[0], right=twists[1])


@dataclass(frozen=True, slots=True)
class _Geometry:
    """A pusher contact on a surface: its frame, friction and the force-to-velocity maps."""

    surface: object
    jacobian: np.ndarray  # J (2, 3)
    normal: np.ndarray
    tangent: np.ndarray
    half_angle: float  # atan(mu)
    ellipsoid: np.ndarray | None  # A of H(L) = L^T A L, when the surface is an ellipsoid

    @classmethod
    def of(cls, surface, contact, normal, mu) -> _Geometry:
        if not (hasattr(surface, "motion") and hasattr(surface, "safety_factor")):
            raise InvalidArgumentError(
                f"surface must have the limit-surface interface (motion, safety_factor), got "
                f"{type(surface).__name__}"
            )
        if getattr(surface, "frictionless", False):
            raise InvalidArgumentError(
                "a part on a frictionless support has no quasi-static motion: the smallest push "
                "accelerates it (give the support friction)"
            )
        cx, cy = validation.finite_array("contact", contact, shape=(2,))
        direction = validation.finite_array("normal", normal, shape=(2,))
        length = float(np.linalg.norm(direction))
        if length == 0.0:
            raise InvalidArgumentError("normal must be a nonzero 2-vector")
        direction = direction / length
        mu = validation.nonnegative_scalar("mu", mu)
        return cls(
            surface=surface,
            jacobian=np.array([[1.0, 0.0, -cy], [0.0, 1.0, cx]]),
            normal=direction,
            tangent=np.array([-direction[1], direction[0]]),
            half_angle=math.atan(mu),
            ellipsoid=_ellipsoid_matrix(surface),
        )

    def edge(self, side: int) -> np.ndarray:
        """Unit force on the left (``side = 1``) or right (-1) edge of the friction cone."""
        return self.force_at(side * self.half_angle)

    def force_at(self, angle: float) -> np.ndarray:
        """Unit force turned ``angle`` [rad] from the normal towards the tangent."""
        return math.cos(angle) * self.normal + math.sin(angle) * self.tangent

    def unit_twist(self, force: np.ndarray) -> np.ndarray:
        """The part's unit twist under the pusher force direction ``force`` (normality)."""
        return self.unit_twist_of_load(self.jacobian.T @ force)

    def unit_twist_of_load(self, load: np.ndarray) -> np.ndarray:
        """The part's unit twist under ``load`` (normality)."""
        if self.ellipsoid is not None:
            twist = self.ellipsoid @ load
        else:
            twist = np.asarray(self.surface.motion(load), dtype=float)
        if not np.all(np.isfinite(twist)):
            raise ModelError(f"the surface gives no motion for the load {load}")
        return twist / np.linalg.norm(twist)

    def in_cone(self, force: np.ndarray) -> bool:
        """Whether ``force`` lies in the pusher's friction cone (to rounding)."""
        along = float(force @ self.normal)
        across = abs(float(force @ self.tangent))
        return along > 0.0 and across <= math.tan(self.half_angle) * along * (1 + CONE_RTOL)

    def twist_and_scale(self, load: np.ndarray) -> tuple[np.ndarray, float]:
        """Unit twist of ``load`` (normality) and the factor that puts ``load`` on the surface."""
        if self.ellipsoid is not None:
            return self.unit_twist_of_load(load), float(self.surface.safety_factor(load))
        if hasattr(self.surface, "motion_and_safety_factor"):
            twist, scale = self.surface.motion_and_safety_factor(load)
            twist = np.asarray(twist, dtype=float)
            return twist / np.linalg.norm(twist), float(scale)
        return self.unit_twist_of_load(load), float(self.surface.safety_factor(load))

    def sticking_by_forward_map(self, velocity: np.ndarray):
        """``(twist, force, load)`` of minimum dissipation with ``J V = velocity``, through the
        forward map; ``None`` for surfaces without one."""
        forward = getattr(self.surface, "load", None)
        if forward is None or self.ellipsoid is not None:
            return None
        start = np.array([velocity[0], velocity[1], 0.0])
        turn = np.array([-self.jacobian[0, 2], -self.jacobian[1, 2], 1.0])  # (cy, -cx, 1)

        def slope(s: float) -> float:
            return float(np.asarray(forward(start + s * turn)) @ turn)

        reach = float(np.linalg.norm(velocity)) / max(float(np.linalg.norm(turn[:2])), 1e-3)
        low, high = -reach, reach
        while slope(low) > 0.0:
            low *= 2.0
        while slope(high) < 0.0:
            high *= 2.0
        s = brentq(slope, low, high, xtol=ANGLE_XTOL * reach, rtol=4 * np.finfo(float).eps)
        twist = start + s * turn
        # At a kink of h (a support point at rest) the slope jumps across 0: the load is the
        # combination of the one-sided loads whose slope is 0 (a subgradient).
        step = max(abs(s), reach) * 1e-9
        below, above = (np.asarray(forward(start + x * turn)) for x in (s - step, s + step))
        a, b = float(below @ turn), float(above @ turn)
        load = below + (above - below) * (-a / (b - a)) if b - a > 0.0 else forward(twist)
        force = np.linalg.lstsq(self.jacobian.T, load, rcond=None)[0]
        return twist, force, self.jacobian.T @ force

    def edge_velocities(self) -> tuple[np.ndarray, np.ndarray]:
        """Contact velocities of the right and left edge twists."""
        return tuple(self.jacobian @ self.unit_twist(self.edge(side)) for side in (-1, 1))

    def sticking_in_cone(self, velocity: np.ndarray):
        """``(twist, force, load)`` of a pusher that sticks, for ``velocity`` inside the motion
        cone, through the inverse map (or the ellipsoid's closed form)."""
        direction = self.sticking_force(velocity)
        twist = self.unit_twist(direction)
        moved = self.jacobian @ twist
        twist = twist * (velocity @ moved) / (moved @ moved)
        load = self.jacobian.T @ direction
        scale = float(self.surface.safety_factor(load))
        return twist, direction * scale, load * scale

    def sticking_force(self, velocity: np.ndarray) -> np.ndarray:
        """The unit force whose twist moves the contact point along ``velocity``."""
        if self.ellipsoid is not None:  # closed form: J A J^T F ∝ v_p
            force = np.linalg.solve(self.jacobian @ self.ellipsoid @ self.jacobian.T, velocity)
            return force / np.linalg.norm(force)
        if self.half_angle == 0.0:
            return self.normal

        def turn(angle: float) -> float:
            moved = self.jacobian @ self.unit_twist(self.force_at(angle))
            return float(moved[0] * velocity[1] - moved[1] * velocity[0])

        low, high = -self.half_angle, self.half_angle
        if turn(low) == 0.0:
            return self.force_at(low)
        if turn(high) == 0.0:
            return self.force_at(high)
        return self.force_at(brentq(turn, low, high, xtol=ANGLE_XTOL, rtol=4 * np.finfo(float).eps))


def _side(normal: np.ndarray, right: np.ndarray, left: np.ndarray, velocity: np.ndarray) -> int:
    """0 when ``velocity`` lies in the cone from ``right`` to ``left`` (counter-clockwise),
    1 beyond its left edge, -1 beyond its right edge; angles are measured from ``normal``."""

    def angle(vector: np.ndarray) -> float:
        return math.atan2(normal[0] * vector[1] - normal[1] * vector[0], normal @ vector)

    turn = angle(velocity)
    if turn > angle(left):
        return 1
    if turn < angle(right):
        return -1
    return 0


def _ellipsoid_matrix(surface) -> np.ndarray | None:
    """``A`` of an ellipsoid model ``H(L) = L^T A L`` (its normals are ``A L``), else ``None``."""
    if not isinstance(surface, Ellipsoid | FittedEllipsoid) or surface.frictionless:
        return None
    return surface.load_matrix
