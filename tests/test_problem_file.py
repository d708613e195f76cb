"""Reading TOML problem files: the valid file round-trips, every mistake is reported at once."""

import hashlib

import numpy as np
import pytest

from fixplan.errors import FixplanError, InvalidArgumentError
from fixplan.io import problem_file as problem_file_module
from fixplan.io.problem_file import Issue, ProblemFile, ProblemFileError, load_problem
from fixplan.motion import ComplianceError, Stiffness
from fixplan.surface.pressure import DiskField, GridField, PolygonField

HEADER = """\
schema_version = 1
name = "vise-milling"
kind = "fixture"
objective = "min-total-clamp-force"
description = "A block held in a machine vise for face milling."

[defaults]
mu = 0.3
model = "ellipsoid"
"""

BODY = """
[body]
mass = 2.0
center_of_mass = [0.0, 0.0, 0.02]
"""

CONTACTS = """
[[contacts]]
name = "jaw-fixed"
role = "locator"
position = [-0.05, 0.0, 0.02]
normal = [1.0, 0.0, 0.0]
mu = 0.25
model = "exact"
patch = { shape = "rectangle", length = 0.08, width = 0.03, axis = [0.0, 1.0, 0.0] }

[[contacts]]
name = "jaw-moving"
role = "clamp"
position = [0.05, 0.0, 0.02]
normal = [-1.0, 0.0, 0.0]
max_force = 2000.0
patch = { shape = "disk", radius = 0.01, pressure = "hertz" }

[[contacts]]
name = "rest"
role = "support"
position = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]
model = "point-pyramid"
facets = 8
inscribed = false
"""

LOADS = """
[[loads]]
name = "face-mill-pass-1"
force = [120.0, -40.0, -60.0]
point = [0.03, 0.0, 0.04]
torque = [0.0, 0.0, 1.5]

[[loads]]
name = "face-mill-pass-2"
force = [-120.0, 40.0, -60.0]
point = [-0.03, 0.0, 0.04]
"""

VALID = HEADER + BODY + CONTACTS + LOADS


def _write(folder, text, name="problem.toml"):
    path = folder / name
    path.write_text(text, encoding="utf-8")
    return path


def _edited(text, *edits):
    """``text`` with each ``(old, new)`` replacement made; ``old`` must occur exactly once."""
    for old, new in edits:
        assert text.count(old) == 1, old
        text = text.replace(old, new)
    return text


def _issues(folder, text, **options) -> list[Issue]:
    with pytest.raises(ProblemFileError) as caught:
        load_problem(_write(folder, text), **options)
    return caught.value.issues


def _assert_issue(issues, key_path, fragment):
    matching = [issue for issue in issues if issue.key_path == key_path]
    assert matching, f"no issue at {key_path!r} among {issues}"
    assert any(fragment in issue.message for issue in matching), matching


def test_a_valid_file_is_read_into_the_expected_problem(tmp_path):
    path = _write(tmp_path, VALID)
    loaded = load_problem(path)
    problem = loaded.problem
    assert isinstance(loaded, ProblemFile)
    assert (loaded.name, loaded.kind, loaded.path) == ("vise-milling", "fixture", path)
    assert loaded.sha256 == hashlib.sha256(path.read_bytes()).hexdigest()
    assert loaded.model_override is None
    assert problem.objective == "min-total-clamp-force"
    assert problem.body.mass == 2.0
    np.testing.assert_array_equal(problem.body.gravity, [0.0, 0.0, -9.81])
    assert [c.name for c in problem.contacts] == ["jaw-fixed", "jaw-moving", "rest"]
    assert [c.role for c in problem.contacts] == ["locator", "clamp", "support"]
    np.testing.assert_array_equal(problem.contacts[1].normal, [-1.0, 0.0, 0.0])
    assert problem.contacts[1].max_force == 2000.0
    assert isinstance(problem.contacts[1].patch, DiskField)
    assert problem.contacts[1].patch.profile == "hertz"
    assert (problem.contacts[2].facets, problem.contacts[2].inscribed) == (8, False)
    assert problem.contacts[2].patch is None
    np.testing.assert_array_equal(problem.loads[0].torque, [0.0, 0.0, 1.5])
    np.testing.assert_array_equal(problem.loads[1].torque, [0.0, 0.0, 0.0])


