"""Push files and ``fixplan push``: the library's push problems give the outcomes their comments
state, bad files are reported at their key paths, and a push report is complete and
reproducible.

The two library files are checked against what the mechanics says independently of the numbers
recorded in them: a finger pushing above the centre of friction turns the part clockwise (Mason's
voting theorem), and a flat pusher ends with the part square to its face (stable pushing).
"""

from __future__ import annotations

import copy
import json
import math
import tomllib
from pathlib import Path

import numpy as np
import pytest

from fixplan.io.cli import EXIT_INVALID_INPUT, EXIT_OK, main
from fixplan.io.figures import trajectory_figure
from fixplan.io.push_file import load_push
from fixplan.io.report_document import MANIFEST
from fixplan.io.toml_schema import ProblemFileError
from fixplan.models import Ellipsoid
from fixplan.motion import LinePusher, PointPusher, push

PROBLEMS = Path(__file__).resolve().parents[1] / "problems"

#: Tolerance of the recorded outcomes of the library files (the integration is deterministic;
#: this leaves room for rounding differences between machines).
RECORDED_RTOL = 1e-4

SMALL_PUSH = """\
schema_version = 1
name = "small-push"
kind = "push"

[part]
outline = { shape = "rectangle", length = 0.04, width = 0.02 }
mass = 0.2
pose = [0.0, 0.0, 0.2]

[support]
mu = 0.4
model = "ellipsoid"

[pusher]
shape = "line"
width = 0.08
mu = 0.3
start = [-0.03, 0.0]
velocity = [0.02, 0.0]

[simulation]
duration = 1.5
steps = 60
"""


def _run_json(capsys, *args: str) -> tuple[int, dict]:
    code = main(["push", *args, "--json", "--quiet"])
    out = capsys.readouterr().out
    return code, json.loads(out) if out else {}


def test_a_finger_pushing_above_the_centre_turns_the_box_clockwise_as_recorded(capsys):
    code, summary = _run_json(capsys, str(PROBLEMS / "push-box-finger.toml"))
    assert code == EXIT_OK
    assert summary["turned_deg"] < 0.0  # Mason's voting theorem: clockwise
    assert summary["turned_deg"] == pytest.approx(-33.82, rel=RECORDED_RTOL * 10)
    assert 1e3 * summary["moved_m"] == pytest.approx(59.4, abs=0.05)
    counts = {mode: round(400 * share) for mode, share in summary["mode_fractions"].items()}
    assert counts == {"sticking": 347, "sliding-left": 0, "sliding-right": 4, "separated": 49}
    # The largest pusher force is the part's friction at most: mu m g.
    assert summary["max_force_N"] <= 0.3 * 0.5 * 9.81 * (1 + 1e-9)


def test_a_flat_pusher_squares_up_the_askew_box_and_carries_it(capsys):
    code, summary = _run_json(capsys, str(PROBLEMS / "push-box-flat.toml"))
    assert code == EXIT_OK
    assert abs(summary["final_pose"][2]) < 1e-9  # flush against the face, which faces +x
    assert summary["turned_deg"] == pytest.approx(-20.0, abs=1e-6)
    assert summary["line_contact_travel_m"] == pytest.approx(0.0598, abs=1e-6)
    assert 1e3 * summary["moved_m"] == pytest.approx(55.73, abs=0.01)


def test_the_cli_summary_says_where_the_part_ends_and_when_it_lies_flush(tmp_path, capsys):
    path = tmp_path / "small.toml"
    path.write_text(SMALL_PUSH, encoding="utf-8")
    assert main(["push", str(path)]) == EXIT_OK
    out = capsys.readouterr().out
    assert out.startswith("push       small-push: LinePusher, ellipsoid support, 60 steps")
    assert "final pose x = " in out and "flush      after " in out


def test_a_push_report_is_complete_and_reproducible(tmp_path):
    path = tmp_path / "small.toml"
    path.write_text(SMALL_PUSH, encoding="utf-8")
    folders = [tmp_path / "one", tmp_path / "two"]
    for folder in folders:
        assert main(["push", str(path), "--report", str(folder), "--quiet"]) == EXIT_OK
    names = {p.name for p in folders[0].iterdir()}
    assert names == {"push.json", "report.md", "report.html", "trajectory.csv", "trajectory.png",
                     "trajectory.gif", MANIFEST}  # fmt: skip
    for name in sorted(names):
        assert (folders[0] / name).read_bytes() == (folders[1] / name).read_bytes(), name
    rows = (folders[0] / "trajectory.csv").read_text().splitlines()
    assert len(rows) == 61
    final = [float(v) for v in rows[-1].split(",")[1:4]]
    summary = json.loads((folders[0] / "push.json").read_text())
    np.testing.assert_allclose(final, summary["final_pose"], rtol=1e-8, atol=1e-12)
    assert (folders[0] / "trajectory.gif").read_bytes()[:6] == b"GIF89a"


