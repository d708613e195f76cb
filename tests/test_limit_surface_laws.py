"""Laws every limit surface obeys, checked on every kind of field (the catalogue of conftest.py).

Convexity (the support function is sublinear and every load lies under every support plane),
central symmetry, positive homogeneity, L = ∇h with L·V = h (paper eqs. 4-5), linear scaling with
mu and the normal force, pure translation (paper eq. 8), the maximum moment with the centre of
rotation at the moment's reference point (at the centre of pressure for centred fields, paper
§2.3), invariance under moving the field, and Table 1 of the paper.
"""

import math

import numpy as np
import pytest
import reference as ref
from conftest import normalised, random_twists
from hypothesis import given, settings
from hypothesis import strategies as st

from fixplan import LimitSurface, pressure

#: Relative slack of the inequalities and identities below (rounding only).
LAW_RTOL = 1e-10

#: Deterministic examples, no example database (the suite must not depend on earlier runs).
LAW_SETTINGS = settings(max_examples=25, deadline=None, derandomize=True, database=None)

_component = st.floats(-1.0, 1.0, allow_nan=False, allow_infinity=False)
#: Twists in normalised coordinates (vx, vy, rho * w), away from zero.
directions = st.tuples(_component, _component, _component).filter(
    lambda v: math.sqrt(v[0] ** 2 + v[1] ** 2 + v[2] ** 2) > 1e-3
)
#: Translations included, and twists with tiny or huge rotation rates.
rates = st.sampled_from([0.0, 1e-9, 1e-3, 1.0, 1e3])


def _twist(surface, direction):
    return np.asarray(direction) / np.array([1.0, 1.0, surface.characteristic_length])


@LAW_SETTINGS
@given(a=directions, b=directions)
def test_support_function_is_subadditive(surface, a, b):
    first, second = _twist(surface, a), _twist(surface, b)
    if not np.any(first + second):
        return
    h_first, h_second = surface.support(first), surface.support(second)
    assert surface.support(first + second) <= (h_first + h_second) * (1 + LAW_RTOL)


@LAW_SETTINGS
@given(a=directions, b=directions)
def test_every_load_lies_under_every_support_plane(surface, a, b):
    twist, probe = _twist(surface, a), _twist(surface, b)
    assert surface.load(twist) @ probe <= surface.support(probe) * (1 + LAW_RTOL) + 1e-300


@LAW_SETTINGS
@given(a=directions, scale=st.floats(1e-6, 1e6))
def test_load_dotted_with_its_twist_is_the_support_value(surface, a, scale):
    twist = _twist(surface, a)
    load = surface.load(twist)
    assert load @ twist == pytest.approx(surface.support(twist), rel=LAW_RTOL)
    assert surface.support(scale * twist) == pytest.approx(
        scale * surface.support(twist), rel=1e-13
    )
    assert np.allclose(
        surface.load(scale * twist), load, rtol=1e-12, atol=1e-14 * np.abs(load).max()
    )


@LAW_SETTINGS
@given(a=directions)
def test_surface_is_centrally_symmetric(surface, a):
    twist = _twist(surface, a)
    assert surface.support(-twist) == pytest.approx(surface.support(twist), rel=1e-13)
    load = surface.load(twist)
    assert np.allclose(surface.load(-twist), -load, rtol=1e-12, atol=1e-14 * np.abs(load).max())


@LAW_SETTINGS
@given(a=directions)
def test_load_is_the_gradient_of_the_support_function(surface, a):
    twist = _twist(surface, a)
    step = 1e-6 * np.array([1.0, 1.0, 1.0 / surface.characteristic_length])
    gradient = [
        (surface.support(twist + d) - surface.support(twist - d)) / (2 * d[i])
        for i, d in enumerate(np.diag(step))
    ]
    units = np.array([surface.max_force, surface.max_force, surface.max_moment])
    assert np.allclose(surface.load(twist) / units, np.array(gradient) / units, rtol=0, atol=1e-5)