def test_defaults_apply_where_a_contact_is_silent_and_yield_where_it_speaks(tmp_path):
    contacts = load_problem(_write(tmp_path, VALID)).problem.contacts
    assert (contacts[0].mu, contacts[0].model) == (0.25, "exact")
    assert (contacts[1].mu, contacts[1].model) == (0.3, "ellipsoid")
    assert (contacts[2].mu, contacts[2].model) == (0.3, "point-pyramid")


def test_default_facets_apply_only_to_pyramid_contacts(tmp_path):
    text = _edited(VALID, ('model = "ellipsoid"\n', 'model = "ellipsoid"\nfacets = 6\n'))
    text = _edited(text, ("facets = 8\n", ""))
    contacts = load_problem(_write(tmp_path, text)).problem.contacts
    assert [c.facets for c in contacts] == [None, None, 6]


def test_integers_are_read_as_numbers(tmp_path):
    text = _edited(VALID, ("mass = 2.0", "mass = 2"))
    body = load_problem(_write(tmp_path, text)).problem.body
    assert body.mass == 2.0
    assert isinstance(body.mass, float)


def test_a_rectangle_axis_sets_the_contact_axis(tmp_path):
    contact = load_problem(_write(tmp_path, VALID)).problem.contacts[0]
    assert isinstance(contact.patch, PolygonField)
    np.testing.assert_allclose(contact.patch.vertices.max(axis=0), [0.04, 0.015])
    np.testing.assert_allclose(contact.axis, [0.0, 1.0, 0.0])
    np.testing.assert_allclose(contact.frame[1], [0.0, 0.0, 1.0])


def test_a_contact_axis_in_the_same_direction_as_its_rectangle_axis_is_accepted(tmp_path):
    text = _edited(VALID, ('model = "exact"\n', 'model = "exact"\naxis = [0.0, 2.0, 0.0]\n'))
    contact = load_problem(_write(tmp_path, text)).problem.contacts[0]
    np.testing.assert_allclose(contact.axis, [0.0, 1.0, 0.0])


def test_grid_values_are_read_from_a_csv_file_next_to_the_problem_file(tmp_path, monkeypatch):
    folder = tmp_path / "problems"
    folder.mkdir()
    (folder / "jaw.csv").write_text("1, 2, 1\n\n0.5, 1.0, 0.5\n", encoding="utf-8")
    grid = 'patch = { shape = "grid", x = [-0.01, 0.0, 0.01], y = [-0.005, 0.005], values = "jaw.csv" }'
    text = _edited(VALID, ('patch = { shape = "disk", radius = 0.01, pressure = "hertz" }', grid))
    monkeypatch.chdir(tmp_path)
    patch = load_problem(_write(folder, text)).problem.contacts[1].patch
    assert isinstance(patch, GridField)
    np.testing.assert_array_equal(patch.values, [[1.0, 2.0, 1.0], [0.5, 1.0, 0.5]])


def test_a_csv_with_a_byte_order_mark_and_trailing_commas_is_read(tmp_path):
    (tmp_path / "map.csv").write_text("\ufeff1, 2, 1,\n0.5, 1.0, 0.5,\n", encoding="utf-8")
    grid = 'patch = { shape = "grid", x = [-0.01, 0.0, 0.01], y = [-0.005, 0.005], values = "map.csv" }'
    text = _edited(VALID, ('patch = { shape = "disk", radius = 0.01, pressure = "hertz" }', grid))
    patch = load_problem(_write(tmp_path, text)).problem.contacts[1].patch
    np.testing.assert_array_equal(patch.values, [[1.0, 2.0, 1.0], [0.5, 1.0, 0.5]])


