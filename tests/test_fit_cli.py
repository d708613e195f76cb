"""``fixplan fit``: measurements in a CSV file, a fitted limit surface out (issue 11 §4).

The measurements are synthetic pairs of an exact limit surface (:func:`fixplan.motion.synthetic`)
written to CSV files with every digit, so the command line must give what :func:`fit` gives on
the same arrays.
"""

import inspect
import json
import math
import subprocess
import sys
from functools import cache
from pathlib import Path

import numpy as np
import pytest

from fixplan import LimitSurface, pressure
from fixplan.io.cli import EXIT_INVALID_INPUT, EXIT_OK, main
from fixplan.io.fit_data import MAX_ISSUES, read_fit_data
from fixplan.io.fit_figures import fit_errors_figure, fit_sections_figure, fit_split, pair_errors
from fixplan.io.report_document import MANIFEST
from fixplan.io.toml_schema import ProblemFileError
from fixplan.motion import Fit, fit, synthetic
from fixplan.motion.fitted_quartic import MONOMIALS
from fixplan.motion.identify import HOLDOUT

SURFACE = LimitSurface(pressure.rectangle(0.1, 0.02), mu=0.5, normal_force=10.0)
HEADER = "fx_N,fy_N,m_Nm,vx_mps,vy_mps,w_radps,normal_force_N"
REPORT_FILES = {"report.md", "report.html", "fit.json", "sections.png", "errors.png"}


@cache
def pairs(count=150):
    loads, twists = synthetic(SURFACE, count, noise_force=0.02, noise_angle=math.radians(3.0),
                              seed=2)  # fmt: skip
    return loads, twists


@cache
def direct(model, twists=True):
    loads, measured = pairs()
    return fit(loads, measured if twists else None, model=model, normal_force=10.0)


def write_csv(path: Path, loads, twists=None, normal_forces=None, *, header=None, comment=True):
    """A CSV file of the pairs with every digit (``repr`` round-trips floats)."""
    columns = ["fx_N", "fy_N", "m_Nm"]
    columns += [] if twists is None else ["vx_mps", "vy_mps", "w_radps"]
    columns += [] if normal_forces is None else ["normal_force_N"]
    lines = ["# synthetic pairs of a 0.1 m x 0.02 m uniform rectangle, mu 0.5; SI units"]
    lines = lines if comment else []
    lines.append(header or ",".join(columns))
    for k, load in enumerate(loads):
        row = [*load, *([] if twists is None else twists[k])]
        row += [] if normal_forces is None else [normal_forces[k]]
        lines.append(",".join(repr(float(v)) for v in row))
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return path


def data_file(tmp_path, twists=True):
    loads, measured = pairs()
    return write_csv(tmp_path / "data.csv", loads, measured if twists else None,
                     np.full(len(loads), 10.0))  # fmt: skip


def run(capsys, *argv):
    code = main(["fit", *map(str, argv)])
    out, err = capsys.readouterr()
    return code, out, err


def printed(out: str, label: str) -> float:
    """The number after ``label`` at the start of a summary line."""
    line = next(line for line in out.splitlines() if line.startswith(label + " "))
    return float(line[len(label) :].split()[0])


# -- the summary ----------------------------------------------------------------------------


@pytest.mark.parametrize("model", ["ellipsoid", "quartic"])
def test_the_printed_mu_and_rho_agree_with_fit_called_directly(tmp_path, capsys, model):
    code, out, err = run(capsys, data_file(tmp_path), "--model", model)
    assert code == EXIT_OK, err
    surface = direct(model).surface
    assert printed(out, "mu") == pytest.approx(surface.mu, rel=1e-5)
    assert printed(out, "rho") == pytest.approx(surface.max_moment / surface.max_force, rel=1e-5)
    assert f"model      {model}" in out
    for words in ("rms(H − 1)", "median radial error", "mean twist angle", "median twist angle",
                  "solver CLARABEL", "fitted", "held out"):  # fmt: skip
        assert words in out


@pytest.mark.parametrize("model", ["ellipsoid", "quartic"])
def test_the_json_document_holds_the_fit_and_its_errors(tmp_path, capsys, model):
    code, out, _ = run(capsys, data_file(tmp_path), "--model", model, "--json")
    assert code == EXIT_OK
    document = json.loads(out)
    expected = direct(model)
    assert document["model"] == model
    assert document["mu"] == pytest.approx(expected.surface.mu, rel=1e-12)
    assert document["coordinates_rho_m"] == pytest.approx(expected.report.rho, rel=1e-12)
    assert document["normal_force_N"] == 10.0
    assert document["data"] == {
        "file": str(tmp_path / "data.csv"),
        "sha256": document["data"]["sha256"],
        "rows": 150,
        "twists": True,
        "normal_force": "column, constant",
    }
    assert document["holdout"] == HOLDOUT and document["weight"] == 1.0
    assert document["solver"] == "CLARABEL"
    training, validation = document["training"], document["validation"]
    assert training["samples"] + validation["samples"] == 150
    assert training["radial_median"] == pytest.approx(expected.report.training.radial_median)
    assert validation["angle_median_rad"] == pytest.approx(expected.report.validation.angle_median)
    if model == "quartic":
        assert document["matrix"] is None
        assert document["monomials"] == list(MONOMIALS)
        np.testing.assert_allclose(
            document["coefficients"], expected.surface.coefficients, rtol=1e-12
        )
    else:
        assert document["coefficients"] is None and document["monomials"] is None
        np.testing.assert_allclose(document["matrix"], expected.surface.matrix, rtol=1e-12)