@LAW_SETTINGS
@given(a=directions, rate=rates)
def test_pure_translation_gives_the_friction_force_of_eq_8(surface, a, rate):
    """|f| = ∫ mu p dA · N whatever the direction, and the moment is that of f at the friction-
    weighted centre of pressure (zero for fields centred there)."""
    vx, vy = a[0], a[1]
    if math.hypot(vx, vy) < 1e-3 or rate != 0.0:
        return
    load = surface.load([vx, vy, 0.0])
    force = math.hypot(load[0], load[1])
    assert force == pytest.approx(surface.max_force, rel=1e-13)
    assert ref.angle_between(load[:2], [vx, vy]) <= 1e-14
    parts = surface.parts or (surface,)
    moment = 0.0
    for part in parts:
        cop = part.field.center_of_pressure(mu=part.mu)
        f = part.load([vx, vy, 0.0])
        moment += cop[0] * f[1] - cop[1] * f[0]
    assert load[2] == pytest.approx(moment, rel=1e-9, abs=1e-13 * surface.max_moment)


def test_maximum_force_is_mu_times_the_normal_force():
    for field in (pressure.disk(0.01, "hertz"), pressure.rectangle(0.1, 0.02)):
        surface = LimitSurface(field, mu=0.37, normal_force=12.5)
        assert surface.max_force == pytest.approx(0.37 * 12.5, rel=1e-14)
        assert surface.characteristic_length == surface.max_moment / surface.max_force


@LAW_SETTINGS
@given(cor=st.tuples(st.floats(-3, 3), st.floats(-3, 3)), about=st.sampled_from(["origin", "cop"]))
def test_moment_about_a_point_is_largest_when_rotating_about_that_point(surface, cor, about):
    """Rotating about ``c``, the moment about ``o`` is ``M(c) + (o - c)·∇M(c) <= M(o)`` because
    ``M(c) = ∫ mu p |x - c| dA`` is convex; equality for ``c = o`` (paper §2.3: with the origin at
    the centre of pressure, the maximum moment occurs for the COR at the origin)."""
    size = surface.characteristic_length
    if about == "cop" and surface.field is not None:
        o = surface.field.center_of_pressure(mu=surface.mu)
    else:
        o = np.zeros(2)
    c = o + size * np.asarray(cor)
    fx, fy, m = surface.load_at_cor(c)
    moment_about_o = m - (o[0] * fy - o[1] * fx)
    best = surface.support(ref.twist_about(o))
    assert moment_about_o <= best * (1 + LAW_RTOL)
    at_o = surface.load_at_cor(o)
    assert at_o[2] - (o[0] * at_o[1] - o[1] * at_o[0]) == pytest.approx(best, rel=1e-12)


def test_maximum_moment_of_a_centred_field_is_at_the_origin_with_zero_force(rng):
    """Fields with periodic rotational symmetry about their centre of pressure peak at f = 0."""
    for field in (
        pressure.disk(0.01, "hertz"),
        pressure.rectangle(0.1, 0.01),
        pressure.points(
            0.05 * np.array([[0, 1], [-math.sqrt(0.75), -0.5], [math.sqrt(0.75), -0.5]])
        ),
        pressure.polygon([[0, 0], [1, 0], [0.5, math.sqrt(0.75)]]),
    ):
        surface = LimitSurface(field, mu=0.5, normal_force=2.0)
        peak = surface.load_at_cor([0.0, 0.0])
        assert peak[2] == pytest.approx(surface.max_moment, rel=1e-14)
        assert math.hypot(peak[0], peak[1]) <= 1e-6 * surface.max_force
        cors = rng.normal(size=(50, 2)) * surface.characteristic_length
        assert np.all(surface.load_at_cor(cors)[:, 2] <= surface.max_moment)
        assert np.all(surface.sample(100)[:, 2] <= surface.max_moment * (1 + 1e-12))


def _moved_mu(mu, angle, shift):
    """``mu`` carried along with a field rotated by ``angle`` about the origin, then shifted."""
    if not callable(mu):
        return mu
    c, s = math.cos(angle), math.sin(angle)

    def moved(x, y):
        x0, y0 = x - shift[0], y - shift[1]
        return mu(c * x0 + s * y0, -s * x0 + c * y0)

    return moved


