r"""One quasi-static pushing step of a flat pusher face touching a part at two points.

The face of a translating pusher lies flush with an edge of the part (or touches two vertices of
it): the part touches it at the two ends ``c_r`` and ``c_l`` of the contact segment (``c_l`` the
one farther along ``t``), both with the face's inward normal ``n``; ``t`` is ``n`` turned a
quarter counter-clockwise. The pusher moves with velocity ``v_p`` (``v_p · n > 0``, else the part
stays at rest) and has friction ``mu`` with the part. The formulation is that of
:mod:`fixplan.motion.pushing` (quasi-static, maximum power: the total load ``L`` on the limit
surface, the twist ``V`` along its normal there), with one friction cone per contact point
(Lynch & Mason 1996, "Stable pushing"). While both points press on the face their normal
velocities equal the pusher's, so the part does not turn: ``V = (v, 0)`` with ``v · n = v_p · n``.

- **Sticking**: ``v = v_p``. The load of that translation (the forward map ``∇h(v_p, 0)``, or for
  an ellipsoid ``H(L) = L^T A L`` the closed form ``L ∝ A^{-1} (v_p, 0)``) must be a nonnegative
  combination of the four edge wrenches of the two friction cones: its force in the friction
  cone and its line of action crossing the contact segment.
- **Sliding left / right**: both points slip along ``±t`` by the same speed; both forces lie on
  the same cone edge ``e``, so the load's force is parallel to ``e`` and its moment lies between
  those of ``e`` at the two points. The translation ``v`` whose load's force is parallel to ``e``
  is unique (the force of a translation turns with it, monotonically); for an ellipsoid it is
  ``v ∝ G^{-1} e`` with ``G`` the force block of ``A^{-1}``, otherwise a root on its direction.
- **Rotating off** one end: the single-point step of :func:`~fixplan.motion.push_step` at that
  end (sticking or sliding there), consistent when the other end moves away from the face.

Which mode. Exactly one of the three two-point modes has its force where the modes need it: the
force of the sticking translation lies in the cone (sticking), beyond its left edge (then the
translation whose force lies on that edge lags the pusher along ``t``: sliding left) or beyond
its right edge. That mode is consistent when its line of action crosses the contact segment, and it is then
taken: the face holds the part (stable pushing). Otherwise the part rotates off the end on whose
side the line passes, if that end's single-point step lifts the other end, else off the other
end if that one's does. For a frictionless pusher these are the optimality conditions of the
convex problem ``min h(V)`` subject to both points moving at least with the pusher, so exactly one
mode is consistent. With friction the conditions need not have a single solution (quasi-static
problems with friction can be ambiguous; stable pushing in Lynch & Mason's sense asks that
sticking be the only consistent mode), and the order above then decides. In random sweeps
(contact segments, normals, pusher directions and ``mu`` in [0, 1.5]; 40,000 on ellipsoids of a
5:2 and a 10:1 rectangle, 1,600 on the exact surfaces of a 5:2 rectangle and of three support
points) exactly one mode was consistent every time. None at all raises
:class:`~fixplan.errors.ModelError`.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.optimize import brentq

from fixplan import validation
from fixplan.errors import InvalidArgumentError, ModelError
from fixplan.models.ellipsoid import Ellipsoid, FittedEllipsoid
from fixplan.motion.forward_map import ForwardMap, forward_map
from fixplan.motion.pushing import ANGLE_XTOL, CONE_RTOL, PushStep, push_step

#: The line of action of a two-point load may pass beyond an end of the contact segment by this
#: fraction of its length and still count as crossing it (rounding).
SEGMENT_RTOL = 1e-9

#: A part rotating off one end may bring its other end towards the face at up to this fraction of
#: the pusher's normal speed and still count as lifting it (rounding).
LIFT_RTOL = 1e-9


def line_push_step(
    surface, *, contacts, normal, velocity, mu: float
) -> tuple[PushStep, np.ndarray]:
    """The quasi-static step of a part touching a flat pusher at two points (module docstring).

    Parameters
    ----------
    surface
        The support's limit surface, with a forward map (the load of a translation):
        :class:`~fixplan.LimitSurface`, :class:`~fixplan.ContactSetSurface`, or the models
        :class:`~fixplan.models.Ellipsoid`, ``FittedEllipsoid`` and ``Exact``.
    contacts : array_like
        ``(2, 2)`` the two contact points on the part [m], in the surface's frame, on a line
        perpendicular to ``normal``.
    normal : array_like
        Inward normal of the part at both points (the direction the face pushes); normalised.
    velocity : array_like
        Velocity of the pusher [m/s].
    mu : float
        Pusher–part friction coefficient, >= 0.

    Returns
    -------
    step : PushStep
        The part's twist, the mode (named as for one point), the slip, and the pusher's total
        force and load.
    bearing : numpy.ndarray
        ``(k, 2)`` the contact points that press on the face: both, the one the part rotates
        about (rotating off), or none (separated).
    """
    translations = _Translations.of(surface)
    points = validation.finite_array("contacts", contacts, shape=(2, 2))
    direction = validation.finite_array("normal", normal, shape=(2,))
    if not np.any(direction):
        raise InvalidArgumentError("normal must be a nonzero 2-vector")
    direction = direction / np.linalg.norm(direction)
    tangent = np.array([-direction[1], direction[0]])
    velocity = validation.finite_array("velocity", velocity, shape=(2,))
    mu = validation.nonnegative_scalar("mu", mu)
    push = float(velocity @ direction)
    if push <= 0.0:
        return PushStep.separated(float(velocity @ tangent)), np.empty((0, 2))
    right, left = points[np.argsort(points @ tangent)]
    if (left - right) @ tangent <= 0.0:
        raise InvalidArgumentError(
            f"contacts must be two points apart along the face, got {points}"
        )
    flush, beyond = _flush(translations, right, left, direction, velocity, mu)
    if beyond == 0:
        return flush, points
    ends = [(left, right), (right, left)] if beyond > 0 else [(right, left), (left, right)]
    for end, other in ends:
        step = push_step(surface, contact=end, normal=direction, velocity=velocity, mu=mu)
        if direction @ _jacobian(other) @ step.twist - push >= -LIFT_RTOL * push:
            return step, end[None, :]
    raise ModelError(
        f"no consistent contact mode for the flat pusher at {points.tolist()} moving with "
        f"{velocity.tolist()}: neither both points nor either one alone can bear the push"
    )


def _flush(translations, right, left, normal, velocity, mu) -> tuple[PushStep | None, int]:
    """The two-point mode the friction cone allows and where its load's line of action passes:
    0 through the contact segment, 1 beyond its left end, -1 beyond its right end."""
    tangent = np.array([-normal[1], normal[0]])
    load = translations.load(velocity)
    along, across = float(load[:2] @ normal), float(load[:2] @ tangent)
    if along > 0.0 and abs(across) <= mu * along * (1 + CONE_RTOL):
        moving, mode = velocity, "sticking"
    else:
        side = 1 if across > 0.0 else -1
        edge = (normal + side * mu * tangent) / math.hypot(1.0, mu)
        moving = translations.sliding(edge, normal, velocity, side)
        if moving is None:
            return None, side
        load = translations.load(moving)
        mode = "sliding-left" if side > 0 else "sliding-right"
    force = load[:2]
    moments = [_cross(point, force) for point in (right, left)]
    share = (load[2] - moments[0]) / (moments[1] - moments[0])  # of the force at the left end
    beyond = 1 if share > 1 + SEGMENT_RTOL else -1 if share < -SEGMENT_RTOL else 0
    twist = np.array([moving[0], moving[1], 0.0])
    slip = 0.0 if mode == "sticking" else float(tangent @ (velocity - moving))
    return PushStep(twist=twist, mode=mode, slip=slip, force=force, load=load), beyond


class _Translations:
    """The loads of a surface's translations ``(v, 0)``: by its forward map
    (:func:`~fixplan.motion.forward_map.forward_map`), with the ellipsoid's closed form for the
    translation whose load has a given force direction."""

    def __init__(self, forward: ForwardMap, inverse: np.ndarray | None):
        self._forward = forward
        self._inverse = inverse  # A^{-1} of an ellipsoid H(L) = L^T A L

    @classmethod
    def of(cls, surface) -> _Translations:
        forward = forward_map(surface)
        if isinstance(surface, Ellipsoid | FittedEllipsoid):
            return cls(forward, np.linalg.inv(surface.load_matrix))
        return cls(forward, None)

    def load(self, velocity: np.ndarray) -> np.ndarray:
        """The load on the surface that sustains the translation ``velocity``."""
        return np.asarray(self._forward.load(np.array([velocity[0], velocity[1], 0.0])), float)

    def sliding(self, edge: np.ndarray, normal: np.ndarray, velocity: np.ndarray, side: int):
        """The translation at the normal speed of ``velocity`` whose load's force is parallel to
        ``edge``, the cone's edge on ``side`` (1 left, -1 right) of the force of ``velocity``'s
        translation; ``None`` when no translation towards ``normal`` has such a force."""
        push = float(velocity @ normal)
        if self._inverse is not None:
            moving = np.linalg.solve(self._inverse[:2, :2], edge)
            speed = float(moving @ normal)
            return moving * push / speed if speed > 0.0 else None
        tangent = np.array([-normal[1], normal[0]])
        target = math.atan2(edge @ tangent, edge @ normal)

        def turn(angle: float) -> float:
            force = self.load(math.cos(angle) * normal + math.sin(angle) * tangent)[:2]
            return math.atan2(force @ tangent, force @ normal) - target

        # The force turns with the direction of the translation: the one along the edge lies
        # between the pusher's direction and the tangent on the edge's other side.
        far = -side * math.pi / 2
        if side * turn(far) >= 0.0:
            return None
        start = math.atan2(velocity @ tangent, push)
        if side * turn(start) < 0.0:  # (then the force along the edge is not on this side)
            return None
        angle = brentq(turn, min(far, start), max(far, start), xtol=ANGLE_XTOL,
                       rtol=4 * np.finfo(float).eps)  # fmt: skip
        return (math.cos(angle) * normal + math.sin(angle) * tangent) * push / math.cos(angle)


def _jacobian(point: np.ndarray) -> np.ndarray:
    """Velocity of the part point ``point`` per twist ``(vx, vy, w)``."""
    return np.array([[1.0, 0.0, -point[1]], [0.0, 1.0, point[0]]])


def _cross(point: np.ndarray, force: np.ndarray) -> float:
    """Moment [N m] about the origin of ``force`` applied at ``point``."""
    return float(point[0] * force[1] - point[1] * force[0])
