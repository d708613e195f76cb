"""One contract suite over every friction model of fixplan.models (issue §1 and §4).

Each law is checked for every model class on four contacts: a Hertz disk (axisymmetric), a
10:1 rectangle (flattened surface), three unequally loaded points (facets, and a tilted axis
because the load at maximum moment has a force component) and the same points in a frame whose
origin is not their centre of pressure (area models only: a point contact sits at its centre
of pressure).
"""

import dataclasses
from functools import cache

import cvxpy as cp
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from fixplan import LimitSurface, pressure
from fixplan.errors import InvalidArgumentError, ModelError
from fixplan.models import (
    MODEL_CLASSES,
    Cone,
    Ellipsoid,
    Exact,
    FacetedEllipsoid,
    FittedEllipsoid,
    FrictionModel,
    PointCone,
    PointPyramid,
    Polytope,
    Pyramid,
)
from fixplan.models.compare import compare
from fixplan.tolerances import UNSAFE_RTOL

MU = 0.4
NORMAL_FORCE = 5.0

SKEWED_XY, SKEWED_WEIGHTS = [[0.0, 0.0], [0.04, 0.0], [0.0, 0.02]], [1, 2, 3]

FIELDS = {
    "hertz-disk": lambda: pressure.disk(0.01, "hertz"),
    "rectangle-10to1": lambda: pressure.rectangle(0.1, 0.01),
    "three-points": lambda: pressure.points(SKEWED_XY, SKEWED_WEIGHTS),
    "off-centre-points": lambda: pressure.points(SKEWED_XY, SKEWED_WEIGHTS, centered=False),
}

FACTORIES = {
    "ellipsoid": Ellipsoid.from_limit_surface,
    "fitted-ellipsoid": lambda ls: FittedEllipsoid.from_limit_surface(ls, samples=300),
    "faceted-ellipsoid": lambda ls: FacetedEllipsoid.from_limit_surface(
        ls, points=_facet_points(ls)
    ),
    "cone": Cone.from_limit_surface,
    "pyramid-4-inscribed": Pyramid.from_limit_surface,
    "pyramid-6-circumscribed": lambda ls: Pyramid.from_limit_surface(ls, facets=6, inscribed=False),
    "point-cone": PointCone.from_limit_surface,
    "point-pyramid-4-inscribed": PointPyramid.from_limit_surface,
    "point-pyramid-8-circumscribed": lambda ls: PointPyramid.from_limit_surface(
        ls, facets=8, inscribed=False
    ),
    "exact": Exact.from_limit_surface,
    "polytope-64-inscribed": lambda ls: Polytope.from_limit_surface(ls, cuts=64),
    "polytope-64-outside": lambda ls: Polytope.from_limit_surface(ls, cuts=64, inscribed=False),
}

POINT_MODELS = ("point-cone", "point-pyramid-4-inscribed", "point-pyramid-8-circumscribed")

CASES = [
    (m, f) for m in FACTORIES for f in FIELDS if not (m in POINT_MODELS and f.startswith("off"))
]

#: A load component in units of the largest force or moment, on a grid of 1e-3.
COMPONENT = st.integers(-1000, 1000).map(lambda k: k / 1000)


def _facet_points(ls):
    """The support points of a discrete field, or two points standing for a patch's ends."""
    if ls.field.is_discrete:
        return None
    radius = ls.field.radius
    return [[-0.8 * radius, 0.0], [0.8 * radius, 0.0]]


@cache
def surface(field_name: str, mu: float = MU) -> LimitSurface:
    return LimitSurface(FIELDS[field_name](), mu=mu, normal_force=NORMAL_FORCE)


@cache
def model(model_name: str, field_name: str, mu: float = MU) -> FrictionModel:
    return FACTORIES[model_name](surface(field_name, mu))


def loads_for(m: FrictionModel, count: int, seed: int = 0) -> np.ndarray:
    """Random loads around the size of the model's set (moment 0 for point models)."""
    rng = np.random.default_rng(seed)
    units = np.array([m.max_force, m.max_force, m.max_moment])
    loads = rng.normal(size=(count, 3)) * units
    if not m.torsion:
        loads[:, 2] = 0.0
    return loads


def test_every_model_class_is_in_the_suite():
    built = {type(model(name, "hertz-disk")) for name in FACTORIES}
    assert built == set(MODEL_CLASSES)


@pytest.mark.parametrize(("name", "field"), CASES)
def test_model_is_an_immutable_value_with_a_readable_repr(name, field):
    m = model(name, field)
    text = repr(m)
    assert text.startswith(type(m).__name__ + "(") and "\n" not in text and len(text) < 200
    first = dataclasses.fields(m)[0].name
    with pytest.raises(dataclasses.FrozenInstanceError):
        setattr(m, first, getattr(m, first))


