"""Screws of twists against their closed form: a rotation ``ω`` about the axis through ``p``
with pitch ``h`` has ``v = p × ω + h ω`` (the velocity of the body point at the origin)."""

import math
import pickle

import numpy as np
import pytest

from fixplan.planner.screw import TRANSLATION_RTOL, Screw

LENGTH_SCALE = 0.05


def twist_of(direction, point, pitch, spin):
    """The twist of a rotation by ``spin`` [rad/s] about ``direction`` through ``point``."""
    omega = spin * np.asarray(direction, dtype=float) / np.linalg.norm(direction)
    return np.r_[np.cross(point, omega) + pitch * omega, omega]


@pytest.mark.parametrize("seed", range(5))
def test_the_axis_point_and_pitch_are_those_the_twist_was_made_of(seed):
    rng = np.random.default_rng(seed)
    direction = rng.normal(size=3)
    direction /= np.linalg.norm(direction)
    point = rng.normal(scale=0.1, size=3)
    point -= (point @ direction) * direction  # the axis point closest to the origin
    pitch, spin = rng.normal(scale=0.02), rng.uniform(0.5, 3.0)
    screw = Screw.from_twist(twist_of(direction, point, pitch, spin), LENGTH_SCALE)
    assert not screw.is_translation
    np.testing.assert_allclose(screw.direction, direction, rtol=0, atol=1e-14)
    np.testing.assert_allclose(screw.point, point, rtol=0, atol=1e-14)
    assert screw.pitch == pytest.approx(pitch, rel=1e-12, abs=1e-15)
    v, w = screw.twist[:3], screw.twist[3:]
    assert v @ v + LENGTH_SCALE**2 * (w @ w) == pytest.approx(1.0, rel=1e-14)


def test_a_twist_that_hardly_turns_is_a_translation():
    speed = np.array([0.3, -0.4, 0.0])
    turning = 0.5 * TRANSLATION_RTOL / LENGTH_SCALE * np.linalg.norm(speed)
    screw = Screw.from_twist(np.r_[speed, 0.0, 0.0, turning], LENGTH_SCALE)
    assert screw.is_translation and screw.point is None and math.isinf(screw.pitch)
    np.testing.assert_allclose(screw.direction, speed / 0.5, rtol=0, atol=1e-15)
    assert screw.describe() == "translates along (0.6, -0.8, 0)"


def test_a_screw_keeps_a_copy_of_its_twist_and_its_repr_makes_it_again():
    twist = twist_of([0, 0, 1], [0.1, 0, 0], 0.0, 1.0)
    screw = Screw.from_twist(twist, LENGTH_SCALE)
    twist[:] = 7.0
    np.testing.assert_allclose(screw.point, [0.1, 0, 0], atol=1e-15)
    again = eval(repr(screw), {"Screw": Screw})
    np.testing.assert_allclose(again.twist, screw.twist, rtol=1e-15, atol=0)  # (normalised again)
    assert again.describe() == screw.describe()


@pytest.mark.parametrize(
    "twist", [np.zeros(6), np.r_[1.0, 0, 0, 0, 0, np.nan], np.ones(5), [[1.0] * 6]]
)
def test_a_twist_without_a_screw_is_refused(twist):
    with pytest.raises(ValueError, match="nonzero, finite twist of 6 numbers"):
        Screw.from_twist(twist, LENGTH_SCALE)


@pytest.mark.parametrize("protocol", range(pickle.HIGHEST_PROTOCOL + 1))
def test_a_screw_pickles_with_every_protocol(protocol):
    screw = Screw.from_twist(twist_of([1, 2, 3], [0.01, -0.02, 0.0], 0.003, 2.0), LENGTH_SCALE)
    again = pickle.loads(pickle.dumps(screw, protocol=protocol))
    np.testing.assert_array_equal(again.twist, screw.twist)
    assert again.describe() == screw.describe()


@pytest.mark.parametrize("size", [1e-300, 1e300])
def test_the_screw_of_a_tiny_or_huge_twist_is_that_of_its_direction(size):
    twist = twist_of([0, 1, 1], [0.02, 0.0, 0.0], 0.01, 1.0)
    screw = Screw(twist * size, LENGTH_SCALE)  # (as the analysis makes them: not checked)
    expected = Screw.from_twist(twist, LENGTH_SCALE)
    np.testing.assert_allclose(screw.twist, expected.twist, rtol=2e-15)
    np.testing.assert_allclose(screw.point, [0.02, 0.0, 0.0], rtol=0, atol=1e-15)


def test_the_screw_of_a_subnormal_twist_is_a_unit_twist():
    """(Its entries hold a few bits: only the scaling is checked.)"""
    screw = Screw(twist_of([0, 1, 1], [0.02, 0.0, 0.0], 0.01, 1.0) * 1e-320, LENGTH_SCALE)
    v, w = screw.twist[:3], screw.twist[3:]
    assert v @ v + LENGTH_SCALE**2 * (w @ w) == pytest.approx(1.0, rel=1e-14)
