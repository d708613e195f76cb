"""The pressure field Drake produces at a contact against the profile fixplan assumed for it.

Drake's hydroelastic contact surface is a set of polygons, each with the pressure at its centroid;
as in :mod:`fixplan.sim.drake_check` the engine's field is one point per polygon carrying area
times pressure (the points the engine applies friction at). It is compared with the contact's
``patch`` scaled to the same normal force: pressure by pressure at the polygon centroids, and by
the largest friction moment about the contact point per unit ``mu N`` (the torsional arm).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from fixplan.planner.problem import Contact
from fixplan.sim.drake_scene import EnginePatch
from fixplan.surface import pressure
from fixplan.surface.limit_surface import LimitSurface


@dataclass(frozen=True, slots=True, kw_only=True)
class ContactField:
    """One area contact's pressure field in the engine, beside the one the plan assumed.

    Attributes
    ----------
    contact : str
        The contact.
    field : PointsField
        The engine's field: polygon centroids in the contact's patch coordinates about the
        contact point [m], weighted by area times pressure.
    normal_force : float
        Integral of the engine's pressure over the patch [N].
    pressures, areas : numpy.ndarray
        The engine's pressure at each polygon's centroid [Pa] and the polygon's area [m²].
    pressure_deviation : float or None
        Largest difference between the engine's pressure and the assumed profile's at the
        same normal force, at the polygon centroids, over ``peak_pressure`` [-]; ``None`` where
        the assumed field has no pressure density (a thin ring, point supports).
    torsion_ratio : float
        The engine field's largest friction moment about the contact point over the assumed
        patch's, both per unit ``mu N`` [-].
    onset_use : float or None
        The shear and torsion ``(ft1, ft2, mn)`` the engine applied at this contact when the part
        started to slide, as a fraction of the exact limit surface of the contact's engine field
        at that moment and normal force (1: on the limit) [-]; ``None`` if the part did not slide
        or the contact is frictionless.
    """

    contact: str
    field: pressure.PointsField
    normal_force: float
    pressures: np.ndarray
    areas: np.ndarray
    pressure_deviation: float | None
    torsion_ratio: float
    onset_use: float | None

    @property
    def polygons(self) -> int:
        """Polygons of the engine's contact surface."""
        return len(self.pressures)

    @property
    def peak_pressure(self) -> float:
        """Largest pressure at a polygon centroid [Pa]."""
        return float(self.pressures.max())


def contact_field(
    contact: Contact, patch: EnginePatch, at_onset: EnginePatch | None = None
) -> ContactField:
    """Compare the engine's ``patch`` of ``contact`` (unloaded polygons dropped) with its
    assumed patch; ``at_onset`` is the engine's patch when the part started to slide."""
    pressures, areas, xy = _loaded(patch)
    forces = pressures * areas
    total = float(forces.sum())
    field = pressure.points(xy, forces, centered=False)
    deviation = profile_deviation(contact.patch, xy, pressures, areas)
    engine_arm = LimitSurface(field, mu=1.0).max_moment
    assumed_arm = LimitSurface(contact.patch, mu=1.0).max_moment
    use = None
    if at_onset is not None and contact.mu > 0.0:
        onset_pressures, onset_areas, onset_xy = _loaded(at_onset)
        onset_field = pressure.points(onset_xy, onset_pressures * onset_areas, centered=False)
        surface = LimitSurface(onset_field, mu=contact.mu, normal_force=at_onset.wrench[0])
        use = float(1.0 / surface.safety_factor(at_onset.wrench[1:]))
    return ContactField(contact=contact.name, field=field, normal_force=total,
                        pressures=pressures, areas=areas, pressure_deviation=deviation,
                        torsion_ratio=float(engine_arm / assumed_arm), onset_use=use)  # fmt: skip


def profile_deviation(
    patch: pressure.PressureField, xy: np.ndarray, pressures: np.ndarray, areas: np.ndarray
) -> float | None:
    """The largest difference between pressures [Pa] at points ``xy`` [m] (polygons of
    ``areas`` [m²]) and ``patch``'s pressure at their total force, over their peak [-];
    ``None`` where ``patch`` has no pressure density."""
    assumed = assumed_pressure(patch, xy)
    if assumed is None:
        return None
    total = float(np.sum(pressures * areas))
    return float(np.max(np.abs(total * assumed - pressures)) / np.max(pressures))


