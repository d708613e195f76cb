r"""Raising the task load on a body held by contact springs: where the first contact slips, what
the contacts carry while some slide, and where the body as a whole moves (used by
:mod:`fixplan.motion.compliance`).

Gravity stays and ``λ`` times the task load is applied, ``λ`` rising from 0.

- **Up to the first slip** every contact sticks and the answer is exact and piecewise affine in
  ``λ``: a piece keeps its set of touching contacts and ends where a touching contact's normal
  force falls to 0 or a lifted contact's gap closes. On each piece a contact's excess
  ``gauge(friction load) − fn`` is convex in ``λ``, so its first root is unique and found by
  Brent's method (:func:`fixplan.motion.compliance` reports it as ``first_slip``).
- **After it**, the load rises in increments. In each the contacts are springs about the state
  before it, and a contact whose trial friction load leaves its friction set at its normal force
  is returned to that set along the set's own normal (it slides with the twist its limit surface
  gives; backward Euler). The friction bounds are the normal forces at the end of the increment,
  found by fixed-point iteration of the convex step with the bounds fixed (Tresca's problem, the
  classical iteration for Coulomb friction), accelerated by Anderson mixing, to
  :data:`FIXED_POINT_RTOL`.
- **Increments** are sized by what they change: none may change a contact force by more than
  :data:`MAX_FORCE_CHANGE` of the forces' scale (and up to the task load none is longer than
  ``max(first slip, 1) / steps``); each accepted increment sizes the next from its change.
- **Collapse**: the body moves as a whole at the multiple beyond which no contact forces within
  the friction sets and unilateral limits balance the load. An increment that has no solution
  (or none Clarabel can find accurately, or whose friction bounds do not settle) is halved; one
  of at most :data:`MIN_INCREMENT` of the multiple that fails bounds the collapse from above,
  and the collapse is bracketed between the state reached and that bound to
  :data:`COLLAPSE_RTOL` (the bound is tried once more from there: if it holds, the body was
  creeping towards its limit and the ramp goes on).

Where normal forces do not depend on the slips (a part pressed on its supports by force-controlled
clamps, loads in the support plane) the path does not matter and the collapse multiple is the
rigid limit load; in general it depends on the path (friction is not associated with the normal
direction). On ``problems/fixture-321-compliant.toml``, dividing :data:`MAX_FORCE_CHANGE` by 4
changes the collapse of its nine cases with a finite one by at most 1.6e-4 relative. Where the
friction bounds' fixed point does not converge along a stretch of the path (seen in 6 of 50
random fixtures of the tests, the body creeping over hundreds of small increments), the budget of
increments ends the ramp and the collapse is reported as not found (NaN).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import brentq

from fixplan.errors import ConvergenceError
from fixplan.motion.contact_springs import (
    UNLIMITED,
    ComplianceError,
    InaccurateStepError,
    NoEquilibriumError,
    SpringSystem,
    WrongContactSetError,
)

#: The first-slip multiple is located to this relative accuracy.
SLIP_RTOL = 1e-10

#: Contact forces below this fraction of the force scale are rounding noise.
NEGLIGIBLE = 1e-12

#: The friction bounds of an increment agree with its normal forces to this fraction of the
#: forces' scale (:meth:`LoadRamp._level`; Clarabel's answers near a change of the sliding or
#: touching contacts are not much more accurate).
FIXED_POINT_RTOL = 1e-6

#: Most fixed-point iterations of one increment before it counts as failed (and is halved).
MAX_FIXED_POINT_ITERATIONS = 30

#: The fixed point of an increment fails when its residual has not decreased for this many
#: iterations (at a limit point of the load path it stalls).
STAGNATION = 6

#: Iterates that Anderson acceleration of the friction bounds remembers.
ANDERSON_MEMORY = 5

#: Largest change of a contact force in one increment, as a fraction of the forces' scale
#: (see :meth:`LoadRamp._coarseness`); a larger change halves the increment.
MAX_FORCE_CHANGE = 0.05

#: Increments of at most this fraction of the multiple are not halved for changing the forces
#: too much (the forces jump, as when a contact starts or stops sliding), and one that fails
#: bounds the collapse from above.
MIN_INCREMENT = 1e-3

#: Most increments (tried, including halved ones) per requested step; beyond them the collapse
#: multiple is reported as not found (NaN).
MAX_INCREMENTS_PER_STEP = 50

#: The collapse multiple is bracketed to this relative accuracy.
COLLAPSE_RTOL = 1e-7


class _FixedPointError(ComplianceError):
    """The friction bounds of an increment did not settle."""


@dataclass(frozen=True, slots=True)
class State:
    """The contacts at one multiple of the task load.

    Attributes
    ----------
    multiple : float
        ``λ``.
    forces : array (m, 4)
        Contact forces ``(fn, ft1, ft2, mn)`` [N, N m].
    delta : array (6,)
        Body displacement from the clamped state [m, rad].
    would_be : array (m,)
        Normal force of each contact's spring without the unilateral limit [N] (negative: an
        open gap); a force-controlled contact's preload.
    """

    multiple: float
    forces: np.ndarray
    delta: np.ndarray
    would_be: np.ndarray


class LoadRamp:
    """Gravity plus ``λ`` times the task load on the clamped contact springs.

    Parameters
    ----------
    system : SpringSystem
        The contact springs of the task step (force-controlled clamp normals have constant 0).
    reference : array (m, 4)
        The forces about which the springs act (the clamped state; an open gap as a negative
        normal force).
    gravity, task : array (6,)
        The weight and the task load as wrenches about the centre of mass.
    models : sequence of FrictionModel
        Each contact's friction model.
    case : str
        The load case's name, for messages.
    """

    def __init__(self, system: SpringSystem, reference, gravity, task, models, case: str):
        self.system, self.reference = system, reference
        self.gravity, self.task, self.models, self.case = gravity, task, models, case
        self._units = np.array([1.0, 1.0, 1.0, system.qp.length])

    def at(self, multiple: float) -> tuple[State, np.ndarray, np.ndarray]:
        """The elastic state at ``multiple`` (every contact sticking), exact; with which contacts
        touch and the springs in effect."""
        forces, delta, touching, springs, _ = self.system.solve(
            self.reference, self.gravity + multiple * self.task, self.case
        )
        return State(multiple, forces, delta, self._would_be(delta)), touching, springs

    def _would_be(self, delta) -> np.ndarray:
        normal = self.system.bases[:, :, 0]
        return self.reference[:, 0] - self.system.springs[:, 0] * (normal @ delta)

    def first_slip(self, limit: float) -> tuple[float, int | None, State | None]:
        """Smallest multiple in ``[0, limit]`` at which a sticking contact reaches its friction
        set (with that contact and the state there), or at which the body leaves its contacts
        or moves where no spring holds it (with ``None`` and the state there); ``(inf, None, None)`` when neither happens.
        Followed piece by piece: at the end of a piece the contact whose normal force reached 0
        lifts (or the one whose gap closed touches). Raises :class:`NoEquilibriumError` when
        the contacts cannot balance the weight."""
        start = 0.0
        try:
            state, touching, springs = self.at(start)
        except WrongContactSetError:
            return self._sliding_at(self.origin(), start)
        for _ in range(4 * len(self.models) + 4):
            zero = np.zeros_like(self.reference)
            slope, _, motion = self.system.linear(zero, springs, self.task, touching)
            if not self.system.balances(slope, self.task):
                return start, None, state  # no spring resists part of the task load
            # The piece ends where a touching contact's normal force falls to 0 or a lifted
            # one's would-be force rises to 0.
            rate = np.where(touching, -slope[:, 0], -self.system.springs[:, 0] * motion[:, 0])
            value = np.where(touching, state.forces[:, 0], -state.would_be)
            with np.errstate(divide="ignore", invalid="ignore"):
                crossing = value / rate
            ahead = (rate > 0.0) & np.isfinite(crossing)
            end = min(limit, start + float(crossing[ahead].min(initial=np.inf)))
            best, who = np.inf, None
            forces, slope = self._rounded(state.forces), self._rounded(slope)
            for i, model in enumerate(self.models):
                if touching[i]:
                    found = _slip_root(model, forces[i], slope[i], start, end)
                    if found is not None and found < best:
                        best, who = found, i
            if who is not None:
                return best, who, self._on(best, touching)[0]
            if end >= limit:
                return np.inf, None, None
            last = self._on(end, touching)[0]
            touching = touching.copy()
            touching[np.flatnonzero(ahead)[np.argmin(crossing[ahead])]] ^= True
            try:
                state, springs = self._on(end, touching)
            except WrongContactSetError:  # several changes at once: ask the QP just after
                try:
                    state, touching, springs = self.at(end * (1 + SLIP_RTOL) + SLIP_RTOL)
                except NoEquilibriumError:
                    return end, None, last
                except WrongContactSetError:
                    return self._sliding_at(last, end)
            start = end
        raise ConvergenceError(f"load case {self.case!r}: too many changes of the lifted contacts")

    def origin(self) -> State:
        """The clamped state, before gravity and the task load."""
        normal = self.reference[:, 0]
        forces = self.reference.copy()
        forces[:, 0] = np.maximum(normal, 0.0)
        return State(0.0, forces, np.zeros(6), normal.copy())

    def _sliding_at(self, state: State, multiple: float) -> tuple[float, int, State]:
        """No state with every contact sticking exists at ``multiple`` (a contact at the verge of
        lifting would have to carry friction): the state there with its sliding contacts, from
        ``state``, and the contact that uses most of its friction set."""
        reached = self.increment(state, multiple)
        usage = np.zeros(len(self.models))
        for i, (model, (fn, *load)) in enumerate(zip(self.models, reached.forces, strict=True)):
            friction = np.array(load[: model.load_dimension])
            if fn > 0.0 and friction.any():
                usage[i] = 1.0 / model.safety_factor(friction, normal_force=fn)
        return multiple, int(np.argmax(usage)), reached

    def _on(self, multiple: float, touching) -> tuple[State, np.ndarray]:
        """The elastic state at ``multiple`` with the contacts ``touching`` given, and the
        springs in effect."""
        forces, delta, springs, _ = self.system.touching(
            self.reference, self.gravity + multiple * self.task, touching, self.case
        )
        return State(multiple, forces, delta, self._would_be(delta)), springs

    def _rounded(self, forces) -> np.ndarray:
        """``forces`` ``(m, 4)`` with rounding noise (below :data:`NEGLIGIBLE` of the force
        scale) set to 0, so that a contact without friction load lifts off, not slips."""
        units = self.system.qp.units.reshape(-1, 4)
        return np.where(np.abs(forces) < NEGLIGIBLE * units, 0.0, forces)

    def increment(self, state: State, multiple: float) -> State:
        """The state at ``multiple`` reached from ``state`` in one increment (see the module
        doc); raises :class:`NoEquilibriumError` or a failed fixed point.

        The friction bounds start at the normal forces before the increment (a small increment
        changes them little), or, if no forces within those bounds balance the load, at those
        of the elastic trial (every contact sticking)."""
        qp = self.system.qp
        reference = state.forces.copy()
        reference[:, 0] = state.would_be
        wrench = self.gravity + multiple * self.task
        try:
            return self._settle(state, multiple, reference, np.maximum(state.forces[:, 0], 0.0))
        except NoEquilibriumError:
            unlimited = np.full(len(self.models), UNLIMITED * qp.scale)
            trial = qp.solve(reference, wrench, unlimited, self.case)[0]
            return self._settle(state, multiple, reference, np.maximum(trial[:, 0], 0.0))

    def _settle(self, state: State, multiple: float, reference, bound) -> State:
        """The fixed point of the friction bounds of an increment from ``bound``."""
        qp = self.system.qp
        wrench = self.gravity + multiple * self.task
        bounds, normals, best, since = [], [], np.inf, 0
        for _ in range(MAX_FIXED_POINT_ITERATIONS):
            forces, step = qp.solve(reference, wrench, bound, self.case)
            normal = np.maximum(forces[:, 0], 0.0)
            residual = np.abs(normal - bound).max()
            if residual <= FIXED_POINT_RTOL * self._level(forces):
                delta = state.delta + step
                return State(multiple, forces, delta, self._would_be(delta))
            best, since = (residual, 0) if residual < best else (best, since + 1)
            if since >= STAGNATION:
                break
            bounds.append(bound)
            normals.append(normal)
            bound = _anderson(bounds[-ANDERSON_MEMORY - 1 :], normals[-ANDERSON_MEMORY - 1 :])
        raise _FixedPointError(f"load case {self.case!r}: the friction bounds did not settle")

    def _level(self, forces) -> float:
        """The forces' scale [N]: the larger of the problem's force scale and the largest
        contact force (moments over the length scale)."""
        qp = self.system.qp
        return max(qp.scale, float(np.abs(forces / self._units).max()))

    def _coarseness(self, state: State, reached: State) -> float:
        """The largest change of a contact force in an increment over :data:`MAX_FORCE_CHANGE`
        of the forces' scale before it (above 1: the path it follows is coarse)."""
        change = float((np.abs(reached.forces - state.forces) / self._units).max())
        return change / (MAX_FORCE_CHANGE * self._level(state.forces))

    def follow(self, start: State, steps: int, limit: float) -> tuple[float, State, State | None]:
        """Raise the load from ``start`` (the first slip) in increments: the collapse multiple
        (``inf`` if none up to ``limit``; NaN if it is not bracketed within the budget of
        increments), the last state reached and the state at the task load (``None`` if the body
        moves before it or it was not reached).

        Increments are sized so that no contact force changes by more than
        :data:`MAX_FORCE_CHANGE` of the forces' scale (and up to the task load, at most
        ``max(first slip, 1) / steps``). One that fails is halved; one of at most
        :data:`MIN_INCREMENT` of the multiple that fails sets a ceiling: later increments bisect
        between the state reached and the ceiling, and once the two are :data:`COLLAPSE_RTOL`
        apart the ceiling is tried once more from there. If it fails again, the state reached is
        the collapse; otherwise the ramp goes on (the body creeps towards its limit)."""
        base = max(start.multiple, 1.0) / steps
        step, state = base, start
        at_task = start if start.multiple == 1.0 else None
        ceiling, retried, failed = np.inf, False, 0.0
        for _ in range(MAX_INCREMENTS_PER_STEP * steps):
            if state.multiple >= limit:
                return np.inf, state, at_task
            closing = ceiling - state.multiple <= COLLAPSE_RTOL * max(state.multiple, base)
            if closing and retried:
                return state.multiple, state, at_task
            multiple = ceiling if closing else min(state.multiple + step, limit)
            if not closing and ceiling < np.inf:
                multiple = min(multiple, 0.5 * (state.multiple + ceiling))
            if state.multiple < 1.0 < multiple:
                multiple = 1.0
            small = multiple - state.multiple <= MIN_INCREMENT * max(state.multiple, base)
            try:
                reached = self.increment(state, multiple)
            except (NoEquilibriumError, InaccurateStepError, _FixedPointError):
                if small and not closing:
                    ceiling, failed = multiple, multiple - state.multiple
                retried = closing
                step = (multiple - state.multiple) / 2.0
                continue
            coarseness = self._coarseness(state, reached)
            if coarseness > 1.0 and not small:  # unless the forces jump, as when a contact
                step = (multiple - state.multiple) / 2.0  # starts or stops sliding
                continue
            taken, state = multiple - state.multiple, reached
            if closing:  # the ceiling held: go on at half the increment that failed there
                ceiling, retried, taken = np.inf, False, failed / 4.0
            if state.multiple == 1.0:
                at_task = state
            step = taken * min(2.0, 0.8 / max(coarseness, 1e-3))
            if state.multiple < 1.0:
                step = min(step, base)
        return np.nan, state, at_task


