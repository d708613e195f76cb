"""Hertzian contact stiffness against force laws and compliances written here from the elastic
half-space (Boussinesq, Cerruti), independently of fixplan.motion.hertz."""

import math

import pytest
from scipy import integrate

from fixplan.motion import compliance, hertz_cylinder, hertz_sphere
from fixplan.motion.compliance import ComplianceError

#: (Young's modulus [Pa], Poisson ratio) of a few materials.
STEEL = (2.1e11, 0.29)
ALUMINIUM = (7.0e10, 0.33)
NYLON = (3.0e9, 0.40)
PAIRS = {"steel-steel": (STEEL, STEEL), "steel-aluminium": (STEEL, ALUMINIUM)}
PAIRS["nylon-steel"] = (NYLON, STEEL)

#: Closed forms evaluated here agree with the code to this relative error (rounding only).
EXACT = 1e-12
#: A central difference of a smooth law with a relative step of 1e-5 is this accurate.
SLOPE_RTOL = 1e-8


def _shear(young, poisson):
    return young / (2 * (1 + poisson))


def _contact_modulus(pair):
    return 1 / sum((1 - nu**2) / e for e, nu in pair)


def _arguments(pair):
    (e1, nu1), (e2, nu2) = pair
    return {"young": e1, "poisson": nu1, "young_flat": e2, "poisson_flat": nu2}


def _sphere(pair, radius=0.004, preload=30.0):
    return hertz_sphere(radius=radius, preload=preload, **_arguments(pair))


def _cylinder(pair, radius=0.005, length=0.02, preload=10.0):
    return hertz_cylinder(radius=radius, length=length, preload=preload, **_arguments(pair))


def _central_slope(law, x, step):
    return (law(x + step) - law(x - step)) / (2 * step)


# --- sphere ----------------------------------------------------------------------------------


@pytest.mark.parametrize("pair", PAIRS.values(), ids=PAIRS)
def test_sphere_normal_stiffness_is_the_slope_of_hertz_law(pair):
    radius, preload = 0.004, 30.0
    e_star = _contact_modulus(pair)
    law = lambda d: 4 / 3 * e_star * math.sqrt(radius) * d**1.5  # noqa: E731
    approach = (3 * preload / (4 * e_star * math.sqrt(radius))) ** (2 / 3)
    assert law(approach) == pytest.approx(preload, rel=EXACT)
    slope = _central_slope(law, approach, 1e-5 * approach)
    assert _sphere(pair, radius, preload).normal == pytest.approx(slope, rel=SLOPE_RTOL)


def test_sphere_of_like_materials_has_mindlins_ratio_of_tangential_to_normal_stiffness():
    # k_t / k_n = 8 G* / (2 E*) = 2 (1 - nu) / (2 - nu) for like materials (Mindlin 1949).
    nu = STEEL[1]
    stiffness = _sphere((STEEL, STEEL))
    assert stiffness.tangential / stiffness.normal == pytest.approx(2 * (1 - nu) / (2 - nu))


def _cerruti_centre_shift(shear, nu, radius):
    """Shift of the centre of a half-space's surface under Mindlin's unit tangential traction
    ``q = 1 / (2 π a √(a² - r²))``, from Cerruti's point force
    ``u_x = ((1 - ν)/ρ + ν x²/ρ³) / (2 π G)`` summed in polar coordinates about the centre."""
    angular = integrate.quad(lambda phi: (1 - nu) + nu * math.cos(phi) ** 2, 0, 2 * math.pi)[0]
    radial = integrate.quad(
        lambda r: 1 / (2 * math.pi * radius * math.sqrt(radius + r)),
        0,
        radius,
        weight="alg",
        wvar=(0, -0.5),
    )[0]
    return angular * radial / (2 * math.pi * shear)


