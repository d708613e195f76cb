"""Problem files with a body from a mesh, contacts on its surface and inertial loads."""

import json

import numpy as np
import pytest
import trimesh

from fixplan.io.cli import EXIT_OK, main
from fixplan.io.problem_file import ProblemFileError, load_problem
from fixplan.planner.planner import Planner

STEEL = 7850.0

FILE = """\
schema_version = 1
name = "meshed-block"
kind = "grasp"
objective = "min-max-normal-force"

[defaults]
mu = 0.5
model = "point-cone"

[body]
mesh = "block.stl"
density = 7850.0
mesh_scale = 0.001

[[contacts]]
name = "left"
role = "finger"
on_surface = [0.0, -0.08, 0.0]

[[contacts]]
name = "right"
role = "finger"
on_surface = [0.0, 0.07, 0.0]

[[loads]]
name = "lift"
acceleration = [0.0, 0.0, 4.0]
"""


def _write(folder, text=FILE):
    trimesh.creation.box(extents=[40.0, 100.0, 20.0]).export(folder / "block.stl")  # mm
    path = folder / "problem.toml"
    path.write_text(text, encoding="utf-8")
    return path


def test_a_mesh_body_with_contacts_on_its_surface_is_read_and_solved(tmp_path):
    problem_file = load_problem(_write(tmp_path))
    body = problem_file.problem.body
    mass = STEEL * 0.04 * 0.1 * 0.02
    assert body.mass == pytest.approx(mass, rel=1e-9)
    np.testing.assert_allclose(body.inertia[2, 2], mass * (0.04**2 + 0.1**2) / 12, rtol=1e-9)
    left, right = problem_file.problem.contacts
    np.testing.assert_allclose(left.position, [0.0, -0.05, 0.0], atol=1e-12)
    np.testing.assert_allclose(left.normal, [0.0, 1.0, 0.0], atol=1e-12)
    np.testing.assert_allclose(right.position, [0.0, 0.05, 0.0], atol=1e-12)
    np.testing.assert_allclose(right.normal, [0.0, -1.0, 0.0], atol=1e-12)
    placed = problem_file.surface_contacts["left"]
    assert placed.distance == pytest.approx(0.03, abs=1e-12)
    plan = Planner(problem_file.problem).solve()
    assert plan.status == "optimal"
    # Point contacts lifting the block at 4 m/s²: m (g + a) / (2 mu) per finger.
    assert plan.forces["left"][0] == pytest.approx(mass * (9.81 + 4.0) / (2 * 0.5), rel=1e-7)


@pytest.mark.parametrize(
    ("old", "new", "key_path", "fragment"),
    [
        ('mesh = "block.stl"', 'mesh = "missing.stl"', "body.mesh", "missing.stl"),
        ("density = 7850.0", "mass = 1.0\ndensity = 7850.0", "body.mesh", "exactly one of"),
        ("density = 7850.0", "density = 7850.0\ncenter_of_mass = [0, 0, 0]",
         "body.center_of_mass", "not with a mesh"),
        ('on_surface = [0.0, -0.08, 0.0]', 'on_surface = [0.0, -0.08, 0.0]\nposition = [0, 0, 0]',
         "contacts[0].position", "not with on_surface"),
        ('name = "lift"', 'name = "lift"\nforce = [1.0, 0.0, 0.0]', "loads[0].point", "missing"),
        ("acceleration = [0.0, 0.0, 4.0]", "angular_velocity = [0.0, 0.0, 1e9]",
         "loads[0].angular_velocity", "rad/s"),
    ],
)  # fmt: skip
def test_mesh_and_motion_mistakes_are_reported_at_their_key_paths(
    tmp_path, old, new, key_path, fragment
):
    assert old in FILE
    with pytest.raises(ProblemFileError) as caught:
        load_problem(_write(tmp_path, FILE.replace(old, new, 1)))
    issues = [(i.key_path, i.message) for i in caught.value.issues]
    assert any(path == key_path and fragment in message for path, message in issues), issues


def test_an_open_mesh_is_refused_with_the_reason(tmp_path):
    path = _write(tmp_path)
    mesh = trimesh.creation.box(extents=[40.0, 100.0, 20.0])
    mesh.update_faces(np.arange(len(mesh.faces)) > 0)
    mesh.export(tmp_path / "block.stl")
    with pytest.raises(ProblemFileError, match="not watertight"):
        load_problem(path)


def test_on_surface_needs_a_mesh_body(tmp_path):
    text = FILE.replace('mesh = "block.stl"\ndensity = 7850.0\nmesh_scale = 0.001',
                        "mass = 1.0\ncenter_of_mass = [0, 0, 0]")  # fmt: skip
    with pytest.raises(ProblemFileError, match="needs a body read from a mesh"):
        load_problem(_write(tmp_path, text))


def test_the_command_line_prints_where_surface_contacts_were_placed(tmp_path, capsys):
    path = _write(tmp_path)
    assert main(["plan", str(path)]) == EXIT_OK
    out = capsys.readouterr().out
    assert "contact 'left' on the mesh surface at (0, -0.05, 0) m, normal (0, 1, 0), 30 mm" in out
    assert main(["plan", str(path), "--json"]) == EXIT_OK
    placed = json.loads(capsys.readouterr().out)["problem"]["surface_contacts"]["right"]
    assert placed["distance"] == pytest.approx(0.02, abs=1e-12)
