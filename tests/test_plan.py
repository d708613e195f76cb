"""Plans built by the planner (``Plan._of``) are the plans of the frozen constructor."""

import dataclasses
import pickle

import numpy as np
import pytest

from fixplan.planner.plan import Plan

VALUES = {
    "status": "optimal", "objective": "min-total-clamp-force", "objective_value": 12.5,
    "load_names": ("cut",), "contact_names": ("pad", "clamp"),
    "normal_forces": np.array([[3.0], [9.5]]), "forces": {"clamp": 9.5},
    "residual": 1e-12, "warnings": ("a note",), "solver": "dual simplex (direct)",
    "solve_time": 1e-4,
}  # fmt: skip


def _fields(plan):
    return {f.name: getattr(plan, f.name) for f in dataclasses.fields(Plan)}


def test_a_plan_of_fields_is_the_constructors_plan():
    built, constructed = Plan._of(dict(VALUES)), Plan(**VALUES)
    assert _fields(built).keys() == _fields(constructed).keys()
    for name, value in _fields(constructed).items():
        if isinstance(value, np.ndarray):
            np.testing.assert_array_equal(getattr(built, name), value)
        else:
            assert getattr(built, name) == value, name
    assert built.as_dict() == constructed.as_dict()


def test_a_plan_of_fields_is_frozen_with_dicts_of_its_own_and_pickles():
    first, second = Plan._of(dict(VALUES)), Plan._of(dict(VALUES))
    with pytest.raises(dataclasses.FrozenInstanceError):
        first.status = "infeasible"
    assert first.safety_factors == {} and first.safety_factors is not second.safety_factors
    first.motions["cut"] = None  # (a user's change to one plan's dict stays there)
    assert second.motions == {} and Plan._of(dict(VALUES)).motions == {}
    again = pickle.loads(pickle.dumps(first))
    assert again.as_dict() == first.as_dict()
