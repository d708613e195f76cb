"""MuJoCo judges plans: the issue's checks of a soft pinch and of point contacts."""

import json
from pathlib import Path

import mujoco
import numpy as np
import pytest

from fixplan.errors import InvalidArgumentError
from fixplan.io.cli import EXIT_INVALID_INPUT, EXIT_NOT_HELD, EXIT_OK, main
from fixplan.io.problem_file import load_problem
from fixplan.planner.planner import Planner
from fixplan.sim.validate import validate

PROBLEMS = Path(__file__).resolve().parents[1] / "problems"


def _planned(name):
    problem = load_problem(PROBLEMS / f"{name}.toml").problem
    return problem, Planner(problem).solve()


def test_a_soft_pinch_holds_at_110_percent_slips_at_90_onset_and_direction_as_planned():
    """Hertz fingertips, ellipsoid model (condim 4), a weight off the grasp axis: slip onset
    within 2 % of the planned load and the slip twist within 2° of the plan's motion."""
    problem, plan = _planned("hertz-pinch")
    (case,) = validate(problem, plan, loads=["lift-accelerating"])
    assert case.planned_held and case.above.held and not case.below.held
    assert case.onset_ratio == pytest.approx(1.0, abs=0.02)
    assert np.degrees(case.motion_angle) < 2.0
    assert not case.contradicts
    times, slips = case.below.history[:, 0], case.below.history[:, 1]
    assert np.all(np.diff(times) > 0) and slips[-1] == pytest.approx(case.below.displacement)


def test_point_contacts_hold_every_case_at_110_percent_and_the_critical_one_slips_at_90():
    problem, plan = _planned("point-grasp")
    cases = {case.load: case for case in validate(problem, plan)}
    assert all(case.above.held for case in cases.values()), {
        name: case.above.displacement for name, case in cases.items()
    }
    assert not cases[plan.critical_load].below.held


def test_the_nose_cone_squeezed_by_point_fingers_is_held_at_110_percent_and_slips_at_90():
    """Lobo and Boyd's nose cone (five point fingers whose forces alone push it out): held at
    +10 %, slipping at -10 %, the slip beginning within 2 % of the planned load."""
    import reference_planner as ref

    problem = ref.nose_cone_problem()
    plan = Planner(problem).solve()
    (case,) = validate(problem, plan)
    assert case.above.held and not case.below.held
    assert case.onset_ratio == pytest.approx(1.0, abs=0.02)


def test_bad_requests_are_refused():
    problem, plan = _planned("hertz-pinch")
    with pytest.raises(InvalidArgumentError, match="margin"):
        validate(problem, plan, margin=1.5)
    with pytest.raises(InvalidArgumentError, match="unknown load case"):
        validate(problem, plan, loads=["nothing"])


def test_an_export_over_its_problem_file_or_into_no_folder_is_refused_before_solving(
    tmp_path, capsys
):
    problem = tmp_path / "pinch.toml"
    problem.write_text((PROBLEMS / "hertz-pinch.toml").read_text(encoding="utf-8"), "utf-8")
    before = problem.read_bytes()
    assert main(["export", str(problem), "--mujoco", str(problem)]) == EXIT_INVALID_INPUT
    assert "that is the problem file; name another file" in capsys.readouterr().err
    assert problem.read_bytes() == before
    missing = tmp_path / "nowhere" / "pinch.xml"
    assert main(["export", str(problem), "--mujoco", str(missing)]) == EXIT_INVALID_INPUT
    assert "does not exist; create it first" in capsys.readouterr().err


def test_the_command_line_validates_exports_and_reports(tmp_path, capsys):
    pinch = str(PROBLEMS / "hertz-pinch.toml")
    code = main(["validate", pinch, "--load", "lift-accelerating", "--json",
                 "--report", str(tmp_path / "report")])  # fmt: skip
    assert code == EXIT_OK
    (case,) = json.loads(capsys.readouterr().out)["cases"]
    assert case["above"]["held"] and not case["below"]["held"] and not case["contradicts"]
    assert (tmp_path / "report" / "case-1.png").is_file()
    scene = tmp_path / "pinch.xml"
    assert main(["export", pinch, "--mujoco", str(scene), "--load", "insert-tip"]) == EXIT_OK
    mujoco.MjModel.from_xml_path(str(scene))
    assert main(["validate", str(PROBLEMS / "unholdable.toml")]) == EXIT_NOT_HELD
    assert "no forces to simulate" in capsys.readouterr().out
