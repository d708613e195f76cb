"""Flat pushers on paths a fuzzer found: the face never passes through the part, poses stay
finite, and what the face contact does not model is refused with a clear error.

Before: a part turning off an end of a narrow face froze where the face went on pushing (28.6 mm
into a box, the modes still "sliding"); the put-back onto the face moved the part by an infinite
gap once it left the strip (a final pose of inf, then an argmin of an empty sequence); a tiny
or huge ``normal`` was normalised into NaN or zero; a frictionless face's sliding translation
was bracketed on the wrong side (brentq's "f(a) and f(b) must have different signs"); and an
arm of a star reaching around the face to its back cycled as "more than 8 new contacts".
"""

import numpy as np
import pytest

from fixplan import LimitSurface, pressure
from fixplan.errors import GeometryError
from fixplan.motion import LinePusher, Outline, push
from fixplan.motion.trajectory import TOUCH_RTOL, _FaceContact

BOX = Outline.rectangle(0.09, 0.06)
BOX_SUPPORT = LimitSurface(pressure.rectangle(0.09, 0.06), mu=0.3, normal_force=0.5 * 9.81)
TRIANGLE = Outline.polygon([[0.0, 0.0], [0.05, 0.0], [0.09124016433245524, 0.0438011273485791]])
TRIANGLE_SUPPORT = LimitSurface(
    pressure.polygon(TRIANGLE.vertices, centered=False), mu=0.3, normal_force=0.5 * 9.81
)


def _deepest_overlap(trajectory, surface, shape, pusher) -> float:
    """The largest overlap [m] of the face with the part over the trajectory's poses."""
    contact = _FaceContact(surface, shape, pusher)
    gaps = [contact.gap(pose, t) for pose, t in zip(trajectory.poses, trajectory.t, strict=True)]
    return -min(gaps)


def test_a_part_turning_off_an_end_of_a_narrow_face_is_not_passed_through():
    face = LinePusher(([-0.06384361848258173, 0.05962222460717062],
                       [0.018469245192836402, 0.00767378537665014]), mu=0.25, width=0.06)  # fmt: skip
    pushed = push(BOX_SUPPORT, face, shape=BOX, pose=(0.0, 0.0, -1.4566943093917728),
                  duration=4.0, steps=400)  # fmt: skip
    assert _deepest_overlap(pushed, BOX_SUPPORT, BOX, face) < TOUCH_RTOL * 0.045
    moved = np.linalg.norm(np.diff(pushed.poses, axis=0), axis=1)
    pressing = np.array([mode != "separated" for mode in pushed.modes])
    assert np.all(moved[pressing] > 0.0)  # (no step that presses leaves the part where it is)


@pytest.mark.parametrize("steps", [1, 50, 200])
def test_coarse_steps_of_a_wide_face_keep_the_part_finite_and_in_front_of_it(steps):
    face = LinePusher(([-0.008143689000777974, -0.07958442265581003],
                       [0.01222590717978094, 0.015828050847510596]), mu=100.0, width=0.15)  # fmt: skip
    pushed = push(TRIANGLE_SUPPORT, face, shape=TRIANGLE, pose=(0.0, 0.0, np.pi / 4),
                  duration=25.0, steps=steps)  # fmt: skip
    assert np.all(np.isfinite(pushed.poses))
    assert _deepest_overlap(pushed, TRIANGLE_SUPPORT, TRIANGLE, face) < TOUCH_RTOL * 0.1


def test_a_face_leaving_a_disk_within_its_one_step_keeps_the_pose_finite():
    disk = Outline.disk(0.05)
    support = LimitSurface(pressure.disk(0.025, "hertz"), mu=0.3, normal_force=0.5 * 9.81)
    face = LinePusher(([0.055, 0.0008], [-0.019, -0.005]), mu=0.55, width=0.025)
    for steps in (1, 2):
        pushed = push(support, face, shape=disk, duration=25.0, steps=steps)
        assert np.all(np.isfinite(pushed.poses))


@pytest.mark.parametrize("normal", [[1e-300, 0.0], [1e-170, 0.0], [1e300, 0.0]])
def test_a_tiny_or_huge_face_normal_is_normalised(normal):
    face = LinePusher(([-0.07, 0.0], [0.02, 0.0]), mu=0.25, width=0.15, normal=normal)
    np.testing.assert_array_equal(face.normal, [1.0, 0.0])
    pushed = push(BOX_SUPPORT, face, shape=BOX, duration=4.0, steps=40)
    np.testing.assert_allclose(pushed.poses[-1], [0.055, 0.0, 0.0], atol=1e-12)
    diagonal = LinePusher(([-0.07, 0.0], [0.02, 0.0]), mu=0.25, width=0.15,
                          normal=[normal[0], normal[0]])  # fmt: skip
    np.testing.assert_allclose(diagonal.normal, [2**-0.5, 2**-0.5], rtol=1e-15)


def test_a_frictionless_face_on_a_grippy_support_finds_its_sliding_translation():
    outline = Outline.polygon([
        [0.027247772738968973, 0.0], [0.03475172663624131, 0.022333578598333563],
        [0.012946578420675302, 0.02834905237707224], [-0.0059986059511890335, 0.041721220808189304],
        [-0.03129231423664424, 0.036113255748938394], [-0.03470375610435396, 0.010189942196709888],
        [-0.02199061850774019, -0.006457028189973284], [-0.01845501754909827, -0.021298225614175718],
        [-0.005525346918400047, -0.038429631934520085], [0.018011782196223684, -0.03944030154482538],
        [0.038232045033520616, -0.02457024342038599],
    ])  # fmt: skip
    support = LimitSurface(pressure.disk(0.025), mu=100.0, normal_force=1.0)
    face = LinePusher(([0.12295777565706502, 0.08591498941085236],
                       [-0.012981358177219798, -0.015214609422352213]), mu=0.0, width=0.15)  # fmt: skip
    pushed = push(support, face, shape=outline, pose=(0.0026262559425038415, 0.0, -3.340017597545395),
                  duration=7.5, steps=10, start_overlap=0.5)  # fmt: skip
    assert np.all(np.isfinite(pushed.poses)) and set(pushed.modes) != {"separated"}


def test_a_part_reaching_around_the_face_to_its_back_is_refused():
    star = Outline.polygon([
        [0.054654949206503343, 0.0], [0.037166508817537754, 0.021458093870644016],
        [0.03816744588885222, 0.04012719336109476], [0.015000000000000001, 0.026667540060371593],
        [-0.012768424932553467, 0.02211556071581183], [-0.02766951283623812, 0.024635254722192267],
        [-0.03162292603395811, 3.8726915147160304e-18], [-0.022688349715772996, -0.0130991248158699],
        [-0.021217983909738492, -0.03675062616584596], [-5.061955923791802e-18, -0.0275560045955897],
        [0.020735531770313415, -0.035914994548141455], [0.02265809133026044, -0.013081655128849005],
    ])  # fmt: skip
    support = LimitSurface(pressure.disk(0.025), mu=0.3, normal_force=0.5 * 9.81)
    face = LinePusher(([-0.10152430247770623, -0.07292335707038736],
                       [0.014462441132717474, 0.013814405397362629]), mu=1.0, width=0.025)  # fmt: skip
    with pytest.raises(GeometryError, match="reaches around an end of the LinePusher"):
        push(support, face, shape=star, pose=(-0.031861612597644355, 0.0, np.pi / 2),
             duration=250.0, steps=400, start_overlap=0.025)  # fmt: skip
