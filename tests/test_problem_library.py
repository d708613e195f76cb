"""The problem library: every file in problems/ solves to the answer its comment block states,
cross-checked against hand calculations where one exists, and the examples run.

Each problem is solved once per session (``_solved``). The expected numbers were computed once
with the planner and are asserted to ``RTOL``; the hand calculations are independent of the
planner (closed forms of the paper and DESIGN.md §4) and carry their own stated tolerances.
"""

from __future__ import annotations

import functools
import math
import subprocess
import sys
import tomllib
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np
import pytest

from fixplan import LimitSurface, pressure
from fixplan.io.cli import EXIT_NOT_HELD, EXIT_OK, main
from fixplan.io.problem_file import load_problem
from fixplan.motion import hertz_sphere
from fixplan.planner.contact_models import contact_model
from fixplan.planner.planner import Planner
from fixplan.planner.problem import MODEL_NAMES

ROOT = Path(__file__).resolve().parents[1]
PROBLEMS = ROOT / "problems"
EXAMPLES = ROOT / "examples"

#: Relative tolerance of the recorded numbers (the solver is accurate to about 1e-7).
RTOL = 1e-4
#: Tolerance of a safety factor that a least-force plan puts on the limit (s = 1).
ON_LIMIT_ATOL = 1e-5
#: Absolute tolerance on unit directions and on points of motion axes [m].
AXIS_ATOL = 1e-6
#: Objectives the library must show in use.
OBJECTIVES = (
    "min-total-clamp-force",
    "min-max-normal-force",
    "min-total-normal-force",
    "max-safety-factor",
    "check",
    "check-compliant",
)


@dataclass(frozen=True, slots=True, kw_only=True)
class Expected:
    """What a problem file must give.

    ``objective_value`` in N or as a safety factor; ``safety_factor`` the smallest over the load
    cases (1.0 where a least-force plan puts its critical case on the limit, checked to
    ``ON_LIMIT_ATOL``); ``critical_load`` only where it is unique; ``free_axis`` the direction
    of the unresisted rotation of every load case of an infeasible problem, through
    ``free_point`` [m].
    """

    status: str
    objective_value: float | None = None
    safety_factor: float | None = None
    critical_load: str | None = None
    safety_factors: dict | None = None
    free_axis: tuple[float, float, float] | None = None
    free_point: tuple[float, float, float] | None = None


EXPECTED = {
    "vise-milling": Expected(
        status="optimal",
        objective_value=1293.132015,
        safety_factor=1.0,
        critical_load="end-mill-profile-climb",
        safety_factors={"face-mill-feed-plus-x": 2.052738, "face-mill-feed-minus-x": 2.449197},
    ),
    "three-pads": Expected(
        status="optimal",
        objective_value=0.7432697,
        safety_factor=0.7432697,
        critical_load="operator-shove",
        safety_factors={"push-through-centre": 1.635, "twist": 1.308, "brush-front-edge": 1.544674},
    ),
    "fixture-321": Expected(
        status="optimal",
        objective_value=487.104755,
        safety_factor=1.0,
        critical_load="slot-feed-plus-x",
    ),
    "fixture-321-compliant": Expected(
        status="optimal",
        objective_value=4.103240,
        safety_factor=4.103240,
        critical_load="drill-outside-supports",
        safety_factors={"slot-feed-plus-x": 4.462649, "face-mill-minus-x": math.inf},
    ),
    "hertz-pinch": Expected(status="optimal", objective_value=23.220633, safety_factor=1.0),
    "three-finger-grasp": Expected(status="optimal", objective_value=26.060177, safety_factor=1.0),
    "tactile-pinch": Expected(
        status="optimal",
        objective_value=1.545727,
        safety_factor=1.545727,
        critical_load="twist",
        safety_factors={
            "lift-accelerating": 10.232416,
            "pull-out": 3.946174,
            "tap-on-corner": 1.820946,
        },
    ),
    "point-grasp": Expected(status="optimal", objective_value=37.025, safety_factor=1.0),
    "pick-and-place": Expected(status="optimal", objective_value=7.905, safety_factor=1.0),
    "unholdable": Expected(
        status="infeasible", free_axis=(0.0, 1.0, 0.0), free_point=(0.0, 0.0, 0.0)
    ),
}


