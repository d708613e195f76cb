"""Candidate contacts spread evenly over faces of a body's mesh."""

from __future__ import annotations

import dataclasses

import numpy as np

from fixplan.errors import InvalidArgumentError
from fixplan.planner.problem import Body, Contact

#: Random surface points per candidate from which the even spread is picked.
OVERSAMPLING = 32
#: Faces whose outward normal is within this angle of ``facing`` are selected [rad].
FACING_TOLERANCE = np.radians(1.0)


def sample_surface(
    body: Body,
    *,
    template: Contact,
    n: int,
    faces=None,
    facing=None,
    seed: int = 0,
    prefix: str = "cand-",
) -> list[Contact]:
    """``n`` candidate contacts like ``template`` spread evenly over faces of ``body.mesh``.

    Parameters
    ----------
    body : Body
        A body with a mesh (:meth:`Body.from_mesh`).
    template : Contact
        Role, friction model, patch, ``mu`` and forces of every candidate; its name, position
        and normal are replaced (its ``axis``, if any, is projected onto each contact plane).
    n : int
        Number of candidates.
    faces : sequence of int, optional
        Indices of the mesh faces to sample.
    facing : array (3,), optional
        Or the faces whose outward normal is within ``FACING_TOLERANCE`` of this direction.
        Neither: the whole surface.
    seed : int
        Seed of the random surface points (the result is deterministic for a seed).
    prefix : str
        Names are ``prefix`` + 0, 1, ...

    Returns
    -------
    list of Contact
        At the points of a farthest-point spread of ``OVERSAMPLING * n`` random surface points
        (the first one nearest their centroid), each pushing along the inward normal of its face.
    """
    import trimesh

    mesh = body.mesh
    if mesh is None:
        raise InvalidArgumentError("sample_surface needs a body with a mesh (Body.from_mesh)")
    if not isinstance(n, int | np.integer) or isinstance(n, bool) or n < 1:
        raise InvalidArgumentError(f"n must be a positive integer, got {n!r}")
    selected = _faces(mesh, faces, facing)
    weights = np.zeros(len(mesh.faces))
    weights[selected] = mesh.area_faces[selected]
    points, index = trimesh.sample.sample_surface(
        mesh, OVERSAMPLING * int(n), face_weight=weights, seed=seed
    )
    chosen = _spread(points, int(n))
    return [
        dataclasses.replace(
            template,
            name=f"{prefix}{k}",
            position=points[i],
            normal=-mesh.face_normals[index[i]],
        )
        for k, i in enumerate(chosen)
    ]


def _faces(mesh, faces, facing) -> np.ndarray:
    if faces is not None and facing is not None:
        raise InvalidArgumentError("give faces or facing, not both")
    if faces is not None:
        selected = np.unique(np.asarray(faces, dtype=int))
        if selected.size == 0 or selected.min() < 0 or selected.max() >= len(mesh.faces):
            raise InvalidArgumentError(
                f"faces must be indices of the mesh's {len(mesh.faces)} faces, got {faces!r}"
            )
        return selected
    if facing is None:
        return np.arange(len(mesh.faces))
    direction = np.asarray(facing, dtype=float)
    if direction.shape != (3,) or not np.all(np.isfinite(direction)) or not direction.any():
        raise InvalidArgumentError(f"facing must be a nonzero 3-vector, got {facing!r}")
    direction = direction / np.linalg.norm(direction)
    selected = np.flatnonzero(mesh.face_normals @ direction >= np.cos(FACING_TOLERANCE))
    if selected.size == 0:
        raise InvalidArgumentError(f"no mesh face faces {direction.tolist()} (within 1°)")
    return selected


def _spread(points: np.ndarray, n: int) -> list[int]:
    """Indices of ``n`` of ``points`` picked farthest-first, from the one nearest the centroid."""
    first = int(np.argmin(np.linalg.norm(points - points.mean(axis=0), axis=1)))
    chosen = [first]
    distance = np.linalg.norm(points - points[first], axis=1)
    for _ in range(n - 1):
        nxt = int(np.argmax(distance))
        chosen.append(nxt)
        distance = np.minimum(distance, np.linalg.norm(points - points[nxt], axis=1))
    return chosen
