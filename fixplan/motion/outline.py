"""The outline of a pushed part in its own frame: where a pusher touches it, and the normal there.

A polygon (counter-clockwise vertices, corners included) or a disk. :meth:`Outline.nearest` gives
the closest point of the outline to a point, the outward unit normal there — for a point outside,
the direction from the closest point to it, so that a round pusher of any radius touches along its
own normal, at corners too — and the signed distance (negative inside).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from fixplan import validation
from fixplan.surface.geometry import simple_polygon


@dataclass(frozen=True, slots=True)
class Outline:
    """A part's outline in the part frame [m]: ``vertices`` ``(n, 2)`` counter-clockwise, or a
    disk of ``radius`` about the origin (``vertices`` empty)."""

    vertices: np.ndarray
    radius: float = 0.0

    @classmethod
    def polygon(cls, vertices) -> Outline:
        """A simple polygon; its vertices are put in counter-clockwise order."""
        points = simple_polygon("vertices", validation.finite_array("vertices", vertices,
                                                                      shape=(None, 2)))  # fmt: skip
        points.setflags(write=False)
        return cls(vertices=points)

    @classmethod
    def rectangle(cls, length: float, width: float) -> Outline:
        """A ``length`` × ``width`` rectangle [m] centred at the origin, long side along x."""
        a = validation.positive_scalar("length", length) / 2
        b = validation.positive_scalar("width", width) / 2
        return cls.polygon([[-a, -b], [a, -b], [a, b], [-a, b]])

    @classmethod
    def disk(cls, radius: float) -> Outline:
        """A disk of ``radius`` [m] about the origin."""
        return cls(vertices=np.empty((0, 2)), radius=validation.positive_scalar("radius", radius))

    def nearest(self, point) -> tuple[np.ndarray, np.ndarray, float]:
        """Closest outline point to ``point`` [m], the outward unit normal there, and the signed
        distance of ``point`` [m] (negative inside)."""
        point = np.asarray(point, dtype=float)
        if not len(self.vertices):
            distance = float(np.linalg.norm(point))
            normal = point / distance if distance > 0.0 else np.array([1.0, 0.0])
            return normal * self.radius, normal, distance - self.radius
        start = self.vertices
        edge = np.roll(self.vertices, -1, axis=0) - start
        along = np.clip(np.einsum("ij,ij->i", point - start, edge) / np.einsum("ij,ij->i", edge, edge),
                        0.0, 1.0)  # fmt: skip
        closest = start + along[:, None] * edge
        gaps = np.linalg.norm(point - closest, axis=1)
        best = int(np.argmin(gaps))
        inside = _inside(self.vertices, point)
        gap = float(gaps[best])
        if gap > 0.0 and not inside:
            normal = (point - closest[best]) / gap
        else:  # on or inside the outline: the edge's outward normal (a corner: the bisector)
            normals = np.column_stack([edge[:, 1], -edge[:, 0]])
            normals /= np.linalg.norm(normals, axis=1, keepdims=True)
            touching = np.flatnonzero(gaps <= gap + 1e-12 * max(gap, np.abs(edge).max()))
            normal = normals[touching].sum(axis=0)
            normal /= np.linalg.norm(normal)
        return closest[best], normal, -gap if inside else gap


def _inside(vertices: np.ndarray, point: np.ndarray) -> bool:
    """Whether ``point`` lies strictly inside the polygon (crossing number)."""
    x, y = point
    inside = False
    for (x0, y0), (x1, y1) in zip(vertices, np.roll(vertices, -1, axis=0), strict=True):
        if (y0 > y) != (y1 > y) and x < x0 + (y - y0) * (x1 - x0) / (y1 - y0):
            inside = not inside
    return inside
