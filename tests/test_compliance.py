"""Compliant contacts against closed forms and statics written here (issue 12)."""

import dataclasses
import warnings

import numpy as np
import pytest

from fixplan import LimitSurface
from fixplan.models import Exact
from fixplan.motion.compliance import ComplianceError, Stiffness, analyse
from fixplan.planner.problem import Body, Contact, Load, Problem
from fixplan.surface import pressure

#: Forces from the polished QP agree with the closed forms to this fraction of the force scale.
RTOL = 1e-9
NO_GRAVITY = np.zeros(3)


def _point(name, role, position, normal, *, mu=0.5, force=None):
    return Contact(
        name=name,
        role=role,
        position=position,
        normal=normal,
        mu=mu,
        model="point-cone",
        force=force,
    )


def _problem(contacts, loads, *, mass=0.0, centre=(0.0, 0.0, 0.0), gravity=NO_GRAVITY):
    body = Body(mass=mass, center_of_mass=np.array(centre), gravity=np.array(gravity))
    return Problem(body=body, contacts=tuple(contacts), loads=tuple(loads), objective="check")


def _pinch(load, *, area=False):
    """Two fingers at x = ∓0.05 m squeezing with 10 N each."""
    model = (
        {"model": "ellipsoid", "patch": pressure.disk(0.005)} if area else {"model": "point-cone"}
    )
    fingers = [
        Contact(name=n, role="finger", position=p, normal=d, mu=0.8, force=10.0, **model)
        for n, p, d in (("a", [-0.05, 0, 0], [1, 0, 0]), ("b", [0.05, 0, 0], [-1, 0, 0]))
    ]
    return _problem(fingers, [load])


def _world_force(problem, result, case, name):
    contact = next(c for c in problem.contacts if c.name == name)
    fn, ft1, ft2, _ = result.wrenches[case][name]
    return np.array([ft1, ft2, fn]) @ contact.frame


@pytest.mark.parametrize(("ka", "kb"), [(1e6, 1e6), (1e6, 4e6), (3e7, 2e5)])
def test_axial_force_changes_pinch_forces_in_proportion_to_normal_stiffness(ka, kb):
    force = 3.0
    problem = _pinch(Load(name="push", force=np.array([force, 0, 0]), point=np.zeros(3)))
    stiffness = {
        "a": Stiffness(normal=ka, tangential=1e5),
        "b": Stiffness(normal=kb, tangential=1e5),
    }
    result = analyse(problem, None, stiffness=stiffness)
    # The body moves x = F / (ka + kb) towards b: a unloads by ka x, b loads by kb x.
    shift = force / (ka + kb)
    assert result.wrenches["push"]["a"][0] == pytest.approx(10.0 - ka * shift, rel=RTOL)
    assert result.wrenches["push"]["b"][0] == pytest.approx(10.0 + kb * shift, rel=RTOL)
    assert result.displacement["push"][0] == pytest.approx(shift, rel=RTOL)
    assert result.lifted["push"] == ()


@pytest.mark.parametrize(("ra", "rb"), [(2.0, 2.0), (1.0, 5.0)])
def test_torque_about_the_axis_splits_in_proportion_to_torsional_stiffness(ra, rb):
    torque = 0.004
    load = Load(name="twist", force=np.zeros(3), point=np.zeros(3), torque=np.array([torque, 0, 0]))
    problem = _pinch(load, area=True)
    stiffness = {
        "a": Stiffness(normal=1e6, tangential=1e5, torsional=ra),
        "b": Stiffness(normal=1e6, tangential=1e5, torsional=rb),
    }
    result = analyse(problem, None, stiffness=stiffness)
    # Rotation θ = T / (ra + rb) about +x; a's normal is +x, b's is -x.
    angle = torque / (ra + rb)
    assert result.wrenches["twist"]["a"][3] == pytest.approx(-ra * angle, rel=RTOL)
    assert result.wrenches["twist"]["b"][3] == pytest.approx(rb * angle, rel=RTOL)
    assert result.displacement["twist"][3] == pytest.approx(angle, rel=RTOL)


