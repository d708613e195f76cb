"""Frictionless contacts (mu = 0), issue 9 §3: the textbook frictionless clamp and locator.

A frictionless contact transmits its normal force only: its limit surface and every model of it
are the single load 0. Its shape (rho, tilt, centre) is that of the same patch with mu = 1, and
its motion is the limit mu → 0+ of the motion, which does not depend on mu. The laws every model
obeys at mu = 0 are in the contract suite (tests/test_models_contract.py); here: the exact
surface, the models' direct constructors, compare, the planner, problem files, the command line
and reports.
"""

import json
import math

import cvxpy as cp
import numpy as np
import pytest

from fixplan import Body, Contact, LimitSurface, Load, Problem, pressure, solve
from fixplan.errors import InvalidArgumentError
from fixplan.io.cli import EXIT_NOT_HELD, EXIT_OK, main
from fixplan.io.problem_file import ProblemFileError, load_problem
from fixplan.models import (
    Cone,
    Ellipsoid,
    Exact,
    FacetedEllipsoid,
    FittedEllipsoid,
    PointCone,
    PointPyramid,
    Pyramid,
)
from fixplan.models.compare import compare
from fixplan.planner.problem import AREA_MODEL_NAMES

NORMAL_FORCE = 5.0

FIELDS = {
    "hertz-disk": lambda: pressure.disk(0.01, "hertz"),
    "annulus": lambda: pressure.disk(0.02, "annulus", inner_radius=0.015),
    "rectangle-10to1": lambda: pressure.rectangle(0.1, 0.01),
    "skewed-points": lambda: pressure.points([[0, 0], [0.04, 0], [0, 0.02]], [1, 2, 3]),
    "off-centre-polygon": lambda: pressure.polygon([[0, 0], [0.03, 0], [0.03, 0.01], [0, 0.02]]),
    "bumpy-function": lambda: pressure.from_function(
        pressure.disk(0.01), lambda x, y: 1.0 + 40.0 * x + 4000.0 * y * y
    ),
}


def surfaces(field_name: str) -> tuple[LimitSurface, LimitSurface]:
    """The frictionless surface of a field and the same field with mu = 1."""
    field = FIELDS[field_name]()
    return (
        LimitSurface(field, mu=0.0, normal_force=NORMAL_FORCE),
        LimitSurface(field, mu=1.0, normal_force=NORMAL_FORCE),
    )


def some_loads(count: int, seed: int = 0) -> np.ndarray:
    """Nonzero loads of the size of a fingertip's or a pad's [N, N, N m]."""
    return np.random.default_rng(seed).normal(size=(count, 3)) * np.array([2.0, 2.0, 0.02])


# -- the exact limit surface ----------------------------------------------------------------------


@pytest.mark.parametrize("field", list(FIELDS))
def test_a_frictionless_surface_is_the_zero_load(field):
    frictionless, unit = surfaces(field)
    loads = some_loads(16)
    twists = some_loads(4, seed=1) * np.array([1.0, 1.0, 100.0])
    assert frictionless.frictionless and not unit.frictionless
    assert frictionless.max_force == 0.0 and frictionless.max_moment == 0.0
    assert np.all(frictionless.support(twists) == 0.0)
    assert np.all(frictionless.load(twists) == 0.0)
    assert np.all(frictionless.safety_factor(loads) == 0.0)
    assert not np.any(frictionless.contains(loads))
    assert frictionless.safety_factor(np.zeros(3)) == math.inf
    assert frictionless.contains(np.zeros(3))
    assert frictionless.contains([0.0, -0.0, 0.0])
    assert np.all(frictionless.curve("fy-m", 9) == 0.0)
    assert np.all(frictionless.sample(9, normalized=True) == 0.0)


@pytest.mark.parametrize("field", list(FIELDS))
def test_a_frictionless_surface_has_the_shape_and_the_motion_of_the_patch_with_mu_one(field):
    frictionless, unit = surfaces(field)
    small = LimitSurface(FIELDS[field](), mu=1e-3, normal_force=NORMAL_FORCE)
    loads = some_loads(16, seed=2)
    assert frictionless.characteristic_length == pytest.approx(unit.characteristic_length, 1e-14)
    assert frictionless.friction_shape.max_force == pytest.approx(unit.max_force, rel=1e-14)
    np.testing.assert_allclose(frictionless.motion(loads), unit.motion(loads), atol=1e-12)
    np.testing.assert_allclose(frictionless.motion(loads), small.motion(loads), atol=1e-9)
    motion, safety = frictionless.motion_and_safety_factor(loads)
    np.testing.assert_allclose(motion, unit.motion(loads), atol=1e-12)
    assert np.all(safety == 0.0)
    assert np.all(np.isnan(frictionless.motion(np.zeros(3))))