@functools.cache
def _solved(name: str):
    """``(problem file, plan)`` of ``problems/<name>.toml``, solved once per session."""
    problem_file = load_problem(PROBLEMS / f"{name}.toml")
    return problem_file, Planner(problem_file.problem).solve()


def _library() -> list[Path]:
    """The planning problems (push files are tested in test_push_files.py)."""
    return sorted(p for p in PROBLEMS.glob("*.toml") if not p.stem.startswith("push-"))


# -- the library as a whole ----------------------------------------------------------------------


def test_every_problem_file_has_an_expected_outcome():
    files = {path.stem for path in _library()}
    assert files == set(EXPECTED), (
        f"problem files without an expectation: {sorted(files - set(EXPECTED))}; expectations "
        f"without a file: {sorted(set(EXPECTED) - files)}"
    )


@pytest.mark.parametrize("path", _library(), ids=lambda p: p.stem)
def test_every_problem_file_explains_its_setting_and_expected_answer(path):
    text = path.read_text(encoding="utf-8")
    document = tomllib.loads(text)
    assert text.startswith("# "), "open the file with a comment block"
    assert "Expected answer" in text.split("schema_version")[0]
    assert document["name"] == path.stem
    assert document.get("description", "").strip()


def test_the_library_uses_every_objective_and_every_model():
    problems = [load_problem(path).problem for path in _library()]
    objectives = {problem.objective for problem in problems}
    models = {contact.model for problem in problems for contact in problem.contacts}
    assert objectives >= set(OBJECTIVES)
    assert models >= set(MODEL_NAMES)


@pytest.mark.parametrize("name", sorted(EXPECTED))
def test_problem_file_gives_its_expected_outcome(name):
    expected = EXPECTED[name]
    _, plan = _solved(name)
    assert plan.status == expected.status, plan.warnings
    if expected.objective_value is None:
        assert plan.objective_value is None
    else:
        assert plan.objective_value == pytest.approx(expected.objective_value, rel=RTOL)
    if expected.safety_factor == 1.0:
        assert plan.safety_factor == pytest.approx(1.0, abs=ON_LIMIT_ATOL)
    elif expected.safety_factor is not None:
        assert plan.safety_factor == pytest.approx(expected.safety_factor, rel=RTOL)
    if expected.critical_load is not None:
        assert plan.critical_load == expected.critical_load
    for load, value in (expected.safety_factors or {}).items():
        assert plan.safety_factors[load] == pytest.approx(value, rel=RTOL), load
    if expected.free_axis is not None:
        assert set(plan.infeasible_motions) == set(plan.load_names)
        for load, motion in plan.infeasible_motions.items():
            assert not motion.is_translation
            assert motion.direction == pytest.approx(expected.free_axis, abs=AXIS_ATOL), load
            assert motion.point == pytest.approx(expected.free_point, abs=AXIS_ATOL), load
            assert f"load case {load!r} cannot be held" in plan.certificate


@pytest.mark.parametrize(
    "name",
    [
        "hertz-pinch",
        "point-grasp",
        "vise-milling",
        "fixture-321",
        "three-finger-grasp",
    ],
)
def test_least_force_plans_hold_every_load_case(name):
    _, plan = _solved(name)
    assert all(plan.held.values()), plan.safety_factors


