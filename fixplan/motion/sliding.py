r"""Free sliding: the dynamics of a body coasting on its support (Goyal; the paper's "dynamic
simulation").

The body's frame sits at its centre of mass, and the support's limit surface is given in that
frame. With the world pose ``(x, y, θ)``, the world velocity ``v`` of the centre of mass and the
angular rate ``ω``,

.. math:: m \dot v = -R(θ) f(V), \qquad I \dot ω = -m(V),

where ``V = (R(θ)^T v, ω)`` is the twist in the body frame and ``(f(V), m(V)) = ∇h(V)`` the load
that sustains sliding with it (the forward map: friction resists it). Friction does not depend on the speed, only on the direction of
the twist, so a body stops in finite time; translation and rotation may stop separately (the
twist then turns into a pure rotation or translation) or together (a uniform puck: the classic
result that a spinning puck stops sliding and turning at the same instant). The step is an
adaptive Runge–Kutta method (scipy's ``solve_ivp``) with an event where the speed vanishes; after
it the body stays at rest. (Applied loads during sliding are not modelled yet.)
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.integrate import solve_ivp

from fixplan import validation
from fixplan.errors import InvalidArgumentError

#: The body counts as stopped when its speed (with rotation counted at the radius of gyration)
#: falls below this fraction of its starting speed.
STOP_RTOL = 1e-9

#: Relative tolerance of the adaptive integration.
INTEGRATION_RTOL = 1e-10


@dataclass(frozen=True, slots=True)
class Sliding:
    """A body's free sliding.

    Attributes
    ----------
    t : numpy.ndarray
        Times [s] of the samples.
    poses : numpy.ndarray
        ``(n, 3)`` world poses ``(x, y, θ)`` of the centre of mass [m, m, rad].
    twists : numpy.ndarray
        ``(n, 3)`` twists in the body frame ``(vx, vy, ω)`` [m/s, m/s, rad/s].
    stopped : float or None
        When the body came to rest [s] (``None``: still sliding at the end).
    """

    t: np.ndarray
    poses: np.ndarray
    twists: np.ndarray
    stopped: float | None


def slide(
    surface,
    *,
    mass: float,
    inertia: float,
    twist0,
    pose0=(0.0, 0.0, 0.0),
    duration: float,
    samples: int = 200,
) -> Sliding:
    """The free sliding of a body from the twist ``twist0`` (body frame) for ``duration`` [s].

    ``surface`` has a forward map ``load(twist)`` (the exact :class:`~fixplan.LimitSurface`, a
    :class:`~fixplan.ContactSetSurface`) and is given in the body frame at the centre of mass,
    at the body's normal force; ``mass`` [kg] and ``inertia`` [kg m²] about the centre of mass;
    ``pose0`` the starting world pose. ``samples`` evenly spaced samples are returned (plus the
    stopping instant).
    """
    forward = getattr(surface, "load", None)
    if forward is None:
        raise InvalidArgumentError(
            f"{type(surface).__name__} has no forward map load(twist): use the exact "
            "LimitSurface or a ContactSetSurface"
        )
    mass = validation.positive_scalar("mass", mass)
    inertia = validation.positive_scalar("inertia", inertia)
    duration = validation.positive_scalar("duration", duration)
    twist = validation.finite_array("twist0", twist0, shape=(3,))
    pose = validation.finite_array("pose0", pose0, shape=(3,))
    gyration = np.sqrt(inertia / mass)

    def body_twist(state):
        c, s = np.cos(state[2]), np.sin(state[2])
        return np.array([c * state[3] + s * state[4], -s * state[3] + c * state[4], state[5]])

    def rate(t, state):
        c, s = np.cos(state[2]), np.sin(state[2])
        body = body_twist(state)
        net = -np.asarray(forward(body), dtype=float) if np.any(body) else np.zeros(3)
        return [state[3], state[4], state[5], (c * net[0] - s * net[1]) / mass,
                (s * net[0] + c * net[1]) / mass, net[2] / inertia]  # fmt: skip

    def speed(state):
        return float(np.hypot(np.hypot(state[3], state[4]), state[5] * gyration))

    c, s = np.cos(pose[2]), np.sin(pose[2])
    state = np.concatenate([pose, [c * twist[0] - s * twist[1], s * twist[0] + c * twist[1],
                                   twist[2]]])  # fmt: skip
    start_speed = speed(state)
    if start_speed == 0.0:
        raise InvalidArgumentError("twist0 must be nonzero (a body at rest does not slide)")

    def stopping(t, state):
        return speed(state) - STOP_RTOL * start_speed

    stopping.terminal = True
    stopping.direction = -1
    grid = np.linspace(0.0, duration, samples + 1)
    result = solve_ivp(
        rate, (0.0, duration), state, t_eval=grid, events=stopping,
        rtol=INTEGRATION_RTOL, atol=INTEGRATION_RTOL * start_speed * max(duration, 1.0),
    )  # fmt: skip
    times, states = list(result.t), list(result.y.T)
    stopped = None
    if result.t_events[0].size:
        stopped = float(result.t_events[0][0])
        rest = result.y_events[0][0].copy()
        rest[3:] = 0.0
        times.append(stopped)
        states.append(rest)
        times += [t for t in grid if t > stopped]
        states += [rest] * (len(times) - len(states))
    states = np.array(states)
    order = np.argsort(times, kind="stable")
    states = states[order]
    return Sliding(
        t=np.array(times)[order],
        poses=states[:, :3],
        twists=np.array([body_twist(x) for x in states]),
        stopped=stopped,
    )
