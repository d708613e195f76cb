"""The general polyhedral model (issue 11 §2) against closed forms: a box, tangent planes of a
sphere, a pyramid written as a polytope, and the planner's optimum with each.

The shared laws of every model (convexity, scaling, symmetry, constraints, motion by maximum
power) are checked by ``tests/test_models_contract.py``.
"""

import itertools
import math

import numpy as np
import pytest

from fixplan import LimitSurface, pressure
from fixplan.errors import InvalidArgumentError
from fixplan.models import Polytope, Pyramid
from fixplan.models.compare import compare
from fixplan.models.polytope import symmetric_directions
from fixplan.planner.planner import solve
from fixplan.planner.problem import Body, Contact, Load, Problem

MU, RHO = 0.5, 0.004
CENTER = (0.002, -0.001)
#: A box |fx|, |fy| <= mu N, |m - c × f| <= mu rho N.
BOX = Polytope(rows=np.eye(3), mu=MU, rho=RHO, center=CENTER)


def about_center(load):
    """``(fx, fy, m - c × f)`` of loads about the frame origin."""
    load = np.atleast_2d(load)
    cx, cy = CENTER
    return np.column_stack(
        [load[:, 0], load[:, 1], load[:, 2] - (cx * load[:, 1] - cy * load[:, 0])]
    )


def test_the_safety_factor_of_a_box_is_its_closed_form():
    rng = np.random.default_rng(0)
    loads = rng.normal(size=(50, 3)) * [MU, MU, MU * RHO]
    for force in (1.0, 7.0):
        moved = about_center(loads)
        expected = np.min(
            np.column_stack(
                [MU * force / np.abs(moved[:, :2]), MU * RHO * force / np.abs(moved[:, 2])]
            ),
            axis=1,
        )
        np.testing.assert_allclose(
            BOX.safety_factor(loads, normal_force=force), expected, rtol=1e-13
        )


def test_the_vertices_of_a_box_are_its_eight_corners():
    corners = np.array(list(itertools.product((-1.0, 1.0), repeat=3))) * [MU, MU, MU * RHO] * 3.0
    cx, cy = CENTER
    corners[:, 2] += cx * corners[:, 1] - cy * corners[:, 0]  # moments about the origin
    vertices = BOX.vertices(normal_force=3.0)
    found = {tuple(np.round(v, 12)) for v in vertices}
    assert found == {tuple(np.round(c, 12)) for c in corners}


def test_a_box_slides_along_the_normal_of_the_facet_its_load_leaves_through():
    load = np.array([0.9 * MU, 0.2 * MU, 0.1 * MU * RHO])
    load[2] += CENTER[0] * load[1] - CENTER[1] * load[0]
    # Facet fx = mu N: twist about the centre (1, 0, 0), a pure translation along x.
    np.testing.assert_allclose(BOX.motion(load), [1.0, 0.0, 0.0], atol=1e-15)
    np.testing.assert_allclose(BOX.motion(-load), [-1.0, 0.0, 0.0], atol=1e-15)


def test_the_inequalities_of_a_box_bound_each_component():
    matrix, bound = BOX.inequalities(normal_force=2.0)
    loads = np.random.default_rng(1).normal(size=(200, 3)) * [MU, MU, MU * RHO]
    inside = np.all(loads @ matrix.T <= bound, axis=1)
    np.testing.assert_array_equal(inside, np.asarray(BOX.contains(loads, normal_force=2.0)))
    frictionless = Polytope(rows=np.eye(3), mu=0.0, rho=RHO)
    assert np.all(frictionless.inequalities()[1] == 0.0)


@pytest.mark.parametrize(
    "normals",
    [np.eye(3), np.array([[1.0, 1.0, 1.0], [1.0, -1.0, 1.0], [1.0, 1.0, -1.0], [-1.0, 1.0, 1.0]])],
    ids=["cube", "octahedron"],
)
@pytest.mark.parametrize("inscribed", [False, True])
def test_tangent_planes_of_a_sphere_report_the_closed_form_gap(normals, inscribed):
    # The unit ball in q: planes at the axes make the cube, at the four diagonals the
    # octahedron; both reach sqrt(3) along their vertices.
    units = np.array([MU, MU, MU * RHO])
    points = normals / np.linalg.norm(normals, axis=1, keepdims=True)
    polytope = Polytope.from_tangent_planes(
        points / units,  # the ball's normal at q as a twist: q / units
        points * units,
        gauge=lambda loads: np.linalg.norm(loads / units, axis=1),
        mu=MU,
        rho=RHO,
        inscribed=inscribed,
    )
    assert polytope.error == pytest.approx(math.sqrt(3.0) - 1.0, rel=1e-13)
    assert polytope.inscribed == polytope.conservative == inscribed
    radii = np.linalg.norm(polytope.vertices() / units, axis=1)
    np.testing.assert_allclose(radii, 1.0 if inscribed else math.sqrt(3.0), rtol=1e-13)


def test_a_pyramid_written_as_a_polytope_is_the_same_set():
    pyramid = Pyramid(mu=MU, rho=RHO, tilt=(0.1, -0.05), center=CENTER, facets=6)
    matrix, _ = pyramid.inequalities(normal_force=1.0)
    polytope = Polytope(rows=matrix @ np.linalg.inv(to_normalised()), mu=MU, rho=RHO, center=CENTER)
    loads = np.random.default_rng(2).normal(size=(300, 3)) * [MU, MU, MU * RHO]
    np.testing.assert_allclose(
        polytope.safety_factor(loads), pyramid.safety_factor(loads), rtol=1e-12
    )