@pytest.mark.parametrize(
    ("name", "code", "words"),
    [
        ("unholdable", EXIT_NOT_HELD, "'lift-slowly' cannot be held"),
        ("three-pads", EXIT_NOT_HELD, "NOT HELD"),
        ("point-grasp", EXIT_OK, "optimal"),
    ],
)
def test_command_line_exit_code_and_summary(name, code, words, capsys):
    assert main(["plan", str(PROBLEMS / f"{name}.toml"), "--quiet"]) == code
    assert words in capsys.readouterr().out


# -- hand calculations -----------------------------------------------------------------------------


def _contact(problem_file, name):
    return next(c for c in problem_file.problem.contacts if c.name == name)


def _total_load(problem_file, load_name):
    """Task load plus gravity: ``(force [N], moment about the world origin [N m])``."""
    problem = problem_file.problem
    load = next(x for x in problem.loads if x.name == load_name)
    wrench = load.wrench + problem.body.weight_wrench
    return wrench[:3], wrench[3:]


def test_point_grasp_needs_the_coulomb_cone_grip_force():
    # Two Coulomb point contacts on the y axis, loads through the grasp centre: moment balance
    # gives both fingers the same friction force, half the force F_t across the grasp axis,
    # and F_y loads one finger more: N_max = |F_t| / (2 mu) + |F_y|.
    problem_file, plan = _solved("point-grasp")
    mu = _contact(problem_file, "finger-left").mu
    for j, load in enumerate(plan.load_names):
        force, _ = _total_load(problem_file, load)
        expected = math.hypot(force[0], force[2]) / (2.0 * mu) + abs(force[1])
        largest = max(plan.forces["finger-left"][j], plan.forces["finger-right"][j])
        assert largest == pytest.approx(expected, rel=1e-6), load
    assert plan.objective_value == pytest.approx(1.5 * (9.81 + 5.0) / (2 * 0.3), rel=1e-6)


def test_hertz_pinch_needs_the_ellipsoid_closed_form_grip_force():
    # Each finger carries half the force F and half the torsion M about the grasp axis (y);
    # the Table 2 ellipsoid of a Hertzian disk, m_max = (3π/16) mu N R, gives
    # N = sqrt((F/2/mu)² + (M/2/(mu k R))²).
    problem_file, plan = _solved("hertz-pinch")
    finger = _contact(problem_file, "finger-left")
    k = 3.0 * math.pi / 16.0
    for j, load in enumerate(plan.load_names):
        force, moment = _total_load(problem_file, load)
        f, m = math.hypot(force[0], force[2]) / 2.0, abs(moment[1]) / 2.0
        expected = math.hypot(f / finger.mu, m / (finger.mu * k * finger.patch.radius))
        for name in ("finger-left", "finger-right"):
            assert plan.forces[name][j] == pytest.approx(expected, rel=1e-6), (load, name)


def test_pick_and_place_grip_is_the_closed_form_of_each_phase_of_the_motion():
    # Only the block's motion loads the grasp: F = m |g - a| in the fingers' plane and
    # M = I_yy α_y about the grasp axis (a uniform box: I_yy = m (a² + c²) / 12), with the same
    # ellipsoid closed form as the Hertz pinch; written out from the file's numbers.
    problem_file, plan = _solved("pick-and-place")
    document = tomllib.loads((PROBLEMS / "pick-and-place.toml").read_text(encoding="utf-8"))
    mass, (a, _, c) = document["body"]["mass"], document["body"]["size"]
    mu, radius, k = 0.8, 0.006, 3.0 * math.pi / 16.0
    for j, load in enumerate(document["loads"]):
        ax, _, az = load.get("acceleration", [0.0, 0.0, 0.0])
        alpha = load.get("angular_acceleration", [0.0, 0.0, 0.0])[1]
        force = mass * math.hypot(ax, 9.81 + az)
        moment = mass * (a * a + c * c) / 12.0 * alpha
        expected = math.hypot(force / 2 / mu, moment / 2 / (mu * k * radius))
        for name in ("finger-left", "finger-right"):
            assert plan.forces[name][j] == pytest.approx(expected, rel=1e-6), (load["name"], name)
    assert problem_file.problem.body.inertia[1, 1] == pytest.approx(mass * (a * a + c * c) / 12)