@pytest.mark.parametrize(("name", "field"), CASES)
def test_safety_factor_of_the_load_scaled_onto_the_boundary_is_one(name, field):
    m = model(name, field)
    loads = loads_for(m, 64)
    safety = m.safety_factor(loads)
    assert np.all(np.isfinite(safety) & (safety > 0.0))
    np.testing.assert_allclose(m.safety_factor(loads * safety[:, None]), 1.0, rtol=1e-9)
    assert np.all(m.contains(loads * (0.999 * safety)[:, None]))
    assert not np.any(m.contains(loads * (1.001 * safety)[:, None]))
    assert m.safety_factor(np.zeros(3)) == np.inf and m.contains(np.zeros(3))


@pytest.mark.parametrize(("name", "field"), CASES)
def test_single_loads_give_scalars_and_batches_give_arrays(name, field):
    m = model(name, field)
    loads = loads_for(m, 3)
    assert isinstance(m.safety_factor(loads[0]), float)
    assert isinstance(m.contains(loads[0]), bool)
    batch = m.safety_factor(loads)
    assert batch.shape == (3,)
    assert batch[1] == pytest.approx(m.safety_factor(loads[1]), rel=1e-12)


@pytest.mark.parametrize(("name", "field"), CASES)
def test_gauge_terms_give_the_safety_factor_of_every_load(name, field):
    """The stacked form the planner checks loads with (norms and maxima of linear maps of the
    load) is the model's own gauge, to 1e-12; only models whose gauge has no such form opt out."""
    m = model(name, field)
    terms = m.gauge_terms()
    if terms is None:
        assert isinstance(m, (Exact, FacetedEllipsoid))
        return
    loads = loads_for(m, 200)[:, : m.load_dimension]
    gauge = np.zeros(len(loads))
    for kind, matrix in terms:
        values = loads @ matrix.T
        gauge += np.linalg.norm(values, axis=1) if kind == "norm" else values.max(axis=1)
    expected = 1.0 / m.safety_factor(loads, normal_force=1.0)
    np.testing.assert_allclose(gauge, expected, rtol=1e-12)
    assert model(name, field, mu=0.0).gauge_terms() is None  # frictionless: asked directly


@pytest.mark.parametrize(("name", "field"), CASES)
def test_model_is_centrally_symmetric(name, field):
    m = model(name, field)
    loads = loads_for(m, 64, seed=1)
    np.testing.assert_allclose(m.safety_factor(-loads), m.safety_factor(loads), rtol=1e-9)


@pytest.mark.parametrize(("name", "field"), CASES)
@settings(max_examples=20, deadline=None)
@given(a=st.lists(COMPONENT, min_size=3, max_size=3), b=st.lists(COMPONENT, min_size=3, max_size=3))
def test_model_is_convex(name, field, a, b):
    # A set given by a positively homogeneous gauge is convex iff the gauge is subadditive.
    m = model(name, field)
    units = np.array([m.max_force, m.max_force, m.max_moment])
    pair = np.array([a, b]) * units
    if not m.torsion:
        pair[:, 2] = 0.0

    def gauge(loads):
        return 1.0 / np.asarray(m.safety_factor(loads))

    total = gauge(pair.sum(axis=0)[None, :])[0]
    assert total <= gauge(pair).sum() * (1.0 + 1e-9) + 1e-12


@pytest.mark.parametrize(("name", "field"), CASES)
@settings(max_examples=8, deadline=None)
@given(scale=st.floats(0.05, 20.0))
def test_model_scales_with_the_normal_force(name, field, scale):
    m = model(name, field)
    loads = loads_for(m, 16, seed=2)
    reference = m.safety_factor(loads)
    np.testing.assert_allclose(
        m.safety_factor(scale * loads, normal_force=scale * m.normal_force), reference, rtol=1e-9
    )
    np.testing.assert_allclose(
        m.safety_factor(loads, normal_force=scale * m.normal_force), scale * reference, rtol=1e-9
    )


@pytest.mark.parametrize(("name", "field"), CASES)
def test_model_scales_with_mu(name, field):
    base, doubled = model(name, field), model(name, field, mu=2 * MU)
    loads = loads_for(base, 16, seed=3)
    np.testing.assert_allclose(doubled.safety_factor(2 * loads), base.safety_factor(loads), 1e-9)