def test_the_trajectory_figure_draws_the_part_where_the_trajectory_puts_it(tmp_path):
    push_file = _small(tmp_path)
    trajectory = push(push_file.surface, push_file.pusher, shape=push_file.shape,
                      pose=push_file.pose, duration=push_file.duration, steps=push_file.steps)  # fmt: skip
    fig = trajectory_figure(trajectory, frames=5)
    (part,) = [line for line in fig.axes[0].lines if line.get_label() == "part"]
    x, y, theta = trajectory.poses[-1]
    corners = np.array([[-0.02, -0.01], [0.02, -0.01], [0.02, 0.01], [-0.02, 0.01]])
    rotation = np.array([[math.cos(theta), -math.sin(theta)], [math.sin(theta), math.cos(theta)]])
    expected = 1e3 * (corners @ rotation.T + [x, y])
    drawn = np.column_stack(part.get_data())[:4]
    np.testing.assert_allclose(drawn, expected, atol=1e-9)


def _small(tmp_path, text: str = SMALL_PUSH):
    path = tmp_path / "small.toml"
    path.write_text(text, encoding="utf-8")
    return load_push(path)


def test_a_push_file_builds_the_surface_pusher_and_outline_it_describes(tmp_path):
    push_file = _small(tmp_path)
    assert isinstance(push_file.surface, Ellipsoid)
    assert isinstance(push_file.pusher, LinePusher)
    np.testing.assert_allclose(push_file.pusher.normal, [1.0, 0.0])
    assert push_file.normal_force == pytest.approx(0.2 * 9.81)
    # The default support pressure is uniform over the outline: the rectangle's limit surface.
    assert push_file.surface.max_force == pytest.approx(0.4 * 0.2 * 9.81, rel=1e-12)
    point = _small(tmp_path, SMALL_PUSH.replace('shape = "line"\nwidth = 0.08', 'shape = "point"\n'
                                                'radius = 0.002'))  # fmt: skip
    assert isinstance(point.pusher, PointPusher) and point.pusher.radius == 0.002


def _mutated(change) -> str:
    document = tomllib.loads(SMALL_PUSH)
    change(document)
    return _to_toml(document)


def _to_toml(document: dict) -> str:
    lines, tables = [], []
    for key, value in document.items():
        if isinstance(value, dict):
            tables.append((key, value))
        else:
            lines.append(f"{key} = {_value(value)}")
    for key, table in tables:
        lines.append(f"[{key}]")
        lines += [f"{k} = {_value(v)}" for k, v in table.items()]
    return "\n".join(lines) + "\n"


def _value(value) -> str:
    if isinstance(value, dict):
        return "{ " + ", ".join(f"{k} = {_value(v)}" for k, v in value.items()) + " }"
    if isinstance(value, list):
        return "[" + ", ".join(_value(v) for v in value) + "]"
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, str):
        return json.dumps(value)
    return repr(value)


def _set(path: str, value):
    def change(document):
        *parents, last = path.split(".")
        table = document
        for key in parents:
            table = table[key]
        if value is _DELETE:
            del table[last]
        else:
            table[last] = copy.deepcopy(value)

    return change


_DELETE = object()

BAD_FILES = {
    "pusher.width": _set("pusher.width", _DELETE),
    "pusher.velocity": _set("pusher.velocity", [0.0, 0.0]),
    "pusher.mu": _set("pusher.mu", -0.1),
    "pusher.radius": _set("pusher.radius", 0.01),
    "pusher.shape": _set("pusher.shape", "round"),
    "support.mu": _set("support.mu", 0.0),
    "support.model": _set("support.model", "pyramid"),
    "support.offset": _set("support.offset", [0.01, 0.0]),
    "simulation.steps": _set("simulation.steps", 0),
    "simulation.duration": _set("simulation.duration", math.inf),
    "simulation.start_overlap": _set("simulation.start_overlap", -0.001),
    "part.mass": _set("part.mass", "heavy"),
    "part.outline": _set(
        "part.outline", {"shape": "polygon", "vertices": [[0, 0], [1, 1], [1, 0], [0, 1]]}
    ),
    "part.pose": _set("part.pose", [0.0, 0.0]),
    "kind": _set("kind", "fixture"),
    "pusher": _set("pusher", _DELETE),
    "simulaton": _set("simulaton", {"steps": 3}),
}


