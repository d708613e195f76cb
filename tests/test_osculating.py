"""The osculating ellipsoid of an exact limit surface, against finite differences of the exact
gauge ``g(q) = 1 / s(q)`` (the inverse map's safety factor), and the support Hessian against
finite differences of the forward map's load (the support's gradient)."""

from __future__ import annotations

import numpy as np
import pytest

from fixplan import LimitSurface, pressure
from fixplan.models.exact import Exact

FIELDS = {
    "uniform disk": pressure.disk(0.01),
    "hertz disk": pressure.disk(0.01, profile="hertz"),
    "rectangle": pressure.rectangle(0.02, 0.01),
}


def gauge(surface: LimitSurface, q: np.ndarray) -> float:
    return 1.0 / float(surface.safety_factor(q * surface.normal_force))


@pytest.mark.parametrize("name", FIELDS)
def test_the_osculating_ellipsoid_has_the_exact_sets_point_normal_and_curvature(name):
    surface = LimitSurface(FIELDS[name], mu=0.4, normal_force=3.0)
    model = Exact(surface=surface)
    units = model._units()
    loads = np.random.default_rng(4).normal(size=(6, 3)) * units
    excess, points, factors = model.osculating(loads)
    step = 1e-4
    for load, extra, u, factor in zip(loads, excess, points, factors, strict=True):
        assert extra == pytest.approx(gauge(surface, load) - 1.0, rel=1e-12)
        shape = factor.T @ factor
        value = np.sqrt(u @ shape @ u)
        gradient = shape @ u / value
        hessian = shape / value - np.outer(shape @ u, shape @ u) / value**3
        moves = np.eye(3) * units * step
        fd_gradient = np.array(
            [(gauge(surface, u + d) - gauge(surface, u - d)) / (2 * step * s)
             for d, s in zip(moves, units, strict=True)]
        )  # fmt: skip
        fd_hessian = np.array(
            [[(gauge(surface, u + d + e) - gauge(surface, u + d - e) - gauge(surface, u - d + e)
               + gauge(surface, u - d - e)) / (4 * step * step * s * t)
              for e, t in zip(moves, units, strict=True)]
             for d, s in zip(moves, units, strict=True)]
        )  # fmt: skip
        assert value == pytest.approx(1.0, abs=1e-14)
        np.testing.assert_array_equal(np.tril(factor, -1), 0.0)  # R is upper triangular
        assert np.abs((gradient - fd_gradient) * units).max() < 1e-7
        scaled = np.outer(units, units)
        assert (
            np.abs((hessian - fd_hessian) * scaled).max() < 1e-6 * np.abs(fd_hessian * scaled).max()
        )


@pytest.mark.parametrize("name", FIELDS)
def test_the_support_hessian_is_the_derivative_of_the_load(name):
    surface = LimitSurface(FIELDS[name], mu=0.4, normal_force=3.0)
    twists = np.random.default_rng(5).normal(size=(5, 3)) * np.array([1.0, 1.0, 80.0])
    hessians = surface.support_hessian(twists)
    for twist, hessian in zip(twists, hessians, strict=True):
        step = 1e-6 * np.linalg.norm(twist[:2] + twist[2] * 0.01)
        columns = []
        for j in range(3):
            move = np.zeros(3)
            move[j] = step / (0.01 if j == 2 else 1.0)
            columns.append(
                (surface.load(twist + move) - surface.load(twist - move)) / (2 * move[j])
            )
        expected = np.array(columns).T
        scale = np.array([1.0, 1.0, 0.01])
        assert (
            np.abs((hessian - expected) * np.outer(scale, scale)).max()
            < 1e-6 * np.abs(expected * np.outer(scale, scale)).max()
        )
        np.testing.assert_allclose(hessian @ twist, 0.0, atol=1e-9 * np.abs(hessian).max())


@pytest.mark.parametrize("name", FIELDS)
def test_the_ellipsoid_osculating_where_the_normal_is_a_twist_is_the_one_at_its_point(name):
    # The forward map's point u = ∇h_1(V) lies on the exact surface with sliding twist V (the
    # inverse map's answer), and its ellipsoid is the one the inverse map's path gives at u
    # (checked against finite differences of the gauge above), whose curvature is the Hessian of
    # Newton's last iterate: about 1e-6 relative from the Hessian at the answer itself.
    surface = LimitSurface(FIELDS[name], mu=0.4, normal_force=3.0)
    model = Exact(surface=surface)
    twists = np.random.default_rng(6).normal(size=(6, 3)) * np.array([1.0, 1.0, 80.0])
    points, factors = model.osculating_at(twists)
    excess, on_ray, expected = model.osculating(points)
    np.testing.assert_allclose(excess, 0.0, atol=1e-12)
    np.testing.assert_allclose(on_ray, points, rtol=1e-12)
    sliding = surface.motion(points * surface.normal_force)
    scale = np.array([1.0, 1.0, 0.01])
    unit = twists * scale / np.linalg.norm(twists * scale, axis=1, keepdims=True)
    moved = sliding * scale / np.linalg.norm(sliding * scale, axis=1, keepdims=True)
    np.testing.assert_allclose(moved, unit, atol=1e-9)
    np.testing.assert_allclose(factors, expected, atol=1e-5 * np.abs(expected).max())
