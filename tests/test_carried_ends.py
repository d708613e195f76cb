"""Ends of held intervals found without a solve (fixplan.planner.carried): against the
independent reference planner, closed forms, and the contacts' own friction sets."""

import dataclasses

import cvxpy as cp
import numpy as np
import pytest
import reference_planner as ref
from test_kept_parameters import bench_fixture, path

from fixplan import pressure
from fixplan.planner import osculating
from fixplan.planner.planner import Planner
from fixplan.planner.problem import Body, Contact, Load, Problem
from fixplan.planner.runner import Runner

#: Held intervals against the reference (relative, at least 1): both end in interior-point
#: solves (or the carried optimum of one), stopped at gaps of 1e-9 and 1e-10.
INTERVAL_RTOL = 1e-6


@pytest.fixture
def ends(monkeypatch):
    """The ends each analysis found without a solve: ``(carried_ends, held_without_load)``
    results, call by call."""
    found = []
    carried, without_load = Runner.carried_ends, Runner.held_without_load

    def counted(self, *args):
        result = carried(self, *args)
        found.append(tuple(sorted(set(result) - {"solved"})))  # (solved: not carried)
        return result

    def counted_without_load(self, *args):
        held = without_load(self, *args)
        found.append(("lowest",) if held else ())
        return held

    monkeypatch.setattr(Runner, "carried_ends", counted)
    monkeypatch.setattr(Runner, "held_without_load", counted_without_load)
    return found


def checked(problem, forces, loads):
    """``problem`` with the active ``forces`` given, objective ``check``, under ``loads``."""
    contacts = [dataclasses.replace(c, force=float(np.ravel(forces[c.name])[0]))
                if c.name in forces else c for c in problem.contacts]  # fmt: skip
    return dataclasses.replace(problem, contacts=contacts, loads=loads, objective="check")


def reference_interval(problem, plan, load):
    """The reference's held interval of ``load`` at the plan's active forces."""
    return ref.held_interval(checked(problem, plan.forces, [load]), 0, None, k_max=1e3)


def assert_interval(found, expected):
    for end, reference in zip(found, expected, strict=True):
        if np.isinf(end) or reference >= 1e3 * (1 - 1e-6):
            assert np.isinf(end) and reference >= 1e3 * (1 - 1e-6)
        else:
            assert end == pytest.approx(reference, rel=INTERVAL_RTOL, abs=INTERVAL_RTOL)


@pytest.mark.parametrize("model", ["ellipsoid", "point-cone", "pyramid", "cone"])
def test_carried_ends_are_the_reference_held_intervals(model, ends):
    loads = path(16)
    problem = bench_fixture(loads[0], model)
    planner = Planner(problem)
    for load in loads[:3]:  # (the direct solvers are built after two solves through cvxpy)
        planner.solve(load)
    ends.clear()
    for load in loads[3:]:
        plan = planner.solve(load)
        assert plan.status == "optimal"
        assert_interval(plan.held_intervals["cut"], reference_interval(problem, plan, load[0]))
    found = [end for call in ends for end in call]
    # The clamps least for the cut (k_max = 1) in most steps; pressing the block into its
    # locators without the cut (k_min = 0) in every one.
    assert found.count("highest") >= len(loads[3:]) // 2
    assert found.count("lowest") == len(loads[3:])


