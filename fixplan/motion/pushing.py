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
  one-sided loads that annuls it). Surfaces with only the inverse map, or with a closed-form
  inverse map and an iterative forward map (a class attribute ``closed_form_motion = True``, as
  :class:`~fixplan.motion.fitted_quartic.FittedQuartic`), are solved on the force angle
  instead: as the force turns across the friction cone the contact velocity ``J V(F)`` turns
  the same way (``J ∇²H J^T`` is positive definite). An ellipsoid ``H(L) = L^T A L`` has
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
import operator
from collections.abc import Callable
from dataclasses import dataclass
from functools import lru_cache

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

#: Load matrices of this many ellipsoid models are kept: building one costs more than a step.
_ELLIPSOIDS_KEPT = 64

#: Relative step to either side of the sticking twist where the one-sided loads of a kink of
#: ``h`` are taken (a support point at rest).
_KINK_STEP = 1e-9

#: The lever of the contact about the origin is taken at least this long [m] when bracketing the
#: line of sticking twists (a push at the origin turns the part about itself).
_MIN_LEVER = 1e-3

_EPS = np.finfo(float).eps

Vector = tuple[float, ...]


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
    velocity = _pair("velocity", velocity)
    push = _dot(velocity, geometry.normal)
    if push <= 0.0:
        return PushStep.separated(_dot(velocity, geometry.tangent))
    # Sticking: through the forward map where the surface has one and its inverse map is not the
    # cheaper (then the force found tells the side it slides on if it lies outside the cone),
    # else from the motion cone.
    sticking = geometry.sticking_by_forward_map(velocity)
    if sticking is None:
        side = _side(geometry.normal, *geometry.edge_velocities(), velocity)
        if side == 0:
            sticking = geometry.sticking_in_cone(velocity)
    elif geometry.in_cone(sticking[1]):
        side = 0
    else:
        side = 1 if _dot(sticking[1], geometry.tangent) > 0.0 else -1
    if side == 0:
        twist, force, load = sticking
        return PushStep(twist=np.array(twist), mode="sticking", slip=0.0, force=np.array(force),
                        load=np.array(load))  # fmt: skip
    force = geometry.edge(side)
    load = geometry.load_of(force)
    twist, scale = geometry.twist_and_scale(load)
    normal_speed = _dot(geometry.normal, geometry.velocity_of(twist))
    # (An edge whose twist does not push the part away makes every push stick: not reached.)
    if normal_speed <= 0.0:  # pragma: no cover
        raise ModelError("the edge force does not drive the part away from the pusher")
    twist = _scaled(twist, push / normal_speed)
    moved = geometry.velocity_of(twist)
    slip = _dot(geometry.tangent, (velocity[0] - moved[0], velocity[1] - moved[1]))
    return PushStep(twist=np.array(twist), mode="sliding-left" if side > 0 else "sliding-right",
                    slip=slip, force=np.array(_scaled(force, scale)),
                    load=np.array(_scaled(load, scale)))  # fmt: skip


def motion_cone(surface, *, contact, normal, mu: float) -> MotionCone:
    """The motion cone of a pusher at ``contact`` (Mason; Lynch, Maekawa & Tanie 1992): the
    twists of the two edge forces of its friction cone, each at unit normal speed of the contact
    point. Arguments as for :func:`push_step`.

    Raises
    ------
    ModelError
        When an edge force moves the contact point along the contact tangent or back into the
        pusher (normal speed <= 0; power stays positive through the tangential part). Then no
        twist of that edge has unit normal speed: the cone of contact velocities is not pointed
        (it holds every push into the part, all of which stick). A contact on the line of a
        two-point support, pushed along it, turns the part about a support point this way.
    """
    geometry = _Geometry.of(surface, contact, normal, mu)
    twists = []
    for side in (1, -1):
        twist = geometry.unit_twist(geometry.edge(side))
        moved = geometry.velocity_of(twist)
        normal_speed = _dot(geometry.normal, moved)
        if not normal_speed > 0.0:
            name = "left" if side > 0 else "right"
            raise ModelError(
                f"the {name} edge force of the pusher's friction cone at contact "
                f"{list(geometry.contact)} moves the part with the twist "
                f"{[float(x) for x in twist]}, whose contact velocity {[float(x) for x in moved]} "
                f"has normal speed {normal_speed:.3g} along the normal {list(geometry.normal)}: "
                "it does not move the part away from the pusher, so the motion cone has no edge "
                "twist at unit normal speed (every push into the part sticks); use push_step "
                "for a given pusher velocity"
            )
        twists.append(np.array(_scaled(twist, 1.0 / normal_speed)))
    return MotionCone(left=twists[0], right=twists[1])


