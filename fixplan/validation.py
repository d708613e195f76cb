"""Argument checks shared by the public constructors.

Each check raises :class:`~fixplan.errors.InvalidArgumentError` whose message names the argument,
the value received and the range allowed.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from fixplan.errors import GeometryError, InvalidArgumentError
from fixplan.tolerances import MAX_LENGTH


def finite_scalar(name: str, value: object) -> float:
    """Return ``value`` as a finite float."""
    try:
        number = float(value)  # type: ignore[arg-type]
    except (TypeError, ValueError) as exc:
        raise InvalidArgumentError(f"{name} must be a real number, got {value!r}") from exc
    except OverflowError as exc:  # (an int beyond the floats)
        raise InvalidArgumentError(f"{name} must be finite, got an integer beyond 1e308") from exc
    if not math.isfinite(number):
        raise InvalidArgumentError(f"{name} must be finite, got {number!r}")
    return number


def positive_scalar(name: str, value: object) -> float:
    """Return ``value`` as a finite float > 0."""
    number = finite_scalar(name, value)
    if number <= 0.0:
        raise InvalidArgumentError(f"{name} must be > 0, got {number!r}")
    return number


def nonnegative_scalar(name: str, value: object) -> float:
    """Return ``value`` as a finite float >= 0 (``-0.0`` becomes ``0.0``)."""
    number = finite_scalar(name, value)
    if number < 0.0:
        raise InvalidArgumentError(f"{name} must be >= 0, got {number!r}")
    return number + 0.0


def unit_vector(vector: np.ndarray) -> tuple[np.ndarray, float]:
    """A finite, nonzero ``vector`` as a unit vector and its norm, without the overflow or
    underflow of squaring its entries (it is scaled by its largest entry first)."""
    peak = float(np.max(np.abs(vector)))
    scaled = vector / peak
    norm = float(np.linalg.norm(scaled))
    return scaled / norm, peak * norm


def positive_int(name: str, value: object) -> int:
    """Return ``value`` as an int >= 1 (booleans are refused)."""
    if isinstance(value, bool) or not isinstance(value, int | np.integer) or value < 1:
        raise InvalidArgumentError(f"{name} must be a positive integer, got {value!r}")
    return int(value)


def finite_array(name: str, value: object, *, shape: tuple[int | None, ...]) -> np.ndarray:
    """Return ``value`` as a read-only float array of ``shape`` (``None`` = any length)."""
    try:
        array = np.array(value, dtype=float)
    except (TypeError, ValueError, OverflowError) as exc:
        raise InvalidArgumentError(
            f"{name} must be an array of finite real numbers, got {value!r}"
        ) from exc
    expected = "(" + ", ".join("n" if n is None else str(n) for n in shape) + ")"
    if array.ndim != len(shape) or any(
        n is not None and size != n for size, n in zip(array.shape, shape, strict=True)
    ):
        raise InvalidArgumentError(f"{name} must have shape {expected}, got {array.shape}")
    if not np.all(np.isfinite(array)):
        raise InvalidArgumentError(f"{name} must be finite, got a NaN or infinite entry")
    array.setflags(write=False)
    return array


def vector_batch(name: str, value: object, *, width: int) -> tuple[np.ndarray, bool]:
    """Return ``value`` as a ``(K, width)`` float array and whether it was a single vector."""
    try:
        array = np.asarray(value, dtype=float)
    except (TypeError, ValueError, OverflowError) as exc:
        raise InvalidArgumentError(
            f"{name} must be an array of finite real numbers, got {value!r}"
        ) from exc
    single = array.ndim == 1
    if single:
        array = array[np.newaxis, :]
    if array.ndim != 2 or array.shape[1] != width:
        raise InvalidArgumentError(
            f"{name} must have shape ({width},) or (K, {width}), got {np.shape(value)}"
        )
    if not np.all(np.isfinite(array)):
        bad = int(np.flatnonzero(~np.all(np.isfinite(array), axis=1))[0])
        raise InvalidArgumentError(f"{name}[{bad}] is not finite: {array[bad].tolist()}")
    return array, single


def choice(name: str, value: object, allowed: tuple[str, ...]) -> str:
    """Return ``value`` if it is one of ``allowed``."""
    if value not in allowed:
        raise InvalidArgumentError(
            f"{name} must be one of {', '.join(repr(a) for a in allowed)}; got {value!r}"
        )
    return str(value)


def callable_argument(name: str, value: object) -> Callable:
    """Return ``value`` if it is callable."""
    if not callable(value):
        raise InvalidArgumentError(f"{name} must be a function of (x, y), got {value!r}")
    return value


def field_values(
    name: str,
    function: Callable,
    x: np.ndarray,
    y: np.ndarray,
    where: str = "over the patch",
    within: tuple[float, float] | None = None,
) -> np.ndarray:
    """``function(x, y)`` of a user's field ``name`` at the points ``x``, ``y`` (arrays of one
    shape) as finite floats of that shape: one value per point, or one for all (``where``: the
    points in words, for the error), each ``within`` ``(lowest, highest)`` where given."""
    try:
        values = np.asarray(function(x, y), dtype=float)
        return_shape = np.broadcast_shapes(values.shape, np.shape(x))
    except InvalidArgumentError:  # (from a function of fixplan's that checks its own values)
        raise
    except (TypeError, ValueError, OverflowError) as exc:
        raise InvalidArgumentError(
            f"{name}(x, y) must return real numbers, one per point of the arrays x and y of shape "
            f"{np.shape(x)} (or one for all): {exc}"
        ) from exc
    if return_shape != np.shape(x):
        raise InvalidArgumentError(
            f"{name}(x, y) returned shape {values.shape} for points of shape {np.shape(x)}"
        )
    values = np.broadcast_to(values, np.shape(x))
    if not np.all(np.isfinite(values)):
        raise InvalidArgumentError(f"{name}(x, y) must be finite {where}")
    if within is not None and (np.any(values < within[0]) or np.any(values > within[1])):
        raise InvalidArgumentError(
            f"{name}(x, y) must be from {within[0]:g} to {within[1]:g} {where}"
        )
    return values


def coordinates(name: str, values: np.ndarray) -> np.ndarray:
    """``values`` [m], checked within ``MAX_LENGTH`` of the origin (areas, moments and
    speeds of farther ones overflow)."""
    largest = float(np.max(np.abs(values), initial=0.0))
    if largest > MAX_LENGTH:
        raise GeometryError(
            f"{name} must lie within {MAX_LENGTH:g} m of the origin, got {largest!r}"
        )
    return values
