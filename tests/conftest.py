"""A catalogue of limit surfaces covering every kind of pressure field, shared by the tests of
the laws every surface obeys and of the inverse map.

The catalogue spans SI scales of real contacts (millimetre fingertips to 10 cm fixture pads,
normal forces from 0.5 N to 200 N) so that unit mistakes show up. The last entries need
``fixplan.surface.function_kernel`` (pressure functions, position-dependent friction on continuous
fields).
"""

import math

import numpy as np
import pytest

from fixplan import LimitSurface, pressure

L_SHAPE = [[0.0, 0.0], [0.03, 0.0], [0.03, 0.01], [0.01, 0.01], [0.01, 0.025], [0.0, 0.025]]
EQUILATERAL = [[math.cos(a), math.sin(a)] for a in np.pi / 2 + 2 * np.pi / 3 * np.arange(3)]


def disk_bump(x, y):
    """A smooth pressure over a disk of radius 0.01 m, heavier towards +x and along y."""
    return 1.0 + 40.0 * x + 4000.0 * y * y


def slippery_corner(x, y):
    """Friction falling towards one corner of the L shape (contact frame, metres)."""
    return 0.9 - 8.0 * x - 6.0 * y


def rising_friction(x, y):
    """Friction rising along x and y over the point set of the catalogue (contact frame)."""
    return 0.4 + 3.0 * x + 2.0 * y


def _points_with_varying_mu():
    xy = [[0.0, 0.0], [0.05, 0.01], [0.02, 0.06], [-0.03, 0.03], [0.01, -0.04]]
    field = pressure.points(xy, [1.0, 2.0, 0.7, 1.3, 0.5], centered=False).shifted(0.02, 0.01)
    return LimitSurface(field, mu=rising_friction, normal_force=7.0)


SURFACES = {
    "uniform disk": lambda: LimitSurface(pressure.disk(0.01), mu=0.5, normal_force=10.0),
    "hertz disk": lambda: LimitSurface(pressure.disk(0.003, "hertz"), mu=0.9, normal_force=2.0),
    "parabolic disk": lambda: LimitSurface(
        pressure.disk(0.008, "parabolic"), mu=0.3, normal_force=0.5
    ),
    "annulus": lambda: LimitSurface(
        pressure.disk(0.02, "annulus", inner_radius=0.018), mu=0.4, normal_force=50.0
    ),
    "ring": lambda: LimitSurface(pressure.disk(0.015, "ring"), mu=0.6, normal_force=3.0),
    "rectangle 10:1": lambda: LimitSurface(
        pressure.rectangle(0.1, 0.01), mu=0.25, normal_force=200.0
    ),
    "L-shaped polygon": lambda: LimitSurface(pressure.polygon(L_SHAPE), mu=0.7, normal_force=4.0),
    "tactile grid": lambda: LimitSurface(
        pressure.grid(
            [-0.006, -0.002, 0.002, 0.006],
            [-0.004, 0.0, 0.004],
            [[0.2, 1.0, 0.0, 0.1], [0.5, 3.0, 2.0, 1.0], [1.0, 0.0, 1.0, 2.5]],
        ),
        mu=0.8,
        normal_force=6.0,
    ),
    "three points": lambda: LimitSurface(
        pressure.points(0.05 * np.asarray(EQUILATERAL)), mu=0.5, normal_force=30.0
    ),
    "two points": lambda: LimitSurface(
        pressure.points([[0.0, 0.0], [0.04, 0.01]], [3.0, 1.0]), mu=0.35, normal_force=12.0
    ),
    "points with varying mu": _points_with_varying_mu,
    "rotated shifted rectangle": lambda: LimitSurface(
        pressure.rectangle(0.05, 0.02).rotated(0.4).shifted(0.03, -0.01), mu=0.6, normal_force=8.0
    ),
    "shifted hertz disk": lambda: LimitSurface(
        pressure.disk(0.004, "hertz").shifted(-0.01, 0.02), mu=1.1, normal_force=1.5
    ),
    "disk and points combined": lambda: LimitSurface.combine(
        [
            LimitSurface(pressure.disk(0.005).shifted(0.04, 0.0), mu=0.5, normal_force=5.0),
            LimitSurface(
                pressure.points([[-0.03, 0.02], [-0.03, -0.02]], centered=False),
                mu=0.3,
                normal_force=8.0,
            ),
        ]
    ),
    "pressure function on a disk": lambda: LimitSurface(
        pressure.from_function(pressure.disk(0.01), disk_bump), mu=0.5, normal_force=2.0
    ),
    "polygon with varying mu": lambda: LimitSurface(
        pressure.polygon(L_SHAPE, centered=False), mu=slippery_corner, normal_force=3.0
    ),
}


@pytest.fixture(scope="session", params=sorted(SURFACES))
def surface(request) -> LimitSurface:
    """Every surface of the catalogue in turn."""
    return SURFACES[request.param]()


@pytest.fixture
def rng() -> np.random.Generator:
    """A freshly seeded generator for each test (results do not depend on test order)."""
    return np.random.default_rng(20240607)


def normalised(surface: LimitSurface, twists) -> np.ndarray:
    """Twists in the normalised coordinates ``(vx, vy, rho * w)`` of ``surface``."""
    return np.asarray(twists) * np.array([1.0, 1.0, surface.characteristic_length])


def random_twists(surface: LimitSurface, rng: np.random.Generator, count: int) -> np.ndarray:
    """Random twists spread evenly over directions in normalised coordinates."""
    directions = rng.normal(size=(count, 3))
    return directions / np.array([1.0, 1.0, surface.characteristic_length])