@pytest.mark.parametrize("key_path", BAD_FILES, ids=str)
def test_a_bad_push_file_is_reported_at_its_key_path(tmp_path, key_path):
    path = tmp_path / "bad.toml"
    path.write_text(_mutated(BAD_FILES[key_path]), encoding="utf-8")
    with pytest.raises(ProblemFileError) as error:
        load_push(path)
    paths = [issue.key_path for issue in error.value.issues]
    assert any(p == key_path or p.startswith(key_path + ".") for p in paths), paths


@pytest.mark.parametrize(("key_path", "smallest"), [("part.mass", "1e-09"),
                                                      ("support.gravity", "1e-06")])  # fmt: skip
def test_a_vanishing_normal_force_of_the_support_is_refused_at_its_key_path(
    tmp_path, key_path, smallest
):
    """A part of 1e-300 kg (or under 1e-300 m/s² of gravity) ended in an overflow; its mass and
    gravity have smallest values, which the message names."""
    path = tmp_path / "light.toml"
    path.write_text(_mutated(_set(key_path, 1e-300)), encoding="utf-8")
    with pytest.raises(ProblemFileError) as error:
        load_push(path)
    (issue,) = error.value.issues
    assert issue.key_path == key_path and f"below {smallest}" in str(error.value)


def test_a_pusher_that_starts_inside_the_part_is_invalid_input_naming_the_file(tmp_path, capsys):
    path = tmp_path / "inside.toml"
    path.write_text(_mutated(_set("pusher.start", [0.0, 0.0])), encoding="utf-8")
    assert main(["push", str(path)]) == EXIT_INVALID_INPUT
    err = capsys.readouterr().err
    assert f"{path}: pusher: the LinePusher" in err and "overlaps the part" in err


def test_a_measured_start_inside_the_part_pushes_if_the_file_allows_its_overlap(tmp_path, capsys):
    # The face starts 1.6 mm into the askew box: refused, unless simulation.start_overlap allows
    # it; then it pushes as the same face set back by its overlap along its normal.
    path = tmp_path / "measured.toml"
    path.write_text(_mutated(_set("pusher.start", [-0.02, 0.0])), encoding="utf-8")
    assert main(["push", str(path)]) == EXIT_INVALID_INPUT
    assert "allow it with start_overlap" in capsys.readouterr().err
    allowing = _set("simulation.start_overlap", 0.002)
    path.write_text(_mutated(lambda d: (_set("pusher.start", [-0.02, 0.0])(d), allowing(d))),
                    encoding="utf-8")  # fmt: skip
    measured = load_push(path)
    assert measured.start_overlap == 0.002
    assert main(["push", str(path), "--json"]) == EXIT_OK
    overlap = 0.02 * math.cos(0.2) + 0.01 * math.sin(0.2) - 0.02
    set_back = LinePusher(([-0.02 - overlap, 0.0], [0.02, 0.0]), mu=0.3, width=0.08)
    expected = push(measured.surface, set_back, shape=measured.shape, pose=measured.pose,
                    duration=1.5, steps=60).poses[-1]  # fmt: skip
    summary = json.loads(capsys.readouterr().out)
    np.testing.assert_allclose(summary["final_pose"], expected, rtol=0.0, atol=1e-12)


def test_fixplan_check_validates_a_push_file_and_plan_points_to_push(capsys):
    file = str(PROBLEMS / "push-box-flat.toml")
    assert main(["check", file, "--json"]) == EXIT_OK
    document = json.loads(capsys.readouterr().out)
    assert document["valid"] and document["kind"] == "push"
    assert main(["plan", file]) == EXIT_INVALID_INPUT
    assert "run it with `fixplan push FILE`" in capsys.readouterr().err


def test_fixplan_push_rejects_a_problem_file_with_a_clear_message(capsys):
    assert main(["push", str(PROBLEMS / "hertz-pinch.toml")]) == EXIT_INVALID_INPUT
    err = capsys.readouterr().err
    assert "kind" in err and "'push'" in err and "Traceback" not in err
