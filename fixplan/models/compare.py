r"""Accuracy of a friction model against the exact limit surface.

Over a dense, evenly spread set of load directions (a Fibonacci lattice in the normalised
coordinates of the paper, or evenly spread angles in one coordinate plane) the radial error of a
model in direction ``d`` is

.. math:: e(d) = \frac{r_\text{model}(d)}{r_\text{exact}(d)} - 1
               = \frac{s_\text{model}(L)}{s_\text{exact}(L)} - 1,

the relative gap between the two boundaries along the ray (``s`` the safety factors of any load
``L`` in direction ``d``). ``e > 0``: the model overestimates what the contact holds (unsafe);
``e < 0``: it underestimates (conservative). For models with a motion map, the motion error is
the angle between the predicted and the exact sliding twist for the same load, both written as
``(vx, vy, rho w)`` with the exact surface's ``rho`` (the paper's normalised coordinates).

A frictionless surface (``mu = 0``) and a model built from it are both the single load 0. Every
model scales with ``mu`` as the surface does, so their errors do not depend on ``mu``: they are
compared on their shapes (``friction_shape``, ``mu = 1``), which gives the errors of the same
model at any ``mu > 0``, and the motion errors of the limit ``mu → 0+``.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from fixplan.errors import InvalidArgumentError
from fixplan.models.base import FrictionModel
from fixplan.surface.limit_surface import LimitSurface
from fixplan.surface.sphere import circle, fibonacci_sphere
from fixplan.tolerances import UNSAFE_RTOL

_PLANES = {"fx-m": (0, 2), "fy-m": (1, 2), "fx-fy": (0, 1)}

#: Default number of load directions of :func:`compare`.
DEFAULT_DIRECTIONS = 2000


@dataclass(frozen=True, slots=True, kw_only=True)
class Accuracy:
    """Radial and motion errors of one model against the exact surface.

    Attributes
    ----------
    model : str
        Repr of the model.
    directions : int
        Number of load directions compared.
    plane : str or None
        Coordinate plane of the directions (``None``: the whole sphere).
    max_overestimate : float
        Largest ``e`` (relative radial error, > 0 means unsafe).
    max_underestimate : float
        Largest ``-e``.
    mean_error : float
        Mean signed ``e``.
    mean_abs_error : float
        Mean ``|e|``.
    unsafe_fraction : float
        Fraction of directions with ``e > UNSAFE_RTOL``.
    max_motion_angle, mean_motion_angle : float or None
        Largest and mean angle [rad] between predicted and exact sliding twist; ``None`` for
        models without a motion map.
    """

    model: str
    directions: int
    plane: str | None
    max_overestimate: float
    max_underestimate: float
    mean_error: float
    mean_abs_error: float
    unsafe_fraction: float
    max_motion_angle: float | None
    mean_motion_angle: float | None

    @property
    def max_error(self) -> float:
        """The signed radial error of largest magnitude."""
        if self.max_overestimate >= self.max_underestimate:
            return self.max_overestimate
        return -self.max_underestimate


def load_directions(
    surface: LimitSurface, n: int = DEFAULT_DIRECTIONS, *, plane: str | None = None
) -> np.ndarray:
    """``n`` loads ``(n, 3)`` of unit length in the surface's normalised coordinates.

    Evenly spread over the sphere (Fibonacci lattice) or, with ``plane`` (``"fx-m"``,
    ``"fy-m"``, ``"fx-fy"``), evenly in angle in that plane. A frictionless surface has the
    coordinates of its shape (``mu = 1``).
    """
    if not isinstance(n, int | np.integer) or n < 1:
        raise InvalidArgumentError(f"n must be a positive integer, got {n!r}")
    surface = surface.friction_shape
    units = np.array([surface.max_force, surface.max_force, surface.max_moment])
    if plane is None:
        return fibonacci_sphere(int(n)) * units
    axes = _PLANES.get(plane)
    if axes is None:
        raise InvalidArgumentError(f"plane must be one of {', '.join(_PLANES)}; got {plane!r}")
    directions = np.zeros((int(n), 3))
    directions[:, axes] = circle(int(n))
    return directions * units


def _shapes(model: FrictionModel, surface: LimitSurface) -> tuple[FrictionModel, LimitSurface]:
    """The model and surface to compare: themselves, or the shapes of frictionless ones."""
    if surface.frictionless and not model.frictionless:
        raise InvalidArgumentError(
            f"surface is frictionless (mu = 0) but model has mu = {model.mu:.6g}: a frictionless "
            "contact holds only the load 0; compare a model built from the surface"
        )
    return model.friction_shape, surface.friction_shape


def radial_errors(model: FrictionModel, surface: LimitSurface, loads) -> np.ndarray:
    """Relative radial errors ``e`` ``(K,)`` of ``model`` along nonzero ``loads`` ``(K, 3)``
    (of the shapes for a frictionless surface and model)."""
    model, surface = _shapes(model, surface)
    exact = surface.safety_factor(loads)
    approx = model.safety_factor(loads, normal_force=surface.normal_force)
    return np.asarray(approx) / np.asarray(exact) - 1.0


def motion_angles(
    model: FrictionModel, surface: LimitSurface, loads, *, exact_motion=None
) -> np.ndarray:
    """Angles [rad] ``(K,)`` between the model's and the exact sliding twists for ``loads``.

    ``exact_motion`` ``(K, 3)`` reuses twists already computed by ``surface.motion``.
    """
    model, surface = _shapes(model, surface)
    exact = surface.motion(loads) if exact_motion is None else exact_motion
    predicted = model.motion(loads, normal_force=surface.normal_force)
    scale = np.array([1.0, 1.0, surface.characteristic_length])
    a = exact * scale
    b = predicted * scale
    a = a / np.linalg.norm(a, axis=1, keepdims=True)
    b = b / np.linalg.norm(b, axis=1, keepdims=True)
    # The angle from the norm of the difference is accurate also for tiny angles.
    return 2.0 * np.arcsin(np.clip(0.5 * np.linalg.norm(a - b, axis=1), 0.0, 1.0))


def compare(
    model: FrictionModel,
    surface: LimitSurface,
    *,
    n: int = DEFAULT_DIRECTIONS,
    plane: str | None = None,
) -> Accuracy:
    """Accuracy of ``model`` against the exact ``surface`` over ``n`` load directions.

    Point models (no torsion) are compared in the ``"fx-fy"`` plane, against the section
    ``m = 0`` of the surface. The comparison is at the surface's normal force. A frictionless
    surface and model are compared on their shapes (see the module docstring); a frictionless
    surface with a model that has friction raises :class:`InvalidArgumentError`.
    """
    if not isinstance(model, FrictionModel):
        raise InvalidArgumentError(f"model must be a friction model, got {type(model).__name__}")
    if not isinstance(surface, LimitSurface):
        raise InvalidArgumentError(f"surface must be a LimitSurface, got {type(surface).__name__}")
    if not model.torsion:
        if plane not in (None, "fx-fy"):
            raise InvalidArgumentError(
                f"a point model bears no moment: compare it in plane 'fx-fy', not {plane!r}"
            )
        plane = "fx-fy"
    name = repr(model)
    model, surface = _shapes(model, surface)
    loads = load_directions(surface, n, plane=plane)
    if model.has_motion:
        exact_motion, exact_safety = surface.motion_and_safety_factor(loads)
        angles = motion_angles(model, surface, loads, exact_motion=exact_motion)
        max_angle, mean_angle = float(angles.max()), float(angles.mean())
    else:
        exact_safety = surface.safety_factor(loads)
        max_angle = mean_angle = None
    approx = model.safety_factor(loads, normal_force=surface.normal_force)
    errors = approx / exact_safety - 1.0
    return Accuracy(
        model=name,
        directions=len(loads),
        plane=plane,
        max_overestimate=float(errors.max()),
        max_underestimate=float(-errors.min()),
        mean_error=float(errors.mean()),
        mean_abs_error=float(np.abs(errors).mean()),
        unsafe_fraction=float(np.mean(errors > UNSAFE_RTOL)),
        max_motion_angle=max_angle,
        mean_motion_angle=mean_angle,
    )


def accuracy_table(rows: Mapping[str, Accuracy]) -> str:
    """A Markdown table of accuracies, one row per ``name: Accuracy``.

    Radial errors in percent, motion angles in degrees.
    """
    lines = [
        "| case | max over % | max under % | mean % | mean abs % | unsafe % "
        "| max angle ° | mean angle ° |",
        "|---|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for name, acc in rows.items():
        angles = (
            ("-", "-")
            if acc.max_motion_angle is None
            else (
                f"{np.degrees(acc.max_motion_angle):.2f}",
                f"{np.degrees(acc.mean_motion_angle):.2f}",
            )
        )
        lines.append(
            f"| {name} | {100 * acc.max_overestimate:.2f} | {100 * acc.max_underestimate:.2f} "
            f"| {100 * acc.mean_error:.2f} | {100 * acc.mean_abs_error:.2f} "
            f"| {100 * acc.unsafe_fraction:.1f} | {angles[0]} | {angles[1]} |"
        )
    return "\n".join(lines) + "\n"
