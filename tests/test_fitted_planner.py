"""Fitted limit surfaces in the planner (issue 11 §2): the quartic's polytope of tangent planes
and its reported error, and problem files whose contacts name a saved fit.

References: radial distances found by bisection along random rays (on the quartic's level
``H(t d) = 1`` and on the polytope's containment test), the planner's optimum with the same
model object built in Python, and the fit's own surface.
"""

import dataclasses
from functools import cache

import numpy as np
import pytest

from fixplan import LimitSurface, pressure
from fixplan.io.cli import EXIT_OK, main
from fixplan.io.problem_file import ProblemFileError, check_problem, load_problem
from fixplan.models import FittedEllipsoid, Polytope
from fixplan.motion import Fit, fit, synthetic
from fixplan.planner.planner import solve
from fixplan.planner.problem import Body, Contact, Load, Problem

#: The paper's Fig. 5 rectangle (10:1), whose quartic fit is far from an ellipsoid.
RECTANGLE = LimitSurface(pressure.rectangle(0.1, 0.01), mu=0.25, normal_force=200.0)
#: Bisection steps: halves a bracket of width 4 to below 1e-15 of it.
BISECTIONS = 60


@cache
def fitted(model: str) -> Fit:
    loads, twists = synthetic(RECTANGLE, 200, seed=1)
    return fit(loads, twists, model=model, normal_force=200.0, holdout=0.0)


def radius_by_bisection(inside, directions: np.ndarray) -> np.ndarray:
    """Largest ``t`` with ``inside(t d)`` along each direction ``d`` (``t`` in [0, 4])."""
    low, high = np.zeros(len(directions)), np.full(len(directions), 4.0)
    for _ in range(BISECTIONS):
        middle = 0.5 * (low + high)
        held = inside(directions * middle[:, None])
        low, high = np.where(held, middle, low), np.where(held, high, middle)
    return low


def random_rays(quartic, count: int) -> np.ndarray:
    """Random load directions ``(count, 3)`` per unit normal force, of about the surface's size."""
    units = np.array([quartic.max_force, quartic.max_force, quartic.max_moment])
    rays = np.random.default_rng(4).normal(size=(count, 3))
    return rays / np.linalg.norm(rays, axis=1, keepdims=True) * units / quartic.normal_force


@pytest.mark.parametrize("inscribed", [False, True])
def test_the_reported_error_bounds_the_radial_gap_found_by_bisection(inscribed):
    quartic = fitted("quartic").surface
    polytope = quartic.planner_model(cuts=128, inscribed=inscribed)
    rays = random_rays(quartic, 4000)
    surface = radius_by_bisection(lambda x: quartic.level(x * quartic.normal_force) <= 1.0, rays)
    cut = radius_by_bisection(lambda x: polytope.contains(x, normal_force=1.0), rays)
    ratio = cut / surface
    error = polytope.error
    assert 0.0 < error < 0.1
    if inscribed:
        assert ratio.max() <= 1.0 + 1e-12
        assert ratio.min() >= 1.0 / (1.0 + error) - 1e-12
        assert ratio.min() <= 1.0 / (1.0 + 0.7 * error)  # the bound is nearly attained
    else:
        assert ratio.min() >= 1.0 - 1e-12
        assert ratio.max() <= 1.0 + error + 1e-12
        assert ratio.max() >= 1.0 + 0.7 * error


def test_the_error_shrinks_about_as_one_over_the_number_of_cuts():
    quartic = fitted("quartic").surface
    errors = [quartic.planner_model(cuts=cuts).error for cuts in (64, 256, 1024)]
    # Facets of width ~ n^(-1/2) on a smooth surface leave gaps ~ 1/n: 4x the cuts, 1/4 the gap.
    assert errors[0] / errors[1] > 2.5 and errors[1] / errors[2] > 2.5
    assert errors[1] < 0.03


def test_the_polytope_is_per_unit_normal_force_with_the_fits_mu():
    quartic = fitted("quartic").surface
    polytope = quartic.planner_model(cuts=64)
    assert polytope.normal_force == 1.0 and polytope.mu == pytest.approx(quartic.mu, rel=1e-15)
    assert polytope.rho == pytest.approx(quartic.characteristic_length, rel=1e-15)
    assert polytope.conservative and len(polytope.rows) == 32