@pytest.mark.parametrize("model", ["ellipsoid", "pyramid"])
def test_the_compiled_pass_gives_the_answers_of_its_parts(model, monkeypatch):
    """Carried.carry_at evaluates the program from its dense maps, carries the optimum and tests
    the point without load in one compiled pass: the same as the program, the carry and the
    WithoutLoad test called one by one (the path of programs with sparse maps)."""
    loads = path(12)
    problem = bench_fixture(loads[0], model)
    planner = Planner(problem)
    for load in loads[:3]:
        planner.solve(load)
    runner, key = planner._runner, ("check", False)
    compared = 0
    for load in loads[3:]:
        plan = planner.solve(load, analyse=False)
        planned = {i: plan.forces[c.name] for i, c in enumerate(problem.contacts)
                   if c.name in plan.forces}  # fmt: skip
        wrenches = problem.task_wrenches(load)
        runner.carried_ends(wrenches, planned)  # (writes check's vector; the pseudo-inverse)
        source, unit = runner._source
        carried, direct, without = (
            runner._carried(source),
            runner._direct[key],
            runner._without(key),
        )
        kept = runner._kept[key]
        arguments = (
            runner._direct[source].solution,
            unit / kept.unit,
            kept.vector,
            direct,
            without,
        )
        assert direct.compiled_maps() is not None
        fused = carried.carry_at(*arguments)
        with monkeypatch.context() as patch:
            patch.setattr(type(direct), "compiled_maps", lambda self: None)
            alpha, worst, held, x, z, program = carried.carry_at(*arguments)
        held = without.held(*program[1:])
        assert fused[2] == held
        for mine, theirs in zip(fused[5], program, strict=True):
            np.testing.assert_allclose(mine, theirs, rtol=1e-14, atol=1e-14)
        assert fused[0] == pytest.approx(alpha, rel=1e-12)
        if np.isfinite(worst):
            assert fused[1] == pytest.approx(worst, rel=1e-6, abs=1e-15)
            np.testing.assert_allclose(fused[3], x, rtol=1e-14, atol=0)
            np.testing.assert_allclose(fused[4], z, rtol=1e-12, atol=1e-15)
        compared += 1
    assert compared == len(loads[3:])


def dissipation_bound(problem, forces, twist):
    """The largest multiple of the task load that ``twist`` allows: the power the contacts can
    take from it (each at most its friction set's, at the given forces) and gravity's, over
    the load's, where no passive contact can do positive power on it (else ``inf``)."""
    wrench = problem.loads[0].wrench
    twist = twist if wrench @ twist > 0 else -twist
    taken = -problem.body.weight_wrench @ twist
    for contact in problem.contacts:
        passive = contact.force is None and contact.role in ("locator", "support")
        fn = cp.Variable(nonneg=True) if passive else forces[contact.name]
        load, constraints = ref.contact_wrench(contact, fn)
        if passive:
            constraints.append(fn <= 1.0)
        power = cp.Problem(cp.Maximize(-load @ twist), constraints)
        power.solve(solver=cp.CLARABEL)
        if passive:
            if power.value > 1e-9 * np.linalg.norm(twist):
                return np.inf
        else:
            taken += power.value
    return taken / (wrench @ twist)


@pytest.mark.parametrize("model", ["ellipsoid", "pyramid"])
def test_the_carried_multipliers_are_an_impending_motion_of_the_largest_multiple(model):
    loads = path(15)
    problem = bench_fixture(loads[0], model)
    planner = Planner(problem)
    for load in loads[:3]:  # (the direct solvers of the force objective and of check)
        planner.solve(load)
    proved = 0
    for load in loads[3:]:
        plan = planner.solve(load, analyse=False)
        planned = {i: plan.forces[c.name] for i, c in enumerate(problem.contacts)
                   if c.name in plan.forces}  # fmt: skip
        highest = planner._runner.carried_ends(problem.task_wrenches(load), planned).get("highest")
        if highest is None:
            continue
        twist = highest["dual"][:, 0]
        bound = dissipation_bound(checked(problem, plan.forces, load), plan.forces, twist)
        assert bound == pytest.approx(1.0, rel=1e-6)
        proved += 1
    assert proved >= len(loads[3:]) // 2


