"""The slot order of the planner's cut pool (``fixplan.planner.cuts``)."""

from __future__ import annotations

import numpy as np
import pytest

from fixplan.planner.cuts import _slots


@pytest.mark.parametrize("seed", range(5))
def test_new_cuts_take_distinct_slots_the_longest_inactive_and_loosest_first(seed):
    rng = np.random.default_rng(seed)
    used = rng.integers(0, 3, size=(12, 7))  # many ties, as when every cut was just active
    slack = rng.uniform(0.0, 1e-6, size=(12, 7))
    order = _slots(used, slack)
    for column in range(7):
        slots = order[:, column]
        assert sorted(slots) == list(range(12))
        keys = list(zip(used[slots, column], -slack[slots, column], strict=True))
        assert keys == sorted(keys)
