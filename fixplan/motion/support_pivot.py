r"""A body that turns about one of its point supports: the facets of the limit surface in the
sliding dynamics (:mod:`fixplan.motion.sliding`).

A point support ``p`` (body frame, from the centre of mass) that does not move makes a facet of
the limit surface: every twist ``V = ω (p_y, -p_x, 1)`` turns the body about it, and the support
function has a kink there, so its gradient (the friction) is not defined. The point itself may
carry any friction force ``F`` of at most its friction ``c`` (``mu`` times its normal force),
the other supports resist with the forward map's ``(f_o, m_o) = ∇h(V)`` (in which the still
point carries nothing). Newton's laws about the still point give the body's angular
acceleration, and the force that keeps the point still,

.. math:: (I + m |p|^2) \, \dot ω = (m_a - p × f_a) - (m_o - p × f_o), \qquad
          F = m (-\dot ω \, J p + ω^2 p) - f_a + f_o, \quad J p = (-p_y, p_x),

with ``(f_a, m_a)`` the applied load (body frame, about the centre of mass); the centre of mass
moves with the velocity ``-ω J p`` and the acceleration ``-\dot ω J p + ω^2 p`` (body frame). The
point sticks while ``|F| <= c``; beyond, it slips and the body slides. Where the body starts from
rest by turning about ``p`` (its starting acceleration ``a = \dot ω (p_y, -p_x, 1)`` on the
facet), ``ω = 0`` and the others' friction is that of the sense ``s = ±1`` of the turn, which
``\dot ω`` must share: the optimality condition of the convex problem of a start
(:func:`~fixplan.motion.sliding.start_acceleration`), ``M a - L + λ = 0`` with ``λ`` in ``∂h(a)``,
is then these three equations.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from fixplan.motion.forward_map import exact_form
from fixplan.surface.limit_surface import LimitSurface
from fixplan.tolerances import CONTAINMENT_RTOL


@dataclass(frozen=True, slots=True)
class PointSupports:
    """The point supports of a limit surface (:attr:`~fixplan.LimitSurface.point_supports`).

    Attributes
    ----------
    points : numpy.ndarray
        ``(P, 2)`` positions [m] in the body frame at the centre of mass.
    friction : numpy.ndarray
        ``(P,)`` friction force each can take [N].
    """

    points: np.ndarray
    friction: np.ndarray

    @classmethod
    def of(cls, surface) -> PointSupports | None:
        """Those of ``surface`` (an exact :class:`~fixplan.LimitSurface`, an ``Exact`` model, or
        a :class:`~fixplan.ContactSetSurface` with an exact form); ``None`` for
        surfaces without them (patches, the smooth friction models)."""
        surface = exact_form(surface)
        if not isinstance(surface, LimitSurface) or not surface.has_facets:
            return None
        points, friction = surface.point_supports
        return cls(points, friction)

    def speeds(self, twist: np.ndarray) -> np.ndarray:
        """``(P,)`` speeds [m/s] of the points under the body-frame ``twist``."""
        vx, vy, w = twist
        return np.hypot(vx - w * self.points[:, 1], vy + w * self.points[:, 0])


def turning_twist(point: np.ndarray, sense: float) -> np.ndarray:
    """The body-frame twist of a turn at unit rate about ``point`` ``(2,)`` [m] in ``sense``."""
    return sense * np.array([point[1], -point[0], 1.0])


@dataclass(frozen=True, slots=True)
class Turn:
    """The dynamics of a body turning about one point support.

    Attributes
    ----------
    point : numpy.ndarray
        ``(2,)`` the still point [m], body frame from the centre of mass.
    capacity : float
        The friction [N] that can keep it still.
    masses : numpy.ndarray
        ``(m, m, I)`` [kg, kg, kg m²].
    """

    point: np.ndarray
    capacity: float
    masses: np.ndarray

    def acceleration(
        self, others, applied: np.ndarray, rate: float, sense: float
    ) -> tuple[float, np.ndarray]:
        """The angular acceleration [rad/s²] about the point and the friction force ``F``
        ``(2,)`` [N] (body frame) that keeps it still, at the angular ``rate`` [rad/s] (its sign
        the ``sense`` of the turn, or 0), under the ``applied`` load ``(fx, fy, m)`` [N, N, N m];
        ``others(twist)`` is the forward map (the friction of the other supports)."""
        px, py = self.point
        mass, inertia = self.masses[0], self.masses[2]
        fo_x, fo_y, mo = others(turning_twist(self.point, sense))
        fa_x, fa_y, ma = applied
        about_point = (ma - (px * fa_y - py * fa_x)) - (mo - (px * fo_y - py * fo_x))
        alpha = about_point / (inertia + mass * (px * px + py * py))
        squared = rate * rate
        force = np.array([mass * (alpha * py + squared * px) - fa_x + fo_x,
                          mass * (-alpha * px + squared * py) - fa_y + fo_y])  # fmt: skip
        return float(alpha), force

    def beyond_friction(self, force: np.ndarray) -> float:
        """How far ``force`` [N] exceeds what the point's friction can give (to
        ``CONTAINMENT_RTOL``): above 0 it slips."""
        return float(np.hypot(*force)) - (1.0 + CONTAINMENT_RTOL) * self.capacity

    def sticks(self, force: np.ndarray) -> bool:
        """Whether the point's friction can give ``force``."""
        return self.beyond_friction(force) <= 0.0


def turn_from_rest(
    supports: PointSupports, others, masses: np.ndarray, applied: np.ndarray
) -> tuple[int, Turn, float, np.ndarray] | None:
    """The turn about a point support in which a body at rest starts under the ``applied``
    load, where it starts so: the point's index, the :class:`Turn`, its sense and the body's
    acceleration ``(ax, ay, α)`` (body frame) as it starts; ``None``
    where no point stays still (the body slides, or stays at rest). ``others`` is the forward
    map (:class:`~fixplan.motion.forward_map.ForwardMap`). Of turns that all meet the
    conditions to rounding, the one of least ``½aᵀMa - L·a + h(a)``."""
    best, least = None, np.inf
    for index, point in enumerate(supports.points):
        turn = Turn(point, float(supports.friction[index]), masses)
        for sense in (1.0, -1.0):
            alpha, force = turn.acceleration(others.load, applied, 0.0, sense)
            if alpha * sense <= 0.0 or not turn.sticks(force):
                continue
            a = alpha * turning_twist(point, 1.0)
            value = 0.5 * float(a @ (masses * a)) - float(applied @ a) + float(others.support(a))
            if value < least:
                best, least = (index, turn, sense, a), value
    return best