def test_moving_a_field_moves_its_surface(surface, rng):
    """Rotating a field by R and shifting it by t (friction moving with it) maps the load of
    rotation about c to (R f, m + t × R f) for rotation about R c + t."""
    if surface.field is None:
        return
    angle, shift = 0.8, np.array([0.02, -0.03])
    moved = LimitSurface(
        surface.field.rotated(angle).shifted(*shift),
        mu=_moved_mu(surface.mu, angle, shift),
        normal_force=surface.normal_force,
    )
    rotation = np.array([[math.cos(angle), -math.sin(angle)], [math.sin(angle), math.cos(angle)]])
    cors = rng.normal(size=(10, 2)) * surface.characteristic_length
    loads = surface.load_at_cor(cors)
    forces = loads[:, :2] @ rotation.T
    expected = np.column_stack(
        [forces, loads[:, 2] + shift[0] * forces[:, 1] - shift[1] * forces[:, 0]]
    )
    actual = moved.load_at_cor(cors @ rotation.T + shift)
    units = np.array([surface.max_force, surface.max_force, surface.max_moment])
    assert np.allclose(actual / units, expected / units, rtol=0, atol=1e-9)


@pytest.mark.parametrize("profile", ["uniform", "hertz", "parabolic", "ring", "annulus"])
def test_disk_surfaces_are_axisymmetric(profile, rng):
    inner = 0.005 if profile == "annulus" else None
    surface = LimitSurface(pressure.disk(0.01, profile, inner_radius=inner), mu=0.6)
    cors = rng.normal(size=(20, 2)) * 0.01
    angle = 2.2
    rotation = np.array([[math.cos(angle), -math.sin(angle)], [math.sin(angle), math.cos(angle)]])
    loads = surface.load_at_cor(cors)
    turned = surface.load_at_cor(cors @ rotation.T)
    assert np.allclose(turned[:, :2], loads[:, :2] @ rotation.T, rtol=0, atol=1e-14)
    assert np.allclose(turned[:, 2], loads[:, 2], rtol=1e-13)


def _rescaled(surface, mu_factor, force_factor):
    if surface.parts:
        return LimitSurface.combine(_rescaled(p, mu_factor, force_factor) for p in surface.parts)
    mu = surface.mu
    scaled_mu = (lambda x, y: mu_factor * mu(x, y)) if callable(mu) else mu_factor * mu
    return LimitSurface(
        surface.field, mu=scaled_mu, normal_force=force_factor * surface.normal_force
    )


@pytest.mark.parametrize(("mu_factor", "force_factor"), [(2.5, 1.0), (1.0, 0.01), (0.3, 40.0)])
def test_surface_scales_linearly_with_mu_and_normal_force(surface, rng, mu_factor, force_factor):
    scaled = _rescaled(surface, mu_factor, force_factor)
    k = mu_factor * force_factor
    twists = random_twists(surface, rng, 8)
    assert np.allclose(scaled.load(twists), k * surface.load(twists), rtol=1e-12, atol=0)
    assert np.allclose(scaled.support(twists), k * surface.support(twists), rtol=1e-12)
    assert scaled.max_force == pytest.approx(k * surface.max_force, rel=1e-13)
    assert scaled.max_moment == pytest.approx(k * surface.max_moment, rel=1e-13)
    assert scaled.characteristic_length == pytest.approx(surface.characteristic_length, rel=1e-13)
    loads = surface.load(twists[:3]) * 0.7
    assert np.allclose(scaled.safety_factor(loads), k / 0.7, rtol=1e-9)
    motions = scaled.motion(loads)
    assert (
        np.max(ref.angle_between(normalised(surface, motions), normalised(surface, twists[:3])))
        <= 1e-8
    )


#: Cheap fields (closed forms and point sets) for property tests that rebuild surfaces.
SCALING_FIELDS = {
    "hertz disk": pressure.disk(0.004, "hertz"),
    "annulus": pressure.disk(0.02, "annulus", inner_radius=0.01),
    "rectangle": pressure.rectangle(0.08, 0.02).rotated(0.3),
    "grid": pressure.grid([0.0, 0.01], [0.0, 0.01, 0.02], [[1.0, 2.0], [0.0, 1.0], [3.0, 1.0]]),
    "points": pressure.points([[0.0, 0.0], [0.03, 0.0], [0.0, 0.02]], [1.0, 2.0, 3.0]),
}


