"""The README tells the truth: its commands are what CI runs, its problem-file sample is a
complete valid problem, and its example error is what ``fixplan check`` prints."""

import math
import re
from pathlib import Path

import pytest

from fixplan.io.cli import EXIT_INVALID_INPUT, EXIT_OK, main
from fixplan.io.problem_file import load_problem

ROOT = Path(__file__).resolve().parents[1]
README = (ROOT / "README.md").read_text(encoding="utf-8")


def _section(title: str) -> str:
    start = README.index(f"## {title}\n")
    end = README.find("\n## ", start + 1)
    return README[start:end]


def _blocks(text: str, language: str) -> list[str]:
    return re.findall(rf"```{language}\n(.*?)```", text, flags=re.DOTALL)


def test_ci_runs_the_two_quick_start_commands_verbatim_in_order():
    commands = [block.strip() for block in _blocks(_section("Quick start"), "sh")]
    assert len(commands) == 2
    script = (ROOT / ".ci" / "run").read_text(encoding="utf-8").splitlines()
    assert [line for line in script if line in commands] == commands


def test_the_problem_file_sample_loads_and_plans(tmp_path, capsys):
    (sample,) = _blocks(_section("Problem files"), "toml")
    path = tmp_path / "vise.toml"
    path.write_text(sample, encoding="utf-8")
    problem_file = load_problem(path)
    assert problem_file.name == "vise-milling"
    assert main(["plan", str(path)]) == EXIT_OK
    assert "status     optimal" in capsys.readouterr().out


def test_the_example_error_is_what_check_prints(tmp_path, capsys, monkeypatch):
    section = _section("Problem files")
    (sample,) = _blocks(section, "toml")
    mistakes = (
        ('role = "locator"', 'frction = 0.25\nrole = "locator"'),
        ('role = "clamp"', 'modle = "exact"\nrole = "clamp"'),
        ("force = [120.0, -40.0, -60.0]", "force = [120.0, -40.0, -6e10]"),
    )
    for old, new in mistakes:
        sample = sample.replace(old, new, 1)
    (tmp_path / "vise.toml").write_text(sample, encoding="utf-8")
    monkeypatch.chdir(tmp_path)
    assert main(["check", "vise.toml"]) == EXIT_INVALID_INPUT
    (documented,) = _blocks(section, "text")
    assert capsys.readouterr().err == documented


def test_the_quick_start_output_is_what_plan_prints(capsys, monkeypatch):
    (documented,) = _blocks(_section("Quick start"), "text")
    monkeypatch.chdir(ROOT)
    assert main(["plan", "problems/vise-milling.toml"]) == EXIT_OK
    assert capsys.readouterr().out == documented


def test_the_pushing_example_gives_the_numbers_its_comments_state():
    (code,) = _blocks(_section("Pushing, pivoting and sliding (`fixplan.motion`)"), "python")
    names: dict = {}
    exec(code, names)
    x, y, theta = names["pushed"].poses[-1]
    assert (round(1e3 * x, 1), round(1e3 * y, 1), round(math.degrees(theta), 1)) == (
        54.8,
        -22.8,
        -33.8,
    )
    assert names["step"].mode == "sliding-right"
    assert round(names["squared"].line_contact_travel(), 4) == 0.0598


def test_the_identification_example_recovers_the_friction_it_was_made_with(tmp_path, monkeypatch):
    (code,) = _blocks(_section("Limit surfaces from measurements (`fixplan.motion.fit`, `SlipEstimator`)"),
                      "python")  # fmt: skip
    monkeypatch.chdir(tmp_path)
    names: dict = {}
    exec(code, names)
    assert names["quartic"].surface.mu == pytest.approx(0.4, rel=0.03)
    assert names["estimator"].mu == pytest.approx(0.4, rel=0.03)
    assert (tmp_path / "rectangle-fit.json").is_file()
