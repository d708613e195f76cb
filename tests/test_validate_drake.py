"""Drake judges plans with hydroelastic fingertips: the issue's checks of a soft pinch.

The pinch is ``problems/hertz-pinch.toml`` with the fingertips' pressure made parabolic (the
profile a hydroelastic sphere produces) and the exact model: held at +10 %, slipping at -10 %,
the slip beginning within 2 % of the plan's safety factor and of fixplan's exact limit surface
of the fields the engine produced, in the planned motion (2°).
"""

import json
import sys
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from scipy import integrate

from fixplan.errors import InvalidArgumentError
from fixplan.io.cli import EXIT_INVALID_INPUT, EXIT_OK, main
from fixplan.io.problem_file import load_problem
from fixplan.planner.planner import Planner
from fixplan.sim.drake_fields import assumed_pressure, profile_deviation
from fixplan.sim.drake_scene import fingertip
from fixplan.sim.drake_validate import validate
from fixplan.surface import pressure

PROBLEMS = Path(__file__).resolve().parents[1] / "problems"
#: Slip onset within this of the plan's and of the exact safety factor (the issue's 2 %), and
#: the simulated slip twist within this of the plan's motion [deg].
ONSET_RTOL, MOTION_DEGREES = 0.02, 2.0
#: The engine's field of a sphere lies within this of the parabolic profile, over its peak
#: (3.7 % measured, mostly the rim the mesh trims), and further than this from a Hertz profile
#: of the same radius (28 % measured).
PARABOLIC_DEVIATION, HERTZ_DEVIATION = 0.06, 0.2
#: Torsional arm of the engine's field over the parabolic disk's (1.001 measured).
TORSION_RTOL = 0.01


def _parabolic_pinch():
    problem = load_problem(PROBLEMS / "hertz-pinch.toml").problem
    contacts = tuple(
        replace(contact, patch=pressure.disk(0.006, "parabolic"), model="exact")
        for contact in problem.contacts
    )
    return replace(problem, contacts=contacts)


@pytest.fixture(scope="module")
def pinch():
    problem = _parabolic_pinch()
    plan = Planner(problem).solve()
    (case,) = validate(problem, plan, loads=["lift-accelerating"])
    return problem, plan, case


@pytest.mark.slow
def test_a_soft_pinch_holds_at_110_percent_and_slips_at_90(pinch):
    _, _, case = pinch
    assert case.planned_held and case.above.held and not case.below.held
    assert not case.contradicts
    assert case.above.displacement < 0.05 * case.below.displacement


@pytest.mark.slow
def test_slip_onset_matches_the_plan_and_the_exact_limit_surface_of_the_engines_fields(pinch):
    _, plan, case = pinch
    assert case.onset_ratio == pytest.approx(1.0, abs=ONSET_RTOL)
    assert case.exact_onset_ratio == pytest.approx(1.0, abs=ONSET_RTOL)
    assert case.exact_safety_factor == pytest.approx(plan.safety_factors[case.load], rel=0.01)
    assert np.degrees(case.motion_angle) < MOTION_DEGREES


@pytest.mark.slow
def test_engine_fields_carry_the_planned_forces_and_are_parabolic_not_hertzian(pinch):
    problem, plan, case = pinch
    assert [item.contact for item in case.fields] == [c.name for c in problem.contacts]
    for item, contact in zip(case.fields, problem.contacts, strict=True):
        planned = float(plan.forces[contact.name][0])
        assert item.normal_force == pytest.approx(planned, rel=1e-3)
        assert item.pressure_deviation < PARABOLIC_DEVIATION
        assert item.torsion_ratio == pytest.approx(1.0, abs=TORSION_RTOL)
        hertz = pressure.disk(0.006, "hertz")
        deviation = profile_deviation(hertz, item.field.xy, item.pressures, item.areas)
        assert deviation > HERTZ_DEVIATION


@pytest.mark.slow
def test_shear_and_torsion_at_slip_onset_lie_on_the_exact_limit_surface_of_each_field(pinch):
    """Both fingertips of the symmetric pinch slip together: at onset each one's friction is on
    the exact limit surface of its engine field (2 %)."""
    _, _, case = pinch
    for item in case.fields:
        assert item.onset_use == pytest.approx(1.0, abs=ONSET_RTOL)


