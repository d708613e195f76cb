"""Osculating ellipsoids against cutting planes, on random problems with smooth exact patches.

The two ways of stating exact friction models (:mod:`fixplan.planner.osculating`, stopped by the
exact problem's optimality conditions, and :mod:`fixplan.planner.cuts`, relaxations exact once
every load is inside) must give the same plans: same status, objective values within 1e-7
relative, safety factors and held intervals within 1e-6, every pressed contact load inside its
exact surface to 1e-9, and the same impending motion where it is unique (the planar motion of
a plate on one support). Patches: disks of every profile, rectangles, a polygon, a small tactile
grid, shifted and rotated patches, and two patches combined into one exact model. Objectives: the three force
objectives, ``max-safety-factor`` with given forces over six load cases (blocks of four, the
last padded), and a fixture whose passive locators face each other (squeezes unloaded).
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from test_exact_planner import OPTIMUM_RTOL, assert_loads_inside_their_exact_surfaces
from test_kept_parameters import bench_fixture

from fixplan import Body, Contact, LimitSurface, Load, Problem, pressure
from fixplan.models.exact import Exact
from fixplan.planner import runner
from fixplan.planner.planner import Planner

SAFETY_RTOL = 1e-6
#: Held multiples below this are 0 (``MULTIPLE_ATOL``).
MULTIPLE_ATOL = 1e-7
MOTION_RTOL = 1e-6
#: A block of a fixed-force solve with a case held at the cap (``MAX_SAFETY_FACTOR`` = 1e3, an
#: infinite safety factor) has ``sum(s) ~ 1e3``, and Clarabel's gap tolerance (1e-9 relative)
#: leaves the other cases' factors about 1e-6 off either way (both ways agree to 1e-9 when the
#: capped case is solved apart). In the facing-locator fixture below (seed 1), whose forces
#: found must have safety factor 1, the factors came out 1.4e-6 to 6.3e-6 from 1 with either
#: method, whatever the force unit of the solves (largest force at 4 to 256 units).
CAPPED_BLOCK_ATOL = 1e-5
#: Planar twists ``(vx, vy, wz)`` are compared in these units (rates times 10 mm).
PLANAR = np.array([1.0, 1.0, 0.01])

PATCHES = {
    "uniform": pressure.disk(0.01),
    "hertz": pressure.disk(0.012, "hertz"),
    "parabolic": pressure.disk(0.008, "parabolic"),
    "annulus": pressure.disk(0.01, "annulus", inner_radius=0.006),
    "ring": pressure.disk(0.01, "ring"),
    "rectangle": pressure.rectangle(0.03, 0.01),
    "polygon": pressure.polygon([[0.0, 0.0], [0.02, 0.0], [0.025, 0.012], [0.0, 0.015]]),
    "grid": pressure.grid(
        [-0.004, 0.0, 0.004], [-0.003, 0.003], [[1.0, 0.6, 0.2], [0.5, 0.9, 0.4]]
    ),
    "shifted": pressure.disk(0.008, "hertz").shifted(0.004, -0.002),
    "rotated": pressure.rectangle(0.024, 0.008).rotated(0.6),
}


def combined(mu: float) -> Exact:
    """Two shifted disks at unit total normal force, one exact model."""
    parts = [
        LimitSurface(pressure.disk(0.006).shifted(dx, 0.0), mu=mu, normal_force=weight)
        for dx, weight in ((0.012, 0.6), (-0.01, 0.4))
    ]
    return Exact.from_limit_surface(LimitSurface.combine(parts))


def contact(name, role, position, normal, mu, patch, **extra) -> Contact:
    """An exact contact on ``patch`` (a PATCHES key, or ``"combined"``)."""
    if patch == "combined":
        model = combined(mu)
        return Contact(name=name, role=role, position=position, normal=normal, mu=model.mu,
                       model=model, **extra)  # fmt: skip
    return Contact(name=name, role=role, position=position, normal=normal, mu=mu, model="exact",
                   patch=PATCHES[patch], **extra)  # fmt: skip


def pinch(rng, patches, objective, *, cases=2, force=None) -> Problem:
    """Two fingers (clamps for ``min-total-clamp-force``: one force for every case) squeezing a
    bar along y; random weights, offsets and twisting torques."""
    role = "clamp" if objective == "min-total-clamp-force" else "finger"
    contacts = [
        contact(f"{role}{side}", role, [0, side * 0.04, 0], [0, -side, 0],
                rng.uniform(0.3, 0.9), patch, force=force)
        for side, patch in zip((-1, 1), patches, strict=True)
    ]  # fmt: skip
    loads = [
        Load(name=f"hold-{k}", force=[rng.normal(0, 2), 0, -rng.uniform(2, 10)],
             point=[rng.normal(0, 0.01), 0, rng.normal(0, 0.01)],
             torque=rng.normal(0, 0.05, 3))
        for k in range(cases)
    ]  # fmt: skip
    return Problem(body=Body(mass=0.1, center_of_mass=[0, 0, 0]), contacts=contacts,
                   loads=loads, objective=objective)  # fmt: skip


def plate(rng, patch, cases) -> Problem:
    """A plate on one support patch pushed in its plane, ``max-safety-factor``."""
    support = contact("base", "support", [0, 0, 0], [0, 0, 1], rng.uniform(0.3, 0.9), patch)
    loads = [
        Load(name=f"push-{k}", force=[*rng.normal(0, 3, 2), 0], point=[0, 0, 0],
             torque=[0, 0, rng.normal(0, 0.03)])
        for k in range(cases)
    ]  # fmt: skip
    return Problem(body=Body(mass=2.0, center_of_mass=[0, 0, 0.01]), contacts=[support],
                   loads=loads, objective="max-safety-factor")  # fmt: skip


def fixture(rng, patches, objective) -> Problem:
    """A block on three pads, two side locators facing each other (they can squeeze), a top
    and a side clamp; three random milling loads."""
    places = [
        ("pad-a", "support", [-0.04, -0.03, 0], [0, 0, 1]),
        ("pad-b", "support", [0.04, -0.03, 0], [0, 0, 1]),
        ("pad-c", "support", [0.0, 0.04, 0], [0, 0, 1]),
        ("side-left", "locator", [-0.06, 0, 0.02], [1, 0, 0]),
        ("side-right", "locator", [0.06, 0, 0.02], [-1, 0, 0]),
        ("clamp-top", "clamp", [0, 0, 0.04], [0, 0, -1]),
        ("clamp-back", "clamp", [0, 0.05, 0.02], [0, -1, 0]),
    ]
    contacts = [
        contact(name, role, p, n, 0.3, patch)
        for (name, role, p, n), patch in zip(places, patches, strict=True)
    ]
    loads = [
        Load(name=f"cut-{k}", force=rng.normal(0, 30, 3), point=[0, 0, 0.03],
             torque=rng.normal(0, 0.3, 3))
        for k in range(3)
    ]  # fmt: skip
    return Problem(body=Body(mass=1.0, center_of_mass=[0, 0, 0.02]), contacts=contacts,
                   loads=loads, objective=objective)  # fmt: skip


def both_ways(problem: Problem, monkeypatch) -> tuple:
    """The plans with osculating ellipsoids and with cutting planes only (a fresh planner)."""
    osculating = Planner(problem)
    assert osculating._runner.osculating
    plan = osculating.solve()
    with monkeypatch.context() as patch:
        patch.setattr(runner, "smooth", lambda models: False)
        cutting = Planner(problem)
        assert not cutting._runner.osculating
        reference = cutting.solve()
    return plan, reference


def assert_same_plans(
    problem: Problem, plan, reference, *, planar_motion: bool, lower_ends: bool = True
) -> None:
    """``planar_motion``: the problem is a plate on one support, whose impending motion in its
    plane ``(vx, vy, wz)`` is unique (its tipping rates are not: no contact resists them).
    ``lower_ends``: compare the held intervals' lower ends too (see the facing locators)."""
    assert plan.status == reference.status == "optimal"
    assert plan.objective_value == pytest.approx(reference.objective_value, rel=OPTIMUM_RTOL)
    names = list(plan.safety_factors)
    capped = not all(map(math.isfinite, plan.safety_factors.values()))
    atol = CAPPED_BLOCK_ATOL if capped else MULTIPLE_ATOL
    for name in names:
        assert plan.safety_factors[name] == pytest.approx(
            reference.safety_factors[name], rel=SAFETY_RTOL, abs=atol
        )
        ends = slice(None) if lower_ends else slice(1, None)
        np.testing.assert_allclose(
            plan.held_intervals[name][ends], reference.held_intervals[name][ends],
            rtol=SAFETY_RTOL, atol=atol,
        )  # fmt: skip
    assert_loads_inside_their_exact_surfaces(problem, plan)
    assert_loads_inside_their_exact_surfaces(problem, reference)
    if planar_motion:
        for name in names:
            first, second = plan.motions[name], reference.motions[name]
            assert (first is None) == (second is None)
            if first is not None:
                a, b = first.twist[[0, 1, 5]] * PLANAR, second.twist[[0, 1, 5]] * PLANAR
                cosine = abs(a @ b) / (np.linalg.norm(a) * np.linalg.norm(b))
                assert cosine > 1.0 - MOTION_RTOL