def test_grid_values_may_be_given_inline(tmp_path):
    grid = 'patch = { shape = "grid", x = [0.0, 0.01], y = [0.0, 0.01], values = [[1, 2], [3, 4]] }'
    text = _edited(VALID, ('patch = { shape = "disk", radius = 0.01, pressure = "hertz" }', grid))
    patch = load_problem(_write(tmp_path, text)).problem.contacts[1].patch
    np.testing.assert_array_equal(patch.values, [[1.0, 2.0], [3.0, 4.0]])


@pytest.mark.parametrize(
    ("model", "facets"), [("point-cone", [None, None, None]), ("point-pyramid", [None, None, 8])]
)
def test_a_model_override_replaces_every_contact_model(tmp_path, model, facets):
    loaded = load_problem(_write(tmp_path, VALID), model=model)
    assert loaded.model_override == model
    assert [c.model for c in loaded.problem.contacts] == [model] * 3
    assert [c.facets for c in loaded.problem.contacts] == facets


def test_an_area_model_override_keeps_point_contacts_point_contacts(tmp_path):
    loaded = load_problem(_write(tmp_path, VALID), model="pyramid")
    contacts = loaded.problem.contacts
    assert [c.model for c in contacts] == ["pyramid", "pyramid", "point-pyramid"]
    assert contacts[2].patch is None
    cone = load_problem(_write(tmp_path, VALID), model="ellipsoid").problem.contacts
    assert [c.model for c in cone] == ["ellipsoid", "ellipsoid", "point-cone"]


def test_an_unknown_model_override_is_an_invalid_argument(tmp_path):
    with pytest.raises(InvalidArgumentError, match="cone"):
        load_problem(_write(tmp_path, VALID), model="cones")


