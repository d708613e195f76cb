"""The impending motions kept in contact (``StayingInContact``) against a plain numpy
reference: per load case, the orthogonal projection onto the twists that move no pressed decided
contact along its normal, kept where it keeps half the twist's norm, signed towards the load."""

import numpy as np
import pytest

from fixplan.planner.analysis import StayingInContact
from fixplan.tolerances import FRICTION_SET_RTOL

LENGTH_SCALE = 0.05
#: Both compute the same projections (one SVD each); the products differ in rounding only.
RTOL = 1e-12


def reference(normal_map, decided, twists, normal_forces, towards):
    """One load case at a time, as the rule states it."""
    out = np.array(twists, dtype=float)
    for j in range(twists.shape[1]):
        size = max(np.abs(normal_forces[:, j]).max(), 1e-300)
        pressed = decided & (normal_forces[:, j] > FRICTION_SET_RTOL * size)
        if pressed.any():
            _, singular, basis = np.linalg.svd(normal_map[:, pressed].T)
            free = basis[int(np.sum(singular > 1e-9 * LENGTH_SCALE)) :]
            projected = free.T @ (free @ twists[:, j])
            if projected @ projected >= 0.25 * (twists[:, j] @ twists[:, j]):
                out[:, j] = projected
        if towards[:, j] @ out[:, j] < 0.0:
            out[:, j] = -out[:, j]
    return out


def contacts(count, rng):
    """The wrench ``(6, count)`` of a unit normal force at random points with random normals."""
    points = rng.uniform(-LENGTH_SCALE, LENGTH_SCALE, (count, 3))
    normals = rng.normal(size=(count, 3))
    normals /= np.linalg.norm(normals, axis=1, keepdims=True)
    return np.vstack([normals.T, np.cross(points, normals).T])


@pytest.mark.parametrize("count", [5, 8, 70, 130])  # (70 and 130: keys of 2 and 3 words)
def test_the_kept_motions_are_the_reference_projections(count):
    rng = np.random.default_rng(count)
    normal_map = contacts(count, rng)
    decided = rng.random(count) < 0.6
    cases = 40
    # Pressed sets that repeat among the cases (kept projections), with noise-level forces
    # that count as not pressed, and a case whose twist is zero.
    patterns = rng.random((4, count)) < 0.3
    normal_forces = rng.uniform(1.0, 50.0, (count, cases))
    normal_forces[patterns[rng.integers(0, 4, cases)].T] = 1e-9
    twists = rng.normal(size=(6, cases))
    twists[:, 3] = 0.0
    towards = rng.normal(size=(6, cases))
    staying = StayingInContact(normal_map, decided, LENGTH_SCALE)
    expected = reference(normal_map, decided, twists, normal_forces, towards)
    for _ in range(2):  # the second time from the kept projections
        found, moving = staying(twists, normal_forces, towards)
        np.testing.assert_allclose(found, expected, rtol=RTOL, atol=RTOL * np.abs(twists).max())
    assert not found[:, 3].any()
    assert moving == found.any(axis=0).tolist()
    # Other pressed sets right after (the groups of the last call are not reused).
    shuffled = normal_forces[:, ::-1].copy()
    found, _ = staying(twists, shuffled, towards)
    expected = reference(normal_map, decided, twists, shuffled, towards)
    np.testing.assert_allclose(found, expected, rtol=RTOL, atol=RTOL * np.abs(twists).max())
    # Fewer cases, the first of which pressed as in the last call.
    found, _ = staying(twists[:, :3], shuffled[:, :3], towards[:, :3])
    np.testing.assert_allclose(found, expected[:, :3], rtol=RTOL, atol=RTOL * np.abs(twists).max())


def test_a_twist_the_pressed_contacts_forbid_is_kept_as_it_is():
    """Three supports under a plate leave no sliding motion that keeps them all pressed and
    rotates the plate about a horizontal axis: the projection would remove most of such a
    twist, so the dual twist itself (which lifts the plate off) is kept."""
    normal_map = contacts(3, np.random.default_rng(0))
    normal_map[:3] = [[0.0] * 3, [0.0] * 3, [1.0] * 3]  # all normals along +z
    normal_map[3:] = np.cross(np.array([[0.03, 0, 0], [-0.03, 0.02, 0], [-0.03, -0.02, 0]]),
                              [0.0, 0.0, 1.0]).T  # fmt: skip
    lift = np.array([[0.0, 0.0, 1.0, 0.0, 0.0, 0.0]]).T
    staying = StayingInContact(normal_map, np.ones(3, dtype=bool), LENGTH_SCALE)
    found, moving = staying(lift, np.full((3, 1), 10.0), lift)
    np.testing.assert_array_equal(found, lift)
    assert moving == [True]


def test_pressed_sets_that_differ_beyond_the_first_64_contacts_are_told_apart():
    """Contact 1 pressed in one case, contact 65 in the other (the same bit of different words
    of the key): each twist loses the normal velocity of its own pressed contact only."""
    rng = np.random.default_rng(7)
    normal_map = contacts(70, rng)
    decided = np.zeros(70, dtype=bool)
    decided[[1, 65]] = True
    normal_forces = np.zeros((70, 2))
    normal_forces[1, 0] = normal_forces[65, 1] = 10.0
    twist = rng.normal(size=6)
    twists = np.column_stack([twist, twist])
    found, _ = StayingInContact(normal_map, decided, LENGTH_SCALE)(twists, normal_forces, twists)
    np.testing.assert_allclose(
        found, reference(normal_map, decided, twists, normal_forces, twists), rtol=RTOL, atol=RTOL
    )
    assert abs(normal_map[:, 1] @ found[:, 0]) <= RTOL
    assert abs(normal_map[:, 65] @ found[:, 1]) <= RTOL
    assert abs(normal_map[:, 65] @ found[:, 0]) > 1e-3