def _anderson(bounds, normals) -> np.ndarray:
    """The next friction bounds of the fixed point ``bound = normal(bound)`` by Anderson
    acceleration (Walker & Ni 2011) over the last iterates; plain iteration on the first."""
    normal = normals[-1]
    if len(bounds) > 1:
        residuals = np.diff(np.array(normals) - np.array(bounds), axis=0).T
        changes = np.diff(np.array(normals), axis=0).T
        weights = np.linalg.lstsq(residuals, normals[-1] - bounds[-1], rcond=None)[0]
        normal = normal - changes @ weights
    return np.maximum(normal, 0.0)


def _slip_root(model, forces, slope, start, end) -> float | None:
    """First ``λ`` in ``[start, end]`` where ``gauge(L(λ)) = fn(λ)``: the excess is convex in
    ``λ`` (a gauge of an affine load minus an affine force), so its first root is unique."""

    width = 4 if model.torsion else 3
    if not (forces[1:width].any() or slope[1:width].any()):
        return None  # no friction load on this piece: the contact can lift off, not slip

    def excess(multiple):
        fn, *load = forces + (multiple - start) * slope
        friction = np.array(load[: width - 1])
        if not friction.any():
            return -fn
        return float(1.0 / model.safety_factor(friction, normal_force=1.0)) - fn

    at_start = excess(start)
    if at_start > 0.0:
        return start
    if excess(end) <= 0.0:
        return None
    if at_start == 0.0:  # on the limit (an unloaded contact): slips now if the excess grows
        probe = start + SLIP_RTOL * (end - start)
        if excess(probe) > 0.0:
            return start
        start = probe
    return brentq(excess, start, end, rtol=SLIP_RTOL)