def block_on(model, push: Load) -> Problem:
    base = Contact(name="base", role="support", position=[0, 0, 0], normal=[0, 0, 1],
                   mu=model.mu, model=model)  # fmt: skip
    body = Body(mass=20.0, center_of_mass=[0, 0, 0.05])
    return Problem(body=body, contacts=[base], loads=[push], objective="max-safety-factor")


def test_the_planner_never_holds_more_than_the_fitted_quartic_and_less_by_at_most_its_error():
    quartic = fitted("quartic").surface
    polytope = quartic.planner_model(cuts=256)
    weight = 20.0 * 9.81
    for k, (fx, fy, mz) in enumerate([(3.0, -1.0, 0.05), (0.0, 2.0, 0.3), (1.0, 0.0, -0.02)]):
        push = Load(name=f"push-{k}", force=[fx, fy, 0.0], point=[0, 0, 0], torque=[0, 0, mz])
        planned = solve(block_on(polytope, push)).safety_factors[push.name]
        # The quartic holds at its normal force: scale the load to it.
        held = quartic.safety_factor(np.array([fx, fy, mz]) * quartic.normal_force / weight)
        assert held / (1.0 + polytope.error) * (1 - 1e-6) <= planned <= held * (1 + 1e-6)


# -- problem files -------------------------------------------------------------------------------

PINCH = """\
schema_version = 1
name = "fitted-pinch"
kind = "grasp"
objective = "min-max-normal-force"

[body]
mass = 0.5
center_of_mass = [0.01, 0.0, 0.0]

[[contacts]]
name = "left"
role = "finger"
position = [0.0, -0.02, 0.0]
normal = [0.0, 1.0, 0.0]
model = "fitted"
fit = "fits/pad.json"
# extra

[[contacts]]
name = "right"
role = "finger"
position = [0.0, 0.02, 0.0]
normal = [0.0, -1.0, 0.0]
model = "fitted"
fit = "fits/pad.json"
# extra

[[loads]]
name = "pull"
force = [2.0, 0.0, -3.0]
point = [0.03, 0.0, 0.0]
"""


def write_problem(folder, model="quartic", extra=""):
    (folder / "fits").mkdir(exist_ok=True)
    fitted(model).save(folder / "fits" / "pad.json")
    path = folder / "pinch.toml"
    path.write_text(PINCH.replace("# extra", extra), encoding="utf-8")
    return path


def python_pinch(model) -> Problem:
    """The problem of :data:`PINCH` built in Python with the friction model object ``model``."""
    contacts = [
        Contact(name=name, role="finger", position=[0, side * 0.02, 0], normal=[0, -side, 0],
                mu=model.mu, model=model)
        for name, side in (("left", -1), ("right", 1))
    ]  # fmt: skip
    body = Body(mass=0.5, center_of_mass=[0.01, 0, 0])
    load = Load(name="pull", force=[2.0, 0.0, -3.0], point=[0.03, 0.0, 0.0])
    return Problem(body=body, contacts=contacts, loads=[load], objective="min-max-normal-force")


@pytest.mark.parametrize(
    ("model", "extra", "python_model"),
    [
        ("quartic", "", lambda surface: surface.planner_model()),
        ("quartic", "cuts = 64", lambda surface: surface.planner_model(cuts=64)),
        ("ellipsoid", "", lambda surface: dataclasses.replace(surface, normal_force=1.0)),
    ],
    ids=["quartic-default-cuts", "quartic-64-cuts", "ellipsoid"],
)
def test_a_problem_naming_a_saved_fit_plans_as_the_same_model_built_in_python(
    model, extra, python_model, tmp_path
):
    problem_file = load_problem(write_problem(tmp_path, model, extra))
    contact = problem_file.problem.contacts[0]
    surface = fitted(model).surface
    expected_type = Polytope if model == "quartic" else FittedEllipsoid
    assert isinstance(contact.model, expected_type) and contact.mu == surface.mu
    plan = solve(problem_file.problem)
    reference = solve(python_pinch(python_model(surface)))
    assert plan.status == reference.status == "optimal"
    assert plan.objective_value == pytest.approx(reference.objective_value, rel=1e-9)