@LAW_SETTINGS
@given(
    name=st.sampled_from(sorted(SCALING_FIELDS)),
    mu=st.floats(1e-3, 10.0),
    normal_force=st.floats(1e-3, 1e4),
    a=directions,
)
def test_loads_scale_linearly_with_any_mu_and_normal_force(name, mu, normal_force, a):
    field = SCALING_FIELDS[name]
    unit = LimitSurface(field, mu=1.0, normal_force=1.0)
    surface = LimitSurface(field, mu=mu, normal_force=normal_force)
    twist = _twist(unit, a)
    k = mu * normal_force
    assert np.allclose(surface.load(twist), k * unit.load(twist), rtol=1e-13, atol=0)
    assert surface.support(twist) == pytest.approx(k * unit.support(twist), rel=1e-13)
    load = unit.load(twist)
    assert surface.safety_factor(load) == pytest.approx(k, rel=1e-9)


def test_midpoints_of_surface_points_are_held(surface):
    """Convexity of the held set: the midpoint of two loads on the surface is held."""
    sample = surface.sample(12)
    midpoints = 0.5 * (sample[:, None, :] + sample[None, :, :])[np.triu_indices(12, 1)]
    assert np.all(surface.safety_factor(midpoints) >= 1.0 - 1e-9)


# -- Table 1 of the paper and the maximum moments of DESIGN.md §4 ---------------------------

TABLE_1 = {
    # contact type: (field for R = 1, m_max / (mu N R) exact, value printed in Table 1)
    "Hertzian": (lambda r: pressure.disk(r, "hertz"), 3 * math.pi / 16, 0.589),
    "Uniform": (lambda r: pressure.disk(r), 2 / 3, 0.667),
    "Annular, s = 0.9": (
        lambda r: pressure.disk(r, "annulus", inner_radius=0.9 * r),
        ref.annulus_max_moment_ratio(0.9),
        0.951,
    ),
}


@pytest.mark.parametrize(("radius", "mu", "normal_force"), [(1.0, 1.0, 1.0), (0.004, 0.3, 25.0)])
@pytest.mark.parametrize("contact", list(TABLE_1))
def test_maximum_moments_match_table_1_of_the_paper(contact, radius, mu, normal_force):
    build, exact, printed = TABLE_1[contact]
    surface = LimitSurface(build(radius), mu=mu, normal_force=normal_force)
    ratio = surface.max_moment / (mu * normal_force * radius)
    assert ratio == pytest.approx(exact, rel=1e-12)
    assert round(ratio, 3) == printed
    assert surface.max_force == pytest.approx(mu * normal_force, rel=1e-13)


@pytest.mark.parametrize(
    ("name", "field", "ratio"),
    [
        ("parabolic disk", pressure.disk(0.02, "parabolic"), 8 / 15),
        ("thin ring", pressure.disk(0.02, "ring"), 1.0),
        *[
            (f"annulus s={s}", pressure.disk(0.02, "annulus", inner_radius=0.02 * s), None)
            for s in (0.1, 0.5, 0.99)
        ],
    ],
)
def test_maximum_moments_match_design_section_4(name, field, ratio):
    if ratio is None:
        ratio = ref.annulus_max_moment_ratio(field.inner_radius / field.radius)
    surface = LimitSurface(field, mu=0.5, normal_force=3.0)
    assert surface.max_moment == pytest.approx(ratio * 0.5 * 3.0 * 0.02, rel=1e-12)


@pytest.mark.parametrize(("length", "width"), [(1.0, 1.0), (0.1, 0.01), (0.03, 0.02)])
def test_maximum_moment_of_a_rectangle_matches_design_section_4(length, width):
    surface = LimitSurface(pressure.rectangle(length, width), mu=0.4, normal_force=9.0)
    expected = 0.4 * 9.0 * ref.rectangle_max_moment(length, width)
    assert surface.max_moment == pytest.approx(expected, rel=1e-12)
    turned = LimitSurface(pressure.rectangle(length, width).rotated(1.0), mu=0.4, normal_force=9.0)
    assert turned.max_moment == pytest.approx(expected, rel=1e-12)