def test_hertz_pinch_ellipsoid_is_within_half_a_percent_of_the_exact_limit_surface():
    # Paper Fig. 3: the ellipse lies close to the exact limit curve of a Hertzian disk.
    exact = load_problem(PROBLEMS / "hertz-pinch.toml", model="exact").problem
    exact_grip = Planner(exact).solve(analyse=False).objective_value
    assert exact_grip == pytest.approx(EXPECTED["hertz-pinch"].objective_value, rel=5e-3)


def test_three_finger_grasp_matches_the_symmetric_closed_form():
    # Three fingers 120° apart at radius r: for a vertical force F_z plus a torque T about the
    # jar's axis each finger carries F_z/3 and T/(3r) without torsion, so the least total
    # grip is sqrt(F_z² + (T/r)²) / mu.
    problem_file, plan = _solved("three-finger-grasp")
    thumb = _contact(problem_file, "thumb")
    radius = float(np.hypot(*thumb.position[:2]))
    for load in ("lift", "hold-for-lid-opening"):
        force, moment = _total_load(problem_file, load)
        assert np.allclose(force[:2], 0.0) and np.allclose(moment[:2], 0.0)
        expected = math.hypot(force[2], moment[2] / radius) / thumb.mu
        j = plan.load_names.index(load)
        total = sum(plan.forces[name][j] for name in ("thumb", "index", "middle"))
        assert total == pytest.approx(expected, rel=1e-6), load
        assert plan.forces["thumb"][j] == pytest.approx(expected / 3.0, rel=1e-4), load


def test_three_pads_safety_factors_are_those_of_the_faceted_planar_limit_surface():
    problem_file, plan = _solved("three-pads")
    contacts = problem_file.problem.contacts
    mu, weight = contacts[0].mu, problem_file.problem.body.mass * 9.81
    r = float(np.hypot(*contacts[0].position[:2]))
    side = r * math.sqrt(3.0)
    # Hand calculations of the file's comment block (DESIGN.md §2, paper §2.5).
    assert plan.safety_factors["push-through-centre"] == pytest.approx(mu * weight / 6.0, rel=1e-7)
    assert plan.safety_factors["twist"] == pytest.approx(mu * weight * r / 0.45, rel=1e-7)
    facet = 2.0 * mu * (weight / 3.0) * side / (4.0 * (0.06 + 0.05))
    assert plan.safety_factors["brush-front-edge"] == pytest.approx(facet, rel=1e-7)
    # Every load against the planar limit surface of the three points, and the in-plane part
    # (vx, vy, wz) of the impending motion against its normal (normality).
    xy = np.array([c.position[:2] for c in contacts])
    surface = LimitSurface(pressure.points(xy, centered=False), mu=mu, normal_force=weight)
    for load in problem_file.problem.loads:
        planar = np.array([load.force[0], load.force[1], load.wrench[5]])
        assert plan.safety_factors[load.name] == pytest.approx(
            surface.safety_factor(planar), rel=1e-7
        )
        twist = plan.motions[load.name].twist[[0, 1, 5]]
        normal = surface.motion(planar)
        assert np.cross(twist / np.linalg.norm(twist), normal / np.linalg.norm(normal)) == (
            pytest.approx(np.zeros(3), abs=1e-5)
        ), load.name
    # On the facet of pad "rear" the part turns about that pad.
    motion = plan.motions["brush-front-edge"]
    offset = _contact(problem_file, "rear").position - motion.point
    assert np.linalg.norm(np.cross(offset, motion.direction)) < AXIS_ATOL
    assert plan.held == {
        "push-through-centre": True,
        "twist": True,
        "brush-front-edge": True,
        "operator-shove": False,
    }