@dataclass(frozen=True, slots=True)
class _Geometry:
    """A pusher contact on a surface: its frame, friction and the force-to-velocity maps.

    Vectors are tuples of floats: forces and velocities ``(x, y)``, loads and twists
    ``(x, y, angular)`` (numpy costs more than the arithmetic at this size).
    """

    surface: object
    contact: Vector  # c; J = [[1, 0, -cy], [0, 1, cx]]
    normal: Vector
    tangent: Vector
    half_angle: float  # atan(mu)
    ellipsoid: tuple[Vector, ...] | None  # A of H(L) = L^T A L, when the surface is an ellipsoid
    forward: Callable | None  # the surface's load(twist), when it has one
    joint: Callable | None  # the surface's motion_and_safety_factor(load), when it has one

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
        contact = _pair("contact", contact)
        validation.coordinates("contact", np.array(contact))  # (1e300 m gave a NaN step)
        nx, ny = _pair("normal", normal)
        length = math.hypot(nx, ny)
        if length == 0.0:
            raise InvalidArgumentError("normal must be a nonzero 2-vector")
        nx, ny = nx / length, ny / length
        mu = validation.nonnegative_scalar("mu", mu)
        ellipsoid = _ellipsoid_matrix(surface)
        # A closed-form inverse map beside an iterative forward map (a quartic's Newton solve):
        # the force-angle route costs less than root finding through the forward map.
        closed_form = getattr(type(surface), "closed_form_motion", False) is True
        return cls(
            surface=surface,
            contact=contact,
            normal=(nx, ny),
            tangent=(-ny, nx),
            half_angle=math.atan(mu),
            ellipsoid=ellipsoid,
            forward=None
            if ellipsoid is not None or closed_form
            else getattr(surface, "load", None),
            joint=getattr(surface, "motion_and_safety_factor", None),
        )

    def velocity_of(self, twist: Vector) -> Vector:
        """``J V``: velocity of the part's contact point under ``twist``."""
        cx, cy = self.contact
        return twist[0] - cy * twist[2], twist[1] + cx * twist[2]

    def load_of(self, force: Vector) -> Vector:
        """``B F = Jᵀ F``: the load of a pusher force about the origin."""
        cx, cy = self.contact
        return force[0], force[1], cx * force[1] - cy * force[0]

    def edge(self, side: int) -> Vector:
        """Unit force on the left (``side = 1``) or right (-1) edge of the friction cone."""
        return self.force_at(side * self.half_angle)

    def force_at(self, angle: float) -> Vector:
        """Unit force turned ``angle`` [rad] from the normal towards the tangent."""
        c, s = math.cos(angle), math.sin(angle)
        (nx, ny), (tx, ty) = self.normal, self.tangent
        return c * nx + s * tx, c * ny + s * ty

    def unit_twist(self, force: Vector) -> Vector:
        """The part's unit twist under the pusher force direction ``force`` (normality)."""
        return self.unit_twist_of_load(self.load_of(force))

    def unit_twist_of_load(self, load: Vector) -> Vector:
        """The part's unit twist under ``load`` (normality)."""
        if self.ellipsoid is not None:
            twist = tuple(_dot(row, load) for row in self.ellipsoid)
        else:
            twist = tuple(np.asarray(self.surface.motion(np.array(load)), dtype=float).tolist())
        if not all(map(math.isfinite, twist)):
            raise ModelError(f"the surface gives no motion for the load {np.array(load)}")
        return _scaled(twist, 1.0 / math.sqrt(_dot(twist, twist)))

    def safety_factor(self, load: Vector) -> float:
        """The factor that puts ``load`` on the surface (an ellipsoid's in closed form)."""
        if self.ellipsoid is not None:
            quadratic = _dot(load, tuple(_dot(row, load) for row in self.ellipsoid))
            return self.surface.normal_force / math.sqrt(quadratic)
        return float(self.surface.safety_factor(np.array(load)))

    def in_cone(self, force: Vector) -> bool:
        """Whether ``force`` lies in the pusher's friction cone (to rounding)."""
        along = _dot(force, self.normal)
        across = abs(_dot(force, self.tangent))
        return along > 0.0 and across <= math.tan(self.half_angle) * along * (1 + CONE_RTOL)

    def twist_and_scale(self, load: Vector) -> tuple[Vector, float]:
        """Unit twist of ``load`` (normality) and the factor that puts ``load`` on the surface."""
        if self.ellipsoid is None and self.joint is not None:
            twist, scale = self.joint(np.array(load))
            twist = tuple(np.asarray(twist, dtype=float).tolist())
            return _scaled(twist, 1.0 / math.sqrt(_dot(twist, twist))), float(scale)
        return self.unit_twist_of_load(load), self.safety_factor(load)

    def sticking_by_forward_map(self, velocity: Vector):
        """``(twist, force, load)`` of minimum dissipation with ``J V = velocity``, through the
        forward map; ``None`` for surfaces without one."""
        forward = self.forward
        if forward is None:
            return None
        cx, cy = self.contact
        vx, vy = velocity
        turn = (cy, -cx, 1.0)  # N: rotation about the contact point

        def on_line(s: float) -> np.ndarray:  # V_0 + s N
            return np.array([vx + s * cy, vy - s * cx, s])

        def slope(s: float) -> float:
            return _dot(np.asarray(forward(on_line(s))).tolist(), turn)

        reach = math.hypot(vx, vy) / max(math.hypot(cx, cy), _MIN_LEVER)
        low, high = -reach, reach
        while slope(low) > 0.0:
            low *= 2.0
        while slope(high) < 0.0:
            high *= 2.0
        s = brentq(slope, low, high, xtol=ANGLE_XTOL * reach, rtol=4 * _EPS)
        # At a kink of h (a support point at rest) the slope jumps across 0: the load is the
        # combination of the one-sided loads whose slope is 0 (a subgradient).
        step = max(abs(s), reach) * _KINK_STEP
        below, above = (np.asarray(forward(on_line(x))).tolist() for x in (s - step, s + step))
        a, b = _dot(below, turn), _dot(above, turn)
        if b - a > 0.0:
            load = tuple(x + (y - x) * (-a / (b - a)) for x, y in zip(below, above, strict=True))
        else:
            load = tuple(np.asarray(forward(on_line(s)), dtype=float).tolist())
        force = self.force_of(load)
        return tuple(on_line(s).tolist()), force, self.load_of(force)

    def force_of(self, load: Vector) -> Vector:
        """The pusher force ``F`` whose load ``Jᵀ F`` is nearest to ``load`` (least squares:
        ``J Jᵀ F = J L``, with ``det J Jᵀ = 1 + |c|²``)."""
        cx, cy = self.contact
        jx, jy = load[0] - cy * load[2], load[1] + cx * load[2]
        det = 1.0 + cx * cx + cy * cy
        return ((1.0 + cx * cx) * jx + cx * cy * jy) / det, (
            cx * cy * jx + (1.0 + cy * cy) * jy
        ) / det

    def edge_velocities(self) -> tuple[Vector, Vector]:
        """Contact velocities of the right and left edge twists."""
        return tuple(self.velocity_of(self.unit_twist(self.edge(side))) for side in (-1, 1))

    def sticking_in_cone(self, velocity: Vector):
        """``(twist, force, load)`` of a pusher that sticks, for ``velocity`` inside the motion
        cone, through the inverse map (or the ellipsoid's closed form)."""
        direction = self.sticking_force(velocity)
        twist = self.unit_twist(direction)
        moved = self.velocity_of(twist)
        twist = _scaled(twist, _dot(velocity, moved) / _dot(moved, moved))
        load = self.load_of(direction)
        scale = self.safety_factor(load)
        return twist, _scaled(direction, scale), _scaled(load, scale)

    def sticking_force(self, velocity: Vector) -> Vector:
        """The unit force whose twist moves the contact point along ``velocity``."""
        if self.ellipsoid is not None:  # closed form: J A J^T F ∝ v_p
            return self._ellipsoid_sticking_force(velocity)
        if self.half_angle == 0.0:
            return self.normal

        def turn(angle: float) -> float:
            moved = self.velocity_of(self.unit_twist(self.force_at(angle)))
            return moved[0] * velocity[1] - moved[1] * velocity[0]

        low, high = -self.half_angle, self.half_angle
        if turn(low) == 0.0:
            return self.force_at(low)
        if turn(high) == 0.0:
            return self.force_at(high)
        return self.force_at(brentq(turn, low, high, xtol=ANGLE_XTOL, rtol=4 * _EPS))

    def _ellipsoid_sticking_force(self, velocity: Vector) -> Vector:
        """``(J A Jᵀ)⁻¹ v_p``, normalised (Cramer's rule on the 2x2 system)."""
        cx, cy = self.contact
        ax = tuple(row[0] - cy * row[2] for row in self.ellipsoid)  # A Jᵀ, first column
        ay = tuple(row[1] + cx * row[2] for row in self.ellipsoid)
        k00, k01 = ax[0] - cy * ax[2], ay[0] - cy * ay[2]
        k10, k11 = ax[1] + cx * ax[2], ay[1] + cx * ay[2]
        det = k00 * k11 - k01 * k10
        fx = (k11 * velocity[0] - k01 * velocity[1]) / det
        fy = (k00 * velocity[1] - k10 * velocity[0]) / det
        return _scaled((fx, fy), 1.0 / math.hypot(fx, fy))