def test_without_twist_columns_only_the_level_set_is_fitted(tmp_path, capsys, caplog):
    loads, _ = pairs()
    path = write_csv(tmp_path / "loads.csv", loads)
    code, out, _ = run(capsys, path, "--normal-force", "10", "--weight", "3", "--json")
    assert code == EXIT_OK
    document = json.loads(out)
    assert document["data"]["twists"] is False
    assert document["data"]["normal_force"] == "given"
    assert document["weight"] == 0.0
    assert document["training"]["angle_mean_rad"] is None
    assert document["mu"] == pytest.approx(direct("ellipsoid", twists=False).surface.mu)
    assert "--weight is ignored" in caplog.text


def test_options_reach_the_fit(tmp_path, capsys):
    path = data_file(tmp_path)
    code, out, _ = run(capsys, path, "--json", "--holdout", "0", "--weight", "0.5")
    assert code == EXIT_OK
    document = json.loads(out)
    assert document["holdout"] == 0.0 and document["validation"] is None
    assert document["weight"] == 0.5
    loads, twists = pairs()
    expected = fit(loads, twists, normal_force=10.0, holdout=0.0, weight=0.5)
    assert document["mu"] == pytest.approx(expected.surface.mu, rel=1e-12)


def test_the_help_states_the_library_defaults(capsys):
    with pytest.raises(SystemExit):
        main(["fit", "--help"])
    text = " ".join(capsys.readouterr().out.split())
    defaults = inspect.signature(fit).parameters
    assert f"(default {HOLDOUT:g})" in text
    assert f"(default {defaults['weight'].default:g})" in text
    assert f"(default {defaults['normal_force'].default:g})" in text
    assert f"(default {defaults['model'].default})" in text


# -- saving and the report ------------------------------------------------------------------


def test_save_writes_a_fit_that_loads_back(tmp_path, capsys):
    target = tmp_path / "fit.json"
    code, _, _ = run(capsys, data_file(tmp_path), "--model", "quartic", "--save", target)
    assert code == EXIT_OK
    loaded = Fit.load(target)
    expected = direct("quartic")
    np.testing.assert_array_equal(loaded.surface.coefficients, expected.surface.coefficients)
    assert loaded.report == expected.report
    assert loaded.surface.normal_force == 10.0


@pytest.fixture(scope="module")
def reports(tmp_path_factory):
    """Two report folders of the same data file, written by two runs."""
    folder = tmp_path_factory.mktemp("fit-report")
    path = data_file(folder)
    out = []
    for name in ("first", "second"):
        assert main(["fit", str(path), "--model", "quartic", "-q", "--report",
                     str(folder / name)]) == EXIT_OK  # fmt: skip
        out.append(folder / name)
    return out


def test_the_report_folder_holds_every_file(reports):
    first, _ = reports
    assert {p.name for p in first.iterdir()} == REPORT_FILES | {MANIFEST}
    markdown = (first / "report.md").read_text(encoding="utf-8")
    for words in ("# fixplan fit report: data.csv", "## Fitted surface", "## Errors",
                  "](sections.png)", "](errors.png)", "`x^4`", "synthetic pairs of a 0.1 m"):  # fmt: skip
        assert words in markdown
    html = (first / "report.html").read_text(encoding="utf-8")
    assert '<img src="sections.png"' in html and '<img src="errors.png"' in html
    saved = Fit.load(first / "fit.json")
    np.testing.assert_array_equal(
        saved.surface.coefficients, direct("quartic").surface.coefficients
    )


def test_two_reports_of_the_same_data_are_byte_identical(reports):
    first, second = reports
    for path in first.iterdir():
        assert path.read_bytes() == (second / path.name).read_bytes(), path.name


def test_report_figures_are_png_without_software_metadata(reports):
    for name in ("sections.png", "errors.png"):
        content = (reports[0] / name).read_bytes()
        assert content.startswith(b"\x89PNG") and b"Software" not in content


# -- figures --------------------------------------------------------------------------------