def _loaded(patch: EnginePatch) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Pressures [Pa], areas [m²] and centroids [m] of the polygons with measurable force
    (:func:`~fixplan.surface.pressure.measurable`; read-only arrays)."""
    loaded = pressure.measurable(patch.pressures * patch.areas) > 0.0
    arrays = tuple(np.array(a[loaded], dtype=float) for a in (patch.pressures, patch.areas))
    xy = np.array(patch.xy[loaded], dtype=float)
    for array in (*arrays, xy):
        array.setflags(write=False)
    return (*arrays, xy)


def assumed_pressure(patch: pressure.PressureField, xy: np.ndarray) -> np.ndarray | None:
    """The pressure of ``patch`` at unit normal force [1/m²] at points ``xy`` ``(n, 2)`` [m] of
    the contact frame; ``None`` for fields without a density (a ring, point supports)."""
    local = (np.asarray(xy, dtype=float) - patch.center) @ patch.pose.rotation
    if isinstance(patch, pressure.DiskField):
        return _disk_pressure(patch, local)
    if isinstance(patch, pressure.PolygonField):
        return _inside(patch.vertices, local) / patch.area
    if isinstance(patch, pressure.GridField):
        return _grid_pressure(patch, local)
    if isinstance(patch, pressure.FunctionField):
        shape = patch.shape
        nodes, weights = shape.quadrature()  # the shape of a FunctionField has no pose
        area = np.pi * shape.radius**2 if isinstance(shape, pressure.DiskField) else shape.area
        integral = area * float(weights @ patch.pressure(nodes))
        inside = _disk_pressure(shape, local) > 0.0 if isinstance(shape, pressure.DiskField) else (
            _inside(shape.vertices, local) > 0.0
        )  # fmt: skip
        return np.where(inside, patch.pressure(local), 0.0) / integral
    return None


def _disk_pressure(patch: pressure.DiskField, local: np.ndarray) -> np.ndarray | None:
    """``(α + 1) / (π R²) (1 - r²/R²)^α`` of the uniform, Hertz and parabolic disks; uniform
    between the radii of an annulus; ``None`` for a ring."""
    radius, profile = patch.radius, patch.profile
    s = np.sum(local**2, axis=1) / radius**2
    if profile == "ring":
        return None
    if profile == "annulus":
        inner = (patch.inner_radius / radius) ** 2
        return np.where((s >= inner) & (s <= 1.0), 1.0, 0.0) / (np.pi * radius**2 * (1.0 - inner))
    alpha = {"uniform": 0.0, "hertz": 0.5, "parabolic": 1.0}[profile]
    return (alpha + 1.0) / (np.pi * radius**2) * np.clip(1.0 - s, 0.0, None) ** alpha * (s <= 1.0)


def _grid_pressure(patch: pressure.GridField, local: np.ndarray) -> np.ndarray:
    """Each cell's share of the force over its area, 0 outside the grid."""
    dx, dy = patch.cell_size
    i = np.floor((local[:, 0] - patch.x[0]) / dx + 0.5).astype(int)
    j = np.floor((local[:, 1] - patch.y[0]) / dy + 0.5).astype(int)
    inside = (i >= 0) & (i < len(patch.x)) & (j >= 0) & (j < len(patch.y))
    values = np.zeros(len(local))
    values[inside] = patch.values[j[inside], i[inside]]
    return values / (patch.values.sum() * dx * dy)


def _inside(vertices: np.ndarray, local: np.ndarray) -> np.ndarray:
    """1 where a point lies inside the simple polygon ``vertices``, else 0 (even-odd rule)."""
    x, y = local[:, 0:1], local[:, 1:2]
    x0, y0 = vertices[:, 0], vertices[:, 1]
    x1, y1 = np.roll(x0, -1), np.roll(y0, -1)
    straddles = (y0 > y) != (y1 > y)
    with np.errstate(divide="ignore", invalid="ignore"):
        crossing = x0 + (y - y0) * (x1 - x0) / (y1 - y0)
    return (np.sum(straddles & (x < crossing), axis=1) % 2).astype(float)
