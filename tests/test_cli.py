"""The fixplan command line: outputs, exit codes and validation messages."""

import json
import math
import os
import subprocess
import sys
from pathlib import Path

import pytest

from fixplan import __version__
from fixplan.errors import ConvergenceError
from fixplan.io import cli as cli_module
from fixplan.io.cli import (
    EXIT_INVALID_INPUT,
    EXIT_NOT_HELD,
    EXIT_OK,
    EXIT_SOLVER,
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


def test_verbose_plan_logs_the_time_of_each_stage(tmp_path, caplog):
    import re

    with caplog.at_level("INFO"):
        assert main(["plan", str(write(tmp_path)), "-v"]) == EXIT_OK
    line = next(r.getMessage() for r in caplog.records if r.getMessage().startswith("time:"))
    stages = dict(re.findall(r"(imports|read|build|solve|output) (\d+\.\d+) s", line))
    assert list(stages) == ["imports", "read", "build", "solve", "output"]
    total = float(re.search(r"total (\d+\.\d+) s", line).group(1))
    assert sum(map(float, stages.values())) == pytest.approx(total, abs=0.003)  # rounding


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


# -- what a new user trips over: every bad input ends in a clear message and exit code 2 --------


def edited(tmp_path: Path, *replacements: tuple[str, str]) -> Path:
    path = write(tmp_path)
    text = path.read_text()
    for old, new in replacements:
        assert old in text, old
        text = text.replace(old, new)
    path.write_text(text)
    return path


@pytest.mark.parametrize(
    ("old", "new", "key_path", "allowed"),
    [
        ("position = [0.0, -0.02, 0.0]", "position = [1e308, -0.02, 0.0]", "contacts[0].position",
         "within ±1000 m"),
        ('force = [0.0, 0.0, -2.0]', "force = [0.0, 0.0, -1e308]", "loads[0].force",
         "within ±1e+09 N"),
        ("point = [0.03, 0.0, 0.0]", "point = [-1e308, 0.0, 0.0]", "loads[0].point",
         "within ±1000 m"),
        ("center_of_mass = [0.0, 0.0, 0.0]", "center_of_mass = [0.0, 1e308, 0.0]",
         "body.center_of_mass", "within ±1000 m"),
        ("mu = 0.8", "mu = 1e300", "defaults.mu", "at most 100"),
        ("mu = 0.8", "mu = 1e-300", "defaults.mu", "below 1e-06"),
        ('model = "ellipsoid"', 'model = "pyramid"\nfacets = 10000000', "defaults.facets",
         "from 3 to 64"),
        ('name = "thumb"', f'name = "{"t" * 250}"', "contacts[0].name", "1 to 100 characters"),
        ("radius = 0.008", "radius = 1e-300", "contacts[0].patch.radius", "below 1e-09 m"),
    ],
)  # fmt: skip
def test_values_out_of_range_are_invalid_input_naming_file_key_and_range(
    tmp_path, capsys, old, new, key_path, allowed
):
    path = edited(tmp_path, (old, new))
    for command in ("check", "plan"):
        assert main([command, str(path)]) == EXIT_INVALID_INPUT
        err = capsys.readouterr().err
        assert f"{path}: {key_path}: " in err and allowed in err


def test_a_polygon_with_too_many_vertices_is_invalid_input(tmp_path, capsys):
    angles = [2 * math.pi * k / 2000 for k in range(2000)]
    circle = [[0.01 * math.cos(a), 0.01 * math.sin(a)] for a in angles]
    patch = f'patch = {{ shape = "polygon", vertices = {circle} }}'
    path = edited(tmp_path, ('patch = { shape = "disk", radius = 0.008, pressure = "hertz" }',
                             patch))  # fmt: skip
    assert main(["check", str(path)]) == EXIT_INVALID_INPUT
    assert "contacts[0].patch.vertices: expected at most 256 items, got 2000" in (
        capsys.readouterr().err
    )


def test_the_exact_model_plans_a_grid_patch_as_the_ellipsoid_does(tmp_path, capsys):
    # The exact model states the grid's own limit surface (no friction disks to count).
    x = [(k - 5.5) / 1000 for k in range(12)]
    patch = f'patch = {{ shape = "grid", x = {x}, y = {x}, values = {[[1.0] * 12] * 12} }}'
    path = edited(tmp_path, ('patch = { shape = "disk", radius = 0.008, pressure = "hertz" }',
                             patch))  # fmt: skip
    assert main(["check", str(path), "--json"]) == EXIT_OK
    capsys.readouterr()
    for model in ("exact", "ellipsoid"):
        assert main(["plan", str(path), "--model", model]) == EXIT_OK
        assert "status     optimal" in capsys.readouterr().out


def test_a_failed_run_writes_no_report(tmp_path, capsys):
    path = edited(tmp_path, ("position = [0.0, -0.02, 0.0]", "position = [1e308, -0.02, 0.0]"))
    report = tmp_path / "report"
    assert main(["plan", str(path), "--report", str(report)]) == EXIT_INVALID_INPUT
    assert not report.exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["pinch.toml"]


def test_a_report_that_fails_midway_leaves_nothing_behind(tmp_path, capsys, monkeypatch):
    from fixplan.io import report_document

    def broken(*args):
        raise report_document.ReportError("cannot write: disk full")

    monkeypatch.setattr(report_document, "to_html", broken)
    report = tmp_path / "out" / "report"
    assert main(["plan", str(write(tmp_path)), "--report", str(report)]) == EXIT_INVALID_INPUT
    assert "disk full" in capsys.readouterr().err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["pinch.toml"]


def test_a_report_path_naming_a_file_is_rejected_before_solving(tmp_path, capsys, monkeypatch):
    from fixplan.planner.planner import Planner

    def never(*args, **kwargs):
        raise AssertionError("solved before checking the report folder")

    monkeypatch.setattr(Planner, "solve", never)
    taken = tmp_path / "taken"
    taken.write_text("a file")
    for report in (taken, taken / "inside"):
        assert main(["plan", str(write(tmp_path)), "--report", str(report)]) == EXIT_INVALID_INPUT
        assert "--report" in capsys.readouterr().err
    assert taken.read_text() == "a file"


def test_a_deeply_nested_table_is_invalid_input(tmp_path, capsys):
    path = edited(tmp_path, ("mass = 0.2", "mass = " + "{a = " * 400 + "1" + "}" * 400))
    assert main(["check", str(path)]) == EXIT_INVALID_INPUT
    assert f"{path}: tables or arrays are nested too deeply" in capsys.readouterr().err


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="no FIFOs on this platform")
def test_a_fifo_is_rejected_without_reading_it(tmp_path, capsys):
    fifo = tmp_path / "problem.toml"
    os.mkfifo(fifo)
    assert main(["check", str(fifo)]) == EXIT_INVALID_INPUT
    assert f"{fifo}: cannot read the file: it is not a regular file" in capsys.readouterr().err


