"""Reports: a self-contained, deterministic folder whose HTML opens in a browser with its figures.

The fixture is a block on three disk pads pressed by two clamps from above, with three load
cases. It is built with the problem classes and written as a TOML problem file with the same
content; the file is read back so the report has a ProblemFile (name, hash) to record.
"""

import html.parser
import json
import re
import shutil
import subprocess
import warnings
from importlib.metadata import version
from pathlib import Path

import cvxpy
import matplotlib.image
import numpy as np
import pytest
from matplotlib.figure import Figure

import fixplan
from fixplan import pressure
from fixplan.errors import InvalidArgumentError
from fixplan.io.figures import contact_section_figure, layout_figure, safety_figure
from fixplan.io.problem_file import load_problem
from fixplan.io.report import _solver_text, default_sliding_subspace, write_report
from fixplan.io.report_document import MANIFEST
from fixplan.planner.contact_models import contact_model
from fixplan.planner.plan import Plan
from fixplan.planner.planner import Planner
from fixplan.planner.problem import Body, Contact, Load, Problem

MU = 0.3
CLAMPS = {"clamp-east": [0.03, 0.0, 0.04], "clamp-west": [-0.03, 0.0, 0.04]}
PADS = {"pad-0": [0.04, 0.0, 0.0], "pad-1": [-0.03, 0.025, 0.0], "pad-2": [-0.03, -0.025, 0.0]}
LOADS = [
    Load(name="mill-x", force=[40.0, 0.0, -10.0], point=[0.0, 0.0, 0.04]),
    Load(name="mill-y", force=[0.0, -30.0, -10.0], point=[0.02, 0.0, 0.04]),
    Load(name="drill-torque", force=[0.0, 0.0, -20.0], point=[0.0, 0.01, 0.04], torque=[0, 0, 1.5]),
]
STATIC_FILES = {"report.md", "report.html", "plan.json", "layout.png", "safety-factors.png"}
CONTACT_FIGURES = {
    "contact-00-clamp-east.png",
    "contact-01-clamp-west.png",
    "contact-02-pad-0.png",
    "contact-03-pad-1.png",
    "contact-04-pad-2.png",
}
#: A screenshot pixel whose colour channels differ by more than this is coloured: the report's
#: text and tables are grey, so coloured pixels come from its figures.
COLOURED = 0.3


def block_problem(clamp_limit: float = 2000.0) -> Problem:
    """The block on pads, built with the problem classes."""
    clamps = [
        Contact(
            name=name, role="clamp", position=position, normal=[0, 0, -1], mu=MU, model="exact",
            patch=pressure.disk(0.005, "hertz"), max_force=clamp_limit,
        )
        for name, position in CLAMPS.items()
    ]  # fmt: skip
    pads = [
        Contact(
            name=name, role="support", position=position, normal=[0, 0, 1], mu=MU,
            model="ellipsoid", patch=pressure.disk(0.008),
        )
        for name, position in PADS.items()
    ]  # fmt: skip
    body = Body(mass=1.0, center_of_mass=[0.0, 0.0, 0.02])
    return Problem(
        body=body, contacts=clamps + pads, loads=LOADS, objective="min-total-clamp-force"
    )


def _toml(value) -> str:
    if isinstance(value, str):
        return f'"{value}"'
    if isinstance(value, np.ndarray | list | tuple):
        return "[" + ", ".join(_toml(x) for x in value) + "]"
    return repr(float(value))


def problem_toml(problem: Problem, name: str) -> str:
    """``problem`` as a TOML problem file (disk patches only)."""
    body = problem.body
    lines = [
        "schema_version = 1",
        f"name = {_toml(name)}",
        'kind = "fixture"',
        f"objective = {_toml(problem.objective)}",
        "",
        "[body]",
        f"mass = {_toml(body.mass)}",
        f"center_of_mass = {_toml(body.center_of_mass)}",
    ]
    for c in problem.contacts:
        patch = c.patch
        lines += [
            "",
            "[[contacts]]",
            f"name = {_toml(c.name)}",
            f"role = {_toml(c.role)}",
            f"position = {_toml(c.position)}",
            f"normal = {_toml(c.normal)}",
            f"mu = {_toml(c.mu)}",
            f"model = {_toml(c.model)}",
            f'patch = {{ shape = "disk", radius = {_toml(patch.radius_m)}, '
            f"pressure = {_toml(patch.profile)} }}",
        ]
        if c.max_force is not None:
            lines.append(f"max_force = {_toml(c.max_force)}")
    for load in problem.loads:
        lines += [
            "",
            "[[loads]]",
            f"name = {_toml(load.name)}",
            f"force = {_toml(load.force)}",
            f"point = {_toml(load.point)}",
            f"torque = {_toml(load.torque)}",
        ]
    return "\n".join(lines) + "\n"


