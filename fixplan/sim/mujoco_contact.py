r"""A planner contact as MuJoCo contact parameters (``condim`` and ``friction`` of a ``<pair>``).

MuJoCo's elliptic friction cone with ``condim="4"`` is the paper's ellipsoid (Table 2) without
tilt, about the contact point:

.. math:: \frac{f_{t1}^2}{\mu^2} + \frac{f_{t2}^2}{\mu^2} + \frac{m_n^2}{\mu_3^2} \le f_n^2,

with the torsional coefficient ``μ3`` a length [m]. fixplan derives it from the contact's patch
and pressure instead of a guess: ``μ3`` is the largest friction moment about the centre of
pressure over the normal force, ``μ ρ`` of the exact limit surface (``2 μ R / 3`` for a uniform
disk of radius ``R``, ``3π μ R / 16`` for a Hertz disk, Table 1). Point contacts become
``condim="3"`` (Coulomb's cone), frictionless ones ``condim="1"``.

What MuJoCo's cone cannot express is listed per contact (:attr:`MujocoContact.lost`): the tilt of
an asymmetric pressure's ellipsoid, the facets of point supports and the non-ellipsoidal shape of
every exact limit surface; :attr:`MujocoContact.error` measures that cone against the exact limit
surface of the patch (:func:`fixplan.models.compare.compare`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from fixplan.errors import InvalidArgumentError
from fixplan.models import Ellipsoid
from fixplan.models.compare import Accuracy, compare
from fixplan.planner.problem import Contact
from fixplan.surface.limit_surface import LimitSurface

#: Load directions of the error measure of an area contact's cone.
ERROR_DIRECTIONS = 2000


@dataclass(frozen=True, slots=True, kw_only=True)
class MujocoContact:
    """MuJoCo parameters of one contact.

    Attributes
    ----------
    condim : int
        1 (frictionless), 3 (point: sliding friction) or 4 (area: sliding and torsional).
    mu : float
        Sliding friction coefficient [-].
    torsion : float
        Torsional coefficient ``μ3`` [m]: largest friction moment about the centre of pressure
        over the normal force (0 for point contacts).
    center : tuple of float
        The centre of pressure in the patch frame [m], where MuJoCo's contact point belongs.
    lost : tuple of str
        What MuJoCo's cone does not represent of this contact.
    error : Accuracy or None
        MuJoCo's cone against the exact limit surface of the patch (area contacts).
    """

    condim: int
    mu: float
    torsion: float
    center: tuple[float, float]
    lost: tuple[str, ...]
    error: Accuracy | None

    @property
    def friction(self) -> tuple[float, float, float, float, float]:
        """The five ``friction`` values of a ``<pair>``: two tangential, torsional, two rolling."""
        return (self.mu, self.mu, self.torsion, 0.0, 0.0)

    def attributes(self) -> dict[str, str]:
        """``condim`` and ``friction`` as MJCF attribute strings of a ``<pair>``."""
        return {
            "condim": str(self.condim),
            "friction": " ".join(f"{value:.9g}" for value in self.friction),
        }


def mujoco_contact(contact: Contact) -> MujocoContact:
    """The MuJoCo parameters of a planner ``contact`` (see the module docstring)."""
    if not isinstance(contact, Contact):
        raise InvalidArgumentError(f"contact must be a Contact, got {type(contact).__name__}")
    if contact.mu == 0.0:
        return MujocoContact(condim=1, mu=0.0, torsion=0.0, center=(0.0, 0.0), lost=(), error=None)
    if contact.patch is None or not contact.has_torsion:
        lost = ()
        if contact.model == "point-pyramid":
            lost = ("the facets of the point pyramid: MuJoCo's elliptic cone is Coulomb's circle",)
        return MujocoContact(condim=3, mu=contact.mu, torsion=0.0, center=(0.0, 0.0), lost=lost,
                             error=None)  # fmt: skip
    surface = LimitSurface(contact.patch, mu=contact.mu, normal_force=1.0)
    tilted = Ellipsoid.from_limit_surface(surface)
    cone = Ellipsoid(mu=tilted.mu, rho=tilted.rho, center=tilted.center, normal_force=1.0)
    lost = ["the shape of the exact limit surface (MuJoCo's cone is an ellipsoid)"]
    if np.any(tilted.tilt):
        lost.append(
            "the tilt of the ellipsoid of an asymmetric pressure "
            f"(force at the largest moment {tuple(round(t, 6) for t in tilted.tilt)} × mu N)"
        )
    if surface.field.is_discrete:
        lost.append("the facets of the point supports' limit surface")
    if contact.model not in ("ellipsoid", "exact"):
        lost.append(f"the planner's {contact.model!r} model: MuJoCo's cone is the ellipsoid")
    return MujocoContact(
        condim=4,
        mu=contact.mu,
        torsion=tilted.mu * tilted.rho,
        center=tuple(float(c) for c in tilted.center),
        lost=tuple(lost),
        error=compare(cone, surface, n=ERROR_DIRECTIONS),
    )
