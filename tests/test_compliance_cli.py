"""The compliant analysis from the command line: objective check-compliant, its text and JSON
sections (equal to calling ``analyse`` directly), its report section and figure, and its errors."""

import json
import math
import re
from pathlib import Path

import matplotlib.image
import numpy as np
import pytest
from test_cli import write as write_pinch

from fixplan.errors import ConvergenceError, InvalidArgumentError
from fixplan.io import compliant_report
from fixplan.io.cli import EXIT_INVALID_INPUT, EXIT_NOT_HELD, EXIT_OK, EXIT_SOLVER, main
from fixplan.io.figures import utilisation_figure
from fixplan.io.problem_file import load_problem
from fixplan.motion.compliance import analyse
from fixplan.planner.planner import Planner

STIFFNESS = "stiffness = { normal = 2e5, tangential = 1e5, torsional = 0.5 }"
#: The index finger's own springs (stiffer than the thumb's default ones).
INDEX_STIFFNESS = "stiffness = { normal = 4e5, tangential = 1e5, torsional = 0.3 }"
#: Printed values carry 4 significant digits.
PRINTED_RTOL = 1e-3


def write(folder: Path, objective="check-compliant", stiffness=STIFFNESS):
    """The pinch of ``test_cli`` with fingers of 10 N and their springs: ``stiffness`` in
    ``[defaults]``, the index finger's own."""
    path = write_pinch(folder, objective=objective, force="force = 10.0")
    text = path.read_text(encoding="utf-8")
    index = 'pressure = "hertz" }\nforce = 10.0\n\n[[loads]]'
    text = text.replace('model = "ellipsoid"\n', f'model = "ellipsoid"\n{stiffness}\n', 1)
    text = text.replace(index, index.replace("10.0\n", f"10.0\n{INDEX_STIFFNESS}\n"))
    path.write_text(text, encoding="utf-8")
    return path


def direct(path: Path):
    """``(problem file, plan, result)``: the rigid check and ``analyse`` called directly."""
    problem_file = load_problem(path, objective="check-compliant")
    plan = Planner(problem_file.problem).solve()
    result = analyse(problem_file.problem, plan, stiffness=problem_file.stiffness)
    return problem_file, plan, result


def run(capsys, *argv):
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


def _numbers(text: str) -> list[float]:
    return [float(x) for x in re.findall(r"-?\d+(?:\.\d+)?(?:e[+-]?\d+)?|inf", text)]


def _case_block(out: str, case: str) -> str:
    start = out.index(f"load case {case!r}:")
    following = out.find("  load case '", start + 1)
    return out[start : following if following > 0 else len(out)]


# -- text -------------------------------------------------------------------------------------


@pytest.mark.parametrize("command", ["plan", "check"])
def test_the_compliant_section_prints_the_values_of_analyse(tmp_path, capsys, command):
    path = write(tmp_path)
    code, out, _ = run(capsys, command, path)
    assert code == EXIT_OK
    _, plan, result = direct(path)
    for j, case in enumerate(result.load_names):
        block = _case_block(out, case)
        first = re.search(r"'(\w+)' slips first, at (\S+) × the task load", block)
        assert first.group(1) == result.first_slip_contact[case]
        assert float(first.group(2)) == pytest.approx(result.first_slip[case], rel=PRINTED_RTOL)
        seating = "seated" if result.seated[case] else "stuck"
        assert re.search(rf"clamping\s+{seating} \(", block)
        moved = re.search(r"displacement \((.*)\) µm, rotation \((.*)\) µrad", block)
        printed = _numbers(moved.group(1)) + _numbers(moved.group(2))
        scale = np.abs(result.displacement[case]).reshape(2, 3).max(axis=1).repeat(3)
        assert np.allclose(
            1e-6 * np.array(printed),
            result.displacement[case],
            rtol=PRINTED_RTOL,
            atol=1e-9 * scale,
        )
        for i, contact in enumerate(result.contact_names):
            rigid, compliant = _numbers(re.search(rf"\n\s+{contact}\s+(.*)", block).group(1))
            assert rigid == pytest.approx(plan.utilisation[i, j], rel=PRINTED_RTOL, abs=1e-4)
            own = 1.0 / result.safety_factors[case][contact]
            assert compliant == pytest.approx(own, rel=PRINTED_RTOL)


def test_other_objectives_print_no_compliant_section(tmp_path, capsys):
    code, out, _ = run(capsys, "plan", write(tmp_path, objective="check"))
    assert code == EXIT_OK
    assert "compliant" not in out
    code, out, _ = run(capsys, "plan", write(tmp_path, objective="check"), "--json")
    assert "compliant" not in json.loads(out)