def _solved(folder: Path, problem: Problem, name: str):
    path = folder / f"{name}.toml"
    path.write_text(problem_toml(problem, name), encoding="utf-8")
    problem_file = load_problem(path)
    planner = Planner(problem_file.problem)
    return problem_file, planner.solve(), planner


@pytest.fixture(scope="module")
def solved(tmp_path_factory):
    """``(problem file, plan, planner)`` of the block on pads (``write_report``'s order)."""
    return _solved(tmp_path_factory.mktemp("problem"), block_problem(), "block-on-pads")


@pytest.fixture(scope="module")
def reports(solved, tmp_path_factory):
    """Two reports of the same plan; the first folder held a stale report and a foreign file."""
    first, second = tmp_path_factory.mktemp("first"), tmp_path_factory.mktemp("second")
    (first / "notes.txt").write_text("kept\n", encoding="utf-8")
    (first / "report.md").write_text("stale\n", encoding="utf-8")
    return [(folder, write_report(folder, *solved)) for folder in (first, second)]


@pytest.fixture(scope="module")
def infeasible(tmp_path_factory):
    """A report of the block whose clamps may push 1 N at most: no load case can be held."""
    folder = tmp_path_factory.mktemp("infeasible")
    solved = _solved(folder, block_problem(clamp_limit=1.0), "weak-clamps")
    return solved[1], folder / "report", write_report(folder / "report", *solved)


# -- the problem ----------------------------------------------------------------------------------


def test_the_problem_file_describes_the_problem_built_in_python(solved):
    built, loaded = block_problem(), solved[0].problem
    assert loaded.objective == built.objective
    for mine, theirs in zip(built.contacts, loaded.contacts, strict=True):
        assert (theirs.name, theirs.role, theirs.model, theirs.mu) == (
            mine.name, mine.role, mine.model, mine.mu,
        )  # fmt: skip
        np.testing.assert_array_equal(theirs.position, mine.position)
        np.testing.assert_array_equal(theirs.normal, mine.normal)
        assert theirs.patch == mine.patch
    for mine, theirs in zip(built.loads, loaded.loads, strict=True):
        assert theirs.name == mine.name
        np.testing.assert_array_equal(theirs.wrench, mine.wrench)
    assert solved[1].status == "optimal"


# -- the folder -----------------------------------------------------------------------------------


def test_two_reports_of_the_same_plan_are_byte_identical(reports):
    (_, written), (second, _) = reports
    for path in written:
        assert path.read_bytes() == (second / path.name).read_bytes(), path.name


def test_the_report_writes_every_expected_file_and_lists_what_it_wrote(reports):
    folder, written = reports[1]
    expected = STATIC_FILES | CONTACT_FIGURES | {"contact-set.png"}
    assert {p.name for p in written} == expected
    assert {p.name for p in folder.iterdir()} == expected | {MANIFEST}
    assert all(p.parent == folder for p in written)


def test_the_report_overwrites_its_own_files_and_leaves_others_alone(reports):
    folder, _ = reports[0]
    assert (folder / "notes.txt").read_text(encoding="utf-8") == "kept\n"
    assert (folder / "report.md").read_text(encoding="utf-8").startswith("# fixplan report")


def test_figures_are_png_files_without_software_or_date_metadata(reports):
    for path in reports[1][1]:
        if path.suffix == ".png":
            content = path.read_bytes()
            assert content.startswith(b"\x89PNG\r\n\x1a\n")
            assert b"matplotlib" not in content and b"tIME" not in content


def _markdown_images(text: str) -> list[str]:
    return re.findall(r"!\[[^\]]*\]\(([^)]+)\)", text)


def test_every_image_referenced_by_the_markdown_and_html_exists(reports):
    folder, _ = reports[1]
    markdown = _markdown_images((folder / "report.md").read_text(encoding="utf-8"))
    page = _structure(folder / "report.html")
    assert markdown == page.images
    assert set(markdown) == {p.name for p in folder.glob("*.png")}
    assert all((folder / name).is_file() for name in markdown)