def test_the_redrawn_split_is_the_fits(capsys):
    result = direct("quartic")
    loads, twists = pairs()
    split = fit_split(result, loads)
    assert split.known
    assert sorted([*split.training, *split.held_out]) == list(range(len(loads)))
    radial, angles = pair_errors(result, loads, twists)
    held = result.report.validation
    assert len(split.held_out) == held.samples
    assert np.median(np.abs(radial[split.held_out])) == pytest.approx(held.radial_median)
    assert np.median(angles[split.held_out]) == pytest.approx(held.angle_median, rel=1e-9)


def test_figures_of_a_fit_without_report_draw_every_pair_as_measured():
    result = direct("ellipsoid")
    loads, twists = pairs()
    bare = Fit(surface=result.surface)
    assert not fit_split(bare, loads).known
    figure = fit_sections_figure(bare, loads)
    assert len(figure.axes) == 3
    assert len(fit_errors_figure(bare, loads, twists).axes) == 2
    # Other data than the fitted: the split cannot be the fit's.
    assert not fit_split(result, loads[:100]).known


# -- reading the CSV file -------------------------------------------------------------------


def test_units_case_blank_lines_comments_and_trailing_commas_are_read(tmp_path):
    loads, twists = pairs()
    plain = read_fit_data(write_csv(tmp_path / "plain.csv", loads[:10], twists[:10],
                                    header="fx,fy,m,vx,vy,w", comment=False))  # fmt: skip
    lines = [
        "\ufeff# measured 2024-05-02",
        "#units: SI",
        "W_rad/s , VY_m/s,vx_mps,M_N m,Fy_N,fx,",
    ]
    for load, twist in zip(loads[:10], twists[:10], strict=True):
        lines += [
            "",
            " # a comment",
            ",".join(repr(float(v)) for v in (*twist[::-1], *load[::-1])) + ",",
        ]
    path = tmp_path / "spelled.csv"
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    data = read_fit_data(path)
    np.testing.assert_array_equal(data.loads, plain.loads)
    np.testing.assert_array_equal(data.twists, plain.twists)
    assert data.comments == ("measured 2024-05-02", "units: SI")
    assert data.lines.tolist() == list(range(6, 36, 3))
    assert data.normal_force is None and data.normal_forces is None


def test_a_constant_normal_force_column_is_the_fits_normal_force(tmp_path):
    loads, twists = pairs()
    data = read_fit_data(write_csv(tmp_path / "d.csv", loads, twists, np.full(150, 7.5)))
    assert data.normal_force == 7.5 and not data.varying_normal_force
    np.testing.assert_array_equal(data.fit_loads, loads)


def test_varying_normal_forces_scale_each_load_to_their_mean(tmp_path, capsys):
    loads, twists = pairs()
    forces = np.where(np.arange(150) % 2 == 0, 5.0, 15.0)
    path = write_csv(tmp_path / "d.csv", loads * (forces / 10.0)[:, None], twists, forces)
    data = read_fit_data(path)
    assert data.varying_normal_force and data.normal_force == 10.0
    np.testing.assert_allclose(data.fit_loads, loads, rtol=1e-14)
    code, out, _ = run(capsys, path, "--json")
    assert code == EXIT_OK
    document = json.loads(out)
    assert document["data"]["normal_force"] == "column, varying"
    assert document["normal_force_N"] == 10.0
    assert document["mu"] == pytest.approx(direct("ellipsoid").surface.mu, rel=1e-6)


BAD_FILES = {
    "missing column": ("fx,fy,vx,vy,w\n", "line 1: missing column m"),
    "bad number": ("fx,fy,m\n1,2,3\n1,x2,3\n", "line 3, column 2 (fy): expected a number, got 'x2'"),
    "nan": ("# units\nfx,fy,m\n1,2,3\n1,2,nan\n", "line 4, column 3 (m): expected a finite number"),
    "infinite": ("fx,fy,m\n1e999,2,3\n", "line 2, column 1 (fx): expected a finite number"),
    "empty cell": ("fx,fy,m\n1,,3\n", "line 2, column 2 (fy): expected a number, got an empty cell"),
    "partial twist": ("fx,fy,m,vx,w\n", "line 1: twist columns vx, w without vy"),
    "empty file": ("", "no header line"),
    "comments only": ("# fx,fy,m\n\n", "no header line"),
    "unknown column": ("fx,fy,mz\n", "line 1, column 3 (mz): unknown column 'mz'; did you mean 'm'?"),
    "unknown, no near miss": ("fx,fy,m,time\n", "unknown column 'time'; allowed: fx, fy, m"),
    "duplicate column": ("fx,fy,m,FX_N\n", "line 1, column 4 (FX_N): column 'fx' again"),
    "non-SI unit": ("fx,fy,m_Nmm\n", "column 3 (m_Nmm): unit 'Nmm' is not N m: fixplan reads SI"),
    "semicolons": ("fx;fy;m\n1;2;3\n", "line 1: the header has a single column: separate"),
    "decimal comma": ("fx,fy,m\n1,2,3,5\n", "line 2: 4 cells, but the header names 3 columns (a decimal"),
    "zero load": ("fx,fy,m\n0,0,0\n", "line 2: the load (fx, fy, m) is zero"),
    "zero twist": ("fx,fy,m,vx,vy,w\n1,2,3,0,0,0\n", "line 2: the twist (vx, vy, w) is zero"),
    "normal force": ("fx,fy,m,normal_force\n1,2,3,-1\n", "line 2, column 4 (normal_force): expected a number > 0"),
    "too few rows": ("fx,fy,m\n1,0,0\n0,1,0\n", "only 2 measurements below the header; a fit needs at least 6"),
    "not UTF-8": (b"fx,fy,m\n\xff\n", "cannot read it: not UTF-8 text"),
}  # fmt: skip