def lift_helping_a_pinch(lift: float) -> Problem:
    """Two point fingers (free forces, least largest, ``mu = 0.5``) pinch a 1 kg part (weight
    ``g``) while the task lifts it by ``lift`` [N]: the fingers hold ``g - k lift`` by friction,
    so the least forces, ``(g - lift) / 2 / mu`` each, hold the lift from ``k = 1`` (less lift
    lets the part slip down) to ``k = (2 g - lift) / lift`` (more lifts it out)."""
    fingers = [
        Contact(name=name, role="finger", position=[0, side * 0.02, 0], normal=[0, -side, 0],
                mu=0.5, model="point-cone")
        for name, side in (("left", -1), ("right", 1))
    ]  # fmt: skip
    body = Body(mass=1.0, center_of_mass=[0, 0, 0])
    load = Load(name="lift", force=[0, 0, lift], point=[0, 0, 0])
    return Problem(body=body, contacts=fingers, loads=[load], objective="min-max-normal-force")


def assert_lifts_held_from_one_up(problem: Problem) -> None:
    """Re-solves of :func:`lift_helping_a_pinch` (or its fingers on other models) with several
    lifts give the closed-form forces and held intervals."""
    weight = -problem.body.weight_wrench[2]
    planner = Planner(problem)
    for lift in (4.0, 4.5, 5.0, 3.0, 4.0):
        plan = planner.solve([dataclasses.replace(problem.loads[0], force=[0, 0, lift])])
        assert plan.forces["left"] == pytest.approx((weight - lift) / 2 / 0.5, rel=1e-7)
        low, high = plan.held_intervals["lift"]
        assert low == pytest.approx(1.0, rel=1e-7)
        assert high == pytest.approx((2 * weight - lift) / lift, rel=1e-7)


def test_a_lift_that_helps_the_grip_holds_from_one_up(ends):
    assert_lifts_held_from_one_up(lift_helping_a_pinch(4.0))
    assert ("lowest",) in ends[-2:]  # carried where the direct solvers were there


def test_switched_off_contacts_are_carried_as_left_out():
    loads = path(8)
    problem = bench_fixture(loads[0], "ellipsoid")
    planner = Planner(problem, switchable=True)
    without = Planner(dataclasses.replace(
        problem, contacts=[c for c in problem.contacts if c.name != "side-2"]
    ))  # fmt: skip
    for load in loads:
        plan = planner.solve(load, disabled=["side-2"])
        expected = without.solve(load)
        np.testing.assert_allclose(
            plan.held_intervals["cut"], expected.held_intervals["cut"], rtol=INTERVAL_RTOL
        )


@pytest.mark.parametrize("model", ["ellipsoid", "pyramid"])
def test_an_end_not_carried_is_solved_in_the_vector_just_written(model, monkeypatch):
    """Where the force solve certifies no end (the cut pushes the block into its locators, the
    clamps idle), ``k_max`` is solved straight in the check program's vector that the carry
    wrote: the reference's held interval, as the full path finds it."""
    solved = []
    carried = Runner.carried_ends

    def recorded(self, *args):
        result = carried(self, *args)
        solved.append("solved" in result)
        return result

    monkeypatch.setattr(Runner, "carried_ends", recorded)
    loads = path(24)
    problem = bench_fixture(loads[0], model)
    planner = Planner(problem)
    for load in loads[:3]:
        planner.solve(load)
    solved.clear()
    for load in loads[3:]:
        plan = planner.solve(load)
        assert plan.status == "optimal"
        if solved[-1]:
            assert_interval(plan.held_intervals["cut"], reference_interval(problem, plan, load[0]))
    assert any(solved)


@pytest.fixture
def osculated(monkeypatch):
    """The ends that each analysis of an exact model carried (``Runner._osculated_ends``)."""
    found = []
    carried = Runner._osculated_ends

    def counted(self, *args):
        result = carried(self, *args)
        found.append({end: float(value["scale"][0]) for end, value in result.items()})
        return result

    monkeypatch.setattr(Runner, "_osculated_ends", counted)
    return found