@pytest.mark.slow
def test_the_command_line_runs_drake_and_reports_fields_and_exact_onsets(tmp_path, capsys):
    """A lifted box in a Hertz-fingertip parallel gripper: held at +10 %, slips at -10 %; the
    JSON and the report say which engine ran, its thresholds and the engine's fields."""
    code = main(["validate", str(PROBLEMS / "pick-and-place.toml"), "--engine", "drake",
                 "--load", "lift-jerk-ramp", "--json", "--report", str(tmp_path / "report")])  # fmt: skip
    assert code == EXIT_OK
    document = json.loads(capsys.readouterr().out)
    assert document["engine"] == "drake"
    assert document["thresholds"] == {"held_slip_m": 1e-3, "onset_speed_m_per_s": 1e-4,
                                      "time_step_s": 1e-3}  # fmt: skip
    (case,) = document["cases"]
    assert case["above"]["held"] and not case["below"]["held"] and not case["contradicts"]
    assert case["exact_onset_ratio"] == pytest.approx(1.0, abs=ONSET_RTOL)
    assert [item["contact"] for item in case["fields"]] == ["finger-left", "finger-right"]
    for item in case["fields"]:
        assert item["pressure_deviation"] > HERTZ_DEVIATION  # Hertz assumed, parabolic made
    report = (tmp_path / "report" / "report.md").read_text(encoding="utf-8")
    assert "Drake" in report and "exact s of the engine's fields" in report
    assert "| load case | plan | safety factor | forces +10% | forces -10% |" in report
    assert (tmp_path / "report" / "case-1.png").is_file()


def test_without_the_drake_extra_the_command_line_says_what_to_install(monkeypatch, capsys):
    monkeypatch.setitem(sys.modules, "pydrake.multibody.plant", None)  # an absent module
    code = main(["validate", str(PROBLEMS / "hertz-pinch.toml"), "--engine", "drake"])
    assert code == EXIT_INVALID_INPUT
    assert "pip install 'fixplan[drake]'" in capsys.readouterr().err


def test_point_supports_as_a_patch_are_refused_before_drake_runs():
    problem = _parabolic_pinch()
    supports = pressure.points([(-0.004, 0.0), (0.004, 0.0)])
    contacts = (replace(problem.contacts[0], patch=supports), *problem.contacts[1:])
    problem = replace(problem, contacts=contacts)
    plan = Planner(problem).solve()
    with pytest.raises(InvalidArgumentError, match=r"finger-left.*point supports"):
        validate(problem, plan)
    with pytest.raises(InvalidArgumentError, match="margin"):
        validate(problem, plan, margin=0.0)


@pytest.mark.parametrize("patch_radius, normal_force", [(0.006, 23.0), (5e-4, 100.0)])
def test_a_fingertip_sphere_makes_the_patch_and_carries_the_force_it_was_sized_for(
    patch_radius, normal_force
):
    """Drake's sphere pressure ``E (R - |x|) / R`` integrated over the plane at depth ``δ``."""
    tip = fingertip(patch_radius, normal_force)
    d = tip.radius - tip.depth
    assert np.sqrt(tip.radius**2 - d**2) == pytest.approx(patch_radius, rel=1e-12)
    carried, _ = integrate.quad(
        lambda r: tip.modulus * (tip.radius - np.hypot(d, r)) / tip.radius * 2.0 * np.pi * r,
        0.0,
        patch_radius,
        epsabs=0.0,
        epsrel=1e-12,
    )
    assert carried == pytest.approx(normal_force, rel=1e-9)
    assert np.pi * tip.modulus * tip.depth**2 == pytest.approx(normal_force, rel=0.05)


@pytest.mark.parametrize(
    "patch",
    [
        pressure.disk(0.01, "uniform"),
        pressure.disk(0.01, "hertz").shifted(0.002, -0.001),
        pressure.disk(0.01, "parabolic").rotated(0.4),
        pressure.disk(0.01, "annulus", inner_radius=0.004),
        pressure.rectangle(0.02, 0.008).rotated(0.3),
        pressure.grid([-0.004, 0.0, 0.004], [-0.002, 0.002], [[1.0, 2.0, 0.0], [3.0, 1.0, 1.0]]),
        pressure.from_function(pressure.disk(0.01), lambda x, y: 1.0 + x / 0.01),
    ],
)
def test_the_assumed_pressure_carries_unit_force_where_the_patch_lies(patch):
    """Midpoint sums on a fine grid over the patch's circle: total 1, centre as the field's."""
    h = 2.0 * patch.radius / 1200
    ticks = np.arange(-patch.radius + h / 2, patch.radius, h)
    xx, yy = np.meshgrid(ticks, ticks)
    xy = np.column_stack([xx.ravel(), yy.ravel()]) + patch.center
    density = assumed_pressure(patch, xy)
    assert density.sum() * h * h == pytest.approx(1.0, rel=5e-3)
    centre = (density @ xy) * h * h
    assert np.allclose(centre, patch.center_of_pressure(), atol=2e-3 * patch.radius)


def test_a_ring_and_point_supports_have_no_pressure_density():
    xy = np.zeros((1, 2))
    assert assumed_pressure(pressure.disk(0.01, "ring"), xy) is None
    assert assumed_pressure(pressure.points([(0.0, 0.0), (0.01, 0.0)]), xy) is None