@pytest.mark.parametrize(
    ("edits", "key_path", "fragment"),
    [
        pytest.param(
            [("mu = 0.25", "muu = 0.25")], "contacts[0].muu", "did you mean 'mu'?", id="typo"
        ),
        pytest.param(
            [('kind = "fixture"', 'kind = "fixture"\nxyzzy = 1')],
            "xyzzy",
            "allowed keys: schema_version, name, kind",
            id="unknown-key",
        ),
        pytest.param(
            [("max_force = 2000.0", 'max_force = 2000.0\n"max force" = 1')],
            'contacts[1]."max force"',
            "did you mean 'max_force'?",
            id="quoted-key",
        ),
        pytest.param(
            [("mass = 2.0", 'mass = "abc"')],
            "body.mass",
            "expected a number, got string 'abc'",
            id="string-for-number",
        ),
        pytest.param(
            [("mass = 2.0", "mass = true")], "body.mass", "got boolean true", id="bool-for-number"
        ),
        pytest.param(
            [("center_of_mass = [0.0, 0.0, 0.02]\n", "")],
            "body.center_of_mass",
            "missing required key; expected an array of 3 numbers",
            id="missing-key",
        ),
        pytest.param(
            [("point = [0.03, 0.0, 0.04]", "point = [0.03, 0.0]")],
            "loads[0].point",
            "expected an array of 3 numbers, got 2 items",
            id="short-array",
        ),
        pytest.param(
            [("force = [120.0, -40.0, -60.0]", "force = [120.0, nan, -60.0]")],
            "loads[0].force",
            "element [1]: expected a finite number, got nan",
            id="nan",
        ),
        pytest.param(
            [("mass = 2.0", "mass = inf")], "body.mass", "expected a finite number", id="inf"
        ),
        pytest.param(
            [("normal = [0.0, 0.0, 1.0]", "normal = [0.0, 0.0, 0.0]")],
            "contacts[2].normal",
            "got the zero vector",
            id="zero-normal",
        ),
        pytest.param(
            [("normal = [0.0, 0.0, 1.0]", "normal = [0.0, 0.0, 2.0]")],
            "contacts[2].normal",
            "expected a unit vector (length 1 within 1e-06), got length 2; did you mean "
            "[0.0, 0.0, 1.0]?",
            id="non-unit-normal",
        ),
        pytest.param(
            [("mu = 0.25", "mu = -0.25")],
            "contacts[0].mu",
            "expected a number >= 0, got -0.25",
            id="negative-mu",
        ),
        pytest.param(
            [("mu = 0.3", "mu = -0.1")],
            "defaults.mu",
            "expected a number >= 0",
            id="negative-default-mu",
        ),
        pytest.param(
            [("max_force = 2000.0", "max_force = -1.0")],
            "contacts[1].max_force",
            "expected a number >= 0, got -1.0",
            id="negative-force",
        ),
        pytest.param(
            [("mass = 2.0", "mass = -2.0")],
            "body.mass",
            "expected a number >= 0",
            id="negative-mass",
        ),
        pytest.param(
            [("length = 0.08", "length = -0.08")],
            "contacts[0].patch.length",
            "expected a number > 0, got -0.08",
            id="negative-length",
        ),
        pytest.param(
            [('name = "rest"', 'name = "jaw-fixed"')],
            "contacts[2].name",
            "duplicate contact name 'jaw-fixed'; contacts[0] already uses it",
            id="duplicate-contact",
        ),
        pytest.param(
            [('name = "face-mill-pass-2"', 'name = "face-mill-pass-1"')],
            "loads[1].name",
            "duplicate load name 'face-mill-pass-1'; loads[0] already uses it",
            id="duplicate-load",
        ),
        pytest.param(
            [('role = "locator"', 'role = "locater"')],
            "contacts[0].role",
            "expected one of 'locator', 'support', 'clamp', 'finger'; got string 'locater' "
            "(did you mean 'locator'?)",
            id="unknown-role",
        ),
        pytest.param(
            [('model = "exact"', 'model = "exakt"')],
            "contacts[0].model",
            "did you mean 'exact'?",
            id="unknown-model",
        ),
        pytest.param(
            [('objective = "min-total-clamp-force"', 'objective = "min-clamp-force"')],
            "objective",
            "expected one of 'min-total-clamp-force', 'min-max-normal-force'",
            id="unknown-objective",
        ),
        pytest.param(
            [('shape = "rectangle"', 'shape = "rectangel"')],
            "contacts[0].patch.shape",
            "did you mean 'rectangle'?",
            id="unknown-shape",
        ),
        pytest.param(
            [('pressure = "hertz"', 'pressure = "hertzian"')],
            "contacts[1].patch.pressure",
            "expected one of 'uniform', 'hertz', 'parabolic', 'annulus', 'ring'",
            id="unknown-pressure",
        ),
        pytest.param(
            [("width = 0.03,", 'width = 0.03, pressure = "hertz",')],
            "contacts[0].patch.pressure",
            "expected 'uniform' (the only pressure of a rectangle)",
            id="rectangle-pressure",
        ),
        pytest.param(
            [('pressure = "hertz"', 'pressure = "annulus"')],
            "contacts[1].patch.inner_radius",
            "pressure 'annulus' needs inner_radius",
            id="annulus-without-inner-radius",
        ),
        pytest.param(
            [('pressure = "hertz"', 'pressure = "hertz", inner_radius = 0.005')],
            "contacts[1].patch.inner_radius",
            "only for pressure 'annulus', not 'hertz'",
            id="inner-radius-without-annulus",
        ),
        pytest.param(
            [('patch = { shape = "disk", radius = 0.01, pressure = "hertz" }\n', "")],
            "contacts[1].patch",
            "missing: contact 'jaw-moving' needs a patch (area and pressure) for model 'ellipsoid'",
            id="area-model-without-patch",
        ),
        pytest.param(
            [('model = "point-pyramid"', 'model = "point-cone"')],
            "contacts[2].facets",
            "only for pyramid models (pyramid, point-pyramid), not model 'point-cone'",
            id="facets-on-cone",
        ),
        pytest.param(
            [("facets = 8", "facets = 2")],
            "contacts[2].facets",
            "expected an integer >= 3, got integer 2",
            id="too-few-facets",
        ),
        pytest.param(
            [('role = "locator"', 'role = "locator"\nforce = 100.0')],
            "contacts[0].force",
            "only clamps and fingers take a force; a locator's normal force is a reaction",
            id="force-on-locator",
        ),
        pytest.param(
            [("mu = 0.3\n", "")],
            "contacts[1].mu",
            "missing required key; expected a number >= 0 here or in [defaults]",
            id="mu-nowhere",
        ),
        pytest.param(
            [('model = "exact"', 'model = "exact"\naxis = [0.0, 0.0, 1.0]')],
            "contacts[0].axis",
            "[0.0, 0.0, 1.0] differs from patch.axis [0.0, 1.0, 0.0]",
            id="axis-conflict",
        ),
        pytest.param(
            [("schema_version = 1", "schema_version = 2")],
            "schema_version",
            "expected 1 (the only schema version this fixplan reads), got integer 2",
            id="schema-version",
        ),
        pytest.param(
            [('kind = "fixture"', 'kind = "gripper"')],
            "kind",
            "expected one of 'fixture', 'grasp'",
            id="unknown-kind",
        ),
    ],
)
def test_each_kind_of_mistake_is_reported_at_its_key_path(tmp_path, edits, key_path, fragment):
    _assert_issue(_issues(tmp_path, _edited(VALID, *edits)), key_path, fragment)


