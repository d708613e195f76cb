"""Held intervals of given forces against closed forms, and how plans put them in words."""

import json

import numpy as np
import pytest

from fixplan.planner.planner import solve
from fixplan.planner.problem import Body, Contact, Load, Problem

MU = 0.5
WEIGHTLESS = Body(mass=0.0, center_of_mass=[0, 0, 0])


def pinch_check(force: float, weight: float) -> Problem:
    """Two point fingers squeezing a bar along y with ``force`` [N]; the task load is a weight
    [N]: held for ``k <= 2 mu force / weight``."""
    fingers = [
        Contact(name=name, role="finger", position=[0, side * 0.02, 0], normal=[0, -side, 0],
                mu=MU, model="point-cone", force=force)
        for name, side in (("left", -1), ("right", 1))
    ]  # fmt: skip
    load = Load(name="weight", force=[0, 0, -weight], point=[0, 0, 0])
    return Problem(body=WEIGHTLESS, contacts=fingers, loads=[load], objective="check")


def push_up_check(force: float, weight: float) -> Problem:
    """A finger pushing the part up with ``force`` [N] from below, between two supports that can
    only push up too: only a task load of at least ``force`` holds it down,
    ``k >= force / weight``."""
    contacts = [
        Contact(name="finger", role="finger", position=[0, 0, 0], normal=[0, 0, 1], mu=MU,
                model="point-cone", force=force),
        *(Contact(name=f"pad-{i}", role="support", position=[x, 0, 0], normal=[0, 0, 1], mu=MU,
                  model="point-cone") for i, x in enumerate((-0.02, 0.02))),
    ]  # fmt: skip
    load = Load(name="press", force=[0, 0, -weight], point=[0, 0, 0])
    return Problem(body=WEIGHTLESS, contacts=contacts, loads=[load], objective="check")


@pytest.mark.parametrize(("force", "weight"), [(10.0, 5.0), (10.0, 10.0), (3.0, 10.0)])
def test_a_pinch_holds_from_zero_up_to_the_coulomb_limit(force, weight):
    plan = solve(pinch_check(force, weight))
    low, high = plan.held_intervals["weight"]
    assert low == 0.0
    assert high == pytest.approx(2 * MU * force / weight, rel=1e-6)
    assert plan.held["weight"] == (high >= 1.0 - 1e-6)
    assert plan.safety_factors["weight"] == high


@pytest.mark.parametrize(("force", "weight"), [(5.0, 10.0), (20.0, 10.0)])
def test_a_part_pushed_up_is_held_only_by_enough_task_load(force, weight):
    plan = solve(push_up_check(force, weight))
    low, high = plan.held_intervals["press"]
    assert low == pytest.approx(force / weight, rel=1e-6)
    assert high == np.inf
    assert plan.held["press"] == (force <= weight)


def test_the_interval_is_put_in_words():
    held = solve(pinch_check(10.0, 4.0))
    assert held.describe_held("weight") == "held for 0–2.5 × the task load"
    slides = solve(pinch_check(3.0, 10.0))
    assert slides.describe_held("weight") == ("not held: slides above 0.3 × the task load")
    pushed = solve(push_up_check(20.0, 10.0))
    assert pushed.describe_held("press") == (
        "not held even without the task load: the active forces themselves push the part out "
        "(held only for 2 × the task load and above)"
    )
    assert solve(push_up_check(5.0, 10.0)).describe_held("press") == (
        "held for 0.5 × the task load and above"
    )


def test_the_json_document_carries_the_intervals_and_their_words():
    document = json.loads(json.dumps(solve(push_up_check(5.0, 10.0)).as_dict()))
    assert document["held_intervals"]["press"] == [pytest.approx(0.5), "inf"]
    assert document["held_descriptions"]["press"] == "held for 0.5 × the task load and above"
    assert document["held"]["press"] is True


def test_the_lower_ends_of_many_cases_are_each_cases_own():
    """k_min is solved for one case per column of given forces and shared only where that case
    is held without its task load: a pinch (every case held at 0) and a part pushed up (no case
    held at 0) over several weights against their closed forms."""
    weights = [5.0, 10.0, 40.0]
    pinch, push = pinch_check(20.0, 1.0), push_up_check(20.0, 1.0)
    for problem, lowest, highest in (
        (pinch, [0.0] * 3, [2 * MU * 20.0 / w for w in weights]),
        (push, [20.0 / w for w in weights], [np.inf] * 3),
    ):
        name = problem.loads[0].name
        loads = [Load(name=f"{name}-{w:g}", force=[0, 0, -w], point=[0, 0, 0]) for w in weights]
        plan = solve(Problem(body=WEIGHTLESS, contacts=problem.contacts, loads=loads,
                             objective="check"))  # fmt: skip
        for load, low, high in zip(loads, lowest, highest, strict=True):
            got = plan.held_intervals[load.name]
            assert got[0] == pytest.approx(low, rel=1e-6, abs=1e-9), load.name
            assert got[1] == pytest.approx(high, rel=1e-6), load.name
