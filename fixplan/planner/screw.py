"""Rigid-body twists as screws, and in words.

A twist ``(v, ω)`` is the velocity ``v`` [m/s] of the body point at the world origin and the
angular velocity ``ω`` [rad/s]. Its screw is the axis along ``ω`` through the point
``r = ω × v / |ω|²`` with pitch ``ω·v / |ω|²`` [m/rad]; a twist with ``ω = 0`` is a translation.
"""

from __future__ import annotations

import math

import numpy as np

from fixplan.tolerances import SCREW_PRINT_RTOL

#: A twist whose rotation moves points at the body's length scale less than this fraction of
#: its translation is reported as a pure translation: twists come from interior-point duals,
#: accurate to about 1e-8. (The certificate of a frictionless pinch dropping its weight came
#: back as a translation with a rotation of 2e-9 of it: an axis 1e7 m away.)
TRANSLATION_RTOL = 1e-7


def _fmt(vector: np.ndarray, noise: float, digits: int = 4) -> str:
    """``vector`` in parentheses, entries smaller than ``noise`` printed as 0."""
    cleaned = np.where(np.abs(vector) < noise, 0.0, vector)
    return "(" + ", ".join(f"{x:.{digits}g}" for x in cleaned + 0.0) + ")"


class Screw:
    """A unit twist and its screw.

    Built from a twist in a fraction of a microsecond: the unit twist and the axis are worked
    out on first use (a controller that reads only the forces of its plans pays nothing for
    their motions).

    Attributes
    ----------
    twist : array (6,)
        ``(v, ω)``: velocity of the body point at the world origin [m/s] and angular velocity
        [rad/s], scaled so that ``|v|² + (L |ω|)² = 1`` with ``L`` the body's length scale.
    direction : array (3,)
        Unit direction of the screw axis (of the translation for a pure translation).
    point : array (3,) or None
        Point of the axis closest to the world origin [m] (``None`` for a translation).
    pitch : float
        Translation per radian along the axis [m/rad] (``inf`` for a translation).
    length_scale : float
        The body's length scale [m]; sets what counts as solver noise when printing.
    """

    __slots__ = ("_axis", "_given", "length_scale")

    def __init__(self, twist: np.ndarray, length_scale: float):
        """The screw of a nonzero, finite ``twist`` ``(6,)``, kept as it is (not to be changed
        afterwards: :meth:`from_twist` checks and copies it); ``length_scale`` [m] sets the
        translation test."""
        self._given = twist
        self.length_scale = length_scale
        self._axis: tuple | None = None

    @classmethod
    def from_twist(cls, twist, length_scale: float) -> Screw:
        """The screw of ``twist`` ``(6,)`` (a copy is kept); ``length_scale`` [m] sets the
        translation test."""
        values = np.array(twist, dtype=float)
        if values.shape != (6,) or not np.isfinite(values).all() or not values.any():
            raise ValueError(f"a screw needs a nonzero, finite twist of 6 numbers, not {twist!r}")
        return cls(values, float(length_scale))

    def __repr__(self) -> str:
        return f"Screw.from_twist({self.twist.tolist()}, {self.length_scale!r})"

    def __reduce__(self) -> tuple:
        return Screw, (self._given, self.length_scale)

    @property
    def twist(self) -> np.ndarray:
        return self._worked_out()[0]

    @property
    def direction(self) -> np.ndarray:
        return self._worked_out()[1]

    @property
    def point(self) -> np.ndarray | None:
        return self._worked_out()[2]

    @property
    def pitch(self) -> float:
        return self._worked_out()[3]

    def _worked_out(self) -> tuple:
        """``(twist, direction, point, pitch)``, worked out once."""
        if self._axis is None:
            self._axis = _unit_twist_and_axis(self._given, self.length_scale)
        return self._axis

    @property
    def is_translation(self) -> bool:
        """Whether the body slides without turning."""
        return self.point is None

    def describe(self) -> str:
        """The motion in words."""
        along = _fmt(self.direction, SCREW_PRINT_RTOL)
        if self.is_translation:
            return f"translates along {along}"
        through = _fmt(self.point, SCREW_PRINT_RTOL * self.length_scale)
        text = f"rotates about an axis through {through} m along {along}"
        if abs(self.pitch) > SCREW_PRINT_RTOL * self.length_scale:
            text += f", advancing {self.pitch:.4g} m/rad along it"
        return text

    def as_dict(self) -> dict:
        """JSON-ready description."""
        return {
            "twist": self.twist.tolist(),
            "axis_direction": self.direction.tolist(),
            "axis_point_m": None if self.point is None else self.point.tolist(),
            "pitch_m_per_rad": None if self.is_translation else self.pitch,
            "words": self.describe(),
        }


def _unit_twist_and_axis(twist: np.ndarray, length_scale: float) -> tuple:
    """``(unit twist, direction, point or None, pitch)`` of a nonzero ``twist`` ``(6,)`` (see
    :class:`Screw`)."""
    # In floats: numpy's calls cost more than the arithmetic on six numbers (14 µs → 4 µs).
    entries = np.asarray(twist, dtype=float).tolist()
    largest = max(map(abs, entries))  # (divided by first: no squares under- or overflow)
    vx, vy, vz, wx, wy, wz = (x / largest for x in entries)
    norm = math.sqrt(vx * vx + vy * vy + vz * vz + length_scale**2 * (wx * wx + wy * wy + wz * wz))
    vx, vy, vz, wx, wy, wz = vx / norm, vy / norm, vz / norm, wx / norm, wy / norm, wz / norm
    speed = math.sqrt(vx * vx + vy * vy + vz * vz)
    spin = math.sqrt(wx * wx + wy * wy + wz * wz)
    # (One array for all three vectors: each np.array of a list costs about 1 µs.)
    if spin * length_scale <= TRANSLATION_RTOL * speed:
        values = np.array([vx, vy, vz, 0.0, 0.0, 0.0, vx / speed, vy / speed, vz / speed])
        return values[:6], values[6:], None, float("inf")
    squared = spin * spin  # the point ω × v / |ω|² and the pitch ω·v / |ω|²
    values = np.array([
        vx, vy, vz, wx, wy, wz, wx / spin, wy / spin, wz / spin,
        (wy * vz - wz * vy) / squared, (wz * vx - wx * vz) / squared,
        (wx * vy - wy * vx) / squared,
    ])  # fmt: skip
    return values[:6], values[6:9], values[9:], (wx * vx + wy * vy + wz * vz) / squared