@pytest.mark.parametrize(
    ("text", "key_path", "fragment"),
    [
        (HEADER + BODY + LOADS, "contacts", "missing required key; add at least one [[contacts]]"),
        ("contacts = []\n" + HEADER + BODY + LOADS, "contacts", "got an empty array"),
        (HEADER + BODY + CONTACTS, "loads", "missing required key; add at least one [[loads]]"),
        (HEADER + CONTACTS + LOADS, "body", "missing required table; add a [body] section"),
    ],
    ids=["no-contacts", "empty-contacts", "no-loads", "no-body"],
)
def test_a_file_without_contacts_loads_or_body_is_rejected(tmp_path, text, key_path, fragment):
    _assert_issue(_issues(tmp_path, text), key_path, fragment)


def test_a_key_given_twice_is_a_toml_syntax_error(tmp_path):
    text = _edited(VALID, ("width = 0.03,", "width = 0.03, length = 0.09,"))
    (issue,) = _issues(tmp_path, text)
    assert issue.key_path == ""
    assert issue.message.startswith("TOML syntax error:")
    assert "(at line 22, column 74)" in issue.message


@pytest.mark.parametrize(
    ("patch", "key_path", "fragment"),
    [
        pytest.param(
            'patch = { shape = "polygon", vertices = [[0.0, 0.0], [0.01, 0.01], [0.01, 0.0], '
            "[0.0, 0.01]] }",
            "contacts[1].patch",
            "vertices",
            id="self-intersecting-polygon",
        ),
        pytest.param(
            'patch = { shape = "points", xy = [[0.0, 0.0]] }',
            "contacts[1].patch",
            "at least two distinct loaded points",
            id="single-point",
        ),
        pytest.param(
            'patch = { shape = "disk", radius = 0.01, pressure = "annulus", inner_radius = 0.02 }',
            "contacts[1].patch",
            "inner_radius must be < radius",
            id="inner-radius-too-large",
        ),
        pytest.param(
            'patch = { shape = "grid", x = [0.0, 0.01], y = [0.0, 0.01], values = [[1, 2]] }',
            "contacts[1].patch.values",
            "expected 2 rows (one per y), got 1",
            id="grid-rows",
        ),
        pytest.param(
            'patch = { shape = "grid", x = [0.0, 0.01], y = [0.0, 0.01], values = "gone.csv" }',
            "contacts[1].patch.values",
            "cannot read the CSV file",
            id="grid-csv-missing",
        ),
        pytest.param(
            'patch = { shape = "grid", x = [0.0, 0.01], y = [0.0, 0.01], values = "bad.csv" }',
            "contacts[1].patch.values",
            "bad.csv line 2, column 2: expected a finite number, got 'x'",
            id="grid-csv-bad-cell",
        ),
        pytest.param(
            'patch = { shape = "grid", x = [0.0, 0.01], y = [0.0, 0.01], values = 3 }',
            "contacts[1].patch.values",
            "or the name of a CSV file, got integer 3",
            id="grid-values-type",
        ),
    ],
)
def test_patch_mistakes_are_reported_under_the_contact_patch(tmp_path, patch, key_path, fragment):
    (tmp_path / "bad.csv").write_text("1, 2\n3, x\n", encoding="utf-8")
    text = _edited(VALID, ('patch = { shape = "disk", radius = 0.01, pressure = "hertz" }', patch))
    _assert_issue(_issues(tmp_path, text), key_path, fragment)


