"""The stacked friction-use check of the planner against each model's own safety factor."""

import itertools

import numpy as np

from fixplan import LimitSurface, pressure
from fixplan.models import Cone, Ellipsoid, Exact, PointCone, PointPyramid, Polytope, Pyramid
from fixplan.planner.friction_use import FrictionUse

NOISE = 1e-9


def _models():
    disk = LimitSurface(pressure.disk(0.01, "hertz"), mu=0.5)
    skewed = LimitSurface(pressure.points([[0, 0], [0.04, 0], [0, 0.02]], [1, 2, 3]), mu=0.3)
    return [
        Ellipsoid.from_limit_surface(skewed),
        Cone.from_limit_surface(skewed),
        Pyramid.from_limit_surface(disk, facets=6, inscribed=False),
        PointCone(mu=0.7),
        PointPyramid(mu=0.4, facets=8),
        Polytope.from_limit_surface(skewed, cuts=32),
        Exact.from_limit_surface(disk),  # asked one by one
        Ellipsoid(mu=0.0, rho=0.01),  # frictionless
    ]


def _reference(models, slices, friction, normal):
    """Use per contact and case, straight from the definition."""
    use = np.zeros(normal.shape)
    for i, (model, part) in enumerate(zip(models, slices, strict=True)):
        for j in range(normal.shape[1]):
            load, fn = friction[part, j], normal[i, j]
            if np.abs(load).max() <= NOISE:
                continue
            if fn <= NOISE:
                use[i, j] = np.inf
                continue
            safety = model.safety_factor(load / fn, normal_force=1.0)
            use[i, j] = np.inf if safety == 0.0 else 1.0 / safety
    return use


def test_the_stacked_use_is_each_models_own_use_for_every_contact_and_case():
    models = _models()
    dims = np.cumsum([0] + [m.load_dimension for m in models])
    slices = [slice(a, b) for a, b in itertools.pairwise(dims)]
    rng = np.random.default_rng(3)
    cases = 40
    friction = rng.normal(size=(dims[-1], cases)) * 0.3
    friction[:, :3] *= 1e-12  # loads at solver noise
    normal = rng.uniform(0.1, 2.0, size=(len(models), cases))
    normal[:, 3:6] = 0.0  # friction without normal force
    expected = _reference(models, slices, friction, normal)
    got = FrictionUse(models, slices)(friction, normal, noise=NOISE)
    assert np.array_equal(np.isinf(got), np.isinf(expected))
    finite = np.isfinite(expected)
    np.testing.assert_allclose(got[finite], expected[finite], rtol=1e-12, atol=1e-15)
    assert np.isinf(got[-1, 6:]).all()  # the frictionless contact cannot carry a load


def test_known_uses_replace_the_one_by_one_queries_where_given():
    """The uses the cutting rounds computed are taken as they are; NaN entries are asked."""
    models = _models()
    dims = np.cumsum([0] + [m.load_dimension for m in models])
    slices = [slice(a, b) for a, b in itertools.pairwise(dims)]
    rng = np.random.default_rng(4)
    friction = rng.normal(size=(dims[-1], 6)) * 0.3
    normal = rng.uniform(0.5, 2.0, size=(len(models), 6))
    exact = 6  # the Exact model of _models(), asked one by one
    known = np.full(normal.shape, np.nan)
    known[exact, :3] = 0.25  # a value no query of these loads gives
    use = FrictionUse(models, slices)
    got = use(friction, normal, noise=NOISE, known=known)
    asked = use(friction, normal, noise=NOISE)
    np.testing.assert_array_equal(got[exact, :3], 0.25)
    np.testing.assert_array_equal(got[exact, 3:], asked[exact, 3:])
    mask = np.ones(len(models), dtype=bool)
    mask[exact] = False
    np.testing.assert_array_equal(got[mask], asked[mask])  # other contacts ignore it