def test_check_and_plan_accept_a_problem_with_a_saved_fit(tmp_path, capsys):
    path = write_problem(tmp_path)
    assert check_problem(path).problem.contacts[1].model.error > 0.0
    assert main(["check", str(path)]) == EXIT_OK
    assert "valid" in capsys.readouterr().out
    assert main(["plan", str(path)]) == EXIT_OK


def test_a_model_override_replaces_the_fit_but_keeps_its_mu(tmp_path):
    problem = load_problem(write_problem(tmp_path), model="point-cone").problem
    assert problem.contacts[0].model == "point-cone"
    assert problem.contacts[0].mu == fitted("quartic").surface.mu


def test_a_contact_mu_that_agrees_with_the_fit_is_accepted(tmp_path):
    mu = fitted("quartic").surface.mu
    problem = load_problem(write_problem(tmp_path, extra=f"mu = {mu:.9g}")).problem
    assert problem.contacts[0].mu == mu


@pytest.mark.parametrize(
    ("edit", "key_path", "message"),
    [
        (lambda p: p.replace("fits/pad.json\"\n#", "fits/nope.json\"\n#"), "contacts[0].fit",
         "No such file"),
        (lambda p: p.replace("fits/pad.json\"\n#", "fits\"\n#"), "contacts[0].fit", "a folder"),
        (lambda p: p.replace('fit = "fits/pad.json"\n# extra', "# extra"), "contacts[0].fit",
         "missing required key"),
        (lambda p: p.replace("# extra", "mu = 0.3"), "contacts[0].mu", "contradicts the fit's mu"),
        (lambda p: p.replace("# extra", "cuts = 65"), "contacts[0].cuts", "even integer"),
        (lambda p: p.replace("# extra", "cuts = 2"), "contacts[0].cuts", "integer >= 6"),
        (lambda p: p.replace("# extra", 'patch = { shape = "disk", radius = 0.01 }'),
         "contacts[0].patch", "not for model 'fitted'"),
        (lambda p: p.replace('"fitted"\nfit = "fits/pad.json"\n# extra',
                             '"point-cone"\nmu = 0.5\nfit = "fits/pad.json"\n# extra'),
         "contacts[0].fit", "only for model 'fitted'"),
    ],
    ids=["missing", "folder", "no-fit", "contradicting-mu", "odd-cuts", "few-cuts", "patch",
         "fit-without-fitted"],
)  # fmt: skip
def test_a_bad_fitted_contact_is_reported_with_the_file_and_key_path(
    edit, key_path, message, tmp_path
):
    path = write_problem(tmp_path)
    path.write_text(edit(PINCH), encoding="utf-8")
    with pytest.raises(ProblemFileError) as error:
        load_problem(path)
    text = str(error.value)
    assert f"{path}: {key_path}: " in text and message in text


def test_cuts_on_an_ellipsoid_fit_are_reported(tmp_path):
    path = write_problem(tmp_path, "ellipsoid", "cuts = 64")
    with pytest.raises(ProblemFileError, match=r"contacts\[0\]\.cuts: only for a quartic fit"):
        load_problem(path)


@pytest.mark.parametrize(
    ("content", "message"),
    [("{not json", "cannot read a fit as JSON"), ('{"format": "fixplan.fit"}', "key 'version'")],
    ids=["not-json", "missing-key"],
)
def test_a_broken_fit_file_is_reported_at_the_contacts_fit_key(content, message, tmp_path):
    path = write_problem(tmp_path)
    (tmp_path / "fits" / "pad.json").write_text(content, encoding="utf-8")
    with pytest.raises(ProblemFileError) as error:
        load_problem(path)
    text = str(error.value)
    assert f"{path}: contacts[0].fit: cannot read the fit file 'fits/pad.json'" in text
    assert message in text