def _cerruti_centre_rotation(shear, radius):
    """Rotation of the centre of a half-space's surface under Lubkin's unit twisting traction
    ``τ = 3 r / (4 π a³ √(a² - r²))``: the curl of Cerruti's field of a point force ``F`` at
    ``p`` is ``F × (-p) / (2 π G |p|³)``, so the rotation is ``∫ τ / r dr / (2 G)``."""
    integral = integrate.quad(
        lambda r: 3 / (4 * math.pi * radius**3 * math.sqrt(radius + r)),
        0,
        radius,
        weight="alg",
        wvar=(0, -0.5),
    )[0]
    return integral / (2 * shear)


@pytest.mark.parametrize("pair", PAIRS.values(), ids=PAIRS)
def test_sphere_tangential_and_torsional_stiffness_add_each_bodys_cerruti_compliance(pair):
    radius, preload = 0.004, 30.0
    a = (3 * preload * radius / (4 * _contact_modulus(pair))) ** (1 / 3)
    shift = [_cerruti_centre_shift(_shear(e, nu), nu, a) for e, nu in pair]
    twist = [_cerruti_centre_rotation(_shear(e, nu), a) for e, nu in pair]
    # The quadratures reproduce Mindlin's (2 - ν) / (8 G a) and Lubkin's 3 / (16 G a³).
    for (e, nu), s, t in zip(pair, shift, twist, strict=True):
        assert s == pytest.approx((2 - nu) / (8 * _shear(e, nu) * a), rel=1e-10)
        assert t == pytest.approx(3 / (16 * _shear(e, nu) * a**3), rel=1e-10)
    stiffness = _sphere(pair, radius, preload)
    assert stiffness.tangential == pytest.approx(1 / sum(shift), rel=1e-10)
    assert stiffness.torsional == pytest.approx(1 / sum(twist), rel=1e-10)


def test_sphere_stiffness_scales_with_the_contact_radius():
    # a ∝ F^{1/3}: eight times the preload doubles a, so k_n, k_t ∝ a double and k_r ∝ a³
    # grows eightfold.
    low, high = (
        _sphere(PAIRS["steel-aluminium"], preload=5.0),
        _sphere(PAIRS["steel-aluminium"], preload=40.0),
    )
    assert high.normal / low.normal == pytest.approx(2.0, rel=EXACT)
    assert high.tangential / low.tangential == pytest.approx(2.0, rel=EXACT)
    assert high.torsional / low.torsional == pytest.approx(8.0, rel=EXACT)
    # ... and twice the radius at the same preload gives a factor 2^{1/3} on a.
    bigger = _sphere(PAIRS["steel-aluminium"], radius=0.008, preload=5.0)
    assert bigger.torsional / low.torsional == pytest.approx(2.0, rel=EXACT)
    assert bigger.normal / low.normal == pytest.approx(2 ** (1 / 3), rel=EXACT)


# --- cylinder --------------------------------------------------------------------------------


def _half_width(pair, radius, length, preload):
    return math.sqrt(4 * preload * radius / (math.pi * length * _contact_modulus(pair)))


def _boussinesq_middle_sink(young, nu, length, half_width, preload):
    """Sink of the middle of a half-space's strip loaded uniformly along ``length`` and
    semi-elliptically across ``2 half_width``, from Boussinesq's ``w = (1 - ν²) P / (π E ρ)``:
    the line load ``p dx`` along the strip gives ``2 asinh(L / (2|x|)) (1 - ν²) p / (π E)``."""
    peak = 2 * preload / (math.pi * half_width * length)

    def line(x):
        return peak * math.sqrt(1 - (x / half_width) ** 2) * 2 * math.asinh(length / (2 * x))

    total = 2 * integrate.quad(line, 0, half_width, limit=200, epsabs=0, epsrel=1e-13)[0]
    return (1 - nu**2) / (math.pi * young) * total