@pytest.mark.parametrize(("ta", "tb"), [(1e5, 1e5), (1e5, 9e5), (4e6, 1e4)])
def test_force_across_the_axis_at_its_midpoint_splits_evenly(ta, tb):
    across = np.array([0.0, 1.5, -2.0])
    problem = _pinch(Load(name="side", force=across, point=np.zeros(3)))
    stiffness = {
        "a": Stiffness(normal=1e6, tangential=ta),
        "b": Stiffness(normal=3e6, tangential=tb),
    }
    result = analyse(problem, None, stiffness=stiffness)
    for name in ("a", "b"):
        tangential = _world_force(problem, result, "side", name)
        tangential[0] = 0.0
        np.testing.assert_allclose(tangential, -across / 2, atol=RTOL * 10)
        assert result.wrenches["side"][name][0] == pytest.approx(10.0, rel=RTOL)


def _plate(stiffnesses):
    supports = [("s1", [0.0, 0.0]), ("s2", [0.3, 0.0]), ("s3", [0.1, 0.2])]
    contacts = [_point(n, "support", [x, y, 0.0], [0, 0, 1]) for n, (x, y) in supports]
    contacts.append(_point("clamp", "clamp", [0.12, 0.08, 0.02], [0, 0, -1], mu=0.0, force=40.0))
    load = Load(name="drill", force=np.array([0, 0, -25.0]), point=np.array([0.2, 0.05, 0.02]))
    problem = _problem(
        contacts, [load], mass=2.0, centre=(0.15, 0.07, 0.01), gravity=(0.0, 0.0, -9.81)
    )
    stiffness = {
        c.name: Stiffness(normal=k, tangential=k / 3)
        for c, k in zip(contacts, stiffnesses, strict=True)
    }
    return problem, analyse(problem, None, stiffness=stiffness), supports


@pytest.mark.parametrize("stiffnesses", [[1e7] * 4, [1e6, 5e7, 2e7, 3e5], [8e8, 1e5, 1e6, 1e9]])
def test_plate_on_three_supports_carries_the_statically_determinate_reactions(stiffnesses):
    _, result, supports = _plate(stiffnesses)
    # Downward vertical forces (clamp, load, weight) at their (x, y): three reactions by statics.
    downs = [(40.0, 0.12, 0.08), (25.0, 0.2, 0.05), (2.0 * 9.81, 0.15, 0.07)]
    matrix = np.array(
        [[1.0, 1.0, 1.0], [x for _, (x, _) in supports], [y for _, (_, y) in supports]]
    )
    rhs = np.array([sum(f for f, _, _ in downs), sum(f * x for f, x, _ in downs)])
    rhs = np.r_[rhs, sum(f * y for f, _, y in downs)]
    reactions = np.linalg.solve(matrix, rhs)
    for (name, _), reaction in zip(supports, reactions, strict=True):
        fn, ft1, ft2, mn = result.wrenches["drill"][name]
        assert fn == pytest.approx(reaction, rel=RTOL)
        assert abs(ft1) + abs(ft2) + abs(mn) < RTOL * reaction
    assert result.wrenches["drill"]["clamp"][0] == pytest.approx(40.0, rel=RTOL)


def test_a_part_tipped_by_a_moment_lifts_one_spring_and_rests_on_three():
    corners = {"pp": (0.1, 0.1), "pm": (0.1, -0.1), "mp": (-0.1, 0.1), "mm": (-0.1, -0.1)}
    contacts = [_point(n, "support", [x, y, 0.0], [0, 0, 1]) for n, (x, y) in corners.items()]
    # Linear springs would give f = 2.5 + 15 x + 15 y [N]: -0.5 N at "mm", so it lifts off.
    tip = Load(name="tip", force=np.zeros(3), point=np.zeros(3), torque=np.array([-0.6, 0.6, 0]))
    problem = _problem(contacts, [tip], mass=1.0, centre=(0, 0, 0.05), gravity=(0, 0, -10.0))
    result = analyse(problem, None, stiffness=Stiffness(normal=2e6, tangential=5e5))
    # The other three are determinate: Σf = 10, Σ x f = My = 0.6, Σ y f = -Mx = 0.6.
    rest = ["pp", "pm", "mp"]
    matrix = np.array([[1.0] * 3, [corners[n][0] for n in rest], [corners[n][1] for n in rest]])
    expected = np.linalg.solve(matrix, [10.0, 0.6, 0.6])
    assert result.lifted["tip"] == ("mm",)
    assert result.wrenches["tip"]["mm"] == (0.0, 0.0, 0.0, 0.0)
    for name, force in zip(rest, expected, strict=True):
        assert result.wrenches["tip"][name][0] == pytest.approx(force, rel=RTOL)