@pytest.mark.parametrize(
    ("name", "field"), [c for c in CASES if model(c[0], "hertz-disk").conservative]
)
def test_conservative_models_lie_inside_the_exact_surface(name, field):
    accuracy = compare(model(name, field), surface(field), n=400)
    assert accuracy.max_overestimate <= UNSAFE_RTOL
    assert accuracy.unsafe_fraction == 0.0


@pytest.mark.parametrize("name", [n for n in FACTORIES if not model(n, "hertz-disk").conservative])
def test_models_not_flagged_conservative_do_overestimate_somewhere(name):
    worst = max(
        compare(model(name, f), surface(f), n=400).max_overestimate
        for f in FIELDS
        if (name, f) in CASES
    )
    assert worst > UNSAFE_RTOL


def _feasibility_problem(m: FrictionModel):
    dim = m.load_dimension
    load = cp.Variable(dim)
    target = cp.Parameter(dim)
    force = cp.Parameter(nonneg=True)
    problem = cp.Problem(cp.Minimize(0), [*m.constraints(load, force), load == target])
    return problem, target, force


@pytest.mark.parametrize(("name", "field"), CASES)
def test_constraints_are_convex_dpp_and_agree_with_contains(name, field):
    # Models whose constraints overestimate their set (the exact model's seed polytope) are
    # probed beyond their constraint_error.
    m = model(name, field)
    problem, target, force = _feasibility_problem(m)
    assert problem.is_dcp(dpp=True)
    loads = loads_for(m, 4, seed=4)
    safety = m.safety_factor(loads)
    for load, s in zip(loads, safety, strict=True):
        for factor in (0.97, 1.03 * (1.0 + m.constraint_error)):
            probe = load * s * factor
            target.value = probe[: m.load_dimension]
            force.value = m.normal_force
            problem.solve(solver=cp.CLARABEL)
            feasible = problem.status == cp.OPTIMAL
            assert problem.status in (cp.OPTIMAL, cp.INFEASIBLE)
            assert feasible == bool(m.contains(probe)) == (factor < 1.0)


@pytest.mark.parametrize(("name", "field"), CASES)
def test_smallest_normal_force_in_the_constraints_matches_the_safety_factor(name, field):
    # Homogeneity in the normal force: with fn a variable, the least fn that holds L is
    # N / s(L, N) (down to that over 1 + constraint_error for an outer polytope).
    m = model(name, field)
    load = cp.Parameter(m.load_dimension)
    fn = cp.Variable(nonneg=True)
    problem = cp.Problem(cp.Minimize(fn), m.constraints(load, fn))
    assert problem.is_dcp(dpp=True)
    for probe in loads_for(m, 3, seed=5):
        load.value = probe[: m.load_dimension]
        problem.solve(solver=cp.CLARABEL)
        expected = m.normal_force / m.safety_factor(probe)
        low = expected / (1.0 + m.constraint_error)
        assert low * (1.0 - 1e-6) <= fn.value <= expected * (1.0 + 1e-6)


@pytest.mark.parametrize(("name", "field"), CASES)
def test_motion_follows_normality_or_is_refused(name, field):
    m = model(name, field)
    loads = loads_for(m, 32, seed=6)
    if not m.has_motion:
        with pytest.raises(ModelError, match="no motion map"):
            m.motion(loads[0])
        return
    twists = m.motion(loads)
    # Unit twist about the centre of pressure c: (vx - cy w, vy + cx w, rho w).
    (cx, cy), rho = m.center, (m.rho if m.torsion else 0.0)
    about_center = twists + np.column_stack(
        [-cy * twists[:, 2], cx * twists[:, 2], (rho - 1.0) * twists[:, 2]]
    )
    np.testing.assert_allclose(np.linalg.norm(about_center, axis=1), 1.0, rtol=1e-12)
    # Maximum power: the twist at a boundary load L makes V·L the largest over the set.
    boundary = loads * m.safety_factor(loads)[:, None]
    others = loads_for(m, 400, seed=7)
    others *= m.safety_factor(others)[:, None]
    power = np.einsum("ij,ij->i", twists, boundary)
    best = (others @ twists.T).max(axis=0)
    assert np.all(best <= power + 1e-7 * np.abs(power))
    assert np.all(np.isnan(m.motion(np.zeros(3))))


@pytest.mark.parametrize(("name", "field"), CASES)
def test_constraints_reject_loads_of_the_wrong_shape(name, field):
    m = model(name, field)
    with pytest.raises(InvalidArgumentError, match="load must have shape"):
        m.constraints(cp.Variable(4), 1.0)
    with pytest.raises(InvalidArgumentError, match="normal_force must be a scalar"):
        m.constraints(cp.Variable(m.load_dimension), cp.Variable(2))


