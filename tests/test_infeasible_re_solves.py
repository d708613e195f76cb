"""Re-solves whose loads cannot be held: the direct solvers give up at once (a ray) and the
plan carries Clarabel's certificate straight from its direct solve, as a fresh planner's solve
through cvxpy reports it."""

import dataclasses

import numpy as np
import pytest
from test_kept_parameters import bench_fixture

from fixplan.planner import cone_interior_point, dual_simplex
from fixplan.planner.planner import Planner
from fixplan.planner.problem import Body, Contact, Load, Problem

#: Clamp force limit [N]: the heavy cut below needs more.
CLAMP_LIMIT = 150.0


def _limited(model):
    problem = bench_fixture([_cut(1.0)], model)
    contacts = tuple(
        dataclasses.replace(c, max_force=CLAMP_LIMIT) if c.role == "clamp" else c
        for c in problem.contacts
    )
    return dataclasses.replace(problem, contacts=contacts)


def _cut(size, turn=0.0):
    """A milling load ``size`` times a 90 N cut, turned by ``turn`` [rad] about z."""
    c, s = np.cos(turn), np.sin(turn)
    return Load(name="cut", force=[size * 60.0 * c, size * 60.0 * s, -size * 30.0],
                point=[0.02, 0.01, 0.04], torque=[0.0, 0.0, size * 0.5])  # fmt: skip


def _twist_direction(plan):
    twist = plan.infeasible_motions["cut"].twist
    return twist / np.linalg.norm(twist)


@pytest.mark.parametrize(
    ("model", "method"), [("ellipsoid", "interior point"), ("pyramid", "dual simplex")]
)
def test_an_unholdable_load_in_a_control_loop_reports_what_a_fresh_solve_does(
    model, method, monkeypatch
):
    """Held, unholdable and held again: each re-solve's plan (status, forces, certificate)
    is a fresh planner's, and the unholdable one comes straight from Clarabel's direct solve,
    after the interior point stopped at the ray (few iterations) or the simplex without an
    artificial start."""
    planner = Planner(_limited(model))
    for k in range(3):  # (the direct solvers are built on the second solve)
        planner.solve([_cut(1.0, 0.1 * k)], analyse=False)
    cold_starts, iterations = [], []
    cold = dual_simplex.DualSimplex._cold
    monkeypatch.setattr(
        dual_simplex.DualSimplex, "_cold", lambda *a: cold_starts.append(1) or cold(*a)
    )
    solve = cone_interior_point.ConeInteriorPoint.solve

    def counted(self, *args):
        found = solve(self, *args)
        iterations.append(self.iterations)
        return found

    monkeypatch.setattr(cone_interior_point.ConeInteriorPoint, "solve", counted)
    for size in (1.2, 20.0, 1.1, 25.0):
        cold_starts.clear(), iterations.clear()
        plan = planner.solve([_cut(size, 0.3)], analyse=False)
        fresh = Planner(_limited(model)).solve([_cut(size, 0.3)], analyse=False)
        assert plan.status == fresh.status
        if size < 2.0:
            assert plan.status == "optimal" and plan.solver == f"{method} (direct)"
            assert plan.objective_value == pytest.approx(fresh.objective_value, rel=1e-7)
            continue
        assert plan.status == "infeasible" and plan.solver == "CLARABEL (direct)"
        assert fresh.solver == "CLARABEL"  # (through cvxpy)
        assert "cannot be held" in plan.certificate
        np.testing.assert_allclose(_twist_direction(plan), _twist_direction(fresh), atol=1e-6)
        assert not cold_starts
        assert len(iterations) == (method == "interior point")
        assert all(n < cone_interior_point.MAX_ITERATIONS // 2 for n in iterations)


@pytest.mark.parametrize(
    ("objective", "lifts"),
    [("min-max-normal-force", [1.0, 2.0, 300.0, 3.0]), ("check", [90.0, -5.0, 5000.0])],
)
def test_a_re_solve_after_an_unholdable_direct_one_with_a_given_force_and_a_new_force_unit(
    objective, lifts
):
    """A pinch with a given finger force (both for ``check``), lifted: the direct solve of an
    unholdable lift, then one in another force unit (which writes the given forces again) —
    each plan a fresh planner's. (That second re-solve ended in a KeyError: the direct
    solve's reader was made only once it had an answer.)"""
    fingers = [("a", -1, 20.0), ("b", 1, 20.0 if objective == "check" else None)]
    contacts = [
        Contact(name=name, role="finger", position=[0, 0.05 * side, 0], normal=[0, -side, 0],
                mu=0.5, model="point-cone", force=force)
        for name, side, force in fingers
    ]  # fmt: skip
    mass = 10.0 if objective == "check" else 0.5
    first = [Load(name="lift", force=[0, 0, lifts[0]])]
    problem = Problem(body=Body(mass=mass, center_of_mass=[0, 0, 0]), contacts=contacts,
                      loads=first, objective=objective)  # fmt: skip
    planner = Planner(problem)
    for lift in lifts:
        loads = [Load(name="lift", force=[0, 0, lift])]
        plan, fresh = planner.solve(loads), Planner(problem).solve(loads)
        assert plan.status == fresh.status
        if fresh.status == "optimal":
            assert plan.objective_value == pytest.approx(fresh.objective_value, rel=1e-7)
        held = [plan.held_intervals.get("lift", ()), fresh.held_intervals.get("lift", ())]
        np.testing.assert_allclose(*held, rtol=1e-7)