@pytest.mark.parametrize("pair", PAIRS.values(), ids=PAIRS)
def test_cylinder_normal_stiffness_is_the_slope_of_the_approach_of_two_half_spaces(pair):
    radius, length, preload = 0.005, 0.02, 10.0

    def approach(force):
        b = _half_width(pair, radius, length, force)
        return sum(_boussinesq_middle_sink(e, nu, length, b, force) for e, nu in pair)

    # The law is Lundberg's; his constant 1.8864 is ln 4 + 1/2 = 1.88629 rounded (1e-5 here).
    b = _half_width(pair, radius, length, preload)
    e_star = _contact_modulus(pair)
    lundberg = 2 * preload / (math.pi * length * e_star) * (math.log(length / (2 * b)) + 1.8864)
    assert approach(preload) == pytest.approx(lundberg, rel=2e-5)
    # The stiffness is its slope, to the leading order in b / L of the code: the neglected
    # asinh(y) - ln(2y) ~ (b / L)² ≈ 3e-6 against logarithms of about 7.
    assert b / length < 2e-3
    slope = 1 / _central_slope(approach, preload, 1e-4 * preload)
    assert _cylinder(pair, radius, length, preload).normal == pytest.approx(slope, rel=1e-6)


def test_the_width_average_of_a_log_over_a_bonded_strip_is_the_log_of_half_its_half_width():
    """The weight ``1 / (π √(b² - x²))`` of the bonded strip, twice over: the mean of
    ``ln|x - x'|`` is ``ln(b/2)``, so a field ``α + β ln|x - x'|`` (the strip's far field) has
    the mean it takes at ``|x - x'| = b/2``. Computed with ``x = b cos θ``."""
    b = 3e-5
    mean = integrate.dblquad(
        lambda phi, theta: math.log(b * abs(math.cos(theta) - math.cos(phi)) + 1e-300),
        0,
        math.pi,
        0,
        lambda theta: theta,
        epsabs=0,
        epsrel=1e-10,
    )[0]
    assert 2 * mean / math.pi**2 == pytest.approx(math.log(b / 2), rel=1e-8)


def _ritz_compliance(shear, nu, length, offset, mode):
    """Complementary energy ``∫ t·u / Q²`` of a half-space (Cerruti) under a traction along a
    line of ``length``, uniform (``across``/``along`` the line) or linear in the position along
    it (``twist``, per unit moment), seen at a lateral ``offset``."""

    def pairs(u):
        # ∫∫ ds ds' (or ∫∫ s s' ds ds' for the twist) over the points of the line at s - s' = u.
        if mode == "twist":
            return (length - u) ** 3 / 6 - u * u * (length - u) / 2
        return 2 * (length - u)

    def cerruti(u):
        # (1 - ν)/ρ + ν c²/ρ³, c the separation along the force: along the line or across it.
        rho = math.hypot(offset, u)
        return ((1 - nu) + nu * (u if mode == "along" else offset) ** 2 / rho**2) / rho

    energy = integrate.quad(
        lambda u: pairs(u) * cerruti(u),
        0,
        length,
        points=[10 * offset],
        limit=400,
        epsabs=0,
        epsrel=1e-12,
    )[0]
    resultant = length**3 / 12 if mode == "twist" else length
    return energy / (2 * math.pi * shear) / resultant**2


@pytest.mark.parametrize("pair", PAIRS.values(), ids=PAIRS)
def test_cylinder_tangential_and_torsional_stiffness_are_the_ritz_bounds_of_two_half_spaces(pair):
    radius, length, preload = 0.005, 0.02, 10.0
    b = _half_width(pair, radius, length, preload)
    assert b / length < 2e-3

    def compliance_of(mode):
        return sum(_ritz_compliance(_shear(e, nu), nu, length, b / 2, mode) for e, nu in pair)

    stiffness = _cylinder(pair, radius, length, preload)
    # The code keeps the leading order in b / L: the terms it neglects are O(b / L).
    tangential = 1 / max(compliance_of("across"), compliance_of("along"))
    assert stiffness.tangential == pytest.approx(tangential, rel=b / length)
    assert stiffness.torsional == pytest.approx(1 / compliance_of("twist"), rel=b / length)
    # Along the axis is the softer direction for positive Poisson ratios.
    assert compliance_of("along") > compliance_of("across")