def _tangents(normal):
    """Two unit vectors spanning the plane normal to ``normal`` (from an SVD)."""
    return np.linalg.svd(np.asarray(normal, float)[None, :])[2][1:]


#: Six locators of a 0.1 m cube: three under it, two against its -y side, one against its -x end.
LOCATORS_3_2_1 = [
    ("z1", [0.02, 0.02, 0], [0, 0, 1]),
    ("z2", [0.08, 0.02, 0], [0, 0, 1]),
    ("z3", [0.05, 0.09, 0], [0, 0, 1]),
    ("y1", [0.02, 0, 0.05], [0, 1, 0]),
    ("y2", [0.08, 0, 0.05], [0, 1, 0]),
    ("x1", [0, 0.05, 0.05], [1, 0, 0]),
]


def test_displacement_of_a_3_2_1_fixture_solves_the_assembled_stiffness_matrix():
    box = 0.1
    places = LOCATORS_3_2_1
    # Friction high enough that no locator slips under the unit load (the springs stay linear).
    contacts = [_point(n, "locator", p, d, mu=2.0) for n, p, d in places]
    centre = np.full(3, box / 2)
    load = Load(name="unit", force=np.array([-0.3, -0.4, -0.866]), point=centre)
    problem = _problem(contacts, [load], centre=centre)
    kn, kt = 2e7, 6e6
    result = analyse(problem, None, stiffness=Stiffness(normal=kn, tangential=kt))
    matrix = np.zeros((6, 6))
    for _, position, normal in places:
        arm = np.asarray(position, float) - centre
        for k, direction in [(kn, np.asarray(normal, float))] + [
            (kt, t) for t in _tangents(normal)
        ]:
            column = np.r_[direction, np.cross(arm, direction)]
            matrix += k * np.outer(column, column)
    expected = np.linalg.solve(matrix, np.r_[load.force, 0, 0, 0])
    assert result.lifted["unit"] == ()
    assert result.first_slip["unit"] > 1.0
    np.testing.assert_allclose(result.displacement["unit"], expected, rtol=1e-8, atol=1e-20)
    np.testing.assert_array_equal(result.clamped_displacement["unit"], np.zeros(6))


def test_first_slip_of_a_pinch_pulled_along_the_surface_matches_coulomb():
    # Fingers with equal stiffness share a force F across the axis: each slips when F/2 = mu 10.
    problem = _pinch(Load(name="pull", force=np.array([0, 0, -2.0]), point=np.zeros(3)))
    result = analyse(problem, None, stiffness=Stiffness(normal=1e6, tangential=1e5))
    assert result.first_slip["pull"] == pytest.approx(2 * 0.8 * 10.0 / 2.0, rel=1e-8)
    assert result.safety_factors["pull"]["a"] == pytest.approx(0.8 * 10.0 / 1.0, rel=RTOL)
    slip = result.slip_directions["pull"]["a"]
    contact = problem.contacts[0]
    world = slip[:2] @ contact.frame[:2]
    np.testing.assert_allclose(world, [0, 0, -1], atol=1e-9)


@pytest.mark.parametrize(
    "arguments", [{"normal": 0.0, "tangential": 1.0}, {"normal": 1.0, "tangential": -1.0}]
)
def test_stiffness_rejects_values_out_of_range(arguments):
    with pytest.raises(ComplianceError, match="stiffness"):
        Stiffness(**arguments)


def test_a_load_that_pulls_the_part_off_its_supports_moves_it_at_once():
    contacts = [_point(n, "support", [x, 0, 0], [0, 0, 1]) for n, x in (("l", -0.1), ("r", 0.1))]
    lift = Load(name="lift", force=np.array([0, 0, 5.0]), point=np.zeros(3))
    problem = _problem(contacts, [lift])
    result = analyse(problem, None, stiffness=Stiffness(normal=1e6, tangential=1e5))
    assert result.collapse["lift"] == result.first_slip["lift"] == 0.0
    assert result.first_slip_contact["lift"] is None and not result.held["lift"]