def test_check_also_reports_the_rigid_check(tmp_path, capsys):
    path = write(tmp_path)
    _, out, _ = run(capsys, "check", path)
    _, plan, _ = direct(path)
    first = out.splitlines()[0]
    assert first.startswith(f"{path}: valid — pinch (grasp), objective check-compliant")
    assert f"rigid check optimal, safety factor {plan.safety_factor:.4g}" in first


# -- JSON -------------------------------------------------------------------------------------


def _strict(value: float):
    """A float as the JSON output writes it."""
    if math.isnan(value):
        return "nan"
    return ("inf" if value > 0 else "-inf") if math.isinf(value) else value


def _flat(value) -> list:
    return list(value) if isinstance(value, list | tuple | np.ndarray) else [value]


def _assert_same(printed, expected):
    """A value of the JSON output against the one computed (a number or a vector)."""
    expected = [_strict(float(x)) for x in _flat(expected)]
    printed = _flat(printed)
    assert [type(x) for x in printed] == [type(x) for x in expected]
    numbers = [(p, e) for p, e in zip(printed, expected, strict=True) if isinstance(e, float)]
    assert all(p == pytest.approx(e, rel=1e-9, abs=1e-12) for p, e in numbers)
    assert [p for p in printed if isinstance(p, str)] == [e for e in expected if isinstance(e, str)]


@pytest.mark.parametrize("command", ["plan", "check"])
def test_the_json_compliant_object_holds_the_values_of_analyse(tmp_path, capsys, command):
    path = write(tmp_path)
    code, out, _ = run(capsys, command, path, "--json")
    assert code == EXIT_OK
    compliant = json.loads(out)["compliant"]
    _, plan, result = direct(path)
    for j, case in enumerate(result.load_names):
        for i, contact in enumerate(result.contact_names):
            _assert_same(compliant["wrenches"][case][contact], result.wrenches[case][contact])
            _assert_same(
                compliant["safety_factors"][case][contact], result.safety_factors[case][contact]
            )
            _assert_same(
                compliant["slip_directions"][case][contact], result.slip_directions[case][contact]
            )
            use = compliant["utilisation"][case][contact]
            _assert_same(use["rigid"], plan.utilisation[i, j])
            _assert_same(use["compliant"], 1.0 / result.safety_factors[case][contact])
        _assert_same(compliant["displacement"][case], result.displacement[case])
        _assert_same(compliant["first_slip"][case], result.first_slip[case])
        _assert_same(compliant["rigid_safety_factors"][case], plan.safety_factors[case])
        assert compliant["lifted"][case] == list(result.lifted[case])
        assert compliant["seated"][case] is result.seated[case]
        assert compliant["first_slip_contact"][case] == result.first_slip_contact[case]


def test_infinite_values_are_written_as_inf_strings(tmp_path, capsys):
    # No load case slips before the largest multiple searched: a first slip of inf.
    path = write(tmp_path)
    path.write_text(path.read_text().replace("force = [0.0, 0.0, -2.0]", "force = [0.0, 0.0, 0.0]"))
    code, out, _ = run(capsys, "plan", path, "--json")
    compliant = json.loads(out)["compliant"]
    _, _, result = direct(path)
    assert code == EXIT_OK
    assert compliant["first_slip"]["lift"] == _strict(result.first_slip["lift"]) == "inf"
    assert compliant["first_slip_contact"]["lift"] is None


# -- the objective ----------------------------------------------------------------------------


def test_the_objective_option_selects_the_compliant_analysis(tmp_path, capsys):
    path = write(tmp_path, objective="check")
    for command in ("plan", "check"):
        code, out, _ = run(capsys, command, path, "--objective", "check-compliant", "--json")
        assert code == EXIT_OK
        document = json.loads(out)
        assert document["objective"] == "check-compliant"
        assert set(document["compliant"]["first_slip"]) == {"lift", "turn"}


def test_the_objective_needs_every_contacts_stiffness_from_the_file_or_the_option(tmp_path, capsys):
    without = write(tmp_path, stiffness="")
    _, out, err = run(capsys, "check", without, "--json")
    (issue,) = json.loads(out)["issues"]
    assert issue["key_path"] == "objective"
    assert "missing for 'thumb'" in issue["message"] and "index" not in issue["message"]
    for command in ("plan", "check"):
        path = write(tmp_path, objective="check", stiffness="")
        code, _, err = run(capsys, command, path, "--objective", "check-compliant")
        assert code == EXIT_INVALID_INPUT
        assert f"{path}: objective: the objective override 'check-compliant' needs" in err


def test_an_unknown_objective_is_a_usage_error(tmp_path, capsys):
    with pytest.raises(SystemExit) as exit_info:
        main(["plan", str(write(tmp_path)), "--objective", "check-compliants"])
    assert exit_info.value.code == EXIT_INVALID_INPUT


def test_a_push_file_takes_no_objective(capsys):
    push = Path(__file__).resolve().parents[1] / "problems" / "push-box-finger.toml"
    code, _, err = run(capsys, "check", push, "--objective", "check")
    assert code == EXIT_INVALID_INPUT
    assert "--objective" in err and "push file" in err


