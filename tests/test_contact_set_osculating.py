"""Contact sets with exact contacts but no exact form (off the plane, or beside approximate
models): supports from the exact surfaces, safety factors through ellipsoids that osculate the
exact sets, against the exact form of the same contacts turned onto the plane and the laws of a
Minkowski sum (additive supports, normality of the motion)."""

import numpy as np
import pytest

from fixplan import Contact, ContactSetSurface, pressure
from fixplan.tolerances import STATED_SET_MARGIN

#: The rotation taking y to z (and z to -y): fingers along y become contacts from below and above.
TURN = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]])
FORCES = [10.0, 14.0]


#: The fingers' patches: smooth (a disk and an off-centre rectangle), or point supports.
PATCHES = {
    "patches": (pressure.disk(0.01), pressure.rectangle(0.02, 0.008).shifted(0.003, 0.0)),
    "point supports": (
        pressure.points([[0.0, 0.0], [0.01, 0.004], [-0.004, 0.008]], [1.0, 2.0, 1.0]),
        pressure.points([[0.003, 0.0], [0.015, -0.002]], centered=False),
    ),
}


def fingers(turned: bool, patches: str = "patches") -> list[Contact]:
    """Two exact fingers squeezing along y (their x axes tilted), or the same turned so that
    they squeeze along z."""
    contacts = []
    for name, side, patch in zip(("left", "right"), (-1, 1), PATCHES[patches], strict=True):
        position = np.array([0.01, side * 0.02, 0.005])
        normal, axis = np.array([0.0, -side, 0.0]), np.array([1.0, 0.0, 0.3])
        if turned:
            position, normal, axis = TURN @ position, TURN @ normal, TURN @ axis
        contacts.append(Contact(name=name, role="finger", position=position, normal=normal,
                                mu=0.5, model="exact", patch=patch, axis=axis))  # fmt: skip
    return contacts


@pytest.mark.parametrize("patches", PATCHES)
def test_exact_fingers_off_the_plane_are_held_to_their_exact_sets(patches):
    """In the subspace (fx, fz, my) the fingers' set is that of the turned fingers in (fx, fy,
    mz) with fy = -fz: an exact LimitSurface. Patches: their loads are held inside their exact
    sets to 1e-9 by osculating ellipsoids; point supports: stated exactly, a cone per point,
    shrunk by 1e-8. Safety factors are within 2e-9 of the exact form for patches (seen: 5.4e-10
    on 40 random loads) and 1e-8 to 1.2e-8 below it for point supports (on those and 20 next to
    their facets, where their seed polytopes were up to 33 % above it), the motions, the
    program's multipliers, within 2e-5 in normalised coordinates ``(v, rho w)`` (patches 4.7e-6
    at most, median 7.6e-7; point supports 2.2e-5 at most, next to a facet, median 2.5e-6);
    supports are the surfaces' sums."""
    across = ContactSetSurface(fingers(False, patches), FORCES, ("fx", "fz", "my"))
    flat = ContactSetSurface(fingers(True, patches), FORCES, ("fx", "fy", "mz"))
    assert across.as_limit_surface() is None and flat.as_limit_surface() is not None
    flip = np.array([1.0, -1.0, 1.0])
    normalised = np.array([1.0, 1.0, flat.as_limit_surface().characteristic_length])

    def unit(twist):
        return twist * normalised / np.linalg.norm(twist * normalised)

    rng = np.random.default_rng(0)
    for load in rng.normal(size=(15, 3)) * [12.0, 12.0, 0.16]:
        motion, safety = across.motion_and_safety_factor(load)
        expected_motion, expected = flat.motion_and_safety_factor(load * flip)
        shrunk = 0.0 if patches == "patches" else STATED_SET_MARGIN
        assert safety == pytest.approx(expected * (1.0 - shrunk), rel=2e-9)
        np.testing.assert_allclose(unit(motion * flip), unit(expected_motion), rtol=0, atol=2e-5)
    for twist in rng.normal(size=(10, 3)):
        assert across.support(twist) == pytest.approx(flat.support(twist * flip), rel=1e-14)
        np.testing.assert_allclose(across.load(twist) * flip, flat.load(twist * flip),
                                   rtol=1e-13, atol=1e-15)  # fmt: skip


def test_exact_contacts_beside_a_cone_obey_the_laws_of_a_minkowski_sum():
    """An exact clamp from above, a cone-model pad and a pin: the support of the set is the sum
    of each contact's alone, and at a safety factor's load ``s d`` its motion ``V`` is the
    normal there: ``h(V) = s d·V`` (to 1e-7, the solver's accuracy)."""
    contacts = [
        Contact(name="clamp", role="clamp", position=[0.0, 0.01, 0.02], normal=[0, 0, -1],
                mu=0.4, model="exact", patch=pressure.rectangle(0.03, 0.01).shifted(0.004, 0)),
        Contact(name="pad", role="support", position=[0.02, -0.01, 0.0], normal=[0, 0, 1],
                mu=0.5, model="cone", patch=pressure.disk(0.012)),
        Contact(name="pin", role="support", position=[-0.03, 0.0, 0.0], normal=[0, 0, 1],
                mu=0.3, model="point-cone"),
    ]  # fmt: skip
    forces = [6.0, 9.0, 3.0]
    both = ContactSetSurface(contacts, forces)
    assert both.as_limit_surface() is None
    alone = [ContactSetSurface([c], [f]) for c, f in zip(contacts, forces, strict=True)]
    rng = np.random.default_rng(1)
    for twist in rng.normal(size=(8, 3)) * [1.0, 1.0, 30.0]:
        parts = sum(surface.support(twist) for surface in alone)
        assert both.support(twist) == pytest.approx(parts, rel=1e-8)
    for load in rng.normal(size=(8, 3)) * both._units:
        motion, safety = both.motion_and_safety_factor(load)
        assert both.support(motion) == pytest.approx(safety * load @ motion, rel=1e-7)


def test_a_set_whose_friction_does_not_span_the_subspace_has_safety_factors_of_zero_not_below():
    """One point contact whose friction has no part in the subspace: every load has the safety
    factor 0, which the interior point returns as rounding of either sign (down to -1.1e-24 on
    2 of these 20 loads; 53 of 400 fuzzed sets gave such negatives); the support is never below
    0 either."""
    contact = Contact(name="pin", role="support", position=[0.01, 0.02, 0.0], normal=[0, 0, 1],
                      mu=0.5, model="point-cone")  # fmt: skip
    surface = ContactSetSurface([contact], [10.0], ("fz", "mx", "my"))
    rng = np.random.default_rng(2)
    for load in rng.normal(size=(20, 3)):
        assert 0.0 <= surface.safety_factor(load) < 1e-12
        assert surface.support(load) >= 0.0
