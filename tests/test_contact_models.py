"""Contacts that ask for the same model of equal patches share one model object."""

from __future__ import annotations

import numpy as np

from fixplan import Contact, pressure
from fixplan.models import Ellipsoid
from fixplan.planner.contact_models import contact_model, contact_models


def pad(name, mu=0.4, model="exact", patch=None, **extra) -> Contact:
    patch = pressure.disk(0.01) if patch is None else patch
    return Contact(name=name, role="support", position=[0, 0, 0], normal=[0, 0, 1], mu=mu,
                   model=model, patch=patch, **extra)  # fmt: skip


def test_equal_patches_built_apart_share_one_model():
    """Equal patches made separately (as a problem file makes them) and the same ``mu``: one
    model; another ``mu``, patch or model name: another."""
    grid = [[1.0, 0.5], [0.2, 0.8]]
    contacts = [
        pad("a"),
        pad("b"),
        pad("c", mu=0.5),
        pad("d", patch=pressure.disk(0.012)),
        pad("e", model="ellipsoid"),
        pad("f", patch=pressure.grid([0.0, 0.01], [0.0, 0.01], grid)),
        pad("g", patch=pressure.grid([0.0, 0.01], [0.0, 0.01], grid)),
        pad("h", patch=pressure.grid([0.0, 0.01], [0.0, 0.02], grid)),
    ]
    models = contact_models(contacts)
    same = [[models[i] is models[j] for j in range(8)] for i in range(8)]
    expected = np.eye(8, dtype=bool)
    expected[0, 1] = expected[1, 0] = expected[5, 6] = expected[6, 5] = True
    np.testing.assert_array_equal(same, expected)
    for contact, model in zip(contacts, models, strict=True):  # each the model it asked for
        alone = contact_model(contact)
        assert type(model) is type(alone)
        load = np.array([0.1, -0.2, 0.001])
        assert model.safety_factor(load) == alone.safety_factor(load)


def test_model_objects_and_patches_that_do_not_pickle_are_not_shared():
    ellipsoid = Ellipsoid(mu=0.5, rho=0.004)
    weighted = pressure.from_function(pressure.disk(0.01), lambda x, y: 1.0 + 0.0 * x)
    contacts = [pad("a", mu=0.5, model=ellipsoid), pad("b", mu=0.5, model=ellipsoid),
                pad("c", patch=weighted), pad("d", patch=weighted)]  # fmt: skip
    models = contact_models(contacts)
    assert models[0] is ellipsoid and models[1] is ellipsoid  # (the user's own object)
    assert models[2] is not models[3]
