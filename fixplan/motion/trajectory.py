r"""Quasi-static pushing trajectories: a round or flat pusher drives a part across its support.

At every instant the part moves with the quasi-static twist of the contact between the pusher and
the part's outline (or stays at rest when they do not touch): :func:`~fixplan.motion.push_step`
at a single contact point, :func:`~fixplan.motion.line_push_step` where a flat pusher's face
touches two points of the part. The part's pose ``(x, y, θ)`` [m, m, rad] in the world is
integrated on SE(2) with the exact exponential of the twist over each step and the explicit
midpoint rule (second order in the step; the twist is taken again at the half step, with the
contact where it is then). When the pusher reaches the part within a step, it first travels to
the touching instant (found by bisection) and pushes for the rest of the step.

A flat pusher touches the lowest points of the outline within the strip its face sweeps
(:meth:`~fixplan.motion.Outline.face_points`). While the part turns about one contact point,
another point of it reaching the face is an event: the step is cut where it comes level with
the contact (bisection on the time within the step), and continues with both points touching —
the part rotates onto the face without passing through it, then rides flush or rotates off as
the mechanics say. After each integrated stretch in which the face presses, the part is put back
onto the face along its normal: the integration moves the contact off it by the step's local
error (third order), which would otherwise add up to a gap or an overlap. A round pusher's step
that ends with the pusher inside the part likewise moves the part out along the outline's normal
(a gap it leaves is closed by the next step's touching instant).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from fixplan import validation
from fixplan.errors import ConvergenceError, GeometryError, InvalidArgumentError
from fixplan.motion.forward_map import exact_form
from fixplan.motion.line_contact import line_push_step
from fixplan.motion.outline import Outline
from fixplan.motion.pushers import LinePusher, PointPusher
from fixplan.motion.pushing import PushStep, push_step

#: The pusher counts as touching the outline within this fraction of the part's size.
TOUCH_RTOL = 1e-9

#: A point of the part that enters a flat pusher's strip through its side more than this
#: fraction of the part's size behind the face has reached around the pusher to its back.
BEHIND_FACE = 1e-6

#: Bisection steps that find the touching instant, or a new contact, within a step (to 2**-50
#: of the step).
TOUCH_BISECTIONS = 50

#: At most this many new contacts are made within one step; more means the contact modes cycle
#: without the part moving (no consistent motion).
EVENTS_PER_STEP = 8


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
        ``(n, 2)`` the pusher's total force on the part, world frame [N].
    contact_points : numpy.ndarray
        ``(n, 2)`` the contact point in the world frame [m] at the start of each step (or when
        the pusher touches within it): the pressing point, for two the midpoint of the contact
        segment (a pusher touching without pressing: where it touches); NaN where not touching.
    shape : Outline
        The part's outline, in the part frame.
    pusher : PointPusher or LinePusher
        The pusher.
    pusher_positions : numpy.ndarray
        ``(n + 1, 2)`` world positions of the pusher's path point (a round pusher's centre, the
        centre of a flat pusher's face) at ``t`` [m].
    contact_counts : numpy.ndarray
        ``(n,)`` how many contact points press on the part at the start of each step (or when
        the pusher touches within it): 0 (separated), 1, or 2 (a flat pusher's face flush with
        the part).
    """

    t: np.ndarray
    poses: np.ndarray
    twists: np.ndarray
    modes: tuple[str, ...]
    forces: np.ndarray
    contact_points: np.ndarray
    shape: Outline
    pusher: PointPusher | LinePusher
    pusher_positions: np.ndarray
    contact_counts: np.ndarray

    def line_contact_travel(self) -> float | None:
        """Travel of the pusher along its path [m] (the length of the polyline through
        :attr:`pusher_positions`) until the start of the first step with two contact points;
        ``None`` if there is none."""
        flush = np.flatnonzero(self.contact_counts == 2)
        if not len(flush):
            return None
        moves = np.diff(self.pusher_positions[: flush[0] + 1], axis=0)
        return float(np.linalg.norm(moves, axis=1).sum())