def test_a_sum_of_frictionless_patches_is_frictionless_with_the_sum_of_their_shapes():
    left = pressure.disk(0.01).shifted(-0.03, 0.0)
    right = pressure.rectangle(0.02, 0.01).shifted(0.03, 0.0)
    frictionless, shape = (
        LimitSurface.combine([LimitSurface(left, mu=mu, normal_force=2.0),
                              LimitSurface(right, mu=mu, normal_force=3.0)])
        for mu in (0.0, 1.0)
    )  # fmt: skip
    loads = some_loads(8, seed=3)
    assert frictionless.frictionless and frictionless.max_force == 0.0
    assert np.all(frictionless.safety_factor(loads) == 0.0)
    np.testing.assert_allclose(frictionless.motion(loads), shape.motion(loads), atol=1e-12)


def test_a_frictionless_patch_adds_nothing_to_a_sum_with_friction():
    rubber = LimitSurface(pressure.disk(0.01).shifted(0.02, 0.0), mu=0.8, normal_force=4.0)
    teflon = LimitSurface(pressure.disk(0.01).shifted(-0.02, 0.0), mu=0.0, normal_force=6.0)
    pad = LimitSurface.combine([rubber, teflon])
    twists = some_loads(8, seed=4) * np.array([1.0, 1.0, 100.0])
    assert not pad.frictionless and pad.normal_force == 10.0
    np.testing.assert_allclose(pad.support(twists), rubber.support(twists), rtol=1e-14)
    np.testing.assert_allclose(pad.load(twists), rubber.load(twists), rtol=1e-14)


def test_friction_that_vanishes_somewhere_on_the_patch_still_works():
    # mu(x, y) falls to 0 at the patch's -x edge: the surface is the uniform disk's times 0.5,
    # shifted in force by the friction gradient; its largest force is ∫ mu p dA = 0.5.
    radius = 0.01
    ls = LimitSurface(
        pressure.disk(radius), mu=lambda x, y: 0.5 * (1.0 + x / radius), normal_force=1.0
    )
    assert not ls.frictionless
    assert ls.max_force == pytest.approx(0.5, rel=1e-12)
    assert ls.safety_factor([0.25, 0.0, 0.0]) == pytest.approx(2.0, rel=1e-9)


def test_friction_that_vanishes_over_the_whole_patch_must_be_given_as_mu_zero():
    with pytest.raises(InvalidArgumentError, match="pass mu=0 for a frictionless contact"):
        LimitSurface(pressure.disk(0.01), mu=lambda x, y: 0.0 * x)


@pytest.mark.parametrize(
    "build",
    [
        lambda: LimitSurface(pressure.disk(0.01), mu=-0.2),
        lambda: Ellipsoid(mu=-0.2, rho=0.01),
        lambda: FittedEllipsoid(matrix=np.eye(3), mu=-0.2, rho=0.01),
        lambda: Cone(mu=-0.2, rho=0.01),
        lambda: Pyramid(mu=-0.2, rho=0.01),
        lambda: PointCone(mu=-0.2),
        lambda: PointPyramid(mu=-0.2),
    ],
)
def test_a_negative_friction_coefficient_is_rejected_naming_mu_and_its_range(build):
    with pytest.raises(InvalidArgumentError, match=r"mu must be >= 0, got -0\.2"):
        build()


# -- models built directly ----------------------------------------------------------------------

POINTS, CAPACITY = np.array([[0.0, 0.0], [0.02, 0.0], [0.0, 0.01]]), np.array([0.5, 0.3, 0.2])

DIRECT = {
    "ellipsoid": lambda mu: Ellipsoid(mu=mu, rho=0.01, tilt=(0.1, -0.05), center=(0.002, 0.0)),
    "fitted-ellipsoid": lambda mu: FittedEllipsoid(
        matrix=[[1.0, 0.1, 0.0], [0.1, 1.2, 0.05], [0.0, 0.05, 0.9]], mu=mu, rho=0.01
    ),
    "faceted-ellipsoid": lambda mu: FacetedEllipsoid(
        ellipsoid=Ellipsoid(mu=mu, rho=0.01), points=[[0.006, 0.0]], facet_support=[0.011]
    ),
    "cone": lambda mu: Cone(mu=mu, rho=0.01, tilt=(0.1, 0.0)),
    "pyramid": lambda mu: Pyramid(mu=mu, rho=0.01, facets=6, inscribed=False),
    "point-cone": lambda mu: PointCone(mu=mu),
    "point-pyramid": lambda mu: PointPyramid(mu=mu, facets=8),
    "exact": lambda mu: Exact(
        surface=LimitSurface(pressure.points(POINTS, CAPACITY, centered=False), mu=mu)
    ),
}


