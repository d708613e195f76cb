"""The vectorised logarithm is the C library's to within one unit in the last place.

Reference: ``math.log`` (glibc's, correctly rounded in nearly all cases), element by element.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from fixplan.surface.vector_log import _LOGS

#: Largest difference from ``math.log`` in units in the last place of the answer.
ULPS = 1.0


def logged(values: np.ndarray) -> np.ndarray:
    out = np.array(values, dtype=float)
    _LOGS(out, np.empty(out.shape, dtype=np.int64))
    return out


@pytest.mark.parametrize(
    "values",
    [
        np.exp(np.random.default_rng(0).uniform(0.0, 70.0, 200_000)),  # the grid's: >= 1
        np.exp(np.random.default_rng(1).uniform(-700.0, 700.0, 200_000)),
        1.0 + np.random.default_rng(2).uniform(-1e-6, 1e-6, 10_000),  # log near 0
        np.sqrt(2.0) * (1.0 + np.arange(-200, 201) * 2.0**-52),  # the mantissa's switch
        2.0 ** np.arange(-1022, 1024, dtype=float),  # powers of two: exact multiples of ln 2
        np.array([np.finfo(float).tiny, np.finfo(float).max, 1.0, 2.0, 0.5, 10.0]),
    ],
    ids=["exp(U(0, 70))", "exp(U(-700, 700))", "1 +- 1e-6", "around sqrt 2", "2^k", "edges"],
)
def test_logarithms_are_within_one_ulp_of_the_c_library(values):
    reference = np.array([math.log(v) for v in values])
    error = np.abs(logged(values) - reference)
    allowed = ULPS * np.spacing(np.abs(reference))
    assert np.all(error <= np.where(reference == 0.0, 0.0, allowed))


def test_the_log_of_one_is_zero_exactly():
    assert logged(np.ones(17)).tolist() == [0.0] * 17