def push(
    surface,
    pusher: PointPusher | LinePusher,
    *,
    shape: Outline,
    pose=(0.0, 0.0, 0.0),
    duration: float,
    steps: int,
    start_overlap: float = 0.0,
    progress: Callable[[int, int], None] | None = None,
) -> Trajectory:
    """Integrate the part's quasi-static motion under ``pusher`` for ``duration`` [s].

    ``surface`` is the support's limit surface in the part frame (see
    :func:`~fixplan.motion.push_step`; for a flat pusher on a polygon also
    :func:`~fixplan.motion.line_push_step`); ``shape`` the part's outline in the same frame;
    ``pose`` its initial world pose ``(x, y, θ)``; ``steps`` the number of integration steps;
    ``progress(done, total)`` is called after each step.

    The pusher must start outside the part, or overlap it by at most ``start_overlap`` [m]
    (default 0): a measured start carries such errors (in the MIT push data, half the pushes
    start with the cylinder up to 3.4 mm into the part). An overlapping pusher touches the part
    from the start and keeps its overlap, pushing as if set back along its normal by it: a round
    one at the outline point nearest its centre (so its overlap is below its radius, the centre
    outside), a flat one with its face that far behind it. A part whose outline reaches around
    an end of a flat pusher to its back raises :class:`~fixplan.errors.GeometryError` (only the
    face is modelled).
    """
    if not isinstance(shape, Outline):
        raise InvalidArgumentError(f"shape must be an Outline, got {type(shape).__name__}")
    surface = exact_form(surface)  # (points and exact or ellipsoid patches: a LimitSurface)
    if isinstance(pusher, PointPusher):
        contact = _RoundContact(surface, shape, pusher)
    elif isinstance(pusher, LinePusher):
        contact = _FaceContact(surface, shape, pusher)
    else:
        raise InvalidArgumentError(
            f"pusher must be a PointPusher or a LinePusher, got {type(pusher).__name__}"
        )
    duration = validation.positive_scalar("duration", duration)
    if isinstance(steps, bool) or not isinstance(steps, int | np.integer) or steps < 1:
        raise InvalidArgumentError(f"steps must be a positive integer, got {steps!r}")
    pose = validation.finite_array("pose", pose, shape=(3,)).copy()
    start_overlap = validation.nonnegative_scalar("start_overlap", start_overlap)
    contact.start(pose, start_overlap)
    dt = duration / steps
    times, poses = [0.0], [pose.copy()]
    twists, modes, forces, points, counts = [], [], [], [], []
    for k in range(steps):
        start = k * dt
        touch = _touching_time(contact, pose, start, dt)
        if touch is None:
            state = _State(PushStep.separated(), np.empty((0, 2)), np.empty((0, 2)), ())
        else:
            state = contact.state(pose, touch)
            pose = contact.advance(pose, touch, start + dt, state)
        twists.append(state.step.twist)
        modes.append(state.step.mode)
        rotation = _rotation(poses[-1][2])
        forces.append(rotation @ state.step.force)
        shown = state.bearing if len(state.bearing) else state.touching
        points.append(poses[-1][:2] + rotation @ shown.mean(axis=0) if len(shown) else
                      np.full(2, np.nan))  # fmt: skip
        counts.append(len(state.bearing))
        times.append(start + dt)
        poses.append(pose.copy())
        if progress is not None:
            progress(k + 1, steps)
    return Trajectory(
        t=np.array(times), poses=np.array(poses), twists=np.array(twists), modes=tuple(modes),
        forces=np.array(forces), contact_points=np.array(points), shape=shape, pusher=pusher,
        pusher_positions=np.array([pusher.position(t) for t in times]),
        contact_counts=np.array(counts, dtype=int),
    )  # fmt: skip


@dataclass(frozen=True, slots=True)
class _State:
    """The push at one instant: the step, the touching points and those that press (part
    frame), and what the pressing points are on the outline (for events)."""

    step: PushStep
    touching: np.ndarray
    bearing: np.ndarray
    keys: tuple