# -- errors -----------------------------------------------------------------------------------


def _without_torsional_springs(folder: Path) -> Path:
    path = write(folder, stiffness="stiffness = { normal = 2e5, tangential = 1e5 }")
    path.write_text(path.read_text().replace(", torsional = 0.3", ""))
    return path


@pytest.mark.parametrize("command", ["plan", "check"])
def test_springs_that_cannot_hold_a_moment_report_the_part_moving_at_once(
    tmp_path, capsys, command
):
    # Without torsional springs nothing holds the moment about the grasp axis: the part turns
    # as soon as the task load is applied, which the analysis reports (not an error).
    path = _without_torsional_springs(tmp_path)
    _, out, err = run(capsys, command, path, "--json")
    compliant = json.loads(out)["compliant"]
    for case in ("lift", "turn"):
        assert compliant["collapse"][case] == compliant["first_slip"][case] == 0.0
        assert compliant["held"][case] is False
        assert compliant["first_slip_contact"][case] is None
    assert "Traceback" not in err
    _, out, _ = run(capsys, command, path)
    assert "the part moves at 0 × the task load" in out


def test_an_analysis_that_does_not_converge_exits_4_naming_the_file(tmp_path, capsys, monkeypatch):
    def diverges(*args, **kwargs):
        raise ConvergenceError("load case 'lift': the contact QP ended 'user_limit'")

    monkeypatch.setattr(compliant_report, "analyse", diverges)
    path = write(tmp_path)
    code, out, err = run(capsys, "plan", path)
    assert code == EXIT_SOLVER
    assert out == ""
    assert f"numerical failure: {path}: the compliant analysis failed: load case 'lift'" in err


def test_a_rigid_check_without_contact_forces_skips_the_analysis(tmp_path, capsys):
    # One finger alone pushes the part away: the rigid check is infeasible.
    path = write(tmp_path)
    text = path.read_text()
    start, end = text.index('[[contacts]]\nname = "index"'), text.index("[[loads]]")
    path.write_text(text[:start] + text[end:])
    code, out, _ = run(capsys, "plan", path)
    assert code == EXIT_NOT_HELD
    assert "compliant  not analysed: the rigid check ended 'infeasible'" in out
    code, out, _ = run(capsys, "check", path, "--json")
    document = json.loads(out)
    assert code == EXIT_NOT_HELD
    assert (document["status"], document["compliant"]) == ("infeasible", None)


# -- report and figure ------------------------------------------------------------------------


def test_the_report_has_the_compliant_section_and_its_figure(tmp_path, capsys):
    report = tmp_path / "report"
    assert main(["plan", str(write(tmp_path)), "--report", str(report), "-q"]) == EXIT_OK
    text = (report / "report.md").read_text(encoding="utf-8")
    section = text[text.index("## Compliant analysis") :]
    assert "![friction used per contact, rigid and compliant](compliant-utilisation.png)" in section
    assert "| thumb | 2e+05 | 1e+05 | 0.5 |" in section
    assert "| index | 4e+05 | 1e+05 | 0.3 |" in section
    for case in ("lift", "turn"):
        assert f"| {case} | thumb |" in section and f"| {case} | index |" in section
    image = matplotlib.image.imread(report / "compliant-utilisation.png")
    assert image.shape[0] > 200 and image.shape[1] > 400
    assert 'src="compliant-utilisation.png"' in (report / "report.html").read_text()


def test_a_report_of_another_objective_has_no_compliant_section(tmp_path, capsys):
    report = tmp_path / "report"
    path = write(tmp_path, objective="check")
    assert main(["plan", str(path), "--report", str(report), "-q"]) == EXIT_OK
    assert "Compliant analysis" not in (report / "report.md").read_text(encoding="utf-8")
    assert not (report / "compliant-utilisation.png").exists()


def test_the_utilisation_figure_has_a_panel_per_load_case_and_bars_per_contact(tmp_path):
    _, plan, result = direct(write(tmp_path))
    fig = utilisation_figure(plan, result)
    panels = [ax for ax in fig.axes if ax.get_visible()]
    assert [ax.get_title() for ax in panels] == list(result.load_names)
    for j, ax in enumerate(panels):
        heights = [patch.get_height() for patch in ax.patches]
        rigid, compliant = (
            heights[: len(result.contact_names)],
            heights[len(result.contact_names) :],
        )
        assert rigid == pytest.approx(plan.utilisation[:, j])
        own = [1.0 / result.safety_factors[result.load_names[j]][c] for c in result.contact_names]
        assert compliant == pytest.approx(own)
    with pytest.raises(InvalidArgumentError, match="axes must hold 2 Axes"):
        utilisation_figure(plan, result, axes=panels[:1])