@pytest.mark.parametrize("name", ["bad\x00name.csv", "folder.csv"])
def test_a_csv_path_that_cannot_be_read_is_invalid_input(tmp_path, capsys, name):
    (tmp_path / "folder.csv").mkdir()
    patch = f'patch = {{ shape = "grid", x = [0.0, 0.01], y = [0.0], values = "{name!s}" }}'
    path = edited(
        tmp_path,
        ('patch = { shape = "disk", radius = 0.008, pressure = "hertz" }',
         patch.replace("\x00", "\\u0000")),
    )  # fmt: skip
    assert main(["check", str(path)]) == EXIT_INVALID_INPUT
    assert "contacts[0].patch.values: cannot read the CSV file" in capsys.readouterr().err


def test_a_toml_file_with_a_byte_order_mark_is_read(tmp_path, capsys):
    path = write(tmp_path)
    path.write_bytes(b"\xef\xbb\xbf" + path.read_bytes())
    assert main(["check", str(path)]) == EXIT_OK


def test_check_json_is_one_document_for_valid_and_invalid_files(tmp_path, capsys):
    path = write(tmp_path)
    assert main(["check", str(path), "--json"]) == EXIT_OK
    document = json.loads(capsys.readouterr().out)
    assert document["valid"] and document["contacts"] == ["thumb", "index"]
    path.write_text(path.read_text().replace("mu = 0.8", "mu = -1"))
    assert main(["check", str(path), "--json"]) == EXIT_INVALID_INPUT
    document = json.loads(capsys.readouterr().out)
    assert not document["valid"]
    assert document["issues"] == [
        {"key_path": "defaults.mu", "message": "expected a number >= 0, got -1"}
    ]