def _start_overlap(contact, pose: np.ndarray, allowed: float) -> float:
    """How far the pusher of a contact (:class:`_RoundContact` or :class:`_FaceContact`) starts
    inside the part at ``pose`` [m] (negative: outside); one deeper than ``allowed`` [m] or than
    the contact allows is refused, as the push has no meaning then."""
    overlap = -contact.gap(pose, 0.0)
    if overlap > min(allowed, contact.deepest_start) + contact.tolerance:
        (x, y), (pusher, advice) = contact.pusher.position(0.0), contact.describe()
        allowance = ""
        if overlap > allowed + contact.tolerance and allowed > 0.0:
            allowance = f" (more than the start_overlap of {allowed:g} m)"
        elif allowed > 0.0:  # (only a round pusher has a deepest start)
            allowance = " (its centre inside the outline)"
        raise GeometryError(
            f"the {pusher} at ({x:g}, {y:g}) m overlaps the part at pose {tuple(pose.tolist())} "
            f"by {overlap:.6g} m at t = 0{allowance}: {advice}"
        )
    return overlap


class _RoundContact:
    """A round pusher on the outline: one contact point, where the outline is nearest."""

    def __init__(self, surface, shape: Outline, pusher: PointPusher):
        self.surface, self.shape, self.pusher = surface, shape, pusher
        self.tolerance = TOUCH_RTOL * max(shape.size, pusher.radius)
        #: The largest overlap at the start that keeps the centre outside the outline [m].
        self.deepest_start = pusher.radius
        #: The radius the pusher acts with [m]: its own, less a start's overlap (:meth:`start`).
        self.reach = pusher.radius
        #: The last query of :meth:`_nearest` and its answer (a step's end is the next's start).
        self._last_query: tuple = (None, None)

    def start(self, pose: np.ndarray, allowed: float) -> None:
        """Check the start at ``pose`` (:func:`_start_overlap`); an overlap makes the pusher act
        as one smaller by as much (its centre outside the outline), as a flat pusher's sets its
        face back."""
        self.reach = self.pusher.radius - max(_start_overlap(self, pose, allowed), 0.0)

    def describe(self) -> tuple[str, str]:
        """The pusher in words, and how to start it outside the part (:func:`_start_overlap`)."""
        return (f"PointPusher of radius {self.pusher.radius:g} m starting",
                "start it at least its radius outside the outline (or, for a measured start, "
                "allow an overlap below its radius with start_overlap)")  # fmt: skip

    def gap(self, pose: np.ndarray, t: float) -> float:
        """Distance between the pusher's surface (at its :attr:`reach`) and the outline at time
        ``t`` [m]."""
        return self._nearest(pose, t)[2] - self.reach

    def _nearest(self, pose: np.ndarray, t: float) -> tuple[np.ndarray, np.ndarray, float]:
        """:meth:`~fixplan.motion.Outline.nearest` of the pusher's centre at time ``t`` [s] in
        the part frame of ``pose`` (not to be changed: the last answer is kept)."""
        centre = _local(pose, self.pusher.position(t))
        key = centre.tobytes()
        if self._last_query[0] != key:
            self._last_query = (key, self.shape.nearest(centre))
        return self._last_query[1]

    def state(self, pose: np.ndarray, t: float) -> _State:
        point, outward, gap = self._nearest(pose, t)
        velocity = _rotation(pose[2]).T @ self.pusher.velocity(t)
        if gap <= self.tolerance and not self.shape.enters(point, velocity):
            # A point pusher on the outline that moves along it (at a corner: along or out of
            # one of its edges) does not push; the corner's bisector would make it.
            step = PushStep.separated()
        else:
            step = push_step(self.surface, contact=point, normal=-outward, velocity=velocity,
                             mu=self.pusher.mu)  # fmt: skip
        bearing = point[None, :] if step.mode != "separated" else np.empty((0, 2))
        return _State(step, point[None, :], bearing, ())

    def advance(self, pose: np.ndarray, t: float, end: float, state: _State) -> np.ndarray:
        """The pose at ``end`` [s] by the midpoint rule from ``state`` at ``t``, moved out of
        the pusher along the outline's normal where the step's error leaves them overlapping.
        A pusher that overlaps the part still (it touches two faces of a notch at once, which
        its single contact does not model) raises :class:`~fixplan.errors.GeometryError`."""
        if state.step.mode == "separated":
            return pose
        rest = end - t
        midpoint = self.state(_compose(pose, state.step.twist, rest / 2), t + rest / 2)
        moved = _compose(pose, midpoint.step.twist, rest)
        _, outward, distance = self._nearest(moved, end)
        overlap = self.reach - distance
        if overlap > 0.0:
            moved[:2] -= overlap * (_rotation(moved[2]) @ outward)
            if self._nearest(moved, end)[2] < self.reach - self.tolerance:
                centre = self.pusher.position(end)
                raise GeometryError(
                    f"at t = {end:.6g} s the PointPusher of radius {self.pusher.radius:g} m at "
                    f"({centre[0]:g}, {centre[1]:g}) m wedges into a notch of the outline (it "
                    "would touch two of its faces at once), which a round pusher's single "
                    "contact does not model: push elsewhere, or with a LinePusher (its face "
                    "touches up to two points)"
                )
        return moved