def test_exact_models_carry_the_ends_their_check_solves_find(osculated, monkeypatch):
    """On the fixture with exact models, the settled force solve carried into check's
    osculating program gives the held intervals, motions (to the duals' accuracy) and
    utilisation (where ``k_max`` is below the cap, past which the loads are anywhere in a face of
    optima) that check's own rounds find (a planner whose carry is switched off), along a
    turning cut."""
    loads = path(14)
    problem = bench_fixture(loads[0], "exact")
    carrying, solving = Planner(problem), Planner(problem)
    for load in loads[:3]:  # (the direct solvers of the force objective and of check)
        carrying.solve(load)
        solving.solve(load)
    osculated.clear()
    found = []
    for load in loads[3:]:
        found.append(carrying.solve(load))
    monkeypatch.setattr(Runner, "_osculated_ends", lambda self, *args: {})
    for plan, load in zip(found, loads[3:], strict=True):
        expected = solving.solve(load)
        assert plan.status == expected.status == "optimal"
        assert plan.forces["clamp-top"] == pytest.approx(expected.forces["clamp-top"], rel=1e-9)
        np.testing.assert_allclose(plan.held_intervals["cut"], expected.held_intervals["cut"],
                                   rtol=1e-7, atol=1e-9)  # fmt: skip
        motion, other = plan.motions["cut"], expected.motions["cut"]
        assert (motion is None) is (other is None)
        if motion is not None:  # (interior-point duals: up to 2.1e-4 apart on the whole path)
            assert np.linalg.norm(motion.twist - other.twist) <= 1e-3 * np.linalg.norm(other.twist)
        if np.isfinite(expected.held_intervals["cut"][1]):  # (at the cap: a face of optima)
            np.testing.assert_allclose(plan.utilisation, expected.utilisation, rtol=0, atol=1e-6)
    assert all(ends.get("lowest") == 0.0 for ends in osculated)  # (held without the cut)
    assert sum("highest" in ends for ends in osculated) >= len(loads[3:]) // 2


def test_an_exact_lift_that_helps_the_grip_is_carried_from_one_up(osculated):
    """:func:`lift_helping_a_pinch` with exact disk patches: a pure force's friction limit is
    ``mu`` times the normal force whatever the pressure, so the closed forms hold, and the lower
    end, 1, is carried from the force solve (the multiple minimised)."""
    problem = lift_helping_a_pinch(4.0)
    patch = pressure.disk(0.005)
    problem = dataclasses.replace(problem, contacts=[
        dataclasses.replace(c, model="exact", patch=patch) for c in problem.contacts
    ])  # fmt: skip
    assert_lifts_held_from_one_up(problem)
    assert {"lowest": 1.0} in osculated[-2:]


def test_a_force_solve_that_left_loads_inside_is_not_carried(osculated, monkeypatch):
    """The force solve's limiting loads left inside their sets cost ``check`` the same, scaled
    by ``α``: where that exceeds ``check``'s own ``COMPLEMENTARITY_RTOL`` the end is not carried
    but found by ``check``'s rounds (here the force solves are made to report a power of 1e-3
    held back): the held intervals of a planner whose carry is off."""
    settle = osculating.SETTLE

    def reported(*args):
        settled, cut, held_back = settle(*args)
        return settled, cut, held_back if args[19] else held_back + 1e-3  # (force solves)

    loads = path(6)
    problem = bench_fixture(loads[0], "exact")
    carrying, solving = Planner(problem), Planner(problem)
    for load in loads[:3]:
        carrying.solve(load)
        solving.solve(load)
    osculated.clear()
    monkeypatch.setattr(osculating, "SETTLE", reported)
    found = [carrying.solve(load) for load in loads[3:]]
    assert osculated and not any("highest" in ends for ends in osculated)
    monkeypatch.setattr(Runner, "_osculated_ends", lambda self, *args: {})
    for plan, load in zip(found, loads[3:], strict=True):
        expected = solving.solve(load)
        assert plan.status == expected.status == "optimal"
        np.testing.assert_allclose(plan.held_intervals["cut"], expected.held_intervals["cut"],
                                   rtol=1e-7, atol=1e-9)  # fmt: skip