def test_solver_output_on_file_descriptor_1_goes_to_stderr(tmp_path, capfd, monkeypatch):
    from fixplan.planner.planner import Planner

    solve = Planner.solve

    def noisy(self, *args, **kwargs):
        os.write(1, b"ERROR: a solver printed this\n")
        return solve(self, *args, **kwargs)

    monkeypatch.setattr(Planner, "solve", noisy)
    assert main(["plan", str(write(tmp_path)), "--json", "-q"]) == EXIT_OK
    out, err = capfd.readouterr()
    assert json.loads(out)["status"] == "optimal"
    assert "ERROR: a solver printed this" in err


@pytest.mark.parametrize(
    ("options", "message"),
    [
        (["--radius", "1e308"], "--radius must be at most 1000 m"),
        (["--radius", "0.01", "--plot", "missing/figure.png"], "the folder"),
        (["--radius", "0.01", "--length", "0.02"], "--length is not an option of --shape disk"),
        (["--radius", "0.01", "--inner-radius", "0.005"], "(only of --pressure annulus)"),
        (["--radius", "0.01", "--normal-force", "1e-200"], "normal_force = 1e-200 N is below"),
    ],
)
def test_surface_options_out_of_range_are_invalid_input(tmp_path, capsys, monkeypatch, options,
                                                        message):  # fmt: skip
    monkeypatch.chdir(tmp_path)
    assert main(["surface", "--shape", "disk", "--mu", "0.5", *options]) == EXIT_INVALID_INPUT
    assert message in capsys.readouterr().err
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("command", [[sys.executable, "-m", "fixplan.io.cli"], ["fixplan"]])
def test_help_does_not_import_the_solver_stack(command):
    script = (
        "import runpy, sys; sys.argv = ['fixplan', '--help']\n"
        "try:\n"
        "    runpy.run_module('fixplan.io.cli', run_name='__main__')\n"
        "except SystemExit:\n"
        "    pass\n"
        "heavy = sorted({m.split('.')[0] for m in sys.modules} & {'numpy', 'cvxpy', 'scipy', "
        "'numba', 'matplotlib'})\n"
        "print(heavy, file=sys.stderr)\n"
    )
    if command == ["fixplan"]:
        script = script.replace(
            "runpy.run_module('fixplan.io.cli', run_name='__main__')",
            "from importlib.metadata import entry_points\n"
            "    entry_points(group='console_scripts')['fixplan'].load()()",
        )
    result = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True)
    assert "exit codes:" in result.stdout
    assert result.stderr.strip() == "[]"


def test_a_reader_that_leaves_early_gets_no_traceback(tmp_path):
    read_end, write_end = os.pipe()
    os.close(read_end)
    result = subprocess.run(
        [sys.executable, "-m", "fixplan.io.cli", "check", str(write(tmp_path))],
        stdout=write_end, stderr=subprocess.PIPE, text=True,
    )  # fmt: skip
    os.close(write_end)
    assert result.returncode == EXIT_OK
    assert "Traceback" not in result.stderr


def test_every_subcommand_example_names_a_problem_file_that_exists():
    root = Path(__file__).resolve().parents[1]
    parser = cli_module._build_parser()
    commands = next(a for a in parser._actions if a.dest == "command").choices
    for name, sub in commands.items():
        example = sub.description.splitlines()[1].split()
        assert example[:2] == ["fixplan", name]
        for word in example[2:]:
            if word.startswith("problems/"):
                assert (root / word).is_file(), f"{name}: {word}"


def test_every_command_with_json_prints_a_document_when_it_fails(tmp_path, capsys, monkeypatch):
    """A script reading ``--json`` gets one document on stdout whatever happens (it got
    nothing but the message on stderr before): invalid input, a numerical failure."""
    path = write(tmp_path)
    path.write_text(path.read_text().replace("mu = 0.8", "mu = -1"))
    assert main(["plan", str(path), "--json"]) == EXIT_INVALID_INPUT
    out, err = capsys.readouterr()
    assert json.loads(out) == {"error": "invalid input", "exit_code": EXIT_INVALID_INPUT,
                               "message": err.removeprefix("fixplan: error: ").strip()}  # fmt: skip

    def fails(*args, **kwargs):
        raise ConvergenceError("the inverse map did not converge")

    monkeypatch.setattr("fixplan.planner.planner.Planner.solve", fails)
    assert main(["plan", str(write(tmp_path)), "--json"]) == EXIT_SOLVER
    document = json.loads(capsys.readouterr().out)
    assert document["error"] == "numerical failure" and "did not converge" in document["message"]