@pytest.mark.parametrize("name", list(DIRECT))
def test_a_model_built_with_mu_zero_holds_only_the_zero_load_and_moves_as_with_mu_one(name):
    frictionless, unit = DIRECT[name](0.0), DIRECT[name](1.0)
    loads = some_loads(8, seed=5)
    if not frictionless.torsion:
        loads[:, 2] = 0.0
    assert frictionless.frictionless and frictionless.mu == 0.0
    assert np.all(frictionless.safety_factor(loads) == 0.0)
    assert frictionless.safety_factor(np.zeros(3)) == math.inf
    assert frictionless.friction_shape.mu == unit.mu
    np.testing.assert_allclose(
        frictionless.friction_shape.safety_factor(loads), unit.safety_factor(loads), rtol=1e-12
    )
    if frictionless.has_motion:
        np.testing.assert_allclose(frictionless.motion(loads), unit.motion(loads), atol=1e-12)
    load = cp.Variable(frictionless.load_dimension)
    problem = cp.Problem(cp.Maximize(cp.sum(load)), frictionless.constraints(load, 100.0))
    problem.solve(solver=cp.CLARABEL)
    np.testing.assert_allclose(load.value, 0.0, atol=1e-9)


def test_an_exact_model_needs_a_limit_surface():
    with pytest.raises(InvalidArgumentError, match=r"ls must be a fixplan\.LimitSurface"):
        Exact(surface=pressure.points(POINTS, CAPACITY))


@pytest.mark.parametrize(
    "pyramid", [Pyramid(mu=0.0, rho=0.01, tilt=(0.2, 0.0)), PointPyramid(mu=0.0, facets=5)]
)
def test_the_inequalities_of_a_frictionless_pyramid_admit_only_the_zero_load(pyramid):
    a, b = pyramid.inequalities(normal_force=20.0)
    assert np.all(b == 0.0)
    loads = some_loads(200, seed=6)[:, : a.shape[1]]
    assert np.all((loads @ a.T).max(axis=1) > 0.0)


# -- comparing models with the exact surface ----------------------------------------------------

COMPARED = {
    "ellipsoid": Ellipsoid.from_limit_surface,
    "cone": Cone.from_limit_surface,
    "pyramid": Pyramid.from_limit_surface,
    "point-cone": PointCone.from_limit_surface,
    "exact": Exact.from_limit_surface,
}


@pytest.mark.parametrize("name", list(COMPARED))
@pytest.mark.parametrize("field", ["hertz-disk", "skewed-points"])
def test_compare_measures_a_frictionless_model_on_its_shape_as_with_mu_one(name, field):
    frictionless, unit = surfaces(field)
    if name == "point-cone" and field == "skewed-points":
        frictionless, unit = (
            LimitSurface(pressure.points([[0, 0], [0.04, 0], [0, 0.02]]), mu=mu, normal_force=5.0)
            for mu in (0.0, 1.0)
        )
    model = COMPARED[name](frictionless)
    got, expected = compare(model, frictionless, n=300), compare(COMPARED[name](unit), unit, n=300)
    assert got.model == repr(model) and "mu=0," in got.model
    for key in ("max_overestimate", "max_underestimate", "mean_error", "unsafe_fraction"):
        assert getattr(got, key) == pytest.approx(getattr(expected, key), abs=1e-9)
    if expected.max_motion_angle is None:
        assert got.max_motion_angle is None
    else:
        assert got.max_motion_angle == pytest.approx(expected.max_motion_angle, abs=1e-9)


def test_compare_refuses_a_model_with_friction_against_a_frictionless_surface():
    frictionless, unit = surfaces("hertz-disk")
    with pytest.raises(InvalidArgumentError, match="surface is frictionless"):
        compare(Ellipsoid.from_limit_surface(unit), frictionless)


# -- the planner --------------------------------------------------------------------------------

PUSH, MU_PLATE, MASS, GRAVITY = 20.0, 0.4, 1.0, 9.81


