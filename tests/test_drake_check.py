"""Drake's hydroelastic fingertip against fixplan's exact limit surface of the engine's field.

A 10 mm compliant sphere (hydroelastic modulus 10 MPa) pressed with 10 N on a rigid plate,
``mu = 0.5``: the engine's pressure field is read, and loads are ramped along pure force, pure
spin and three mixed directions until the fingertip slides. Onset must be on the exact limit
surface of that field (2 %); the Table 2 ellipsoid is exact at pure force and pure spin and
visibly off in between (the parabolic disk's ellipsoid error peaks at about 6 %).
"""

import numpy as np
import pytest

from fixplan.errors import InvalidArgumentError
from fixplan.sim.drake_check import hydroelastic_check

RADIUS, MODULUS, MU, NORMAL_FORCE = 0.01, 1e7, 0.5, 10.0
#: Load directions (fx [N], fy [N], m [N m]); the engine's field has rho = m_max / f_max ≈ 1.8 mm,
#: so the mixed ones lie at about 40°, 59° and 31° from the force plane in normalised coordinates.
PURE = {"force": (1.0, 0.0, 0.0), "spin": (0.0, 0.0, 1.0)}
MIXED = {
    "x and ccw spin": (1.0, 0.0, 0.0015),
    "y and cw spin": (0.0, 1.0, -0.003),
    "diagonal and ccw spin": (-1.0, 1.0, 0.0015),
}
DIRECTIONS = {**PURE, **MIXED}
#: Slip onset within this of the exact limit surface of the engine's field (the issue's 2 %).
ONSET_RTOL = 0.02
#: The ellipsoid's error in the mixed directions exceeds this (theory: 4.1-6.0 % for this field).
ELLIPSOID_VISIBLE = 0.03
#: The engine's pressure lies within this of the least-squares paraboloid, over the peak (1.3 %
#: measured), and further than this from the least-squares Hertz profile (13 % measured).
PARABOLIC_DEVIATION, HERTZ_DEVIATION = 0.03, 0.10


@pytest.fixture(scope="module")
def check():
    return hydroelastic_check(
        radius=RADIUS,
        modulus=MODULUS,
        mu=MU,
        normal_force=NORMAL_FORCE,
        directions=list(DIRECTIONS.values()),
    )


def _result(check, name):
    return check.directions[list(DIRECTIONS).index(name)]


@pytest.mark.slow
@pytest.mark.parametrize("name", DIRECTIONS)
def test_slip_onset_lies_on_the_exact_limit_surface_of_the_engines_field(check, name):
    result = _result(check, name)
    assert result.onset is not None
    assert result.onset == pytest.approx(1.0, abs=ONSET_RTOL)
    onset_load = result.onset * result.exact_load
    assert check.limit_surface.safety_factor(onset_load) == pytest.approx(1.0, abs=ONSET_RTOL)


@pytest.mark.slow
@pytest.mark.parametrize("name", PURE)
def test_ellipsoid_is_exact_at_pure_force_and_pure_spin(check, name):
    assert abs(_result(check, name).ellipsoid_error) < ONSET_RTOL


@pytest.mark.slow
@pytest.mark.parametrize("name", MIXED)
def test_ellipsoid_overestimates_the_mixed_loads_visibly(check, name):
    result = _result(check, name)
    assert result.ellipsoid_error > ELLIPSOID_VISIBLE
    assert result.ellipsoid_error > 3.0 * abs(result.onset - 1.0)


@pytest.mark.slow
def test_engine_pressure_field_carries_the_normal_force(check):
    assert check.resultant == pytest.approx(NORMAL_FORCE, rel=1e-6)
    assert check.limit_surface.max_force == pytest.approx(MU * NORMAL_FORCE, rel=1e-9)
    assert np.allclose(check.field.center_of_pressure(), 0.0, atol=1e-6 * RADIUS)


@pytest.mark.slow
def test_engine_pressure_field_is_parabolic_not_hertzian(check):
    assert check.parabolic_deviation < PARABOLIC_DEVIATION
    assert check.hertz_deviation > HERTZ_DEVIATION
    # The paraboloid of the sphere's continuum field has radius sqrt(2 R delta); the mesh's
    # linear interpolation trims the rim.
    continuum = np.sqrt(2.0 * RADIUS * check.penetration)
    assert check.parabolic_radius == pytest.approx(continuum, rel=0.05)
    # Largest moment of a parabolic disk: (8/15) mu N a (DESIGN.md §4).
    ls = check.limit_surface
    fitted = ls.max_moment / (MU * NORMAL_FORCE * check.parabolic_radius)
    assert fitted == pytest.approx(8.0 / 15.0, rel=0.01)


@pytest.mark.parametrize(
    "arguments",
    [
        {"radius": 0.0},
        {"modulus": -1.0},
        {"mu": 0.0},
        {"directions": [(0.0, 0.0, 0.0)]},
        {"directions": [(1.0, 0.0)]},
    ],
)
def test_bad_arguments_are_rejected_before_drake_runs(arguments):
    options = {
        "radius": RADIUS,
        "modulus": MODULUS,
        "mu": MU,
        "normal_force": NORMAL_FORCE,
        "directions": [(1.0, 0.0, 0.0)],
    }
    with pytest.raises(InvalidArgumentError):
        hydroelastic_check(**{**options, **arguments})
