"""Mass properties and surface points of a part from its closed triangle mesh (trimesh).

A mesh gives a body its mass, centre of mass and inertia tensor (about the centre of mass, world
axes) by exact integration over the enclosed volume, and gives contacts their position and
inward normal from a point near the surface (:func:`surface_contact`). Mesh coordinates are in
the world frame [m] after ``scale`` (0.001 for a part drawn in millimetres).
"""

from __future__ import annotations

import os

import numpy as np

from fixplan.errors import InvalidArgumentError

#: A mesh whose volume is below this fraction of its bounding box's is treated as empty (a
#: sheet or a degenerate solid has no mass to integrate).
MIN_VOLUME_FRACTION = 1e-9


class MeshError(InvalidArgumentError):
    """A mesh cannot be read or does not enclose a volume; the message says what is wrong."""


def read_mesh(source, *, scale: float = 1.0, where: str = "mesh"):
    """The closed, consistently wound triangle mesh ``source`` (a path or a ``trimesh.Trimesh``)
    scaled by ``scale``; :class:`MeshError` says why a mesh is not a solid."""
    import trimesh

    if not np.isfinite(scale) or scale <= 0.0:
        raise MeshError(f"{where}: scale must be a positive number, got {scale!r}")
    if isinstance(source, str | os.PathLike):
        where = f"{where} {os.fspath(source)!r}"
        try:
            mesh = trimesh.load(os.fspath(source), force="mesh", process=True)
        except NotImplementedError as exc:  # (trimesh's word for a format it does not read)
            raise MeshError(
                f"{where}: cannot read it: {exc}; mesh formats are those trimesh reads, e.g. "
                ".stl, .obj, .ply, .off, .glb"
            ) from None
        except (OSError, ValueError, KeyError, IndexError, TypeError) as exc:
            raise MeshError(f"{where}: cannot read it: {exc}") from None
    elif isinstance(source, trimesh.Trimesh):
        mesh = source.copy()
    else:
        raise MeshError(f"{where} must be a file path or a trimesh.Trimesh, got {source!r}")
    if not isinstance(mesh, trimesh.Trimesh) or len(mesh.faces) == 0:
        raise MeshError(f"{where}: the file holds no triangles")
    if scale != 1.0:
        mesh.apply_scale(scale)
    if not mesh.is_watertight:
        raise MeshError(
            f"{where} is not watertight (it has open edges or holes): a body's mass needs a "
            "closed surface; repair it (e.g. trimesh.repair.fill_holes) and try again"
        )
    if not mesh.is_winding_consistent:
        raise MeshError(
            f"{where} has inconsistently wound faces (their normals disagree): fix the winding "
            "(e.g. trimesh.repair.fix_winding)"
        )
    extent = float(np.prod(mesh.extents))
    with np.errstate(invalid="ignore", divide="ignore"):  # trimesh divides by a zero volume
        volume = float(mesh.volume)
    if extent == 0.0 or abs(volume) <= MIN_VOLUME_FRACTION * extent:
        raise MeshError(f"{where} encloses zero volume (a flat or degenerate surface)")
    if volume < 0.0:
        raise MeshError(
            f"{where} has inverted normals (they point into the part, so its volume comes out "
            "negative): invert the faces (trimesh's mesh.invert())"
        )
    return mesh


def mass_properties(mesh, *, density: float | None = None, mass: float | None = None):
    """``(mass [kg], centre of mass (3,) [m], inertia (3, 3) [kg m²] about the centre of mass)``
    of a solid of uniform ``density`` [kg/m³] or total ``mass`` [kg] (exactly one)."""
    if (density is None) == (mass is None):
        raise MeshError("give exactly one of density [kg/m³] and mass [kg] for a mesh body")
    volume = float(mesh.volume)
    value = density if density is not None else mass
    if not np.isfinite(value) or value < 0.0:
        name = "density" if density is not None else "mass"
        raise MeshError(f"{name} must be a finite number >= 0, got {value!r}")
    rho = density if density is not None else mass / volume
    # trimesh integrates the volume's moments exactly (signed tetrahedra from the origin).
    properties = mesh.mass_properties
    total = float(rho * volume)
    inertia = rho * np.asarray(properties["inertia"], dtype=float) / properties["density"]
    return total, np.asarray(properties["center_mass"], dtype=float), 0.5 * (inertia + inertia.T)


def surface_contact(mesh, point) -> tuple[np.ndarray, np.ndarray, float]:
    """The surface point of ``mesh`` closest to ``point`` [m], the inward normal of its face and
    the distance [m] from ``point``."""
    import trimesh

    point = np.asarray(point, dtype=float)
    # Every face's closest point (no spatial index needed for the few contacts of a problem).
    candidates = trimesh.triangles.closest_point(
        mesh.triangles, np.tile(point, (len(mesh.faces), 1))
    )
    distances = np.linalg.norm(candidates - point, axis=1)
    face = int(np.argmin(distances))
    normal = -np.asarray(mesh.face_normals[face], dtype=float)
    return candidates[face], normal / np.linalg.norm(normal), float(distances[face])