PINCH_PATCHES = [
    ("uniform", "hertz"),
    ("parabolic", "annulus"),
    ("ring", "rectangle"),
    ("polygon", "grid"),
    ("shifted", "rotated"),
    ("combined", "uniform"),
]


@pytest.mark.parametrize("seed", range(len(PINCH_PATCHES)))
def test_force_objectives_agree_on_random_pinches(seed, monkeypatch):
    rng = np.random.default_rng(100 + seed)
    objective = ("min-max-normal-force", "min-total-normal-force", "min-total-clamp-force")[
        seed % 3
    ]
    problem = pinch(rng, PINCH_PATCHES[seed], objective)
    plan, reference = both_ways(problem, monkeypatch)
    assert_same_plans(problem, plan, reference, planar_motion=False)


@pytest.mark.parametrize("patch", ["uniform", "rectangle", "rotated", "grid", "combined"])
def test_safety_factors_agree_over_six_load_cases_in_padded_blocks(patch, monkeypatch):
    rng = np.random.default_rng(sum(map(ord, patch)))
    problem = plate(rng, patch, cases=6)
    plan, reference = both_ways(problem, monkeypatch)
    assert_same_plans(problem, plan, reference, planar_motion=True)


def test_safety_factors_agree_with_given_finger_forces(monkeypatch):
    rng = np.random.default_rng(7)
    problem = pinch(rng, ("hertz", "rectangle"), "max-safety-factor", cases=6, force=30.0)
    plan, reference = both_ways(problem, monkeypatch)
    assert_same_plans(problem, plan, reference, planar_motion=False)


