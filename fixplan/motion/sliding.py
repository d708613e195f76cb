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
started from the load scaled onto the surface, and where that stalls (a load barely outside,
whose ``a*`` is tiny) for the direction of ``a*`` alone. So a body can stop and stay while the
load is inside the surface and start again when the load leaves it (stick–slip).

The state is integrated by an adaptive Runge–Kutta method (scipy's ``solve_ivp``; LSODA where
that is stiff, ``MAX_EVALUATIONS``) with an event
where the speed falls below ``STOP_RTOL`` of the run's speed scale (the larger of the starting
speed and the speed the largest friction force takes away over the run); there the body is put
at rest. Without a load it stays at rest. With one, the load on the resting body is checked at
the samples, and the instant it leaves the surface is found between them by root finding; the
body starts to slide there (a load that leaves the surface and comes back between two samples
goes unnoticed).

**Point supports** (an exact surface's :attr:`~fixplan.LimitSurface.point_supports`) make
facets, where ``h`` has kinks: a body can turn about one of them while it sticks
(:mod:`fixplan.motion.support_pivot`). A second event finds where a point support comes to rest
(below the stopping speed) while the body slides; where its friction can hold it, the body
turns about it (its angle and rate integrated, the point still) until it stops or the point's
friction gives out and it slips (the body slides on, that point starting at ``SLIP_START``
times the stopping speed). A body that starts from rest by turning about a point (the minimiser
of the convex problem on a facet) is found before the smooth start is solved for (at the
instant its load reaches the surface, on that load scaled just beyond it: ``LEAVE_EXCESS``).
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
from fixplan.motion.support_pivot import PointSupports, Turn, turn_from_rest
from fixplan.tolerances import CONTAINMENT_RTOL, MAX_STEPS

#: The body counts as stopped when its speed (with rotation counted at the radius of gyration)
#: falls below this fraction of the run's speed scale.
STOP_RTOL = 1e-9

#: A point support that slips after a turn about it starts at this multiple of the stopping
#: speed (its speed grows from 0 as its friction gives out, and the direction of its friction
#: is the direction of that speed: from the stopping speed itself the integration turned it at
#: every step and gave up). On a bar pushed sideways at one of its two support points (tests/
#: test_support_pivot.py), against an integration of friction regularised below 1e-9 m/s: 10
#: times, 2.5e-9 rad off after the slip; 100 times, 1.4e-8 rad; 1,000 times, 1.8e-7 rad.
SLIP_START = 10.0

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

#: Whether a resting body whose load has just reached the surface starts by turning about a
#: point support is decided on its load scaled out to this fraction beyond the surface. At the
#: surface itself the turn's acceleration is 0 (1e-16 of the load either way): decided there, 2
#: of 247 fuzzed slides on points and a disk patch found no turn, slid, and the smooth start's
#: root finders failed at the kink of the point that stays still, as did a bar pushed at one end
#: by a ramping force (tests/test_support_pivot.py).
LEAVE_EXCESS = 1e-6

#: Relative step tolerance of the root finding of the starting acceleration.
START_XTOL = 1e-12

#: A starting acceleration is accepted when the residual of its optimality condition is below
#: this fraction of the load and of the acceleration itself (in the scaled coordinates ``b =
#: M^{1/2} a``, where the objective's Hessian is at least the identity, so that ``b`` is off by
#: at most the residual). Of the load alone: for a load 1.7e-9 outside a surface of points and
#: a disk, Powell's method stopped at 1.8e-10 of the load, 12 % of ``b``; the root of the
#: direction alone (:func:`_start_direction`) came to 1e-14 of the load.
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
    pivots : tuple of (float, float, int)
        Every turn about a point support that stayed still: its start and end [s] and the
        point's index in the surface's :attr:`~fixplan.LimitSurface.point_supports`.
    """

    t: np.ndarray
    poses: np.ndarray
    twists: np.ndarray
    stopped: float | None
    stops: tuple[float, ...]
    starts: tuple[float, ...]
    pivots: tuple[tuple[float, float, int], ...]


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
    supports = PointSupports.of(surface)
    body = _Body(friction, np.array([mass, mass, inertia]), load, supports)
    start = np.concatenate([pose, _rotated(pose[2], twist)])
    scale = max(body.speed(start), float(friction.support(np.array([1.0, 0.0, 0.0]))) / mass
                * duration)  # fmt: skip
    gyration = np.sqrt(inertia / mass)
    run = _Run(body, STOP_RTOL * scale, INTEGRATION_RTOL * scale * max(duration, 1.0), gyration)
    grid = np.linspace(0.0, duration, int(samples) + 1)
    times, states, stops, starts, pivots = [0.0], [start], [], [], []
    t, state, turn = 0.0, start, None
    while t < duration:
        if turn is None and not np.any(state[3:]):  # at rest until the load leaves the surface
            leave = body.leaving(t, state[:3], grid)
            rest = grid[(grid > t) & (grid <= (duration if leave is None else leave))]
            times += list(rest)
            states += [state] * len(rest)
            if leave is None:
                break
            t = leave
            starts.append(t)
            turn = body.turn_from_rest(t, state[:3])
        if turn is not None:
            pivots.append([t, duration, turn.index])
            segment_times, segment, ended = run.turning(turn, (t, duration), state, grid)
        else:
            segment_times, segment, ended = run.sliding((t, duration), state, grid)
        times += segment_times
        states += segment
        if ended is None:
            break
        if turn is not None:
            pivots[-1][1] = ended[0]
        t, state, turn = ended
        if turn is None and not np.any(state[3:]):
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
        pivots=tuple((float(a), float(b), int(i)) for a, b, i in pivots),
    )


def start_acceleration(surface, load, *, mass: float, inertia: float) -> np.ndarray:
    """The acceleration ``(ax, ay, α)`` [m/s², m/s², rad/s²] (body frame) of a body at rest under
    ``load`` ``(fx, fy, m)`` [N, N, N m]: the minimiser of the convex problem of the module
    docstring, 0 when the load lies inside the limit surface. Where it turns the body about a
    point support (a facet: :mod:`fixplan.motion.support_pivot`), that turn's.

    Arguments as for :func:`slide`.
    """
    friction = forward_map(surface)
    masses = np.array([validation.positive_scalar("mass", mass),
                       validation.positive_scalar("inertia", inertia)])[[0, 0, 1]]  # fmt: skip
    load = validation.finite_array("load", load, shape=(3,))
    supports = PointSupports.of(surface)
    if supports is not None and friction.safety_factor(load) < 1.0 - CONTAINMENT_RTOL:
        found = turn_from_rest(supports, friction, masses, load)
        if found is not None:
            return found[3]
    return _start(friction, masses, load)


class _StiffError(Exception):
    """An integration took more than ``MAX_EVALUATIONS`` of the equations of motion."""


def _integrate(rate, span, state, samples, events, atol):
    """``solve_ivp`` of ``rate(t, y)`` over ``span`` from ``state``: explicitly (RK45), and
    where that takes more than ``MAX_EVALUATIONS`` (stiff), with LSODA, which switches to an
    implicit method; :class:`~fixplan.errors.ConvergenceError` where that does too."""
    for method in ("RK45", "LSODA"):
        count = 0

        def counted(t, y):
            nonlocal count
            count += 1
            if count > MAX_EVALUATIONS:
                raise _StiffError
            return rate(t, y)

        try:
            result = solve_ivp(counted, span, state, method=method, t_eval=samples,
                               events=events, rtol=INTEGRATION_RTOL, atol=atol)  # fmt: skip
        except _StiffError:
            continue
        if result.status >= 0:
            return result
    raise ConvergenceError(
        f"slide: the motion from t = {span[0]:.6g} s took more than {MAX_EVALUATIONS:,} "
        "evaluations of its equations, or failed, with RK45 and with LSODA: its friction "
        "switches faster than either can follow (as at a point contact of a "
        "ContactSetSurface with cone or pyramid patches too, whose turns about its points are "
        "not followed; a LimitSurface's point supports are, and a set of point contacts and "
        "exact or ellipsoid patches is one). Support the part on a patch, or shorten the "
        "duration"
    )


def _terminal(function, direction: float):
    """``function`` as a terminal event of ``solve_ivp`` crossing 0 in ``direction``."""
    function.terminal = True
    function.direction = direction
    return function


@dataclass(frozen=True, slots=True)
class _Turning:
    """A turn about the point support ``index`` (:class:`~fixplan.motion.support_pivot.Turn`)
    in ``sense`` (±1), the point still at ``anchor`` ``(2,)`` [m] in the world."""

    index: int
    turn: Turn
    sense: float
    anchor: np.ndarray

    def pose(self, angle: float) -> np.ndarray:
        """The world pose of the centre of mass at the body's ``angle`` [rad]."""
        return np.array([*(self.anchor - _offset(self.turn.point, angle)), angle])

    def state(self, angle: float, rate: float) -> np.ndarray:
        """The slide's state ``(pose, world velocity, rate)`` at ``angle`` and ``rate``."""
        reach = _offset(self.turn.point, angle)
        return np.array([*self.pose(angle), rate * reach[1], -rate * reach[0], rate])


@dataclass(frozen=True, slots=True)
class _Body:
    """The equations of motion of a body on its support."""

    friction: ForwardMap
    masses: np.ndarray  # (m, m, I)
    load: Callable | None
    supports: PointSupports | None

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

    def turn_from_rest(self, t: float, pose: np.ndarray) -> _Turning | None:
        """The turn about a point support in which the body resting at ``pose`` starts at
        ``t`` [s], if it starts so (:func:`~fixplan.motion.support_pivot.turn_from_rest`).

        At the instant the load leaves the surface it lies on it, where the turn's acceleration
        is 0 and its sign rounding's: the turn is then that of the load scaled out to
        ``LEAVE_EXCESS`` beyond the surface (through the face it leaves by)."""
        if self.supports is None:
            return None
        applied = self.applied(t, pose)
        safety = float(self.friction.safety_factor(applied))
        if 1.0 - LEAVE_EXCESS < safety < 1.0 + LEAVE_EXCESS:
            applied = applied * ((1.0 + LEAVE_EXCESS) / safety)
        found = turn_from_rest(self.supports, self.friction, self.masses, applied)
        return None if found is None else self._turning(pose, *found[:3])

    def turn_at(self, t: float, state: np.ndarray, index: int) -> _Turning | None:
        """The turn about point support ``index``, now at rest in the sliding ``state`` (whose
        rate is not 0), where its friction keeps it still (``None``: it slips on)."""
        rate = float(state[5])
        turn = Turn(self.supports.points[index], float(self.supports.friction[index]), self.masses)
        sense = float(np.sign(rate))
        applied = self.applied(t, state[:3])
        if not turn.sticks(turn.acceleration(self.friction.load, applied, rate, sense)[1]):
            return None
        return self._turning(state[:3], index, turn, sense)

    @staticmethod
    def _turning(pose: np.ndarray, index: int, turn: Turn, sense: float) -> _Turning:
        return _Turning(index, turn, sense, pose[:2] + _offset(turn.point, pose[2]))


@dataclass(frozen=True, slots=True)
class _Run:
    """The segments of a slide: sliding, or turning about a point support, each integrated
    to its end (``stop_speed`` [m/s]; ``position_atol`` [m] and the radius of ``gyration``
    [m] set the absolute tolerances)."""

    body: _Body
    stop_speed: float
    position_atol: float
    gyration: float

    def sliding(self, span, state, grid) -> tuple[list, list, tuple | None]:
        """Times and states of the body sliding from ``state`` over ``span``, and how the
        segment ended: ``None`` at the end of ``span``, else ``(t, state, turn)``: at rest
        (``turn`` ``None``, the velocities 0) or turning about a point support that came to
        rest (a :class:`_Turning`)."""
        body, stop_speed = self.body, self.stop_speed
        # Velocities to well below the stopping speed: a step that jumps across rest would
        # otherwise bounce off it (friction reverses there) unseen by the events.
        velocity_atol = STOP_ATOL * stop_speed / np.array([1.0, 1.0, self.gyration])
        atol = np.array([*[self.position_atol] * 3, *velocity_atol])
        stopping = _terminal(lambda t, y: body.speed(y) - stop_speed, -1.0)
        times, states, slipping = [], [], np.zeros(0, dtype=int)
        if body.supports is not None and np.any(state[3:]):  # (a point already still)
            index, speed = self._slowest_point(state, slipping)
            ended = self._still(span[0], state, index) if speed <= stop_speed else None
            if ended is not None:
                return times, states, ended
        while True:
            events = [stopping]
            if body.supports is not None:
                events.append(_terminal(self._point_at_rest(slipping), -1.0))
            result = _integrate(body.rate, span, state, grid[grid > span[0]], events, atol)
            more_times, more_states = _samples(result, len(state))
            times += more_times
            states += more_states
            event = _first_event(result)
            if event is None:
                return times, states, None
            t, which, state = event
            if which == 0:
                state[3:] = 0.0
                return times, states, (t, state, None)
            index = self._slowest_point(state, slipping)[0]
            ended = self._still(t, state, index)
            if ended is not None:
                return times, states, ended
            # Its friction cannot keep it still: it slips through rest, not followed by the
            # event again in this segment.
            slipping = np.append(slipping, index)
            span = (t, span[1])

    def _still(self, t: float, state: np.ndarray, index: int) -> tuple | None:
        """How a slide ends where point support ``index`` came to rest at ``t``: at rest where
        the turn about it would be below the stopping speed already, turning about it where its
        friction holds it; ``None`` where it slips on."""
        if abs(state[5]) * self._reach(self.body.supports.points[index]) <= self.stop_speed:
            return t, np.concatenate([state[:3], np.zeros(3)]), None
        turning = self.body.turn_at(t, state, index)
        return None if turning is None else (t, turning.state(state[2], state[5]), turning)

    def _reach(self, point: np.ndarray) -> float:
        """The speed [m/s] (:meth:`_Body.speed`) of a turn about ``point`` at 1 rad/s."""
        return float(np.hypot(np.hypot(*point), self.gyration))

    def _slowest_point(self, state: np.ndarray, slipping: np.ndarray) -> tuple[int, float]:
        """The slowest point support in the sliding ``state`` but for those ``slipping``: its
        index and speed [m/s]."""
        speeds = self.body.supports.speeds(_rotated(-state[2], state[3:]))
        speeds[slipping] = np.inf
        index = int(np.argmin(speeds))
        return index, float(speeds[index])

    def _point_at_rest(self, slipping: np.ndarray):
        """The event of a point support (not among ``slipping``) coming to rest."""
        return lambda t, y: self._slowest_point(y, slipping)[1] - self.stop_speed

    def turning(self, turning: _Turning, span, state, grid) -> tuple[list, list, tuple | None]:
        """:meth:`sliding` for a body turning about a point support: its angle and rate
        integrated, until it stops or the point slips (then ``turn`` is ``None``)."""
        body, turn = self.body, turning.turn
        reach = self._reach(turn.point)

        def accelerated(t, y):  # (in the turn's sense until it stops: no flips)
            applied = body.applied(t, turning.pose(y[0]))
            return turn.acceleration(body.friction.load, applied, y[1], turning.sense)

        def rate(t, y):
            return [y[1], accelerated(t, y)[0]]

        def slipping(t, y):
            return turn.beyond_friction(accelerated(t, y)[1])

        stopping = _terminal(lambda t, y: turning.sense * y[1] * reach - self.stop_speed, -1.0)
        atol = np.array([self.position_atol / reach, STOP_ATOL * self.stop_speed / reach])
        start = np.array([state[2], state[5]])
        events = [stopping, _terminal(slipping, 1.0)]
        result = _integrate(rate, span, start, grid[grid > span[0]], events, atol)
        angles, samples = _samples(result, 2)
        states = [turning.state(*y) for y in samples]
        event = _first_event(result)
        if event is None:
            return angles, states, None
        t, which, (angle, rate_now) = event
        if which == 0:
            return angles, states, (t, turning.state(angle, 0.0), None)
        # The point slips where its friction gives out, along the force it gave, reversed (the
        # friction then goes on giving it), at SLIP_START times the stopping speed.
        end = turning.state(angle, rate_now)
        force = accelerated(t, [angle, rate_now])[1]
        slip = -SLIP_START * self.stop_speed * force / np.hypot(*force)
        end[3:5] += _rotated(angle, np.array([*slip, 0.0]))[:2]
        return angles, states, (t, end, None)


def _first_event(result) -> tuple[float, int, np.ndarray] | None:
    """The first terminal event of a ``solve_ivp`` result: its time, index and state (a copy);
    ``None`` where the run reached its end."""
    hits = [(float(t[0]), k) for k, t in enumerate(result.t_events) if t.size]
    if not hits:
        return None
    t, which = min(hits)
    return t, which, result.y_events[which][0].copy()


def _samples(result, width: int) -> tuple[list, list]:
    """The times and states of a ``solve_ivp`` result as lists (scipy returns lists, not
    arrays, when the run ends before the first sample)."""
    times = list(np.asarray(result.t, dtype=float))
    return times, list(np.reshape(result.y, (width, -1)).T)


def _start(friction: ForwardMap, masses: np.ndarray, load: np.ndarray) -> np.ndarray:
    """``argmin 1/2 a^T M a - L·a + h(a)``, solved in ``b = M^{1/2} a`` (unit Hessian of the
    quadratic): the root of ``b - M^{-1/2} (L - ∇h(M^{-1/2} b))``; where that is not found, in
    the direction of ``b`` alone (:func:`_start_direction`)."""
    safety = float(friction.safety_factor(load))
    if safety >= 1.0 - CONTAINMENT_RTOL:
        return np.zeros(3)
    root_masses = np.sqrt(masses)
    scaled = load / root_masses
    size = float(np.linalg.norm(scaled))

    def unbalanced(b: np.ndarray) -> np.ndarray:
        """The scaled load that friction does not take at ``b`` (the same along its ray)."""
        return scaled - np.asarray(friction.load(b / root_masses)) / root_masses

    def gradient(b: np.ndarray) -> np.ndarray:
        return b - unbalanced(b) if np.any(b) else -scaled

    guess = (1.0 - safety) * scaled
    # Powell's method, and from where it stopped Levenberg-Marquardt: on point supports, with
    # a load 6e-8 outside the surface (a start found by a fuzzer), Powell's stalled at a
    # residual of 4e-8 of the load and Levenberg-Marquardt's came to 1e-16.
    for method, options in (("hybr", {"xtol": START_XTOL}), ("lm", {"xtol": START_XTOL})):
        solution = root(gradient, guess, method=method, options=options)
        residual = float(np.linalg.norm(gradient(solution.x)))
        if residual <= START_RTOL * min(size, float(np.linalg.norm(solution.x))):
            return solution.x / root_masses
        guess = solution.x if np.any(solution.x) else guess
    found, residual = _start_direction(unbalanced, size, guess)
    if found is not None:
        return found / root_masses
    raise ConvergenceError(
        f"the starting motion under the load {load} was not found (root finding in the "
        f"acceleration and in its direction; optimality residual {residual:.3g} of the load)"
    )


def _start_direction(
    unbalanced: Callable, size: float, guess: np.ndarray
) -> tuple[np.ndarray | None, float]:
    """The start ``b`` of :func:`_start` from its direction ``u`` alone, from that of ``guess``:
    ``h`` is of degree 1, so ``∇h`` is the same along ``b = t u`` and the optimality condition
    ``b - s + ∇h(b) = 0`` (``s = M^{-1/2} L``, of size ``size``) says that ``unbalanced(u) = s
    - ∇h(u)`` (the load friction does not take, scaled) is along ``u``: ``t`` is its component
    along ``u``. Solved for ``u`` with the length of ``u`` as a fourth condition, the equations
    are conditioned independently of ``|b|``: for a load 1e-9 outside the surface ``b`` is 1e-9
    of ``s``, and the root finders in ``b`` stalled short of ``START_RTOL`` (3 of 247 fuzzed
    slides; the direction's came to 1e-16). Returns ``b`` (``None`` where not found) and the
    residual (gradient in ``b``) relative to ``size``."""

    def conditions(direction: np.ndarray) -> np.ndarray:
        length = float(np.linalg.norm(direction))
        unit = direction / length
        rest = unbalanced(unit) / size
        return rest - (rest @ unit) * unit + (length - 1.0) * unit

    solution = root(conditions, guess / np.linalg.norm(guess), options={"xtol": START_XTOL})
    if not np.any(solution.x):
        return None, np.inf
    unit = solution.x / np.linalg.norm(solution.x)
    rest = unbalanced(unit)
    along = float(rest @ unit)
    residual = float(np.linalg.norm(rest - along * unit)) / size
    if along > 0.0 and residual <= START_RTOL:
        return along * unit, residual
    return None, residual


def _offset(point: np.ndarray, angle: float) -> np.ndarray:
    """A body-frame ``point`` ``(2,)`` [m] from the centre of mass, in the world at ``angle``."""
    return _rotated(angle, np.array([*point, 0.0]))[:2]


def _rotated(angle: float, twist: np.ndarray) -> np.ndarray:
    """``twist`` with its translation turned by ``angle`` [rad] (body to world for ``θ``)."""
    c, s = np.cos(angle), np.sin(angle)
    return np.array([c * twist[0] - s * twist[1], s * twist[0] + c * twist[1], twist[2]])