def test_a_fixed_force_above_max_force_is_reported_at_the_contact(tmp_path):
    text = _edited(VALID, ("max_force = 2000.0", "max_force = 2000.0\nforce = 2500.0"))
    _assert_issue(_issues(tmp_path, text), "contacts[1]", "exceeds max_force 2000.0")


def test_an_objective_the_contacts_cannot_meet_is_reported_at_the_contacts(tmp_path):
    # (At the objective before: the force to give is the contact's.)
    text = _edited(VALID, ('objective = "min-total-clamp-force"', 'objective = "check"'))
    _assert_issue(_issues(tmp_path, text), "contacts[1].force",
                  "required: objective 'check' takes the active forces as given")  # fmt: skip


def test_a_turning_load_without_the_bodys_inertia_is_reported_at_the_body(tmp_path):
    text = _edited(VALID, ("point = [0.03, 0.0, 0.04]",
                           "point = [0.03, 0.0, 0.04]\nangular_velocity = [0, 0, 1]"))  # fmt: skip
    _assert_issue(
        _issues(tmp_path, text), "body", "load 'face-mill-pass-1' (loads[0]) has an angular"
    )


def test_all_mistakes_of_a_file_are_reported_at_once(tmp_path):
    text = _edited(
        VALID,
        ("mass = 2.0", "mass = -2.0"),
        ("mu = 0.25", "frction = 0.25"),
        ("point = [0.03, 0.0, 0.04]", 'point = [0.03, "0.0", 0.04]'),
    )
    issues = _issues(tmp_path, text)
    assert [issue.key_path for issue in issues] == [
        "body.mass",
        "contacts[0].frction",
        "loads[0].point",
    ]


def test_the_error_lists_one_issue_per_line_with_file_and_key_path(tmp_path):
    text = _edited(VALID, ("mass = 2.0", "mass = -2.0"), ("mu = 0.25", "muu = 0.25"))
    path = _write(tmp_path, text)
    with pytest.raises(ProblemFileError) as caught:
        load_problem(path)
    error = caught.value
    assert isinstance(error, FixplanError)
    assert isinstance(error, ValueError)
    assert error.path == path
    assert str(error).splitlines() == [
        f"{path}: body.mass: expected a number >= 0, got -2.0",
        f"{path}: contacts[0].muu: unknown key; did you mean 'mu'?",
    ]


def test_a_toml_syntax_error_names_line_and_column(tmp_path):
    text = _edited(VALID, ("mass = 2.0", "mass = "))
    (issue,) = _issues(tmp_path, text)
    assert issue.key_path == ""
    assert "TOML syntax error" in issue.message
    assert "line 12, column 8" in issue.message


@pytest.mark.parametrize(
    ("content", "fragment"),
    [(None, "cannot read the file"), (b"name = '\xff'\n", "not UTF-8 text")],
    ids=["missing", "not-utf8"],
)
def test_an_unreadable_file_is_one_issue_for_the_whole_file(tmp_path, content, fragment):
    path = tmp_path / "problem.toml"
    if content is not None:
        path.write_bytes(content)
    with pytest.raises(ProblemFileError) as caught:
        load_problem(path)
    (issue,) = caught.value.issues
    assert issue.key_path == ""
    assert fragment in issue.message
    assert str(caught.value).startswith(f"{path}: {fragment}")