@pytest.mark.parametrize("seed", [0, 1])
def test_a_fixture_with_facing_locators_agrees(seed, monkeypatch):
    rng = np.random.default_rng(40 + seed)
    names = list(PATCHES)
    patches = [names[i] for i in rng.choice(len(names), size=7)]
    centred = ["uniform", "hertz", "annulus", "ring", "rectangle", "grid", "combined"]
    patches[3:5] = rng.choice(centred, size=2)  # the locators push along one line
    problem = fixture(rng, patches, "min-total-clamp-force")
    assert Planner(problem).squeeze_contacts  # the side locators can squeeze each other
    plan, reference = both_ways(problem, monkeypatch)
    # The lower ends are not compared: at k = 0 the optimal loads form a face that includes
    # squeezes of the facing locators of any size, and which contacts the planner then unloads
    # (and so k_min) depends on the point of that face a solve returns (seed 1: k_min 0.057,
    # 0.111, 0.269 with the ellipsoids against 0, 0, 0 with the cutting planes).
    assert_same_plans(problem, plan, reference, planar_motion=False, lower_ends=False)
    assert math.isfinite(plan.objective_value)


def test_a_warm_re_solve_leaves_no_limiting_load_inside_its_set(monkeypatch):
    """A pinch (a combined pair of disks against a tactile grid, clamps) re-solved with new
    loads settled, with ``COMPLEMENTARITY_RTOL`` at 1e-5, with a limiting load 1.7e-5 inside
    its set and clamp forces 3.9e-6 above the optimum (cutting planes, and a fresh planner, got
    it to 2e-9): every plan of the warm planner is the cutting planes' to 1e-7 (3.7e-9 at
    most, seen)."""
    names = [*PATCHES, "combined"]

    def problem_of(seed):
        rng = np.random.default_rng(seed)
        patches = [names[i] for i in rng.choice(len(names), 2)]
        return pinch(rng, patches, "min-total-clamp-force")

    problem = problem_of(15)
    new_loads = [problem_of(10_000 + 7 * 15 + j).loads for j in range(3)]
    warm = Planner(problem)
    plans = [warm.solve(), warm.solve(), *(warm.solve(loads) for loads in new_loads)]
    with monkeypatch.context() as patch:
        patch.setattr(runner, "smooth", lambda models: False)
        cutting = Planner(problem)
        references = [
            cutting.solve(),
            cutting.solve(),
            *(cutting.solve(loads) for loads in new_loads),
        ]
    for plan, reference in zip(plans, references, strict=True):
        assert plan.solver == "CLARABEL (osculating ellipsoids)"
        assert plan.objective_value == pytest.approx(reference.objective_value, rel=OPTIMUM_RTOL)
        assert_loads_inside_their_exact_surfaces(problem, plan)