def _side(normal: Vector, right: Vector, left: Vector, velocity: Vector) -> int:
    """0 when ``velocity`` lies in the cone from ``right`` to ``left`` (counter-clockwise),
    1 beyond its left edge, -1 beyond its right edge; angles are measured from ``normal``."""

    def angle(vector: Vector) -> float:
        return math.atan2(normal[0] * vector[1] - normal[1] * vector[0], _dot(normal, vector))

    turn = angle(velocity)
    if turn > angle(left):
        return 1
    if turn < angle(right):
        return -1
    return 0


def _dot(a: Vector, b: Vector) -> float:
    return sum(map(operator.mul, a, b))


def _scaled(vector: Vector, factor: float) -> Vector:
    return tuple(x * factor for x in vector)


def _pair(name: str, value: object) -> Vector:
    """``value`` as two finite floats, checked as :func:`validation.finite_array` does (a pair
    of plain numbers is taken without building an array)."""
    plain = isinstance(value, list | tuple) and len(value) == 2
    if plain or (isinstance(value, np.ndarray) and value.shape == (2,) and value.dtype == float):
        x, y = value
        if isinstance(x, float | int) and isinstance(y, float | int):
            x, y = float(x), float(y)
            if math.isfinite(x) and math.isfinite(y):
                return x, y
    x, y = validation.finite_array(name, value, shape=(2,)).tolist()
    return x, y


def _ellipsoid_matrix(surface) -> tuple[Vector, ...] | None:
    """``A`` of an ellipsoid model ``H(L) = L^T A L`` (its normals are ``A L``), else ``None``."""
    if not isinstance(surface, Ellipsoid | FittedEllipsoid) or surface.frictionless:
        return None
    return _load_matrix(surface)


@lru_cache(maxsize=_ELLIPSOIDS_KEPT)
def _load_matrix(model: Ellipsoid | FittedEllipsoid) -> tuple[Vector, ...]:
    """The rows of ``model.load_matrix`` (models are immutable: equal models, equal matrices)."""
    return tuple(tuple(row) for row in model.load_matrix.tolist())
