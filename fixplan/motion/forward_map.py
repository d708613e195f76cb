r"""The friction of a sliding twist: the forward map ``L(V) = ∇h(V)`` of any limit surface.

The exact :class:`~fixplan.LimitSurface` and a planar :class:`~fixplan.ContactSetSurface` have
it (``load`` and ``support``). Of the friction models, an ellipsoid ``H(L) = L^T A L <= N²``
(``A`` its :attr:`~fixplan.models.Ellipsoid.load_matrix`, ``N`` its normal force) has it in
closed form, its support function being that of the ellipsoid,

.. math:: h(V) = N \sqrt{V^T A^{-1} V}, \qquad \nabla h(V) = \frac{N A^{-1} V}{\sqrt{V^T A^{-1} V}},

and the :class:`~fixplan.models.Exact` model is its exact limit surface. Loads ``(fx, fy, m)`` [N, N, N m] and twists ``(vx, vy, w)`` are about the
surface's frame origin (docs/conventions.md).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from fixplan.errors import InvalidArgumentError
from fixplan.models.ellipsoid import Ellipsoid, FittedEllipsoid
from fixplan.models.exact import Exact


@dataclass(frozen=True, slots=True)
class ForwardMap:
    """A surface's support function and its gradient, the friction load of a sliding twist.

    Attributes
    ----------
    support : callable
        ``support(twist)`` -> ``h(V)`` [W per unit speed] for a twist ``(3,)``.
    load : callable
        ``load(twist)`` -> ``∇h(V)`` ``(fx, fy, m)`` [N, N, N m] for a nonzero twist ``(3,)``.
    safety_factor : callable
        ``safety_factor(load)`` -> the factor that puts a load ``(3,)`` on the surface.
    """

    support: Callable
    load: Callable
    safety_factor: Callable


def forward_map(surface) -> ForwardMap:
    """The forward map of ``surface`` (see the module docstring).

    Raises
    ------
    InvalidArgumentError
        For a frictionless surface (no friction resists sliding: no quasi-static motion either)
        or one without a forward map (cones, pyramids, faceted ellipsoids).
    """
    surface = exact_form(surface)
    if getattr(surface, "frictionless", False):
        raise InvalidArgumentError(
            f"{type(surface).__name__} is frictionless: give the support friction"
        )
    if isinstance(surface, Ellipsoid | FittedEllipsoid):
        return _ellipsoid(np.linalg.inv(surface.load_matrix), surface.normal_force,
                          surface.safety_factor)  # fmt: skip
    if all(hasattr(surface, name) for name in ("support", "load", "safety_factor")):
        return ForwardMap(support=surface.support, load=surface.load,
                          safety_factor=surface.safety_factor)  # fmt: skip
    raise InvalidArgumentError(
        f"{type(surface).__name__} has no forward map load(twist): use the exact LimitSurface, "
        "a ContactSetSurface, an Ellipsoid, a FittedEllipsoid or an Exact model"
    )


def exact_form(surface):
    """``surface``, or the exact :class:`~fixplan.LimitSurface` it equals where it is another
    kind that has one: the :class:`~fixplan.models.Exact` model's, or a
    :class:`~fixplan.ContactSetSurface` of point contacts and exact or ellipsoid patches on a plane
    (:meth:`~fixplan.ContactSetSurface.as_limit_surface`)."""
    if isinstance(surface, Exact):
        return surface.surface
    convert = getattr(surface, "as_limit_surface", None)
    found = None if convert is None else convert()
    return surface if found is None else found


def _ellipsoid(inverse: np.ndarray, normal_force: float, safety_factor: Callable) -> ForwardMap:
    """The closed forms of an ellipsoid with ``A^{-1} = inverse`` at ``normal_force`` [N]."""

    def support(twist) -> float:
        twist = np.asarray(twist, dtype=float)
        return normal_force * math.sqrt(max(float(twist @ inverse @ twist), 0.0))

    def load(twist) -> np.ndarray:
        twist = np.asarray(twist, dtype=float)
        stretched = inverse @ twist
        return normal_force * stretched / math.sqrt(float(twist @ stretched))

    return ForwardMap(support=support, load=load, safety_factor=safety_factor)