@pytest.mark.parametrize("seed", range(6))
def test_warm_single_case_re_solves_carry_the_cutting_planes_held_intervals(seed, monkeypatch):
    """A warm planner's analysis of a single load case carries the settled force solve into
    check's osculating program (:meth:`~fixplan.planner.runner.Runner._osculated_ends`):
    re-solves of a random single-case pinch with new loads agree with the cutting planes."""
    carried = []
    osculated = runner.Runner._osculated_ends
    monkeypatch.setattr(runner.Runner, "_osculated_ends",
                        lambda self, *args: carried.append(osculated(self, *args)) or carried[-1])  # fmt: skip
    names = [*PATCHES, "combined"]

    def problem_of(number):
        rng = np.random.default_rng(number)
        patches = [names[i] for i in rng.choice(len(names), 2)]
        objective = ("min-max-normal-force", "min-total-clamp-force")[seed % 2]
        return pinch(rng, patches, objective, cases=1)

    problem = problem_of(200 + seed)
    new_loads = [problem_of(20_000 + 10 * seed + j).loads for j in range(5)]
    warm = Planner(problem)
    plans = [warm.solve(), *(warm.solve(loads) for loads in new_loads)]
    with monkeypatch.context() as patch:
        patch.setattr(runner, "smooth", lambda models: False)
        cutting = Planner(problem)
        references = [cutting.solve(), *(cutting.solve(loads) for loads in new_loads)]
    for plan, reference, loads in zip(plans, references, [problem.loads, *new_loads],
                                      strict=True):  # fmt: skip
        assert_same_plans(dataclasses.replace(problem, loads=loads), plan, reference,
                          planar_motion=False)  # fmt: skip
    assert sum("highest" in ends for ends in carried) >= 3, carried


