"""Every answer checked in numpy before it is reported: equilibrium and friction sets."""

from __future__ import annotations

import numpy as np

from fixplan.planner.friction_use import FrictionUse
from fixplan.planner.problem import Problem
from fixplan.planner.stacking import ContactLayout
from fixplan.surface.point_kernel import compiled_scalar
from fixplan.tolerances import EQUILIBRIUM_RTOL, FRICTION_SET_RTOL


class Verifier:
    """Checks every answer of one problem's planner: equilibrium and friction sets.

    Parameters
    ----------
    problem : Problem
        The problem (its contact names and weight).
    layout : ContactLayout
        Where each contact's normal force and friction load sit.
    friction_use : FrictionUse
        The friction use of every contact load.
    length_scale : float
        Moments are compared with at least force × ``length_scale`` [m].
    """

    def __init__(
        self,
        problem: Problem,
        layout: ContactLayout,
        friction_use: FrictionUse,
        length_scale: float,
    ):
        self._names = [contact.name for contact in problem.contacts]
        self._gravity = np.ascontiguousarray(problem.body.weight_wrench, dtype=float)
        self._maps = tuple(
            np.ascontiguousarray(m, dtype=float) for m in (layout.normal_map, layout.friction_map)
        )
        self._use = friction_use
        self._length_scale = length_scale

    def __call__(self, answer: dict, wrenches: np.ndarray) -> tuple[float, list[str], np.ndarray]:
        """The largest relative equilibrium residual of ``answer``, what failed, in words, and
        the friction use ``(C, K)`` of its loads (:class:`~fixplan.planner.friction_use.
        FrictionUse`, with the noise of the largest normal force or task force).

        ``answer`` holds ``normal`` ``(C, K)`` [N], ``friction`` ``(D, K)`` and ``scale``
        ``(K,)``; ``wrenches`` ``(6, K)`` are the task wrenches. Forces are compared with the
        forces of each case's wrench terms and moments with their moments; a contact's friction
        may exceed its set by ``FRICTION_SET_RTOL`` of the largest normal force or task force.
        """
        normal, friction, scale = answer["normal"], answer["friction"], answer["scale"]
        sizes = np.empty((2, normal.shape[1]))
        ratios = np.empty((2, normal.shape[1]))
        relative, largest = _EQUILIBRIUM(*self._maps, normal, friction, wrenches, scale,
                                         self._gravity, self._length_scale, sizes, ratios)  # fmt: skip
        problems = []
        if relative > EQUILIBRIUM_RTOL:
            for row, unit in ((0, "N"), (1, "N m")):
                worst = int(np.argmax(ratios[row]))
                ratio, size = ratios[row, worst], sizes[row, worst]
                if ratio == np.inf:
                    problems.append(f"load case {worst + 1}: forces not finite (NaN or infinite)")
                    break
                if ratio > EQUILIBRIUM_RTOL:
                    problems.append(
                        f"equilibrium residual of load case {worst + 1}: "
                        f"{ratio * size:.3g} {unit}, over {EQUILIBRIUM_RTOL:g} of the "
                        f"wrenches involved ({size:.3g} {unit})"
                    )
        # Against the largest normal force, or task force at multiple 1 (the solver's accuracy is
        # relative to its largest data; a multiple near 0 leaves every force tiny).
        scale_force = max(largest, LARGEST_MAGNITUDE(wrenches[:3]), 1e-12)
        noise = FRICTION_SET_RTOL * scale_force
        use = self._use(friction, normal, noise=noise, known=answer.get("known_use"))
        if _TROUBLED(normal, use, noise):
            problems += self._friction_problems(normal, use, noise, scale_force)
        return relative, problems, use

    def _friction_problems(self, normal, use, noise, scale_force) -> list[str]:
        """Pulling contacts, friction without normal force and friction outside its set, at
        the uses ``use`` ``(C, K)`` of the loads, in words (``noise`` [N]: the solver's, and
        ``scale_force`` [N]: the largest normal force or task force)."""
        problems = [
            f"contact {self._names[i]!r} pulls: normal force {normal[i].min():.3g} N"
            for i in np.flatnonzero((normal < -noise).any(axis=1))
        ]
        pressed = normal > noise
        problems += [
            f"contact {self._names[i]!r} carries friction without normal force"
            for i in np.flatnonzero((np.isinf(use) & ~pressed).any(axis=1))
        ]
        # The excess of a contact's friction over its set, as a force, against the largest
        # normal force: solver accuracy is absolute, so a lightly pressed contact may exceed its
        # own set by more than FRICTION_SET_RTOL in relative terms and still be exact enough.
        excess = np.where(pressed, use - 1.0, -np.inf)
        excess[pressed] *= normal[pressed]
        for i in np.flatnonzero((excess > noise).any(axis=1)):
            worst = int(np.argmax(excess[i]))
            problems.append(
                f"contact {self._names[i]!r} exceeds its friction set by "
                f"{excess[i, worst]:.3g} N (over {FRICTION_SET_RTOL:g} of the largest normal "
                f"force or task force, {scale_force:.3g} N)"
            )
        return problems


