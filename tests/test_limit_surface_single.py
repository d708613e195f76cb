"""Single queries of a limit surface (one twist, one load) take a fast path: they must give the
answers of the batched path, which solves many loads at once, and check their input the same."""

from __future__ import annotations

import math

import numpy as np
import pytest

from fixplan import InvalidArgumentError, LimitSurface, pressure

SAFETY_RTOL = 1e-12  # both paths run Newton to 1e-12 on the twist: s agrees to its square
MOTION_RAD = 1e-9  # ... and the motions to about that angle


def test_one_load_at_a_time_gives_the_answers_of_the_batch(surface, rng):
    loads = rng.normal(size=(5, 3)) * np.array([1.0, 1.0, surface.characteristic_length])
    loads *= surface.max_force
    motions, safety = surface.motion_and_safety_factor(loads)
    for load, motion, factor in zip(loads, motions, safety, strict=True):
        single_motion, single_factor = surface.motion_and_safety_factor(load)
        assert single_factor == pytest.approx(factor, rel=SAFETY_RTOL)
        assert np.linalg.norm(single_motion - motion) < MOTION_RAD * np.linalg.norm(motion)
        assert surface.safety_factor(load) == single_factor
        np.testing.assert_array_equal(surface.motion(load), single_motion)


def test_one_twist_at_a_time_gives_the_loads_of_the_batch(surface, rng):
    twists = rng.normal(size=(8, 3)) / np.array([1.0, 1.0, surface.characteristic_length])
    loads = surface.load(twists)
    for twist, load in zip(twists, loads, strict=True):
        np.testing.assert_allclose(surface.load(twist), load, rtol=1e-14, atol=1e-15)


RECTANGLE = LimitSurface(pressure.rectangle(0.2, 0.02), mu=0.4, normal_force=2.0)


@pytest.mark.parametrize(
    ("value", "words"),
    [
        (np.array([math.nan, 0.0, 1.0]), ["twist[0]", "finite"]),
        (np.array([0.0, -math.inf, 1.0]), ["twist[0]", "finite"]),
        (np.zeros(3), ["twist[0]", "zero"]),
        (np.zeros(3, dtype=int), ["twist[0]", "zero"]),
        (np.ones(2), ["twist", "(K, 3)"]),
    ],
)
def test_a_bad_single_twist_given_as_an_array_raises_an_error_naming_it(value, words):
    with pytest.raises(InvalidArgumentError) as caught:
        RECTANGLE.load(value)
    for word in words:
        assert word in str(caught.value)


def test_a_single_zero_load_is_held_with_no_motion():
    motion, safety = RECTANGLE.motion_and_safety_factor(np.zeros(3))
    assert safety == math.inf
    assert np.all(np.isnan(motion))


@pytest.mark.parametrize("dtype", [np.float32, np.int64])
def test_a_single_twist_or_load_of_another_dtype_gives_the_same_answer(dtype):
    twist, load = np.array([1.0, -2.0, 30.0]), np.array([3.0, 1.0, -2.0])
    np.testing.assert_array_equal(RECTANGLE.load(twist.astype(dtype)),
                                  RECTANGLE.load(twist.astype(dtype).astype(float)))  # fmt: skip
    assert RECTANGLE.safety_factor(load.astype(dtype)) == RECTANGLE.safety_factor(
        load.astype(dtype).astype(float)
    )