def _abs_moment(x0: float, x1: float, y0: float, y1: float) -> float:
    """``∫∫ sqrt(x² + y²) dx dy`` over ``[x0, x1] × [y0, y1]`` [m³] (DESIGN.md §4)."""

    def corner(x: float, y: float) -> float:
        ax, ay, r = abs(x), abs(y), math.hypot(x, y)
        value = 2.0 * ax * ay * r
        value += ax**3 * math.asinh(ay / ax) if ax else 0.0
        value += ay**3 * math.asinh(ax / ay) if ay else 0.0
        return math.copysign(1.0, x) * math.copysign(1.0, y) * value / 6.0

    return corner(x1, y1) - corner(x0, y1) - corner(x1, y0) + corner(x0, y0)


def test_tactile_pinch_margins_match_the_coulomb_circle_and_the_maps_maximum_moment():
    problem_file, plan = _solved("tactile-pinch")
    finger = _contact(problem_file, "finger-left")
    grip, mu = finger.force, finger.mu
    weight = problem_file.problem.body.mass * 9.81
    loads = {load.name: load for load in problem_file.problem.loads}
    # Forces through the grasp axis: each finger holds at most mu N of friction.
    lift = (2.0 * mu * grip - weight) / -loads["lift-accelerating"].force[2]
    pull_force = loads["pull-out"].force[0]
    pull = 2.0 * math.sqrt((mu * grip) ** 2 - (weight / 2.0) ** 2) / pull_force
    assert plan.safety_factors["lift-accelerating"] == pytest.approx(lift, rel=1e-6)
    assert plan.safety_factors["pull-out"] == pytest.approx(pull, rel=1e-6)
    # Torsion: the map's maximum moment about its centre of pressure, cell by cell in closed
    # form (uniform pressure within each 2.5 mm cell), then the untilted ellipsoid.
    table = tomllib.loads((PROBLEMS / "tactile-pinch.toml").read_text(encoding="utf-8"))
    grid = table["contacts"][0]["patch"]
    values = np.loadtxt(PROBLEMS / grid["values"], delimiter=",")
    x, y = np.asarray(grid["x"]), np.asarray(grid["y"])
    half = (x[1] - x[0]) / 2.0
    xx, yy = np.meshgrid(x, y)
    cx, cy = (values * xx).sum() / values.sum(), (values * yy).sum() / values.sum()
    integral = sum(
        p * _abs_moment(xc - half - cx, xc + half - cx, yc - half - cy, yc + half - cy)
        for p, xc, yc in zip(values.ravel(), xx.ravel(), yy.ravel(), strict=True)
    )
    max_moment = mu * grip * integral / (values.sum() * (2.0 * half) ** 2)
    assert contact_model(finger).rho * mu * grip == pytest.approx(max_moment, rel=1e-9)
    torque = loads["twist"].torque[1]
    twist = 2.0 * max_moment * math.sqrt(1.0 - (weight / 2.0 / (mu * grip)) ** 2) / torque
    assert plan.safety_factors["twist"] == pytest.approx(twist, rel=1e-3)
    motion = plan.motions["twist"]
    assert abs(motion.direction[1]) == pytest.approx(1.0, abs=1e-6)
    assert np.hypot(motion.point[0], motion.point[2]) < 2e-3


def test_vise_jaws_modelled_by_the_conservative_cone_need_a_little_more_clamping():
    exact_grip = EXPECTED["vise-milling"].objective_value
    cone = load_problem(PROBLEMS / "vise-milling.toml", model="cone").problem
    cone_grip = Planner(cone).solve(analyse=False).objective_value
    assert exact_grip < cone_grip < 1.01 * exact_grip


