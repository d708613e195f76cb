r"""Sliding dynamics: a body on its support under an applied load (Goyal; the paper's "dynamic
simulation").

The body's frame sits at its centre of mass, and the support's limit surface is given in that
frame. With the world pose ``(x, y, θ)``, the world velocity ``v`` of the centre of mass, the
angular rate ``ω`` and the applied load ``L(t, pose) = (f, m)`` in the body frame about the
centre of mass,

.. math:: m \dot v = R(θ) (f - f_F), \qquad I \dot ω = m - m_F, \qquad
          (f_F, m_F) = \nabla h(V) \quad (V \ne 0),

where ``V = (R(θ)^T v, ω)`` is the twist in the body frame and ``∇h(V)`` the friction load
that resists sliding with it (the forward map). Friction does not depend on the speed, only on
the direction of the twist, so a body stops in finite time; translation and rotation may stop
separately (the twist then turns into a pure rotation or translation) or together (a uniform
puck: the classic result that a spinning puck stops sliding and turning at the same instant).

**At rest** friction is any load inside the limit surface. The body's acceleration ``a`` (body
frame) then solves ``M a = L - λ`` with ``λ`` the friction of the motion that starts,
``λ ∈ ∂h(a)``, which is the optimality condition of the convex problem

.. math:: a^* = \arg\min_a \tfrac12 a^T M a - L \cdot a + h(a), \qquad M = \mathrm{diag}(m, m, I):

``a* = 0`` exactly when ``L`` lies inside the limit surface (static friction holds; as in the
friction models, a load whose safety factor is at least ``1 - CONTAINMENT_RTOL`` counts as held,
so a load on the surface itself, such as a push of exactly ``mu N``, leaves the body at rest), and
otherwise ``λ = L - M a*`` is the point of the limit surface nearest to ``L`` in the metric of
``M^{-1}`` (Moreau's decomposition), with the surface's normal there along ``a*`` (normality).
It is solved as the root of its smooth gradient ``M a - L + ∇h(a)`` (Powell's hybrid method),
started from the load scaled onto the surface. So a body can stop and stay while the load is
inside the surface and start again when the load leaves it (stick–slip).

The state is integrated by an adaptive Runge–Kutta method (scipy's ``solve_ivp``; LSODA where
that is stiff, ``MAX_EVALUATIONS``) with an event
where the speed falls below ``STOP_RTOL`` of the run's speed scale (the larger of the starting
speed and the speed the largest friction force takes away over the run); there the body is put
at rest. Without a load it stays at rest. With one, the load on the resting body is checked at
the samples, and the instant it leaves the surface is found between them by root finding; the
body starts to slide there (a load that leaves the surface and comes back between two samples
goes unnoticed).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from scipy.integrate import solve_ivp
from scipy.optimize import brentq, root

from fixplan import validation
from fixplan.errors import ConvergenceError, InvalidArgumentError
from fixplan.motion.forward_map import ForwardMap, forward_map
from fixplan.tolerances import CONTAINMENT_RTOL, MAX_STEPS

#: The body counts as stopped when its speed (with rotation counted at the radius of gyration)
#: falls below this fraction of the run's speed scale.
STOP_RTOL = 1e-9

#: Relative tolerance of the adaptive integration.
INTEGRATION_RTOL = 1e-10

#: Evaluations of the equations of motion one integration (from a start to a stop) may take:
#: five times the most the tests' runs take (18,512: a periodic push's stick-slip). Beyond it the
#: explicit method is judged stiff (a load within about 1e-6 of the limit surface: steps of the
#: friction's time scale over the small net force; RK45 ran for minutes where LSODA takes
#: milliseconds), and the integration is repeated with LSODA; beyond it again, given up.
MAX_EVALUATIONS = 100_000

#: Absolute tolerance of the velocities, as a fraction of the stopping speed.
STOP_ATOL = 1e-2

#: The instant a resting body starts to slide is found to this fraction of the duration.
LEAVE_XTOL = 1e-15

#: Relative step tolerance of the root finding of the starting acceleration.
START_XTOL = 1e-12

#: A starting acceleration is accepted when the residual of its optimality condition is below
#: this fraction of the load (in the scaled coordinates ``M^{-1/2} L``).
START_RTOL = 1e-9


@dataclass(frozen=True, slots=True)
class Sliding:
    """A body's sliding.

    Attributes
    ----------
    t : numpy.ndarray
        Times [s] of the samples.
    poses : numpy.ndarray
        ``(n, 3)`` world poses ``(x, y, θ)`` of the centre of mass [m, m, rad].
    twists : numpy.ndarray
        ``(n, 3)`` twists in the body frame ``(vx, vy, ω)`` [m/s, m/s, rad/s].
    stopped : float or None
        The instant [s] from which the body stays at rest to the end (0 for a body that never
        moved; ``None``: moving at the end).
    stops : tuple of float
        Every instant [s] at which the body came to rest (it may start again under a load).
    starts : tuple of float
        Every instant [s] at which a resting body started to slide (its load left the surface).
    """

    t: np.ndarray
    poses: np.ndarray
    twists: np.ndarray
    stopped: float | None
    stops: tuple[float, ...]
    starts: tuple[float, ...]


def slide(
    surface,
    *,
    mass: float,
    inertia: float,
    twist0,
    load: Callable | None = None,
    pose0=(0.0, 0.0, 0.0),
    duration: float,
    samples: int = 200,
) -> Sliding:
    """The sliding of a body from the twist ``twist0`` (body frame) for ``duration`` [s].

    Parameters
    ----------
    surface
        The support's limit surface in the body frame at the centre of mass, at the body's
        normal force, with a forward map: the exact :class:`~fixplan.LimitSurface`, a
        :class:`~fixplan.ContactSetSurface`, an ellipsoid model or the ``Exact`` model.
    mass, inertia : float
        Mass [kg] and moment of inertia about the centre of mass [kg m²], > 0.
    twist0 : array_like
        Starting twist ``(vx, vy, ω)`` in the body frame [m/s, m/s, rad/s]; may be zero when a
        load is applied.
    load : callable, optional
        ``load(t, pose)`` -> ``(fx, fy, m)`` [N, N, N m], the load applied at time ``t`` [s] and
        world pose ``pose``, in the body frame about the centre of mass. ``None``: free sliding.
    pose0 : array_like
        Starting world pose ``(x, y, θ)`` [m, m, rad].
    duration : float
        Simulated time [s], > 0.
    samples : int
        Evenly spaced samples returned, at most ``MAX_STEPS`` (plus the instants the body
        stops; a resting body's load is checked at them).
    """
    friction = forward_map(surface)
    mass = validation.positive_scalar("mass", mass)
    inertia = validation.positive_scalar("inertia", inertia)
    duration = validation.positive_scalar("duration", duration)
    twist = validation.finite_array("twist0", twist0, shape=(3,))
    pose = validation.finite_array("pose0", pose0, shape=(3,))
    if (isinstance(samples, bool) or not isinstance(samples, int | np.integer)
            or not 1 <= samples <= MAX_STEPS):  # fmt: skip
        raise InvalidArgumentError(
            f"samples must be an integer from 1 to {MAX_STEPS:,}, got {samples!r}"
        )
    if load is not None and not callable(load):
        raise InvalidArgumentError(f"load must be a function of (t, pose) or None, got {load!r}")
    if load is None and not np.any(twist):
        raise InvalidArgumentError(
            "twist0 must be nonzero without a load (a body at rest does not slide)"
        )
    body = _Body(friction, np.array([mass, mass, inertia]), load)
    start = np.concatenate([pose, _rotated(pose[2], twist)])
    scale = max(body.speed(start), float(friction.support(np.array([1.0, 0.0, 0.0]))) / mass
                * duration)  # fmt: skip
    stop_speed = STOP_RTOL * scale

    def stopping(t, state):
        return body.speed(state) - stop_speed

    stopping.terminal = True
    stopping.direction = -1
    # Velocities to well below the stopping speed: a step that jumps across rest would
    # otherwise bounce off it (friction reverses there) unseen by the event.
    gyration = np.sqrt(inertia / mass)
    atol = np.array([*[INTEGRATION_RTOL * scale * max(duration, 1.0)] * 3,
                     *(STOP_ATOL * stop_speed / np.array([1.0, 1.0, gyration]))])  # fmt: skip
    grid = np.linspace(0.0, duration, int(samples) + 1)
    times, states, stops, starts = [0.0], [start], [], []
    t, state = 0.0, start
    while t < duration:
        if not np.any(state[3:]):  # at rest until the load leaves the surface
            leave = body.leaving(t, state[:3], grid)
            rest = grid[(grid > t) & (grid <= (duration if leave is None else leave))]
            times += list(rest)
            states += [state] * len(rest)
            if leave is None:
                break
            t = leave
            starts.append(t)
        result = _integrate(body, (t, duration), state, grid[grid > t], stopping, atol)
        # scipy returns lists, not arrays, when the run ends before the first sample.
        times += list(np.asarray(result.t, dtype=float))
        states += list(np.reshape(result.y, (len(state), -1)).T)
        if not result.t_events[0].size:
            break
        t = float(result.t_events[0][0])
        state = result.y_events[0][0].copy()
        state[3:] = 0.0
        stops.append(t)
        times.append(t)
        states.append(state)
    states = np.array(states)
    order = np.argsort(times, kind="stable")
    states = states[order]
    resting = not np.any(states[-1, 3:])
    return Sliding(
        t=np.array(times)[order],
        poses=states[:, :3],
        twists=np.array([_rotated(-x[2], x[3:]) for x in states]),
        stopped=(stops[-1] if stops else 0.0) if resting else None,
        stops=tuple(stops),
        starts=tuple(starts),
    )


def start_acceleration(surface, load, *, mass: float, inertia: float) -> np.ndarray:
    """The acceleration ``(ax, ay, α)`` [m/s², m/s², rad/s²] (body frame) of a body at rest under
    ``load`` ``(fx, fy, m)`` [N, N, N m]: the minimiser of the convex problem of the module
    docstring, 0 when the load lies inside the limit surface.

    Arguments as for :func:`slide`.
    """
    friction = forward_map(surface)
    masses = np.array([validation.positive_scalar("mass", mass),
                       validation.positive_scalar("inertia", inertia)])[[0, 0, 1]]  # fmt: skip
    return _start(friction, masses, validation.finite_array("load", load, shape=(3,)))


class _StiffError(Exception):
    """An integration took more than ``MAX_EVALUATIONS`` of the equations of motion."""


def _integrate(body, span, state, samples, stopping, atol):
    """``solve_ivp`` of ``body`` over ``span`` from ``state``: explicitly (RK45), and where that
    takes more than ``MAX_EVALUATIONS`` (stiff), with LSODA, which switches to an implicit
    method; :class:`~fixplan.errors.ConvergenceError` where that does too."""
    for method in ("RK45", "LSODA"):
        count = 0

        def rate(t, y):
            nonlocal count
            count += 1
            if count > MAX_EVALUATIONS:
                raise _StiffError
            return body.rate(t, y)

        try:
            return solve_ivp(rate, span, state, method=method, t_eval=samples, events=stopping,
                             rtol=INTEGRATION_RTOL, atol=atol)  # fmt: skip
        except _StiffError:
            continue
    raise ConvergenceError(
        f"slide: the motion from t = {span[0]:.6g} s took more than {MAX_EVALUATIONS:,} "
        "evaluations of its equations with RK45 and with LSODA: its friction switches faster "
        "than either can follow, as for a part on point supports that pivots about one of "
        "them (the friction of that point flips at every step), which is not modelled yet. "
        "Support the part on a patch, or shorten the duration to before the pivot"
    )


@dataclass(frozen=True, slots=True)
class _Body:
    """The equations of motion of a body on its support."""

    friction: ForwardMap
    masses: np.ndarray  # (m, m, I)
    load: Callable | None

    def speed(self, state: np.ndarray) -> float:
        """Speed [m/s] with rotation counted at the radius of gyration."""
        gyration = np.sqrt(self.masses[2] / self.masses[0])
        return float(np.hypot(np.hypot(state[3], state[4]), state[5] * gyration))

    def applied(self, t: float, pose: np.ndarray) -> np.ndarray:
        """The applied load [N, N, N m] at time ``t`` [s] and world pose ``pose``."""
        if self.load is None:
            return np.zeros(3)
        return validation.finite_array("load(t, pose)", self.load(t, pose.copy()), shape=(3,))

    def leaving(self, t: float, pose: np.ndarray, grid: np.ndarray) -> float | None:
        """The first instant from ``t`` [s] at which the load on the body resting at ``pose``
        leaves the surface: checked at the samples ``grid`` and found between them by
        root finding; ``None`` if it stays inside."""
        if self.load is None:
            return None

        def margin(time: float) -> float:
            return float(self.friction.safety_factor(self.applied(time, pose))) - 1.0

        if margin(t) < -CONTAINMENT_RTOL:
            return t
        before = t
        for time in grid[grid > t]:
            if margin(time) < -CONTAINMENT_RTOL:
                # It leaves where the load crosses the surface itself (held until then).
                if margin(before) <= 0.0:
                    return before
                return brentq(margin, before, time, xtol=LEAVE_XTOL * grid[-1])
            before = time
        return None

    def rate(self, t: float, state: np.ndarray) -> list[float]:
        applied = self.applied(t, state[:3])
        twist = _rotated(-state[2], state[3:])
        if np.any(twist):
            acceleration = (applied - np.asarray(self.friction.load(twist))) / self.masses
        elif np.any(applied):
            acceleration = _start(self.friction, self.masses, applied)
        else:
            acceleration = np.zeros(3)
        return [*state[3:], *_rotated(state[2], acceleration)]


def _start(friction: ForwardMap, masses: np.ndarray, load: np.ndarray) -> np.ndarray:
    """``argmin 1/2 a^T M a - L·a + h(a)``, solved in ``b = M^{1/2} a`` (unit Hessian of the
    quadratic): the root of ``b - M^{-1/2} (L - ∇h(M^{-1/2} b))``."""
    safety = float(friction.safety_factor(load))
    if safety >= 1.0 - CONTAINMENT_RTOL:
        return np.zeros(3)
    root_masses = np.sqrt(masses)
    scaled = load / root_masses

    def gradient(b: np.ndarray) -> np.ndarray:
        if not np.any(b):
            return -scaled
        return b - scaled + np.asarray(friction.load(b / root_masses)) / root_masses

    solution = root(gradient, (1.0 - safety) * scaled, method="hybr",
                    options={"xtol": START_XTOL})  # fmt: skip
    residual = float(np.linalg.norm(gradient(solution.x)))
    if not np.any(solution.x) or residual > START_RTOL * float(np.linalg.norm(scaled)):
        raise ConvergenceError(
            f"the starting motion under the load {load} was not found ({solution.message}; "
            f"gradient residual {residual:.3g}): it may be a pivot about a support point, where "
            "the friction is not smooth"
        )
    return solution.x / root_masses


def _rotated(angle: float, twist: np.ndarray) -> np.ndarray:
    """``twist`` with its translation turned by ``angle`` [rad] (body to world for ``θ``)."""
    c, s = np.cos(angle), np.sin(angle)
    return np.array([c * twist[0] - s * twist[1], s * twist[0] + c * twist[1], twist[2]])