def to_normalised():
    """The map from loads about the origin to ``q`` at unit normal force, written out."""
    cx, cy = CENTER
    return np.diag([1 / MU, 1 / MU, 1 / (MU * RHO)]) @ np.array(
        [[1, 0, 0], [0, 1, 0], [cy, -cx, 1]]
    )


def pinch(model, load):
    """Two fingers squeezing a bar along y, both with the friction model object ``model``."""
    contacts = [
        Contact(name=name, role="finger", position=[0, side * 0.02, 0], normal=[0, -side, 0],
                mu=MU, model=model)
        for name, side in (("left", -1), ("right", 1))
    ]  # fmt: skip
    body = Body(mass=0.0, center_of_mass=[0, 0, 0])
    return Problem(body=body, contacts=contacts, loads=[load], objective="min-max-normal-force")


@pytest.mark.parametrize("offset", [0.0, 0.004, 0.02])
def test_a_pyramid_and_the_same_polytope_plan_the_same_grip(offset):
    pyramid = Pyramid(mu=MU, rho=RHO, tilt=(0.1, -0.05), center=CENTER, facets=8)
    matrix, _ = pyramid.inequalities(normal_force=1.0)
    polytope = Polytope(rows=matrix @ np.linalg.inv(to_normalised()), mu=MU, rho=RHO, center=CENTER)
    load = Load(name="off-axis", force=[1.0, 0.0, -10.0], point=[offset, 0.0, 0.0])
    expected = solve(pinch(pyramid, load))
    plan = solve(pinch(polytope, load))
    assert expected.status == plan.status == "optimal"
    assert plan.objective_value == pytest.approx(expected.objective_value, rel=1e-7)


def test_a_block_on_a_box_base_has_the_closed_form_safety_factor():
    # Normal force = the weight; the largest multiple of the push with each component within
    # its bound.
    weight, push = 2.0 * 9.81, np.array([3.0, -1.0, 0.003])
    base = Contact(name="base", role="support", position=[0, 0, 0], normal=[0, 0, 1], mu=MU,
                   model=BOX)  # fmt: skip
    load = Load(name="push", force=[*push[:2], 0.0], point=[0, 0, 0], torque=[0, 0, push[2]])
    problem = Problem(body=Body(mass=2.0, center_of_mass=[0, 0, 0.05]), contacts=[base],
                      loads=[load], objective="max-safety-factor")  # fmt: skip
    moved = about_center(push)[0]
    expected = min(MU * weight / abs(moved[0]), MU * weight / abs(moved[1]),
                   MU * RHO * weight / abs(moved[2]))  # fmt: skip
    assert solve(problem).safety_factors["push"] == pytest.approx(expected, rel=1e-6)


def test_the_inscribed_polytope_of_a_limit_surface_lies_within_its_error_inside_it():
    ls = LimitSurface(pressure.rectangle(0.1, 0.01), mu=MU, normal_force=3.0)
    inner = Polytope.from_limit_surface(ls, cuts=128)
    outer = Polytope.from_limit_surface(ls, cuts=128, inscribed=False)
    assert inner.error == outer.error
    assert compare(inner, ls, n=2000).max_overestimate <= 1e-9
    loads = np.random.default_rng(3).normal(size=(2000, 3)) * [ls.max_force, ls.max_force,
                                                               ls.max_moment]  # fmt: skip
    ratio = outer.safety_factor(loads) / ls.safety_factor(loads)
    assert ratio.min() >= 1.0 - 1e-9 and ratio.max() <= 1.0 + outer.error + 1e-9
    # The random rays come close to the vertices: the bound is attained, not loose.
    assert ratio.max() >= 1.0 + 0.8 * outer.error


def test_symmetric_directions_are_the_upper_half_of_an_even_spread():
    directions = symmetric_directions(100)
    assert directions.shape == (50, 3) and np.all(directions[:, 2] > 0.0)
    np.testing.assert_allclose(np.linalg.norm(directions, axis=1), 1.0, rtol=1e-14)


@pytest.mark.parametrize(
    ("arguments", "message"),
    [
        ({"rows": [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 1.0, 0.0]]}, "span all three"),
        ({"rows": [[1.0, 0.0, 0.0]]}, "span all three"),
        ({"rows": np.eye(3), "rho": 0.0}, "rho"),
        ({"rows": [[np.nan, 0.0, 0.0], [0, 1, 0], [0, 0, 1]]}, "rows"),
    ],
)
def test_invalid_polytopes_are_refused(arguments, message):
    with pytest.raises(InvalidArgumentError, match=message):
        Polytope(**{"mu": MU, "rho": RHO, **arguments})


@pytest.mark.parametrize("cuts", [5, 7, 4, True, 8.0])
def test_cut_counts_must_be_even_integers_of_at_least_six(cuts):
    with pytest.raises(InvalidArgumentError, match="cuts must be an even integer"):
        symmetric_directions(cuts)


def test_a_twist_that_is_not_an_outward_normal_is_refused():
    with pytest.raises(InvalidArgumentError, match="outward normal"):
        Polytope.from_tangent_planes(
            -np.eye(3), np.eye(3), gauge=lambda x: np.abs(x).max(axis=1), mu=MU, rho=RHO
        )