def test_a_clamp_that_pushes_the_part_off_its_supports_is_an_error():
    support = _point("s", "support", [0, 0, 0], [0, 0, 1])
    clamp = _point("c", "clamp", [0, 0, -0.01], [0, 0, 1], mu=0.0, force=20.0)
    problem = _problem([support, clamp], [Load(name="none", force=np.zeros(3), point=np.zeros(3))])
    with pytest.raises(
        ComplianceError, match=r"'none'.*push the part off them while it is clamped"
    ):
        analyse(problem, None, stiffness=Stiffness(normal=1e6, tangential=1e5))


def test_first_slip_after_a_support_lifts_matches_statics_on_the_remaining_three():
    # Four supports at the corners; "mm" is frictionless, so the others carry the in-plane force
    # and, the force passing through their centroid, carry a third of it each.
    corners = {"pp": (0.1, 0.1), "pm": (0.1, -0.1), "mp": (-0.1, 0.1), "mm": (-0.1, -0.1)}
    contacts = [
        _point(n, "support", [x, y, 0.0], [0, 0, 1], mu=0.0 if n == "mm" else 0.5)
        for n, (x, y) in corners.items()
    ]
    push = 1.2
    load = Load(
        name="tip",
        force=np.array([push, 0, 0]),
        point=np.array([0.1, 0.1, 0.0]) / 3,
        torque=np.array([-0.6, 0.6, 0]),
    )
    problem = _problem(contacts, [load], mass=1.0, centre=(0, 0, 0.05), gravity=(0, 0, -10.0))
    result = analyse(problem, None, stiffness=Stiffness(normal=2e6, tangential=5e5))
    # "mm" lifts at λ = 5/6; then statics on three supports gives fn(pm) = fn(mp) = 5 - 3 λ,
    # and they slip when λ push / 3 = mu (5 - 3 λ).
    assert result.first_slip["tip"] == pytest.approx(0.5 * 5 / (push / 3 + 0.5 * 3), rel=1e-9)
    assert result.first_slip_contact["tip"] in ("pm", "mp")
    assert result.lifted["tip"] == ("mm",)
    assert result.wrenches["tip"]["pm"][0] == pytest.approx(2.0, rel=RTOL)


def _pressed_plate(model, load):
    """A plate on three supports pressed by a frictionless clamp: in-plane loads at the support
    plane leave every normal force where statics puts it."""
    patch = {"patch": pressure.disk(0.01)} if model != "point-cone" else {}
    supports = [("s1", [0.0, 0.0]), ("s2", [0.3, 0.0]), ("s3", [0.1, 0.2])]
    contacts = [
        Contact(
            name=n, role="support", position=[x, y, 0.0], normal=[0, 0, 1], mu=0.4, model=model,
            **patch,
        )
        for n, (x, y) in supports
    ]  # fmt: skip
    contacts.append(_point("clamp", "clamp", [0.12, 0.08, 0.02], [0, 0, -1], mu=0.0, force=60.0))
    return _problem(contacts, [load], mass=1.5, centre=(0.15, 0.07, 0.01), gravity=(0, 0, -9.81))


@pytest.mark.parametrize("model", ["point-cone", "ellipsoid"])
@pytest.mark.parametrize(
    ("force", "point", "torque"),
    [([3.0, 1.0, 0.0], [0.2, 0.1, 0.0], 0.0), ([-1.0, 2.0, 0.0], [0.0, 0.3, 0.0], 0.4)],
)
def test_with_normal_forces_fixed_by_statics_the_part_moves_at_the_rigid_safety_factor(
    model, force, point, torque
):
    from fixplan.planner.planner import Planner

    load = Load(
        name="mill", force=np.array(force), point=np.array(point), torque=np.array([0, 0, torque])
    )
    problem = _pressed_plate(model, load)
    stiffness = {
        "s1": Stiffness(normal=1e7, tangential=3e6, torsional=20.0),
        "s2": Stiffness(normal=4e7, tangential=1e6, torsional=5.0),
        "s3": Stiffness(normal=2e6, tangential=8e6, torsional=50.0),
        "clamp": Stiffness(normal=1e7, tangential=1e6),
    }
    result = analyse(problem, None, stiffness=stiffness)
    rigid = Planner(problem).solve().safety_factors["mill"]
    assert result.collapse["mill"] == pytest.approx(rigid, rel=1e-6)
    assert result.first_slip["mill"] <= result.collapse["mill"]
    assert result.held["mill"] == (rigid >= 1.0)


