"""The friction model of each planner contact, at unit normal force.

Area models are built from the exact limit surface of the contact's patch (its pressure shape
and ``mu``), so the torsional friction comes from the patch, never from a guessed coefficient.
"""

from __future__ import annotations

import pickle
from collections.abc import Sequence

from fixplan.models import Cone, Ellipsoid, Exact, PointCone, PointPyramid, Pyramid
from fixplan.models.base import FrictionModel
from fixplan.planner.problem import DEFAULT_FACETS, DEFAULT_INSCRIBED, Contact
from fixplan.surface.limit_surface import LimitSurface


def contact_model(contact: Contact) -> FrictionModel:
    """The friction model of ``contact`` for unit normal force."""
    model = contact.model
    if not isinstance(model, str):
        return model
    facets = DEFAULT_FACETS if contact.facets is None else int(contact.facets)
    inscribed = DEFAULT_INSCRIBED if contact.inscribed is None else bool(contact.inscribed)
    if model == "point-cone":
        return PointCone(mu=contact.mu)
    if model == "point-pyramid":
        return PointPyramid(mu=contact.mu, facets=facets, inscribed=inscribed)
    surface = LimitSurface(contact.patch, mu=contact.mu, normal_force=1.0)
    if model == "ellipsoid":
        return Ellipsoid.from_limit_surface(surface)
    if model == "cone":
        return Cone.from_limit_surface(surface)
    if model == "pyramid":
        return Pyramid.from_limit_surface(surface, facets=facets, inscribed=inscribed)
    return Exact.from_limit_surface(surface)


def contact_models(contacts: Sequence[Contact]) -> list[FrictionModel]:
    """The friction model of each of ``contacts`` for unit normal force; contacts that ask for
    the same model of equal patches with the same ``mu`` share one model object (its surface is
    built once, and the exact rounds query the loads of such contacts together)."""
    built: dict = {}
    models = []
    for contact in contacts:
        key = _model_key(contact)
        if key is None:
            models.append(contact_model(contact))
            continue
        if key not in built:
            built[key] = contact_model(contact)
        models.append(built[key])
    return models


def _model_key(contact: Contact) -> tuple | None:
    """What decides a contact's named model: the name, ``mu``, the pyramid's settings and the
    patch (its pickled fields: equal patches give equal bytes); ``None`` for a model object or
    a patch that does not pickle."""
    if not isinstance(contact.model, str):
        return None
    try:
        patch = pickle.dumps(contact.patch, protocol=pickle.HIGHEST_PROTOCOL)
    except (pickle.PicklingError, AttributeError, TypeError):
        return None
    return (contact.model, float(contact.mu), contact.facets, contact.inscribed, patch)