@pytest.mark.parametrize(
    "text",
    [
        "",
        "contacts = 3\nbody = []\n[[loads]]\nforce = 'x'\n",
        HEADER + "body = 1\ncontacts = [1, 'a', []]\nloads = [{}]\n",
        "defaults = 'x'\n" + BODY + "[[contacts]]\npatch = 5\n[[loads]]\nname = 3\n",
        "schema_version = true\nname = [1]\nkind = {}\nobjective = 1979-05-27\n",
        HEADER + BODY + "[[contacts]]\nname = 'a'\nnormal = [[1.0], 0.0, {}]\nfacets = 3.0\n"
        "patch = { shape = 'grid', x = 1, y = [], values = [1, 2] }\n" + LOADS,
        HEADER
        + BODY
        + "[[contacts]]\npatch = { shape = 'points', xy = [[1, 2, 3]], weights = 'w' }"
        "\naxis = [0, 0, 0]\nmax_force = nan\n" + LOADS,
    ],
    ids=[
        "empty",
        "wrong-sections",
        "non-table-items",
        "wrong-defaults",
        "wrong-header",
        "nested",
        "points",
    ],
)
def test_malformed_documents_raise_only_problem_file_errors(tmp_path, text):
    issues = _issues(tmp_path, text)
    assert issues
    assert all(isinstance(issue, Issue) and issue.message for issue in issues)


def test_an_integer_too_large_for_a_float_is_an_issue_not_a_crash(tmp_path):
    text = _edited(VALID, ("mass = 2.0", "mass = 1" + "0" * 400))
    _assert_issue(_issues(tmp_path, text), "body.mass", "too large")


# -- contact stiffnesses (the compliant analysis) --------------------------------------------------

DEFAULT_STIFFNESS = (
    'model = "ellipsoid"\nstiffness = { normal = 1e8, tangential = 5e7, torsional = 30 }\n'
)
OWN_STIFFNESS = "max_force = 2000.0\nstiffness = { normal = 2e8, tangential = 6e7 }"


def _with_stiffness(*edits):
    return _edited(VALID, ('model = "ellipsoid"\n', DEFAULT_STIFFNESS), *edits)


def test_a_file_without_stiffness_carries_none(tmp_path):
    assert load_problem(_write(tmp_path, VALID)).stiffness is None


def test_defaults_give_every_contact_its_stiffness_and_a_contact_table_replaces_it_whole(tmp_path):
    text = _with_stiffness(("max_force = 2000.0", OWN_STIFFNESS))
    stiffness = load_problem(_write(tmp_path, text)).stiffness
    default = Stiffness(normal=1e8, tangential=5e7, torsional=30.0)
    assert stiffness == {
        "jaw-fixed": default,
        "jaw-moving": Stiffness(normal=2e8, tangential=6e7),
        "rest": default,
    }


def test_a_stiffness_may_be_given_for_some_contacts_only(tmp_path):
    text = _edited(VALID, ("max_force = 2000.0", OWN_STIFFNESS))
    loaded = load_problem(_write(tmp_path, text))
    assert loaded.stiffness == {"jaw-moving": Stiffness(normal=2e8, tangential=6e7)}
    assert not hasattr(loaded.problem.contacts[1], "stiffness")


