"""Start twists of the compiled inverse map (``CompiledKernel.solve(..., start)``) move where
Newton starts, never the answer: the safety factor is ``scale * h`` on the plane ``L·V = 1``.

A start put on that plane by dividing it by its work ``L·S`` misses the plane by the rounding
of ``L·S`` where that sum cancels (a start doing little work for its size) or its products are
subnormal (a tiny start: "any size" is allowed); Newton moves only along the plane's
directions, so the twist would stay off it and ``scale * h`` be off by the same factor, with no
error raised (as it was, found in review). Starts now only move the ellipsoid's twist, which is
on the plane, along the plane.

Reference: the same solve without a start (Newton from the ellipsoid's twist, which
``test_compiled_inverse`` pins to the NumPy path and ``test_grid_kernel`` to the four-edges
kernel), to ``SAFETY_RTOL`` (both run Newton to 1e-12 on the twist, so the safety factors agree
to about its square; rounding dominates). The returned twist must also do unit work on the
normalised load to the same tolerance.
"""

from __future__ import annotations

import numpy as np
import pytest
from conftest import SURFACES as SHARED_SURFACES

from fixplan import InvalidArgumentError

SAFETY_RTOL = 1e-12

SURFACES = {name: SHARED_SURFACES[name] for name in ("tactile grid", "hertz disk", "three points")}


def loads_and_answers(surface):
    rng = np.random.default_rng(21)
    units = np.array([surface.max_force, surface.max_force, surface.max_moment])
    loads = rng.normal(size=(12, 3)) * units
    safety, twists = surface._compiled.solve(loads, units, surface._scale)
    return units, loads, safety, twists


def unit_work(loads, units, twists):
    """``L·V`` of the loads normalised as the solve normalises them (largest ``|L_i/u_i|`` 1)."""
    size = np.max(np.abs(loads / units), axis=1)
    return np.einsum("ij,ij->i", loads / size[:, None], twists)


def check(surface, units, loads, start, expected):
    safety, twists = surface._compiled.solve(loads, units, surface._scale, start)
    np.testing.assert_allclose(safety, expected, rtol=SAFETY_RTOL)
    np.testing.assert_allclose(unit_work(loads, units, twists), 1.0, rtol=SAFETY_RTOL)


@pytest.mark.parametrize("name", sorted(SURFACES))
def test_a_start_doing_little_work_for_its_size_gives_the_answer(name):
    # The answer plus a large twist that does no work on the load: the start does the answer's
    # positive work, 1e-7 of the largest product in L·S.
    surface = SURFACES[name]()
    units, loads, expected, answers = loads_and_answers(surface)
    rho = surface.characteristic_length
    rng = np.random.default_rng(3)
    idle = rng.normal(size=loads.shape) * [1.0, 1.0, 1.0 / rho]
    along = np.einsum("ij,ij->i", idle, loads) / np.einsum("ij,ij->i", loads, loads)
    idle -= along[:, None] * loads
    size = np.linalg.norm(answers * [1.0, 1.0, rho], axis=1, keepdims=True)
    idle *= 1e7 * size / np.linalg.norm(idle * [1.0, 1.0, rho], axis=1, keepdims=True)
    check(surface, units, loads, answers + idle, expected)


@pytest.mark.parametrize("name", sorted(SURFACES))
def test_the_answers_scaled_to_a_tiny_size_give_the_answer(name):
    # solve() takes starts of any size; 1e-320 makes the products of L·S subnormal.
    surface = SURFACES[name]()
    units, loads, expected, answers = loads_and_answers(surface)
    check(surface, units, loads, answers * 1e-320, expected)


@pytest.mark.parametrize("name", sorted(SURFACES))
def test_starts_that_are_not_finite_or_nearly_along_the_plane_are_not_used(name):
    # Such rows start from the ellipsoid's twist: the answer comes out the same.
    surface = SURFACES[name]()
    units, loads, expected, answers = loads_and_answers(surface)
    starts = answers.copy()
    starts[0::4, 0] = np.nan
    starts[1::4, 2] = np.inf
    starts[2::4, 1] = -np.inf
    # Row 3 of every 4: a twist doing no work on its load, plus a tiny share of the answer.
    idle = np.cross(loads, [0.3, -0.2, 1.0])
    starts[3::4] = idle[3::4] + 1e-9 * answers[3::4]
    check(surface, units, loads, starts, expected)


def test_a_start_of_the_wrong_shape_is_refused():
    surface = SURFACES["hertz disk"]()
    units, loads, _, answers = loads_and_answers(surface)
    with pytest.raises(InvalidArgumentError, match=r"start must have the shape of the loads"):
        surface._compiled.solve(loads, units, surface._scale, answers[:1])