@pytest.mark.parametrize("name", BAD_FILES)
def test_a_bad_file_is_named_with_line_and_column_and_exits_with_2(tmp_path, capsys, name):
    content, message = BAD_FILES[name]
    path = tmp_path / "bad.csv"
    if isinstance(content, bytes):
        path.write_bytes(content)
    else:
        path.write_text(content, encoding="utf-8")
    code, out, err = run(capsys, path)
    assert code == EXIT_INVALID_INPUT
    assert out == ""
    assert err.startswith(f"fixplan: error: {path}: ")
    assert message in err
    assert "Traceback" not in err


def test_every_mistake_is_listed_up_to_a_limit(tmp_path):
    path = tmp_path / "bad.csv"
    path.write_text("fx,fy,m\n" + "1,2,x\n" * (MAX_ISSUES + 7), encoding="utf-8")
    with pytest.raises(ProblemFileError) as caught:
        read_fit_data(path)
    issues = caught.value.issues
    assert len(issues) == MAX_ISSUES + 1
    assert issues[0].key_path == "line 2, column 3 (m)"
    assert issues[-1].message == "and 7 more mistakes not listed"


def test_data_the_fit_cannot_use_names_the_file(tmp_path, capsys):
    loads, twists = pairs()
    path = write_csv(tmp_path / "few.csv", loads[:18], twists[:18])
    code, _, err = run(capsys, path, "--model", "quartic")
    assert code == EXIT_INVALID_INPUT
    assert err.startswith(f"fixplan: error: {path}: the quartic fit needs at least 15 fitted pairs")
    flat = np.column_stack([loads[:, :2], np.zeros(150)])
    code, _, err = run(capsys, write_csv(tmp_path / "flat.csv", flat))
    assert code == EXIT_INVALID_INPUT and "every moment is zero" in err


@pytest.mark.parametrize(
    ("options", "message"),
    [
        (["--holdout", "1"], "--holdout must be a fraction in [0, 1), got 1"),
        (["--holdout", "nan"], "--holdout must be a fraction in [0, 1)"),
        (["--weight", "-1"], "--weight must be a number from 0 to 10000 (keep it near 1), got -1"),
        (
            ["--weight", "inf"],
            "--weight must be a number from 0 to 10000 (keep it near 1), got inf",
        ),
        (["--weight", "1e300"], "--weight must be a number from 0 to 10000"),
        (["--normal-force", "3"], "has a normal_force column already; drop one of them"),
        (["--save", "no-such-folder/fit.json"], "--save no-such-folder/fit.json: the folder"),
    ],
)
def test_bad_options_exit_with_2_before_fitting(tmp_path, capsys, options, message):
    code, out, err = run(capsys, data_file(tmp_path), *options)
    assert code == EXIT_INVALID_INPUT and out == ""
    assert message in err


def test_bad_input_prints_one_line_and_no_traceback_from_the_installed_command(tmp_path):
    path = tmp_path / "bad.csv"
    path.write_text("fx,fy,m\n1,2,oops\n", encoding="utf-8")
    result = subprocess.run(
        [sys.executable, "-m", "fixplan.io.cli", "fit", str(path)],
        capture_output=True, text=True, check=False,
    )  # fmt: skip
    assert result.returncode == EXIT_INVALID_INPUT
    assert result.stdout == ""
    assert result.stderr == (
        f"fixplan: error: {path}: line 2, column 3 (m): expected a number, got 'oops'\n"
    )


def test_a_fit_is_not_saved_over_its_measurements(tmp_path, capsys):
    """(``--save DATA.csv`` replaced the measurements with the fit's JSON.)"""
    path = write_csv(tmp_path / "data.csv", *pairs())
    before = path.read_bytes()
    assert main(["fit", str(path), "--save", str(path)]) == EXIT_INVALID_INPUT
    assert "that is the measurements' file" in capsys.readouterr().err
    assert path.read_bytes() == before
