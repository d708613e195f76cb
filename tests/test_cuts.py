"""The planner's cut pool (``fixplan.planner.cuts``): the order of its slots and when its rounds
end."""

from __future__ import annotations

import numpy as np
import pytest

from fixplan.planner.cuts import MAX_CUT_ROUNDS, CutPool, _slots


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


class _StillOutside:
    """A cut pool whose loads stay outside their sets whatever is cut (the rounds' loop alone)."""

    def add_cuts(self) -> float:
        return 1.0


def _rounds(first: str, statuses: list[str]) -> tuple[str, list[str], int]:
    """The final status, notes and number of re-solves of the rounds from a first solve's
    status, with later solves returning ``statuses`` in turn (then ``optimal``)."""
    given = iter(statuses)
    solves = []

    def solve() -> str:
        solves.append(1)
        return next(given, "optimal")

    status, notes = CutPool.converge(_StillOutside(), solve, first)
    return status, notes, len(solves)


def test_two_inaccurate_solves_in_a_row_end_the_rounds_for_the_fallback_solver():
    # (One between accurate ones is passed over.)
    statuses = ["inaccurate", "optimal", "inaccurate", "inaccurate"]
    assert _rounds("optimal", statuses) == ("inaccurate", [], 4)
    assert _rounds("inaccurate", ["inaccurate"]) == ("inaccurate", [], 1)


def test_rounds_of_accurate_solves_that_do_not_converge_end_with_a_note():
    status, notes, solves = _rounds("optimal", ["inaccurate"])
    assert (status, solves) == ("optimal", MAX_CUT_ROUNDS)
    assert len(notes) == 1 and f"after {MAX_CUT_ROUNDS} rounds of cuts" in notes[0]


def test_rounds_that_end_on_an_inaccurate_solve_leave_no_note_for_the_fallback_solver():
    # (The fallback solver's own rounds note a load still outside.)
    statuses = ["optimal"] * (MAX_CUT_ROUNDS - 1) + ["inaccurate"]
    assert _rounds("optimal", statuses) == ("inaccurate", [], MAX_CUT_ROUNDS)