#: The planner's verification (fixplan/planner/planner.py, _verify) judges a contact's friction
#: load by its model's safety factor, which is exactly 0 at mu = 0 for the ~1e-16 N of solver
#: rounding left on the frictionless clamp: the plan is flagged 'inaccurate' with a division by
#: zero. The optimum itself is right. The stacked-constraint planner handles mu = 0.
def clamped_block(plate_model: str, clamp_model: str) -> Problem:
    """A 1 kg block on a frictional plate, pressed from above by a frictionless clamp and
    pushed sideways through the plate's centre at its height (no tipping moment)."""
    plate = Contact(
        name="plate", role="support", position=[0, 0, 0], normal=[0, 0, 1], mu=MU_PLATE,
        model=plate_model,
        patch=pressure.rectangle(0.06, 0.04) if plate_model in AREA_MODEL_NAMES else None,
    )  # fmt: skip
    clamp = Contact(
        name="clamp", role="clamp", position=[0, 0, 0.03], normal=[0, 0, -1], mu=0.0,
        model=clamp_model,
        patch=pressure.disk(0.005, "hertz") if clamp_model in AREA_MODEL_NAMES else None,
    )  # fmt: skip
    return Problem(
        body=Body(mass=MASS, center_of_mass=[0, 0, 0.015], gravity=[0, 0, -GRAVITY]),
        contacts=[plate, clamp],
        loads=[Load(name="push", force=[PUSH, 0, 0], point=[0, 0, 0])],
        objective="min-total-clamp-force",
    )


@pytest.mark.parametrize(
    ("plate_model", "clamp_model"),
    [
        ("ellipsoid", "point-cone"),
        ("cone", "ellipsoid"),
        ("exact", "exact"),
        ("point-cone", "point-pyramid"),
        ("ellipsoid", "pyramid"),
    ],
)
def test_a_frictionless_clamp_must_press_with_the_push_over_mu_less_the_weight(
    plate_model, clamp_model
):
    # Only the plate's friction resists the push: PUSH <= MU_PLATE * (clamp + weight).
    plan = solve(clamped_block(plate_model, clamp_model))
    expected = PUSH / MU_PLATE - MASS * GRAVITY
    assert plan.objective_value == pytest.approx(expected, rel=1e-6)
    assert plan.forces["clamp"] == pytest.approx(expected, rel=1e-6)
    np.testing.assert_allclose(plan.contact_wrenches[1, 0, 1:], 0.0, atol=1e-9)


def test_a_plan_with_a_frictionless_clamp_is_verified_optimal():
    plan = solve(clamped_block("ellipsoid", "point-cone"))
    assert plan.status == "optimal", plan.warnings
    assert plan.safety_factors["push"] == pytest.approx(1.0, rel=1e-5)
    assert plan.critical_contact == "plate"


def frictionless_pinch(model: str) -> Problem:
    """Two opposing frictionless fingers squeezing a 0.3 kg object."""
    patch = pressure.disk(0.008, "hertz") if model in AREA_MODEL_NAMES else None
    fingers = [
        Contact(name=name, role="finger", position=[0, side * 0.02, 0], normal=[0, -side, 0],
                mu=0.0, model=model, patch=patch)
        for name, side in (("thumb", -1), ("index", 1))
    ]  # fmt: skip
    return Problem(
        body=Body(mass=0.3, center_of_mass=[0, 0, 0]),
        contacts=fingers,
        loads=[Load(name="hold", force=[0, 0, 0], point=[0, 0, 0])],
        objective="min-max-normal-force",
    )


@pytest.mark.parametrize("model", ["point-cone", "point-pyramid", "ellipsoid", "pyramid", "exact"])
def test_a_frictionless_pinch_cannot_hold_a_weight_and_says_it_falls(model):
    plan = solve(frictionless_pinch(model))
    assert plan.status == "infeasible"
    assert plan.certificate == (
        "load case 'hold' cannot be held: nothing resists the motion in which the body "
        "translates along (0, 0, -1)"
    )
    np.testing.assert_allclose(plan.infeasible_motions["hold"].direction, [0, 0, -1], atol=1e-6)


# -- problem files, the command line and reports -------------------------------------------------

CLAMPED_FILE = """\
schema_version = 1
name = "frictionless-clamp"
kind = "fixture"
objective = "min-total-clamp-force"

[defaults]
mu = 0.4
model = "ellipsoid"

[body]
mass = 1.0
center_of_mass = [0.0, 0.0, 0.015]

[[contacts]]
name = "plate"
role = "support"
position = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]
patch = { shape = "rectangle", length = 0.06, width = 0.04 }

[[contacts]]
name = "clamp"
role = "clamp"
position = [0.0, 0.0, 0.03]
normal = [0.0, 0.0, -1.0]
mu = 0
patch = { shape = "disk", radius = 0.005, pressure = "hertz" }

[[loads]]
name = "push"
force = [20.0, 0.0, 0.0]
point = [0.0, 0.0, 0.0]
"""

