"""The compiled largest magnitudes of the verification and the planner's force unit, against
NumPy's on random arrays (exact: the same products and comparisons), with NaN propagating."""

import numpy as np
import pytest

from fixplan.planner.verify import LARGEST_MAGNITUDE, LARGEST_SCALED_MAGNITUDE


@pytest.mark.parametrize("seed", range(5))
def test_largest_magnitudes_match_numpy(seed):
    rng = np.random.default_rng(seed)
    values = rng.normal(size=(6, 1 + seed)) * 10.0 ** rng.uniform(-3, 3, (6, 1))
    scales = np.repeat([1.0, 1.0 / rng.uniform(0.01, 0.5)], 3)
    assert LARGEST_MAGNITUDE(values) == np.abs(values).max()
    assert LARGEST_SCALED_MAGNITUDE(values, scales) == np.abs(values * scales[:, None]).max()
    columns = values[:, ::2]  # (a view, not contiguous)
    assert LARGEST_SCALED_MAGNITUDE(columns, scales) == np.abs(columns * scales[:, None]).max()


def test_largest_magnitudes_of_nothing_and_of_nan():
    scales = np.ones(6)
    assert LARGEST_SCALED_MAGNITUDE(np.zeros((6, 0)), scales) == 0.0
    values = np.ones((6, 2))
    values[4, 1] = np.nan
    assert np.isnan(LARGEST_MAGNITUDE(values))
    assert np.isnan(LARGEST_SCALED_MAGNITUDE(values, scales))