def _random_fixture(rng, contact=_point):
    """A box on three supports against two side locators and an end locator, each set pressed
    by its own clamp, under a random load (``contact`` makes the contacts, as :func:`_point`)."""
    size = np.array([0.2, 0.12, 0.05])
    contacts = []
    for i in range(3):
        xy = rng.uniform(0.1, 0.9, 2) * size[:2]
        contacts.append(
            contact(f"z{i}", "support", [*xy, 0.0], [0, 0, 1], mu=rng.uniform(0.2, 0.6))
        )
    for i, x in enumerate(np.array([0.2, 0.8]) * size[0]):
        z = rng.uniform(0.3, 0.7) * size[2]
        contacts.append(contact(f"y{i}", "locator", [x, 0.0, z], [0, 1, 0], mu=0.3))
    contacts.append(contact("x0", "locator", [0.0, size[1] / 2, size[2] / 2], [1, 0, 0], mu=0.3))
    clamps = [
        ("top", [*(rng.uniform(0.3, 0.7, 2) * size[:2]), size[2]], [0, 0, -1]),
        ("side", [size[0] / 2, size[1], size[2] / 2], [0, -1, 0]),
        ("end", [size[0], size[1] / 2, size[2] / 2], [-1, 0, 0]),
    ]
    for name, position, normal in clamps:
        force = rng.uniform(50.0, 200.0)
        contacts.append(contact(name, "clamp", position, normal, mu=0.3, force=force))
    load = Load(name="cut", force=rng.normal(size=3) * 20.0, point=rng.uniform(0, 1, 3) * size)
    problem = _problem(contacts, [load], mass=2.0, centre=size / 2, gravity=(0, 0, -9.81))
    stiffness = {
        c.name: Stiffness(normal=k, tangential=k * rng.uniform(0.2, 1.0))
        for c, k in zip(contacts, 10 ** rng.uniform(6, 8, len(contacts)), strict=True)
    }
    return problem, stiffness


def _random_case(seed, contact=_point):
    from fixplan.planner.planner import Planner

    problem, stiffness = _random_fixture(np.random.default_rng(seed), contact)
    result = analyse(problem, None, stiffness=stiffness)
    rigid = Planner(problem, allow_squeeze=True).solve().safety_factors["cut"]
    return result.first_slip["cut"], result.collapse["cut"], rigid


@pytest.mark.parametrize("seed", [0, 1, 2, 3, 4, 10])  # 4 and 10 are seated
def test_over_random_fixtures_the_first_slip_never_exceeds_the_rigid_safety_factor(seed):
    first, _, rigid = _random_case(seed)
    assert first <= rigid * (1 + 1e-9)


# Seed 0 is left out here: its ramp stalls and its collapse is reported as not found (NaN), the
# known limit of fixplan.motion.load_ramp (6 of the first 50 seeds).
@pytest.mark.parametrize("seed", [1, 2, 3, 4, 10])
def test_over_random_fixtures_the_collapse_lies_between_first_slip_and_rigid_safety_factor(seed):
    first, collapse, rigid = _random_case(seed)
    assert first <= collapse * (1 + 1e-9)
    assert collapse <= rigid * (1 + 1e-6)


# -- seating ----------------------------------------------------------------------------------