def equilibrium(normal_map, friction_map, normal, friction, wrenches, scale, gravity,
                length_scale, sizes, ratios):  # fmt: skip  # pragma: no cover - compiled
    """Each case's largest residual of force and of moment (rows of ``ratios`` ``(2, K)``)
    over the size of its wrench terms and its task load at multiple 1 (``sizes``: the largest
    force and moment of any term, moments at least force × ``length_scale``); returns the
    largest ratio (0 for no case) and the largest magnitude of ``normal`` (see
    :func:`largest_magnitude`). A row with a term that
    is not finite (NaN or infinite) has an infinite residual."""
    largest = 0.0
    for k in range(normal.shape[1]):
        residual = np.zeros(6)
        magnitude = np.zeros(6)
        for row in range(6):
            task = wrenches[row, k] * scale[k]
            total = task + gravity[row]
            # (The task load at multiple 1 at least: a multiple near 0 leaves every term tiny.)
            size = abs(wrenches[row, k]) * max(abs(scale[k]), 1.0) + abs(gravity[row])
            for c in range(normal.shape[0]):
                term = normal_map[row, c] * normal[c, k]
                total += term
                size += abs(term)
            for d in range(friction.shape[0]):
                term = friction_map[row, d] * friction[d, k]
                total += term
                size += abs(term)
            if not (abs(total) < np.inf and size < np.inf):  # NaN or infinite terms
                total, size = np.inf, 1.0
            residual[row], magnitude[row] = abs(total), size
        force = max(max(magnitude[0], magnitude[1], magnitude[2]), 1e-12)
        moment = max(max(magnitude[3], magnitude[4], magnitude[5]), force * length_scale)
        sizes[0, k], sizes[1, k] = force, moment
        ratios[0, k] = max(residual[0], residual[1], residual[2]) / force
        ratios[1, k] = max(residual[3], residual[4], residual[5]) / moment
        largest = max(largest, ratios[0, k], ratios[1, k])
    return largest, LARGEST_MAGNITUDE(normal)


def largest_magnitude(values):  # pragma: no cover - compiled
    """The largest absolute value of ``values`` ``(C, K)`` (0 for none; NaN if any is)."""
    largest = 0.0
    for c in range(values.shape[0]):
        for k in range(values.shape[1]):
            value = abs(values[c, k])
            if value != value:  # NaN
                return value
            largest = max(largest, value)
    return largest


def largest_scaled_magnitude(values, row_scales):  # pragma: no cover - compiled
    """The largest absolute value of ``values`` ``(R, K)`` times its row's ``row_scales``
    ``(R,)`` (0 for none; NaN if any is), without the product's array."""
    largest = 0.0
    for r in range(values.shape[0]):
        for k in range(values.shape[1]):
            value = abs(values[r, k]) * row_scales[r]
            if value != value:  # NaN
                return value
            largest = max(largest, value)
    return largest


def troubled(normal, use, noise):  # pragma: no cover - compiled
    """Whether a contact pulls, carries friction without normal force or exceeds its set by
    more than ``noise`` [N] (see :meth:`Verifier._friction_problems`)."""
    for c in range(normal.shape[0]):
        for k in range(normal.shape[1]):
            force = normal[c, k]
            if force < -noise:
                return True
            if force > noise:
                if (use[c, k] - 1.0) * force > noise:
                    return True
            elif np.isinf(use[c, k]):
                return True
    return False


#: :func:`largest_magnitude` compiled (also for the analysis).
LARGEST_MAGNITUDE = compiled_scalar(largest_magnitude)
#: :func:`largest_scaled_magnitude` compiled (for the planner's force unit).
LARGEST_SCALED_MAGNITUDE = compiled_scalar(largest_scaled_magnitude)
_EQUILIBRIUM = compiled_scalar(equilibrium)
_TROUBLED = compiled_scalar(troubled)
