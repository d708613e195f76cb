"""An exact contact in a small convex program of its own: an ellipsoid that osculates its set.

A program with exact friction models (a contact-set query, a step of the compliant analysis)
states each exact contact's set by the ellipsoid that osculates it (same point, tangent plane and
curvature; :meth:`~fixplan.models.Exact.osculating`) where the ray of the contact's load meets
it, and is solved again after moving each ellipsoid where the load asks
(:meth:`OsculatingContact.follow`), until every exact contact's load is inside its exact set and,
where its ellipsoid holds it back, on the exact surface with the ellipsoid's normal there the
exact surface's: there the program meets the exact problem's optimality conditions, and its
multipliers are the exact problem's. This is
the planner's sequential convex programming with exact second-order models
(:mod:`fixplan.planner.osculating`) for one contact at a time. The ellipsoids are not outer
approximations, so only the settled program is the exact one. Sets with facets (point supports)
have no osculating ellipsoid there.
"""

from __future__ import annotations

import numpy as np

from fixplan.errors import ConvergenceError
from fixplan.models import Exact
from fixplan.tolerances import EXACT_CUT_RTOL

#: Most solves of one program while its exact contacts' ellipsoids move.
MAX_OSCULATING_ROUNDS = 30

#: A round that brings a load less than this factor closer to its exact set has stalled.
STALL_RATIO = 0.1

#: A load counts as on its ellipsoid within this fraction of it.
ACTIVE_RTOL = 1e-7

#: A load held back by its ellipsoid on the exact surface has settled where the two normals
#: there agree to this (unit normals in normalised coordinates: loads over the surface's
#: extents). Tighter than the planner's 1e-6: the compliant analysis feeds its steps to a fixed
#: point held to 1e-6 of the forces (on fixture-321-compliant.toml with exact clamp pads, 1e-6
#: left two collapses unbracketed, 1e-8 one, before each load case started afresh).
NORMAL_RTOL = 1e-8


def osculates(model) -> bool:
    """Whether ``model`` is stated by an :class:`OsculatingContact`: an exact model with
    friction and no facets (at a point support no ellipsoid osculates its set)."""
    return isinstance(model, Exact) and not model.frictionless and not model.surface.has_facets


class OsculatingContact:
    """An exact contact's friction set in a small cvxpy program of its own: the ellipsoid
    ``‖R ℓ‖ <= g`` (``R`` a Parameter, per unit normal force; first the axis ellipsoid) that
    osculates its exact set, moved by :meth:`follow` after each solve."""

    def __init__(self, model: Exact):
        import cvxpy as cp

        self.model = model
        self._units = model._units()
        self.factor = cp.Parameter((3, 3))
        self._excess: float | None = None  # (of the last load followed since start())
        self.reset()

    def reset(self) -> None:
        """Back to the axis ellipsoid, through the surface's axis points."""
        self.factor.value = np.diag(1.0 / self._units)

    def start(self) -> None:
        """A new program's rounds begin (the ellipsoid stays where it is)."""
        self._excess = None

    def constraint(self, load, bound):
        """The ellipsoid on the friction ``load`` (3 entries) at the normal force ``bound``."""
        import cvxpy as cp

        return cp.norm(self.factor @ load) <= bound

    def safety_factor(self, load: np.ndarray, normal_force: float) -> float:
        """The safety factor of ``load`` in the ellipsoid at ``normal_force`` [N]."""
        size = np.linalg.norm(self.factor.value @ load)
        return normal_force / size if size > 0.0 else np.inf

    def follow(self, load: np.ndarray, bound: float, twist: np.ndarray | None = None) -> bool:
        """Move the ellipsoid where the program's friction ``load`` ``(3,)`` [N, N, N m] at the
        normal force ``bound`` [N] asks: to osculate the exact set at the load's ray where the
        load lies outside the set, or is held back by the ellipsoid off the exact surface or
        where the two normals differ (:data:`NORMAL_RTOL`); where
        the last round brought the load less than ``STALL_RATIO`` closer to the set and the
        program gives the contact's ``twist`` in its impending motion, at the point whose
        normal that twist is (:meth:`~fixplan.models.Exact.osculating_at`: where several
        contacts share a load, the rounds move it between them more than they move the
        motion). Returns whether it moved; raises :class:`~fixplan.errors.ConvergenceError`
        where the set has no curvature there."""
        if bound <= 0.0 or not np.any(load):
            return False
        per_unit = load / bound
        gauge = float(np.linalg.norm(self.factor.value @ per_unit))  # (1 on the ellipsoid)
        excess, _, factors = self.model.osculating(per_unit[None, :])
        if excess[0] <= EXACT_CUT_RTOL and (
            gauge < 1.0 - ACTIVE_RTOL  # (inside both: the ellipsoid does not hold it back)
            or (
                abs(excess[0] - (gauge - 1.0)) <= EXACT_CUT_RTOL  # (where the two meet)
                and self._normal_agrees(per_unit, factors[0])
            )
        ):
            return False
        last, self._excess = self._excess, abs(float(excess[0]))
        stalled = last is not None and self._excess > STALL_RATIO * last
        if stalled and twist is not None and np.any(twist):
            outward = twist if twist @ per_unit >= 0.0 else -twist
            _, factors = self.model.osculating_at(outward[None, :])
        if not np.all(np.isfinite(factors)):
            raise ConvergenceError("an exact contact's set has no curvature at its load")
        self.factor.value = factors[0]
        return True

    def _normal_agrees(self, per_unit: np.ndarray, exact_factor: np.ndarray) -> bool:
        """Whether the ellipsoid's normal at the load ``per_unit`` (on the exact surface) is
        the exact surface's there, the normal of ``exact_factor``'s ellipsoid (which osculates
        it at the load's ray), to ``NORMAL_RTOL`` in normalised coordinates."""
        if not np.all(np.isfinite(exact_factor)):
            return False
        mine = self.factor.value.T @ (self.factor.value @ per_unit) * self._units
        exact = exact_factor.T @ (exact_factor @ per_unit) * self._units
        mine, exact = mine / np.linalg.norm(mine), exact / np.linalg.norm(exact)
        return float(np.linalg.norm(mine - exact)) <= NORMAL_RTOL