class _FaceContact:
    """A flat pusher's face on the outline: the lowest points within its strip (module
    docstring), one or two contact points, new contacts as events."""

    def __init__(self, surface, shape: Outline, pusher: LinePusher):
        self.surface, self.shape, self.pusher = surface, shape, pusher
        self.size, self.tolerance = shape.size, TOUCH_RTOL * shape.size
        self.deepest_start = math.inf  # (any overlap along the normal is a set-back)
        #: How far behind the pusher the face acts [m]: a start's overlap (:meth:`start`).
        self.set_back = 0.0

    def start(self, pose: np.ndarray, allowed: float) -> None:
        """Check the start at ``pose`` (:func:`_start_overlap`); an overlap sets the face back
        along its normal by as much, as the round pusher's overlap does."""
        self.set_back = max(_start_overlap(self, pose, allowed), 0.0)

    def points(self, pose: np.ndarray, t: float):
        """The outline's candidate contact points with the face at time ``t``."""
        normal = _rotation(pose[2]).T @ self.pusher.normal
        face = self.pusher.position(t) - self.set_back * self.pusher.normal
        return self.shape.face_points(_local(pose, face), normal, self.pusher.width / 2)

    def describe(self) -> tuple[str, str]:
        """The pusher in words, and how to start it outside the part (:func:`_start_overlap`)."""
        return (f"LinePusher of width {self.pusher.width:g} m centred",
                "start its face outside the outline (the overlap is along its normal; for a "
                "measured start, allow it with start_overlap)")  # fmt: skip

    def gap(self, pose: np.ndarray, t: float) -> float:
        """Height of the outline's lowest point in the strip above the face [m] (inf: none)."""
        levels = self.points(pose, t).levels
        return float(levels.min()) if len(levels) else math.inf

    def state(self, pose: np.ndarray, t: float) -> _State:
        found = self.points(pose, t)
        if not len(found.keys):  # the part has left the strip
            return _State(PushStep.separated(), np.empty((0, 2)), np.empty((0, 2)), ())
        velocity = _rotation(pose[2]).T @ self.pusher.velocity(t)
        touching = np.flatnonzero(found.levels <= found.levels.min() + self.tolerance)
        along = found.along[touching]
        ends = [touching[np.argmin(along)], touching[np.argmax(along)]]
        if along.max() - along.min() > self.tolerance:
            normal = _rotation(pose[2]).T @ self.pusher.normal
            step, bearing = line_push_step(self.surface, contacts=found.points[ends],
                                           normal=normal, velocity=velocity,
                                           mu=self.pusher.mu)  # fmt: skip
            keys = ()
            if len(bearing) == 1:
                end = ends[int(np.argmin(np.linalg.norm(found.points[ends] - bearing, axis=1)))]
                keys = self._keys_at(found, touching, end)
            return _State(step, found.points[ends], bearing, keys)
        end = ends[0]
        step = push_step(self.surface, contact=found.points[end], normal=found.normals[end],
                         velocity=velocity, mu=self.pusher.mu)  # fmt: skip
        point = found.points[end][None, :]
        if step.mode == "separated":
            return _State(step, point, np.empty((0, 2)), ())
        return _State(step, point, point, self._keys_at(found, touching, end))

    def _keys_at(self, found, touching: np.ndarray, end: int) -> tuple:
        """The keys of the touching points at the place of point ``end`` (a vertex on the
        strip's side is also an edge crossing)."""
        near = np.abs(found.along[touching] - found.along[end]) <= self.tolerance
        return tuple(found.keys[i] for i in touching[near])

    def advance(self, pose: np.ndarray, t: float, end: float, state: _State) -> np.ndarray:
        """The pose at ``end`` [s] by the midpoint rule from ``state`` at ``t``, cut at the
        instants where a new point of the part reaches the face."""
        for _ in range(EVENTS_PER_STEP):
            if state.step.mode == "separated":
                return pose
            moved = self._midpoint(pose, t, end - t, state)
            if moved is not None:
                return moved
            low, high = 0.0, end - t
            for _ in range(TOUCH_BISECTIONS):
                middle = 0.5 * (low + high)
                if self._midpoint(pose, t, middle, state) is None:
                    high = middle
                else:
                    low = middle
            before = pose
            pose = self._midpoint(before, t, low, state)
            event = self.state(pose, t + low)
            if event.keys == state.keys:
                # The new point is not in the strip at the event: it comes in through a side of
                # the strip. Level with the face, a corner passing an end of the face: step past
                # the instant. Far below it, a part of the outline reaching around an end of the
                # pusher to its back, which the face contact does not model.
                pose, low = _compose(before, state.step.twist, high), high
                if self._dip(pose, t + high, state.keys) < -BEHIND_FACE * self.size:
                    x, y = self.pusher.position(t + high)
                    raise GeometryError(
                        f"at t = {t + high:.6g} s the part reaches around an end of the "
                        f"{self.describe()[0]} at ({x:g}, {y:g}) m to its back, which a flat "
                        "pusher's contact does not model (only its face pushes): start it "
                        "elsewhere, or make its face wider"
                    )
                event = self.state(pose, t + high)
            state, t = event, t + low
        raise ConvergenceError(
            f"more than {EVENTS_PER_STEP} new contacts within one step at t = {t} s: the contact "
            "modes cycle without a consistent motion"
        )

    def _midpoint(self, pose: np.ndarray, t: float, time: float, state: _State):
        """The pose after ``time`` [s] by the midpoint rule, put back onto the face along its
        normal while it presses (the integration's error moves the contact off it); ``None``
        when a new point of the part reaches the face by the half step or the end (the step of
        one pressing point holds only until then)."""
        half = _compose(pose, state.step.twist, time / 2)
        if self._dip(half, t + time / 2, state.keys) < -self.tolerance / 2:
            return None
        midpoint = self.state(half, t + time / 2)
        if midpoint.step.mode == "separated":
            # The pressing point left the strip by the half step (the part turns off an end of
            # the face): the step keeps the motion of its start, and the next one finds the
            # contact where it is then. (A step at rest would leave the part where the face
            # pushes on, and the face would pass through it.)
            midpoint = state
        moved = _compose(pose, midpoint.step.twist, time)
        if self._dip(moved, t + time, state.keys) < -self.tolerance / 2:
            return None
        gap = self.gap(moved, t + time)
        if math.isfinite(gap):  # (inf: the part has left the strip; nothing to put back onto)
            moved[:2] -= gap * self.pusher.normal
        return moved

    def _dip(self, pose: np.ndarray, t: float, keys: tuple) -> float:
        """How far the lowest other point of the part lies above the pressing point [m]
        (negative: a new point has come closer to the face); inf when the pressing point has
        left the strip or ``keys`` is empty (two pressing points: the part translates)."""
        if not keys:
            return math.inf
        found = self.points(pose, t)
        pressing = [k for k, key in enumerate(found.keys) if key in keys]
        others = [k for k, key in enumerate(found.keys) if key not in keys]
        if not pressing or not others:
            return math.inf
        return float(found.levels[others].min() - found.levels[pressing].min())


def _touching_time(contact, pose, start, dt) -> float | None:
    """When within ``[start, start + dt]`` the pusher touches the resting part (``None``: not)."""
    if contact.gap(pose, start) <= contact.tolerance:
        return start
    if contact.gap(pose, start + dt) > contact.tolerance:
        return None
    low, high = start, start + dt
    for _ in range(TOUCH_BISECTIONS):
        middle = 0.5 * (low + high)
        if contact.gap(pose, middle) > contact.tolerance:
            low = middle
        else:
            high = middle
    return high


def _local(pose: np.ndarray, point: np.ndarray) -> np.ndarray:
    """A world point in the part frame of ``pose``."""
    return _rotation(pose[2]).T @ (point - pose[:2])


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