def test_cylinder_ritz_bounds_converge_to_the_closed_forms_as_the_strip_narrows():
    pair = PAIRS["steel-aluminium"]
    length, preload = 0.02, 10.0
    errors = []
    for radius in (5e-3, 5e-5, 5e-7):  # b ∝ √R: b / L from 1e-3 to 1e-5
        b = _half_width(pair, radius, length, preload)
        twist = sum(_ritz_compliance(_shear(e, nu), nu, length, b / 2, "twist") for e, nu in pair)
        errors.append(abs(_cylinder(pair, radius, length, preload).torsional * twist - 1))
    assert errors[2] < 1e-5
    assert errors[0] > errors[1] > errors[2]


# --- both ------------------------------------------------------------------------------------


@pytest.mark.parametrize("shape", [_sphere, _cylinder], ids=["sphere", "cylinder"])
@pytest.mark.parametrize("pair", [PAIRS["steel-aluminium"], PAIRS["nylon-steel"]])
def test_swapping_the_materials_leaves_the_stiffness_unchanged(shape, pair):
    # Both bodies are half-spaces near the contact, so only the sum of their compliances counts.
    one, other = shape(pair), shape(pair[::-1])
    for name in ("normal", "tangential", "torsional"):
        assert getattr(one, name) == pytest.approx(getattr(other, name), rel=EXACT)


GOOD = {
    "radius": 0.005,
    "length": 0.02,
    "preload": 50.0,
    "young": 2.1e11,
    "poisson": 0.3,
    "young_flat": 7e10,
    "poisson_flat": 0.33,
}
BAD = [
    ("radius", 0.0),
    ("radius", -1e-3),
    ("length", 0.0),
    ("length", -0.02),
    ("preload", 0.0),
    ("preload", -5.0),
    ("preload", math.nan),
    ("young", 0.0),
    ("young", -2e11),
    ("young", math.inf),
    ("young_flat", 0.0),
    ("young", "steel"),
    ("poisson", 0.5),
    ("poisson", -1.0),
    ("poisson", 0.7),
    ("poisson", math.nan),
    ("poisson_flat", 0.5),
    ("poisson_flat", -1.2),
]


BAD_CASES = [
    pytest.param(shape, name, value, id=f"{shape.__name__}-{name}={value!r}")
    for shape in (hertz_sphere, hertz_cylinder)
    for name, value in BAD
    if shape is hertz_cylinder or name != "length"
]


@pytest.mark.parametrize(("shape", "name", "value"), BAD_CASES)
def test_bad_input_is_an_error_naming_the_argument(shape, name, value):
    arguments = {k: v for k, v in GOOD.items() if shape is hertz_cylinder or k != "length"}
    arguments[name] = value
    with pytest.raises(ComplianceError, match=rf"^{name} must"):
        shape(**arguments)


def test_a_preload_that_spreads_the_strip_wider_than_a_tenth_of_its_length_is_an_error():
    # b = √(4 F R / (π L E*)) > L / 10 when F > π L³ E* / (400 R).
    arguments = dict(GOOD, length=1e-3, young=3e9, poisson=0.4, young_flat=3e9, poisson_flat=0.4)
    e_star = 3e9 / (2 * (1 - 0.4**2))
    limit = math.pi * 1e-3**3 * e_star / (400 * GOOD["radius"])
    hertz_cylinder(**dict(arguments, preload=0.99 * limit))
    with pytest.raises(ComplianceError, match=r"preload .* not a line contact"):
        hertz_cylinder(**dict(arguments, preload=1.01 * limit))


def test_hertz_shapes_live_in_their_own_module():
    assert not hasattr(compliance, "hertz_sphere")
    assert hertz_sphere.__module__ == hertz_cylinder.__module__ == "fixplan.motion.hertz"
