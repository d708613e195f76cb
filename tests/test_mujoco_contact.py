"""MuJoCo contact parameters of planner contacts against Table 1's closed forms."""

import math

import pytest

from fixplan import Contact, pressure
from fixplan.sim import mujoco_contact

MU, RADIUS = 0.8, 0.006


def _contact(patch=None, model="ellipsoid", mu=MU):
    return Contact(name="tip", role="finger", position=[0, 0, 0], normal=[0, 0, 1], mu=mu,
                   model=model, patch=patch)  # fmt: skip


@pytest.mark.parametrize(
    ("profile", "factor"),
    [("uniform", 2.0 / 3.0), ("hertz", 3.0 * math.pi / 16.0)],
)
def test_the_torsional_coefficient_of_a_disk_is_its_table_1_moment(profile, factor):
    parameters = mujoco_contact(_contact(pressure.disk(RADIUS, profile)))
    assert parameters.condim == 4
    assert parameters.torsion == pytest.approx(factor * MU * RADIUS, rel=1e-9)
    assert parameters.friction == (MU, MU, parameters.torsion, 0.0, 0.0)
    assert parameters.attributes()["condim"] == "4"
    # MuJoCo's cone is the Table 2 ellipsoid: 6.4-7 % over the exact disk surface, never under.
    assert 0.05 < parameters.error.max_overestimate < 0.08
    assert parameters.error.max_underestimate < 1e-6


def test_point_and_frictionless_contacts():
    point = mujoco_contact(_contact(model="point-cone"))
    assert (point.condim, point.torsion) == (3, 0.0)
    assert mujoco_contact(_contact(model="point-pyramid")).lost
    assert mujoco_contact(_contact(model="point-cone", mu=0.0)).condim == 1


def test_an_asymmetric_patch_says_what_the_cone_loses():
    points = pressure.points(
        [[0.0, 0.0], [0.02, 0.0], [0.0, 0.01]], [1.0, 2.0, 3.0], centered=False
    )
    parameters = mujoco_contact(_contact(points))
    assert any("tilt" in note for note in parameters.lost)
    assert any("facets" in note for note in parameters.lost)
    assert parameters.center == pytest.approx((0.02 * 2 / 6, 0.01 * 3 / 6), abs=1e-12)