def test_fixture_clamp_total_is_the_least_that_holds_every_cut():
    # The plan's clamp forces hold every case; 1 % less of both no longer holds the critical one.
    problem_file, plan = _solved("fixture-321")
    for scale, held in ((1.0, True), (0.99, False)):
        contacts = tuple(
            replace(c, force=scale * plan.forces[c.name]) if c.role == "clamp" else c
            for c in problem_file.problem.contacts
        )
        check = replace(problem_file.problem, contacts=contacts, objective="check")
        result = Planner(check).solve()
        assert (result.safety_factor >= 1.0 - ON_LIMIT_ATOL) is held
        assert result.critical_load == "slot-feed-plus-x"


@pytest.mark.parametrize(
    ("contacts", "radius", "preload"),
    [
        (("rest-a", "rest-b", "rest-c", "side-pin-a", "side-pin-b", "end-pin"), 0.01, 300.0),
        (("clamp-top",), 0.05, 1000.0),
        (("clamp-side", "clamp-end"), 0.05, 400.0),
    ],
)
def test_compliant_fixture_stiffnesses_are_the_hertz_contacts_its_comment_states(
    contacts, radius, preload
):
    steel = {"young": 210e9, "poisson": 0.3, "young_flat": 210e9, "poisson_flat": 0.3}
    expected = hertz_sphere(radius=radius, preload=preload, **steel)
    stiffness = load_problem(PROBLEMS / "fixture-321-compliant.toml").stiffness
    for name in contacts:
        for key in ("normal", "tangential", "torsional"):
            given, hertz = getattr(stiffness[name], key), getattr(expected, key)
            assert given == pytest.approx(hertz, rel=5e-3), (name, key)


# -- examples ------------------------------------------------------------------------------------


@pytest.mark.slow
@pytest.mark.parametrize(
    ("script", "png", "words"),
    [
        ("fixture_sweep.py", "fixture_sweep.png", "<- least"),
        ("grasp_mu_study.py", "grasp_mu_study.png", "cannot"),
    ],
)
def test_example_runs_and_writes_its_plot(script, png, words, tmp_path):
    result = subprocess.run(
        [sys.executable, str(EXAMPLES / script), "--out", str(tmp_path)],
        capture_output=True,
        text=True,
        timeout=300,
        cwd=tmp_path,
    )
    assert result.returncode == 0, result.stderr
    assert words in result.stdout
    assert (tmp_path / png).stat().st_size > 10_000


@pytest.mark.slow
def test_the_pushing_example_runs_and_writes_its_figures(tmp_path):
    result = subprocess.run(
        [sys.executable, str(EXAMPLES / "pushing.py"), "--figures", str(tmp_path)],
        capture_output=True,
        text=True,
        timeout=300,
        cwd=tmp_path,
    )
    assert result.returncode == 0, result.stderr
    assert "flush against the face after 59.8 mm of pusher travel" in result.stdout
    for name in ("push-finger.png", "push-finger.gif", "push-flat.png", "push-flat.gif"):
        assert (tmp_path / name).stat().st_size > 10_000


@pytest.mark.slow
def test_mujoco_confirms_the_critical_case_of_every_least_force_plan(tmp_path):
    """``examples/validate_library.py --quick``: the critical case of every problem with an
    optimal plan, held at +10 % whenever the plan holds it, on the limit (slip onset within 2 %
    of the safety factor) where a least-force plan put it."""
    table = tmp_path / "table.md"
    result = subprocess.run(
        [sys.executable, str(EXAMPLES / "validate_library.py"), "--quick", "--markdown",
         str(table)],
        capture_output=True, text=True, timeout=600, cwd=tmp_path,
    )  # fmt: skip
    assert result.returncode == 0, result.stdout + result.stderr
    rows = {line.split(" | ")[0].strip("| "): line.split(" | ") for line in
            table.read_text(encoding="utf-8").splitlines()[2:]}  # fmt: skip
    for name in ("hertz-pinch", "point-grasp", "fixture-321", "three-finger-grasp"):
        assert rows[name][3] == "held" and rows[name][4] == "slips", rows[name]
        assert float(rows[name][5]) == pytest.approx(1.0, abs=0.02), rows[name]