PINCH_FILE = """\
schema_version = 1
name = "frictionless-pinch"
kind = "grasp"
objective = "min-max-normal-force"

[defaults]
mu = 0.0
model = "ellipsoid"

[body]
mass = 0.3
center_of_mass = [0.0, 0.0, 0.0]

[[contacts]]
name = "thumb"
role = "finger"
position = [0.0, -0.02, 0.0]
normal = [0.0, 1.0, 0.0]
patch = { shape = "disk", radius = 0.008, pressure = "hertz" }

[[contacts]]
name = "index"
role = "finger"
position = [0.0, 0.02, 0.0]
normal = [0.0, -1.0, 0.0]
patch = { shape = "disk", radius = 0.008, pressure = "hertz" }

[[loads]]
name = "hold"
force = [0.0, 0.0, 0.0]
point = [0.0, 0.0, 0.0]
"""


def test_problem_files_accept_mu_zero_in_a_contact_and_in_the_defaults(tmp_path):
    clamped, pinch = tmp_path / "clamped.toml", tmp_path / "pinch.toml"
    clamped.write_text(CLAMPED_FILE, encoding="utf-8")
    pinch.write_text(PINCH_FILE, encoding="utf-8")
    assert [c.mu for c in load_problem(clamped).problem.contacts] == [0.4, 0.0]
    assert [c.mu for c in load_problem(pinch).problem.contacts] == [0.0, 0.0]


def test_problem_files_reject_a_negative_mu_at_its_key_path(tmp_path):
    path = tmp_path / "clamped.toml"
    path.write_text(CLAMPED_FILE.replace("mu = 0\n", "mu = -0.1\n"), encoding="utf-8")
    with pytest.raises(ProblemFileError) as caught:
        load_problem(path)
    assert [(i.key_path, i.message) for i in caught.value.issues] == [
        ("contacts[1].mu", "expected a number >= 0, got -0.1")
    ]


def test_fixplan_compare_runs_every_model_on_a_frictionless_pinch(tmp_path, capsys):
    path = tmp_path / "pinch.toml"
    path.write_text(PINCH_FILE, encoding="utf-8")
    assert main(["compare", str(path), "--json", "-q"]) == EXIT_NOT_HELD
    rows = json.loads(capsys.readouterr().out)
    assert set(rows) == {"exact", "ellipsoid", "cone", "pyramid", "point-cone", "point-pyramid"}
    assert {row["status"] for row in rows.values()} == {"infeasible"}


def test_a_report_with_a_frictionless_clamp_notes_why_its_sections_are_not_drawn(tmp_path):
    path = tmp_path / "clamped.toml"
    path.write_text(CLAMPED_FILE, encoding="utf-8")
    main(["plan", str(path), "--report", str(tmp_path / "report"), "-q"])
    report = (tmp_path / "report" / "report.md").read_text(encoding="utf-8")
    assert "Contact 'clamp' is frictionless (mu = 0)" in report
    drawn = {p.name for p in (tmp_path / "report").glob("*.png")}
    assert {"layout.png", "contact-00-plate.png", "contact-set.png"} <= drawn
    assert not any("clamp" in name for name in drawn)


def test_fixplan_surface_of_a_frictionless_patch_gives_the_errors_of_its_shape(tmp_path, capsys):
    arguments = ["surface", "--shape", "disk", "--radius", "0.01", "--pressure", "hertz"]
    plot = tmp_path / "surface.png"
    assert main([*arguments, "--mu", "0", "--json", "--plot", str(plot)]) == EXIT_OK
    frictionless = json.loads(capsys.readouterr().out)
    assert main([*arguments, "--mu", "1", "--json"]) == EXIT_OK
    unit = json.loads(capsys.readouterr().out)
    assert frictionless["frictionless"] and not unit["frictionless"]
    assert frictionless["max_force_N"] == 0.0 and frictionless["max_moment_Nm"] == 0.0
    assert frictionless["characteristic_length_m"] == pytest.approx(
        unit["characteristic_length_m"], rel=1e-14
    )
    assert frictionless["models"].keys() == unit["models"].keys()
    for name, errors in unit["models"].items():
        assert frictionless["models"][name] == pytest.approx(errors, abs=1e-9), name
    assert plot.stat().st_size > 0