def _clamped_3_2_1(*, stiffness_seed=0):
    """A 3-2-1 fixture of a box pressed on its six locators by three clamps off their axes,
    with gravity, and no task load."""
    places = LOCATORS_3_2_1
    contacts = [_point(n, "locator", p, d, mu=0.3) for n, p, d in places]
    clamps = [
        ("top", [0.06, 0.05, 0.1], [0, 0, -1], 120.0),
        ("side", [0.04, 0.1, 0.04], [0, -1, 0], 60.0),
        ("end", [0.1, 0.06, 0.06], [-1, 0, 0], 40.0),
    ]
    contacts += [_point(n, "clamp", p, d, mu=0.3, force=f) for n, p, d, f in clamps]
    centre = np.array([0.05, 0.05, 0.05])
    load = Load(name="rest", force=np.zeros(3), point=centre)
    problem = _problem(contacts, [load], mass=1.5, centre=centre, gravity=(0, 0, -9.81))
    rng = np.random.default_rng(stiffness_seed)
    stiffness = {
        c.name: Stiffness(normal=k, tangential=k * rng.uniform(0.3, 1.0))
        for c, k in zip(contacts, 10 ** rng.uniform(6, 8, len(contacts)), strict=True)
    }
    return problem, stiffness, places, clamps


@pytest.mark.parametrize("stiffness_seed", [0, 1])
def test_a_seated_3_2_1_fixture_carries_the_frictionless_statics_of_its_clamps(stiffness_seed):
    problem, stiffness, places, clamps = _clamped_3_2_1(stiffness_seed=stiffness_seed)
    result = analyse(problem, None, stiffness=stiffness)
    # Six locator reactions along their normals balance clamps and weight: six equations.
    centre = problem.body.center_of_mass
    columns = [
        np.r_[n, np.cross(np.subtract(p, centre), n)] for _, p, n in np.array(places, dtype=object)
    ]
    pushed = (
        sum(f * np.r_[n, np.cross(np.subtract(p, centre), n)] for _, p, n, f in clamps)
        + np.r_[0, 0, -1.5 * 9.81, 0, 0, 0]
    )
    reactions = np.linalg.solve(np.array(columns, float).T, -pushed)
    assert result.seated["rest"]
    for (name, *_), reaction in zip(places, reactions, strict=True):
        fn, ft1, ft2, mn = result.wrenches["rest"][name]
        assert fn == pytest.approx(reaction, rel=RTOL)
        assert abs(ft1) + abs(ft2) + abs(mn) < RTOL * 100.0
    assert np.isinf(result.first_slip["rest"])


def test_stuck_clamping_loads_the_locators_friction_springs():
    problem, stiffness, places, _ = _clamped_3_2_1()
    result = analyse(problem, None, stiffness=stiffness, seating="stuck")
    assert not result.seated["rest"]
    friction = [np.abs(result.wrenches["rest"][name][1:3]).sum() for name, *_ in places]
    assert max(friction) > 1.0  # N: the clamps' side pushes are shared by friction


def test_a_grasp_that_holds_its_weight_by_friction_cannot_be_seated():
    fingers = _pinch(Load(name="hold", force=np.zeros(3), point=np.zeros(3))).contacts
    problem = _problem(fingers, [Load(name="hold", force=np.zeros(3), point=np.zeros(3))],
                       mass=0.5, gravity=(0, 0, -9.81))  # fmt: skip
    result = analyse(problem, None, stiffness=Stiffness(normal=1e6, tangential=5e5))
    assert not result.seated["hold"]
    weight = sum(_world_force(problem, result, "hold", n) for n in ("a", "b"))
    np.testing.assert_allclose(weight, [0, 0, 0.5 * 9.81], atol=RTOL * 10)


def test_an_unknown_seating_is_refused():
    problem, stiffness, *_ = _clamped_3_2_1()
    with pytest.raises(ComplianceError, match="seating must be one of seated, stuck"):
        analyse(problem, None, stiffness=stiffness, seating="tapped")


#: Point supports of exact pads (their facets: no ellipsoid osculates there).
PINS = pressure.points([[-0.005, 0.0], [0.005, 0.0], [0.0, 0.006]])


def _with_patches(problem, make):
    """``problem`` with each exact contact's patch (or model) replaced by ``make(contact)``."""
    contacts = [make(c) if c.model == "exact" else c for c in problem.contacts]
    return dataclasses.replace(problem, contacts=tuple(contacts))