def test_a_warm_re_solve_leaves_no_power_held_back_inside_the_sets(monkeypatch):
    """A random pinch (a tactile grid against a shifted Hertz disk, clamps, three cases; seed 606
    of a randomised audit) re-solved with new loads: with loads left inside their sets weighed
    by their twists' sizes (1e-6 each), the solve settled with a limiting load 2.1e-6 inside at
    twist weight 0.32, its clamp forces 7.6e-7 above the cutting planes' optimum; weighed by
    their powers, the plans are the cutting planes' (1.2e-10 apart)."""
    contacts = [
        contact("clamp-1", "clamp", [0.0, -0.04, 0.0], [0.0, 1.0, 0.0], 0.316, "grid"),
        contact("clamp1", "clamp", [0.0, 0.04, 0.0], [0.0, -1.0, 0.0], 0.562, "shifted"),
    ]

    def hold(*rows):
        return [Load(name=f"hold-{k}", force=[fx, 0.0, fz], point=[px, 0.0, pz], torque=torque)
                for k, (fx, fz, px, pz, torque) in enumerate(rows)]  # fmt: skip

    problem = Problem(body=Body(mass=0.1, center_of_mass=[0.0, 0.0, 0.0]), contacts=contacts,
                      objective="min-total-clamp-force", loads=hold(
        (1.4722431, -2.3560291, -0.0141716, 0.0121667, [0.0308209, -0.0668952, -0.0346207]),
        (-0.7658328, -4.9813285, 0.0150571, -0.0009814, [-0.0321469, -0.0516706, -0.0488408]),
        (-1.3840540, -7.8386487, 0.0053938, -0.0021605, [-0.0565257, 0.0251116, 0.0114791]),
    ))  # fmt: skip
    new_loads = hold(
        (2.5212423, -4.4689057, 0.0030208, -0.0096905, [0.0377694, -0.0405055, -0.0086563]),
        (-1.3826559, -2.2118025, 0.0010341, -0.0062219, [0.0908552, 0.0473116, -0.0636602]),
        (-1.4562733, -9.6890768, -0.0099132, 0.0114585, [-0.0189245, -0.0167752, 0.0052485]),
    )
    warm = Planner(problem)
    warm.solve(), warm.solve()
    plan = warm.solve(new_loads, analyse=False)
    with monkeypatch.context() as patch:
        patch.setattr(runner, "smooth", lambda models: False)
        reference = Planner(problem).solve(new_loads, analyse=False)
    assert plan.solver == "CLARABEL (osculating ellipsoids)"
    assert plan.objective_value == pytest.approx(reference.objective_value, rel=OPTIMUM_RTOL)
    assert_loads_inside_their_exact_surfaces(dataclasses.replace(problem, loads=new_loads), plan)


def test_analyses_where_no_clamp_force_is_needed_find_the_exact_largest_multiple(monkeypatch):
    """Steps 2580-2590 of benchmarks/bench_realtime.py's turning cut on its fixture, where the
    pads and locators hold the cut alone (clamp forces about 1e-11 N), analysed by one planner:
    each ``k_max`` is a cutting-plane check's of the same forces to 1e-6 (8.5e-8 at most, seen).
    With loads left inside their sets weighed by their twists' sizes, the pads' loads, with the
    smallest twists but the largest loads, settled up to 5e-5 inside: ``k_max`` 5.4e-6 low."""
    angles = 4.0 * np.pi * np.arange(2580, 2591) / 9999
    path = [[Load(name="cut", force=[80.0 * np.cos(a), 80.0 * np.sin(a), -30.0],
                  point=[0.02 * np.cos(a / 2), 0.01, 0.04], torque=[0.0, 0.0, 0.8 * np.sin(a)])]
            for a in angles]  # fmt: skip
    problem = bench_fixture(path[0], "exact")
    planner = Planner(problem)
    plans = [planner.solve(loads) for loads in path]
    with monkeypatch.context() as patch:
        patch.setattr(runner, "smooth", lambda models: False)
        for plan, loads in zip(plans, path, strict=True):
            assert max(plan.forces.values()) < 1e-6
            forces = {name: float(force) for name, force in plan.forces.items()}
            checked = dataclasses.replace(problem, loads=loads, objective="check", contacts=[
                dataclasses.replace(c, force=forces[c.name]) if c.name in forces else c
                for c in problem.contacts
            ])  # fmt: skip
            reference = Planner(checked).solve().held_intervals["cut"][1]
            assert plan.held_intervals["cut"][1] == pytest.approx(reference, rel=SAFETY_RTOL)
