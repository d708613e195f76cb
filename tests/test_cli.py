"""The fixplan command line: outputs, exit codes and validation messages."""

import json
import subprocess
import sys
from pathlib import Path

import pytest

from fixplan import __version__
from fixplan.io.cli import (
    EXIT_INVALID_INPUT,
    EXIT_NOT_HELD,
    EXIT_OK,
    main,
)

PINCH = """\
schema_version = 1
name = "pinch"
kind = "grasp"
objective = "{objective}"

[defaults]
mu = 0.8
model = "{model}"

[body]
mass = 0.2
center_of_mass = [0.0, 0.0, 0.0]

[[contacts]]
name = "thumb"
role = "finger"
position = [0.0, -0.02, 0.0]
normal = [0.0, 1.0, 0.0]
patch = {{ shape = "disk", radius = 0.008, pressure = "hertz" }}
{force}

[[contacts]]
name = "index"
role = "finger"
position = [0.0, 0.02, 0.0]
normal = [0.0, -1.0, 0.0]
patch = {{ shape = "disk", radius = 0.008, pressure = "hertz" }}
{force}

[[loads]]
name = "lift"
force = [0.0, 0.0, -2.0]
point = [0.03, 0.0, 0.0]

[[loads]]
name = "turn"
force = [0.0, 0.0, 0.0]
point = [0.0, 0.0, 0.0]
torque = [0.0, 0.05, 0.0]
"""


def write(tmp_path: Path, objective="min-max-normal-force", model="ellipsoid", force=""):
    path = tmp_path / "pinch.toml"
    path.write_text(PINCH.format(objective=objective, model=model, force=force))
    return path


def test_plan_prints_a_readable_summary(tmp_path, capsys):
    code = main(["plan", str(write(tmp_path))])
    out = capsys.readouterr().out
    assert code == EXIT_OK
    assert "status     optimal" in out
    assert "thumb" in out and "index" in out
    assert "safety factors" in out
    assert "if it slips, the part rotates about an axis through" in out


def test_plan_json_has_the_documented_fields(tmp_path, capsys):
    assert main(["plan", str(write(tmp_path)), "--json"]) == EXIT_OK
    document = json.loads(capsys.readouterr().out)
    for key in ("status", "objective_value", "forces_N", "safety_factors", "motions"):
        assert key in document
    assert document["status"] == "optimal"
    assert set(document["forces_N"]) == {"thumb", "index"}
    assert document["motions"]["lift"]["words"].startswith("rotates about")


def test_model_override_changes_the_answer(tmp_path, capsys):
    main(["plan", str(write(tmp_path)), "--json"])
    ellipsoid = json.loads(capsys.readouterr().out)["objective_value"]
    main(["plan", str(write(tmp_path)), "--json", "--model", "cone"])
    cone = json.loads(capsys.readouterr().out)["objective_value"]
    assert cone > ellipsoid


def test_a_load_that_is_not_held_exits_with_3(tmp_path, capsys):
    path = write(tmp_path, objective="check", force="force = 3.0")
    assert main(["plan", str(path)]) == EXIT_NOT_HELD
    assert "NOT HELD" in capsys.readouterr().out


def test_an_infeasible_problem_exits_with_3_and_explains_the_free_motion(tmp_path, capsys):
    path = write(tmp_path, model="point-cone")
    path.write_text(path.read_text().replace('patch = { shape = "disk", radius = 0.008, '
                                             'pressure = "hertz" }\n', ""))  # fmt: skip
    assert main(["plan", str(path)]) == EXIT_NOT_HELD
    out = capsys.readouterr().out
    assert "cannot be held" in out and "'turn'" in out and "along (0, 1, 0)" in out


def test_check_reports_every_problem_of_a_file_and_exits_with_2(tmp_path, capsys):
    path = write(tmp_path)
    text = (
        path.read_text()
        .replace("mu = 0.8", "mu = -0.8")
        .replace('role = "finger"\nposition = [0.0, 0.02', 'role = "fingr"\nposition = [0.0, 0.02')
    )
    text = text.replace('name = "turn"', 'name = "turn"\nfrce = [1, 2, 3]')
    path.write_text(text)
    assert main(["check", str(path)]) == EXIT_INVALID_INPUT
    err = capsys.readouterr().err
    assert "defaults.mu" in err
    assert "contacts[1].role" in err
    assert "loads[1].frce: unknown key; did you mean 'force'?" in err


def test_check_accepts_a_valid_file(tmp_path, capsys):
    assert main(["check", str(write(tmp_path))]) == EXIT_OK
    assert "valid" in capsys.readouterr().out


def test_a_missing_file_is_invalid_input(tmp_path, capsys):
    assert main(["plan", str(tmp_path / "nope.toml")]) == EXIT_INVALID_INPUT
    assert "nope.toml" in capsys.readouterr().err


def test_bad_options_are_invalid_input(capsys):
    with pytest.raises(SystemExit) as exit_info:
        main(["plan"])
    assert exit_info.value.code == EXIT_INVALID_INPUT


def test_surface_reports_the_models_errors(capsys):
    code = main(
        ["surface", "--shape", "disk", "--radius", "0.01", "--pressure", "hertz", "--mu", "0.8",
         "--normal-force", "20", "--json"]
    )  # fmt: skip
    summary = json.loads(capsys.readouterr().out)
    assert code == EXIT_OK
    assert summary["max_force_N"] == pytest.approx(16.0)
    assert summary["max_moment_Nm"] == pytest.approx(3 * 3.141592653589793 / 16 * 16.0 * 0.01)
    assert summary["models"]["cone"]["unsafe_fraction"] == 0.0


def test_surface_rejects_a_negative_radius(capsys):
    code = main(["surface", "--shape", "disk", "--radius", "-1", "--mu", "0.3"])
    assert code == EXIT_INVALID_INPUT
    assert "radius must be > 0" in capsys.readouterr().err


def test_compare_tabulates_every_applicable_model(tmp_path, capsys):
    assert main(["compare", str(write(tmp_path))]) == EXIT_NOT_HELD  # point models: 'turn'
    out = capsys.readouterr().out
    for model in ("exact", "ellipsoid", "cone", "pyramid", "point-cone", "point-pyramid"):
        assert model in out


def test_help_starts_with_an_example_and_lists_exit_codes():
    result = subprocess.run(
        [sys.executable, "-m", "fixplan.io.cli", "--help"], capture_output=True, text=True
    )
    assert result.returncode == 0
    assert result.stdout.splitlines()[1].strip() == "example:" or "example:" in result.stdout[:200]
    assert "exit codes:" in result.stdout and "3  cannot be held" in result.stdout


def test_version_is_printed():
    result = subprocess.run(
        [sys.executable, "-m", "fixplan.io.cli", "--version"], capture_output=True, text=True
    )
    assert result.stdout.strip() == f"fixplan {__version__}"


def test_results_go_to_stdout_and_nothing_else_to_it_when_quiet(tmp_path):
    result = subprocess.run(
        [sys.executable, "-m", "fixplan.io.cli", "plan", str(write(tmp_path)), "--json", "-q"],
        capture_output=True, text=True,
    )  # fmt: skip
    json.loads(result.stdout)
    assert result.stderr == ""