def test_plan_json_parses_and_holds_the_plan(reports, solved):
    folder, _ = reports[1]
    document = json.loads((folder / "plan.json").read_text(encoding="utf-8"))
    plan = solved[1]
    for key in ("status", "objective_value", "forces_N", "safety_factors", "motions"):
        assert key in document
    assert document["status"] == "optimal"
    assert document["objective_value"] == pytest.approx(plan.objective_value)
    assert set(document["safety_factors"]) == {load.name for load in LOADS}
    assert set(document["motions"]) == {load.name for load in LOADS}


# -- the content ----------------------------------------------------------------------------------


def test_the_header_records_versions_models_and_the_file_hash(reports, solved):
    problem_file, _, planner = solved
    text = (reports[1][0] / "report.md").read_text(encoding="utf-8")
    assert f"| fixplan | {fixplan.__version__} |" in text
    assert f"| cvxpy | {cvxpy.__version__} |" in text
    assert f"CLARABEL {version('clarabel')}" in text
    assert problem_file.sha256 in text
    assert f"`{problem_file.path.name}`" in text
    for model in planner.models:
        assert f"`{model!r}`" in text


def test_the_report_gives_forces_safety_factors_and_motions_in_words(reports, solved):
    plan = solved[1]
    text = (reports[1][0] / "report.md").read_text(encoding="utf-8")
    assert "| status | optimal |" in text
    for name in CLAMPS:
        assert f"| {name} | clamp |" in text
    for name, motion in plan.motions.items():
        assert f"| {name} | {motion.describe()} |" in text
    assert f"Critical load case: {plan.critical_load}" in text
    assert "/home" not in text and "/tmp" not in text  # no machine paths


def test_an_infeasible_plan_is_reported_with_its_certificate_and_without_force_figures(
    infeasible,
):
    plan, folder, written = infeasible
    assert plan.status == "infeasible" and plan.certificate
    text = (folder / "report.md").read_text(encoding="utf-8")
    assert "| status | infeasible |" in text
    assert plan.certificate in text
    assert plan.certificate.replace("'", "&#x27;") in (folder / "report.html").read_text("utf-8")
    assert {p.name for p in written} == {"report.md", "report.html", "plan.json", "layout.png"}
    assert "Force figures were skipped" in text
    assert json.loads((folder / "plan.json").read_text("utf-8"))["certificate"] == plan.certificate


def test_the_sliding_subspace_lies_across_the_supports_normals():
    assert default_sliding_subspace(block_problem()) == ("fx", "fy", "mz")
    wall = Contact(
        name="wall", role="support", position=[0, 0, 0], normal=[1, 0, 0], mu=MU,
        model="point-cone",
    )  # fmt: skip
    clamp = Contact(
        name="clamp", role="clamp", position=[0.1, 0, 0], normal=[-1, 0, 0], mu=MU,
        model="point-cone",
    )  # fmt: skip
    problem = Problem(
        body=Body(mass=0.0, center_of_mass=[0, 0, 0]), contacts=[wall, clamp], loads=LOADS[:1],
        objective="min-total-clamp-force",
    )  # fmt: skip
    assert default_sliding_subspace(problem) == ("fy", "fz", "mx")


def test_an_unknown_sliding_subspace_component_is_rejected(solved, tmp_path):
    with pytest.raises(InvalidArgumentError, match="sliding_subspace"):
        write_report(tmp_path, *solved, sliding_subspace=("fx", "vy"))


# -- figures --------------------------------------------------------------------------------------


def test_the_safety_figure_draws_an_infinite_safety_factor_at_the_axis_top():
    plan = Plan(
        status="optimal", objective="check", objective_value=0.8, load_names=("a", "b"),
        contact_names=("c",), safety_factors={"a": 0.8, "b": float("inf")},
        held={"a": False, "b": True}, critical_load="a",
    )  # fmt: skip
    figure = safety_figure(plan)
    ax = figure.axes[0]
    heights = [bar.get_height() for bar in ax.patches]
    assert isinstance(figure, Figure)
    assert heights[0] == 0.8 and heights[1] == ax.get_ylim()[1]
    assert any(text.get_text() == "∞" for text in ax.texts)


def test_figures_reject_a_point_model_section_and_an_unknown_load_case(solved):
    problem_file, plan, _ = solved
    point = Contact(
        name="tip", role="finger", position=[0, 0, 0], normal=[0, 0, 1], mu=MU, model="point-cone"
    )
    with pytest.raises(InvalidArgumentError, match="point model"):
        contact_section_figure(point, contact_model(point), [0.0, 0.0, 0.0], 1.0)
    with pytest.raises(InvalidArgumentError, match="load_name"):
        layout_figure(problem_file.problem, plan, "no-such-case")