@pytest.mark.parametrize("field", list(FIELDS))
@pytest.mark.parametrize("facets", [3, 4, 8])
def test_inner_pyramid_lies_inside_cone_inside_outer_pyramid(field, facets):
    ls = surface(field)
    inner = Pyramid.from_limit_surface(ls, facets=facets)
    cone = Cone.from_limit_surface(ls)
    outer = Pyramid.from_limit_surface(ls, facets=facets, inscribed=False)
    loads = loads_for(cone, 2000, seed=8)
    s_inner, s_cone, s_outer = (m.safety_factor(loads) for m in (inner, cone, outer))
    assert np.all(s_inner <= s_cone * (1 + 1e-12))
    assert np.all(s_cone <= s_outer * (1 + 1e-12))
    points = [
        PointPyramid(mu=cone.mu, facets=facets),
        PointCone(mu=cone.mu),
        PointPyramid(mu=cone.mu, facets=facets, inscribed=False),
    ]
    forces = loads[:, :2]
    s_point = [p.safety_factor(forces) for p in points]
    assert np.all(s_point[0] <= s_point[1] * (1 + 1e-12))
    assert np.all(s_point[1] <= s_point[2] * (1 + 1e-12))


# -- frictionless contacts (mu = 0) ---------------------------------------------------------------


@pytest.mark.parametrize(("name", "field"), CASES)
def test_a_frictionless_model_holds_the_zero_load_and_nothing_else(name, field):
    m = model(name, field, mu=0.0)
    loads = loads_for(model(name, field), 16, seed=9)
    assert m.frictionless and m.mu == 0.0
    assert m.max_force == 0.0 and m.max_moment == 0.0
    assert np.all(m.safety_factor(loads) == 0.0) and not np.any(m.contains(loads))
    assert m.safety_factor(np.zeros(3)) == np.inf and m.contains(np.zeros(3))
    assert m.conservative == model(name, field).conservative
    plane = "fx-m" if m.torsion else "fx-fy"
    assert np.all(m.curve(plane, 12) == 0.0)
    assert np.all(m.curve(plane, 12, normalized=True) == 0.0)


@pytest.mark.parametrize(("name", "field"), CASES)
def test_a_frictionless_model_has_the_shape_of_the_same_model_with_mu_one(name, field):
    frictionless, unit = model(name, field, mu=0.0), model(name, field, mu=1.0)
    assert frictionless.rho == pytest.approx(unit.rho, rel=1e-12)
    assert frictionless.center == pytest.approx(unit.center, abs=1e-15)
    assert frictionless.friction_shape.mu == pytest.approx(unit.mu, rel=1e-12)
    loads = loads_for(unit, 16, seed=10)
    np.testing.assert_allclose(
        frictionless.friction_shape.safety_factor(loads), unit.safety_factor(loads), rtol=1e-9
    )


@pytest.mark.parametrize(("name", "field"), CASES)
def test_the_motion_of_a_frictionless_model_is_the_limit_of_vanishing_friction(name, field):
    frictionless = model(name, field, mu=0.0)
    loads = loads_for(model(name, field), 16, seed=11)
    if not frictionless.has_motion:
        with pytest.raises(ModelError, match="no motion map"):
            frictionless.motion(loads[0])
        return
    twists = frictionless.motion(loads)
    for mu in (1.0, 1e-3):
        np.testing.assert_allclose(twists, model(name, field, mu=mu).motion(loads), atol=1e-9)
    assert np.all(np.isnan(frictionless.motion(np.zeros(3))))


@pytest.mark.parametrize(("name", "field"), CASES)
def test_the_constraints_of_a_frictionless_model_force_the_load_to_zero(name, field):
    m = model(name, field, mu=0.0)
    load = cp.Variable(m.load_dimension)
    target = cp.Parameter(m.load_dimension)
    force = cp.Parameter(nonneg=True)
    nearest = cp.Problem(cp.Minimize(cp.sum_squares(load - target)), m.constraints(load, force))
    assert nearest.is_dcp(dpp=True)
    target.value, force.value = np.array([3.0, -2.0, 0.05])[: m.load_dimension], 10.0
    nearest.solve(solver=cp.CLARABEL)
    assert nearest.status == cp.OPTIMAL
    np.testing.assert_allclose(load.value, 0.0, atol=1e-9)
    # Homogeneous in the normal force: no normal force, however large, holds a nonzero load.
    fn = cp.Variable(nonneg=True)
    least = cp.Problem(cp.Minimize(fn), [*m.constraints(load, fn), load == target])
    least.solve(solver=cp.CLARABEL)
    assert least.status == cp.INFEASIBLE