@pytest.mark.parametrize(
    ("table", "key_path", "fragment"),
    [
        ("{ normal = 0, tangential = 5e7 }", ".normal", "expected a number > 0, got 0"),
        ("{ normal = -1e8, tangential = 5e7 }", ".normal", "expected a number > 0"),
        ("{ normal = nan, tangential = 5e7 }", ".normal", "expected a finite number"),
        ("{ normal = 1e14, tangential = 5e7 }", ".normal", "and at most 1e+13 N/m, got 1"),
        ("{ normal = 1e-9, tangential = 5e7 }", ".normal", "below 1e-06 (springs that soft"),
        ("{ normal = '1e8', tangential = 5e7 }", ".normal", "expected a number, got string"),
        ("{ tangential = 5e7 }", ".normal", "missing required key; expected a number > 0"),
        ("{ normal = 1e8 }", ".tangential", "missing required key; expected a number >= 0"),
        ("{ normal = 1e8, tangential = -1 }", ".tangential", "expected a number >= 0"),
        ("{ normal = 1e8, tangential = 1e-9 }", ".tangential", "or give 0)"),
        ("{ normal = 1e8, tangential = 0, torsional = true }", ".torsional", "got boolean"),
        ("{ normal = 1e8, tangential = 0, torsional = 1e14 }", ".torsional", "1e+13 N m/rad"),
        ("{ normal = 1e8, tangential = 0, torsion = 1 }", ".torsion", "did you mean 'torsional'"),
        ("5e7", "", "expected a table, got float 50000000.0"),
    ],
)
def test_each_stiffness_mistake_is_reported_at_its_key_path(tmp_path, table, key_path, fragment):
    for edits, where in (
        ([("max_force = 2000.0", f"max_force = 2000.0\nstiffness = {table}")], "contacts[1]"),
        ([('model = "ellipsoid"\n', f'model = "ellipsoid"\nstiffness = {table}\n')], "defaults"),
    ):
        issues = _issues(tmp_path, _edited(VALID, *edits))
        _assert_issue(issues, f"{where}.stiffness{key_path}", fragment)


def test_a_stiffness_the_library_rejects_is_an_issue_at_the_table(tmp_path, monkeypatch):
    def rejected(**values):
        raise ComplianceError("stiffness.normal must be finite [N/m, N/m, N m/rad]")

    monkeypatch.setattr(problem_file_module, "Stiffness", rejected)
    text = _edited(VALID, ("max_force = 2000.0", OWN_STIFFNESS))
    _assert_issue(_issues(tmp_path, text), "contacts[1].stiffness", "must be finite")


COMPLIANT = ('objective = "min-total-clamp-force"', 'objective = "check-compliant"')
CLAMP_FORCE = ("max_force = 2000.0", "max_force = 2000.0\nforce = 500.0")


def test_check_compliant_reads_like_check_with_every_stiffness(tmp_path):
    loaded = load_problem(_write(tmp_path, _with_stiffness(COMPLIANT, CLAMP_FORCE)))
    assert loaded.problem.objective == "check-compliant"
    assert set(loaded.stiffness) == {"jaw-fixed", "jaw-moving", "rest"}


def test_check_compliant_names_the_contacts_without_stiffness(tmp_path):
    text = _edited(VALID, COMPLIANT, ("max_force = 2000.0", OWN_STIFFNESS + "\nforce = 500.0"))
    (issue,) = _issues(tmp_path, text)
    assert issue.key_path == "objective"
    assert issue.message.startswith(
        "objective 'check-compliant' needs every contact's stiffness; missing for 'jaw-fixed', "
        "'rest': add stiffness"
    )


def test_check_compliant_takes_the_active_forces_as_given(tmp_path):
    text = _with_stiffness(COMPLIANT)
    _assert_issue(_issues(tmp_path, text), "contacts[1].force",
                  "required: objective 'check-compliant' takes the active forces")  # fmt: skip


def test_an_invalid_default_stiffness_is_reported_once(tmp_path):
    text = _edited(
        VALID,
        COMPLIANT,
        CLAMP_FORCE,
        (
            'model = "ellipsoid"\n',
            'model = "ellipsoid"\nstiffness = { normal = -1, tangential = 1 }\n',
        ),
    )
    assert [issue.key_path for issue in _issues(tmp_path, text)] == ["defaults.stiffness.normal"]


def test_an_objective_override_replaces_the_files_and_meets_its_demands(tmp_path):
    check = ('objective = "min-total-clamp-force"', 'objective = "check"')
    path = _write(tmp_path, _with_stiffness(check, CLAMP_FORCE))
    assert load_problem(path, objective="check-compliant").problem.objective == "check-compliant"
    assert load_problem(path).problem.objective == "check"
    (issue,) = _issues(tmp_path, _edited(VALID, check, CLAMP_FORCE), objective="check-compliant")
    assert issue.key_path == "objective"
    assert issue.message.startswith("the objective override 'check-compliant' needs every")
    with pytest.raises(InvalidArgumentError, match="objective"):
        load_problem(path, objective="cheque")