# -- the HTML page --------------------------------------------------------------------------------

VOID_ELEMENTS = {"meta", "img", "br", "hr", "link", "input"}


class _Structure(html.parser.HTMLParser):
    """Checks nesting as it parses and collects the title, charset and image sources."""

    def __init__(self):
        super().__init__()
        self.open: list[str] = []
        self.errors: list[str] = []
        self.title = ""
        self.charset = None
        self.images: list[str] = []
        self.alts: list[str | None] = []
        self.tags: set[str] = set()

    def handle_starttag(self, tag, attrs):
        attributes = dict(attrs)
        self.tags.add(tag)
        if tag == "meta" and "charset" in attributes:
            self.charset = attributes["charset"]
        if tag == "img":
            self.images.append(attributes.get("src"))
            self.alts.append(attributes.get("alt"))
        if tag not in VOID_ELEMENTS:
            self.open.append(tag)

    def handle_endtag(self, tag):
        if not self.open or self.open[-1] != tag:
            self.errors.append(f"</{tag}> closes {self.open[-1:] or 'nothing'}")
        else:
            self.open.pop()

    def handle_data(self, data):
        if self.open and self.open[-1] == "title":
            self.title += data


def _structure(path: Path) -> _Structure:
    parser = _Structure()
    parser.feed(path.read_text(encoding="utf-8"))
    parser.close()
    return parser


def _assert_well_formed(path: Path) -> None:
    page = _structure(path)
    assert not page.errors, page.errors
    assert not page.open, f"unclosed elements {page.open}"
    assert {"html", "head", "body", "title", "table", "figure"} <= page.tags
    assert page.charset == "utf-8"
    assert page.title == "fixplan report: block-on-pads"
    assert page.images and all(page.alts)
    for source in page.images:
        assert (path.parent / source).is_file(), source


def test_the_html_page_is_well_formed_with_a_title_and_resolvable_images(reports):
    _assert_well_formed(reports[1][0] / "report.html")


def test_the_html_page_renders_with_its_figures_in_a_headless_browser(reports, tmp_path):
    """Chromium (``apt-get install chromium``) renders the page to a screenshot whose coloured
    pixels come from the figures. Without chromium the page is checked structurally instead and
    a warning says so: a browser cannot be installed by a test."""
    page = reports[1][0] / "report.html"
    browser = shutil.which("chromium") or shutil.which("chromium-browser")
    if browser is None:
        warnings.warn(
            "chromium is not installed: report.html was checked structurally, not rendered "
            "(apt-get install -y chromium enables the browser check)",
            stacklevel=1,
        )
        _assert_well_formed(page)
        return
    screenshot = tmp_path / "report.png"
    command = [
        browser, "--headless", "--no-sandbox", "--disable-gpu", "--disable-background-networking",
        "--disable-component-update", "--disable-sync", "--no-first-run",
        f"--user-data-dir={tmp_path / 'profile'}", f"--screenshot={screenshot}",
        "--window-size=1200,7000", page.resolve().as_uri(),
    ]  # fmt: skip
    result = subprocess.run(command, capture_output=True, text=True, timeout=120, check=False)
    assert result.returncode == 0, result.stderr[-2000:]
    assert screenshot.is_file()
    pixels = matplotlib.image.imread(screenshot)[..., :3]
    channels = np.rint(pixels * 255).astype(np.uint32)
    colours = np.unique(channels[..., 0] << 16 | channels[..., 1] << 8 | channels[..., 2])
    coloured = np.ptp(pixels, axis=-1) > COLOURED
    assert len(colours) > 100
    # Text and tables alone give a few hundred coloured pixels (measured: 240 with every image
    # missing); the figures give about 1e5.
    assert coloured.sum() > 10_000


@pytest.mark.parametrize(
    ("solvers", "expected"),
    [
        (
            "CLARABEL (osculating ellipsoids)",
            f"CLARABEL (osculating ellipsoids) {version('clarabel')}",
        ),
        (
            "dual simplex (direct), CLARABEL",
            f"dual simplex (direct) {version('fixplan')}, CLARABEL",
        ),
    ],
)
def test_the_solver_used_names_the_package_behind_each_method(solvers, expected):
    # A method in parentheses keeps its solver's version; the dual simplex is fixplan's own.
    assert _solver_text(solvers).startswith(expected)