@pytest.mark.parametrize("pads", ["disks", "point supports"])
@pytest.mark.parametrize(
    ("force", "point", "torque"),
    [([3.0, 1.0, 0.0], [0.2, 0.1, 0.0], 0.0), ([-1.0, 2.0, 0.0], [0.0, 0.3, 0.0], 0.4)],
)
def test_exact_pads_move_at_the_rigid_exact_safety_factor(pads, force, point, torque):
    """Exact pads, stated in each step by ellipsoids that osculate their exact sets (disks) or
    by a cone per point (point supports): with the normal forces fixed by statics the part
    moves at the rigid planner's exact safety factor (disks 4.0e-8 and 1.3e-8 off, the collapse
    bracketed to 1e-7; stated by the seed polytopes they came out 6.6 % and 7.2 % above it;
    point supports 5.7e-8 and 4.6e-9 off, 6.9 % and 6.0 % above it by their seed polytopes),
    and no warning is given."""
    from fixplan.planner.planner import Planner

    load = Load(
        name="mill", force=np.array(force), point=np.array(point), torque=np.array([0, 0, torque])
    )
    problem = _pressed_plate("exact", load)
    if pads == "point supports":
        problem = _with_patches(problem, lambda c: dataclasses.replace(c, patch=PINS))
    stiffness = {
        "s1": Stiffness(normal=1e7, tangential=3e6, torsional=20.0),
        "s2": Stiffness(normal=4e7, tangential=1e6, torsional=5.0),
        "s3": Stiffness(normal=2e6, tangential=8e6, torsional=50.0),
        "clamp": Stiffness(normal=1e7, tangential=1e6),
    }
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        result = analyse(problem, None, stiffness=stiffness)
    rigid = Planner(problem).solve().safety_factors["mill"]
    assert result.collapse["mill"] == pytest.approx(rigid, rel=1e-6)
    assert result.first_slip["mill"] <= result.collapse["mill"]


def _many_points():
    """An exact model of 8 x 9 point supports: more than the model states a cone for each."""
    grid = [[x, y] for x in np.linspace(-0.005, 0.005, 8) for y in np.linspace(-0.004, 0.004, 9)]
    return Exact.from_limit_surface(LimitSurface(pressure.points(grid), mu=0.4))


def _beside_a_patch():
    """An exact model of point supports and a patch together."""
    both = [LimitSurface(PINS, mu=0.4), LimitSurface(pressure.disk(0.004), mu=0.4)]
    return Exact.from_limit_surface(LimitSurface.combine(both))


@pytest.mark.parametrize("model", [_beside_a_patch, _many_points])
def test_exact_models_with_facets_not_stated_exactly_warn_of_their_seed_polytopes(model):
    """Point supports beside a patch (neither an osculating ellipsoid at the facets nor a cone
    per point for the patch), or more of them than ``MAX_STATED_POINTS``: the steps state their
    seed polytopes, and the analysis says so."""
    load = Load(name="mill", force=np.array([3.0, 1.0, 0.0]), point=np.array([0.2, 0.1, 0.0]))
    exact = model()
    assert not exact.stated_exactly
    problem = _with_patches(
        _pressed_plate("exact", load), lambda c: dataclasses.replace(c, model=exact, patch=None)
    )
    with pytest.warns(UserWarning, match=r"s1, s2, s3 have facets \(point supports beside a "):
        analyse(problem, None, stiffness=Stiffness(normal=1e7, tangential=3e6, torsional=20.0))


def _exact_pads(name, role, position, normal, *, mu=0.5, force=None):
    """:func:`_point`, but clamps and supports on exact disk pads."""
    if role not in ("clamp", "support"):
        return _point(name, role, position, normal, mu=mu, force=force)
    return Contact(name=name, role=role, position=position, normal=normal, mu=mu, model="exact",
                   patch=pressure.disk(0.006), force=force)  # fmt: skip


# The seeds whose collapse exceeded the rigid exact safety factor (by up to 8.1 %) when exact
# models were stated by their seed polytopes; now none of the first 30 does (one not found).
@pytest.mark.parametrize("seed", [10, 11, 15, 27])
def test_with_exact_pads_the_collapse_lies_between_first_slip_and_rigid_safety_factor(seed):
    first, collapse, rigid = _random_case(seed, _exact_pads)
    assert first <= collapse * (1 + 1e-9)
    assert collapse <= rigid * (1 + 1e-6)
