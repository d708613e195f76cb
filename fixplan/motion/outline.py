"""The outline of a pushed part in its own frame: where a pusher touches it, and the normal there.

A polygon (counter-clockwise vertices, corners included) or a disk. :meth:`Outline.nearest` gives
the closest point of the outline to a point, the outward unit normal there — for a point outside,
the direction from the closest point to it, so that a round pusher of any radius touches along its
own normal, at corners too — and the signed distance (negative inside).

:meth:`Outline.face_points` serves a flat pusher face: the outline clipped to the strip the face
sweeps, whose lowest points (along the face normal) are the ones the face touches. For a polygon
they are the vertices of the clipped polygon: the part's vertices within the strip and the points
where its edges cross the strip's sides (where a pusher end meets a part edge); for a disk, its
lowest point within the strip.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from fixplan import validation
from fixplan.surface.geometry import simple_polygon

#: A point within this fraction of the longest edge of a polygon lies on its outline (rounding).
ON_OUTLINE_RTOL = 1e-12


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

    @property
    def size(self) -> float:
        """The part's size [m]: its largest vertex coordinate, or a disk's radius (the scale of
        the pushers' tolerances)."""
        return float(np.abs(self.vertices).max()) if len(self.vertices) else self.radius

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
        lengths = np.einsum("ij,ij->i", edge, edge)
        along = np.clip(np.einsum("ij,ij->i", point - start, edge) / lengths, 0.0, 1.0)
        closest = start + along[:, None] * edge
        gaps = np.linalg.norm(point - closest, axis=1)
        best = int(np.argmin(gaps))
        inside = _inside(self.vertices, point)
        gap = float(gaps[best])
        # A point on an edge has a gap of rounding size, along any direction: the edge's normal,
        # not that direction, is the normal there.
        slack = ON_OUTLINE_RTOL * np.abs(edge).max()
        if gap > slack and not inside:
            normal = (point - closest[best]) / gap
        else:  # on or inside the outline: the edge's outward normal (a corner: the bisector)
            normals = self._edge_normals(point)
            normal = normals.sum(axis=0)
            length = np.linalg.norm(normal)
            # Inside, equally far from opposite edges: the first one's.
            normal = normal / length if length > 0.0 else normals[0]
        return closest[best], normal, -gap if inside else gap

    def enters(self, point, direction) -> bool:
        """Whether a point on the outline moving along ``direction`` (part frame) goes into the
        part: into the inner side of its edge, and at a corner of the inner sides of both edges
        (a convex corner) or of either (a reflex one). A disk: against its outward normal."""
        point = np.asarray(point, dtype=float)
        direction = np.asarray(direction, dtype=float)
        if not len(self.vertices):
            return float(direction @ point) < 0.0
        normals = self._edge_normals(point)
        inward = normals @ direction < 0.0
        if len(normals) == 1:
            return bool(inward[0])
        return bool(inward.all() if _turns_left(self.vertices, point) else inward.any())

    def _edge_normals(self, point: np.ndarray) -> np.ndarray:
        """The outward unit normals of the edges nearest to ``point`` (two at a corner), in
        the order of the edges."""
        start = self.vertices
        edge = np.roll(self.vertices, -1, axis=0) - start
        lengths = np.einsum("ij,ij->i", edge, edge)
        along = np.clip(np.einsum("ij,ij->i", point - start, edge) / lengths, 0.0, 1.0)
        gaps = np.linalg.norm(point - (start + along[:, None] * edge), axis=1)
        gap = float(gaps.min())
        touching = np.flatnonzero(gaps <= gap + ON_OUTLINE_RTOL * max(gap, np.abs(edge).max()))
        if len(touching) == 2 and touching[0] == 0 and touching[1] == len(edge) - 1:
            touching = touching[::-1]  # the last edge and the first meet at vertex 0
        normals = np.column_stack([edge[touching, 1], -edge[touching, 0]])
        return normals / np.linalg.norm(normals, axis=1, keepdims=True)

    def face_points(self, centre, normal, half_width: float) -> FacePoints:
        """The points of the outline that a flat face can touch (see the module docstring).

        Parameters
        ----------
        centre : array_like
            Centre of the face in the part frame [m].
        normal : array_like
            Unit normal of the face in the part frame, pointing from the face to the part.
        half_width : float
            Half the face's width [m]: the strip is ``|t · (x - centre)| <= half_width`` with
            ``t`` the normal turned a quarter counter-clockwise.
        """
        centre = np.asarray(centre, dtype=float)
        normal = np.asarray(normal, dtype=float)
        tangent = np.array([-normal[1], normal[0]])
        if not len(self.vertices):
            return self._disk_face_point(centre, normal, tangent, half_width)
        along = (self.vertices - centre) @ tangent
        inside = np.flatnonzero(np.abs(along) <= half_width)
        keys = [("vertex", int(i)) for i in inside]
        points, normals = [self.vertices[inside]], [np.tile(normal, (len(inside), 1))]
        following = np.roll(np.arange(len(self.vertices)), -1)
        edges = self.vertices[following] - self.vertices
        inward = np.column_stack([-edges[:, 1], edges[:, 0]])
        inward /= np.linalg.norm(inward, axis=1, keepdims=True)
        for side in (1, -1):
            offset = along - side * half_width
            crossing = np.flatnonzero(offset * offset[following] < 0.0)
            fraction = offset[crossing] / (offset[crossing] - offset[following][crossing])
            points.append(self.vertices[crossing] + fraction[:, None] * edges[crossing])
            normals.append(inward[crossing])
            keys += [("edge", int(i), side) for i in crossing]
        points = np.vstack(points)
        return FacePoints(keys=tuple(keys), points=points, along=(points - centre) @ tangent,
                          levels=(points - centre) @ normal, normals=np.vstack(normals))  # fmt: skip

    def _disk_face_point(self, centre, normal, tangent, half_width) -> FacePoints:
        """The disk's lowest point within the strip (none when the disk misses the strip)."""
        along_centre, level_centre = -centre @ tangent, -centre @ normal
        along = min(max(along_centre, -half_width), half_width)
        off = along - along_centre
        if abs(off) >= self.radius:
            return FacePoints(keys=(), points=np.empty((0, 2)), along=np.empty(0),
                              levels=np.empty(0), normals=np.empty((0, 2)))  # fmt: skip
        level = level_centre - math.sqrt(self.radius**2 - off**2)
        point = centre + along * tangent + level * normal
        return FacePoints(keys=(("disk",),), points=point[None, :], along=np.array([along]),
                          levels=np.array([level]), normals=-point[None, :] / self.radius)  # fmt: skip


@dataclass(frozen=True, slots=True)
class FacePoints:
    """The candidate contact points of an outline with a flat face (see the module docstring).

    Attributes
    ----------
    keys : tuple
        What each point is, stable while the part moves: ``("vertex", i)``, ``("edge", i, side)``
        (edge ``i`` from vertex ``i`` to ``i + 1`` crossing the strip side ``side = ±1`` along the
        face) or ``("disk",)``.
    points : numpy.ndarray
        ``(k, 2)`` the points in the part frame [m].
    along : numpy.ndarray
        ``(k,)`` their position along the face from its centre (along the face tangent) [m].
    levels : numpy.ndarray
        ``(k,)`` their height above the face along its normal [m] (negative: behind the face).
    normals : numpy.ndarray
        ``(k, 2)`` the inward unit normal the part has where each point alone touches the face:
        the face normal at a vertex, the edge's at an edge crossing, the radial one on a disk.
    """

    keys: tuple
    points: np.ndarray
    along: np.ndarray
    levels: np.ndarray
    normals: np.ndarray


def _inside(vertices: np.ndarray, point: np.ndarray) -> bool:
    """Whether ``point`` lies strictly inside the polygon (crossing number, over all edges at
    once)."""
    x, y = point
    x0, y0 = vertices[:, 0], vertices[:, 1]
    x1, y1 = np.roll(x0, -1), np.roll(y0, -1)
    straddles = (y0 > y) != (y1 > y)
    with np.errstate(divide="ignore", invalid="ignore"):
        crossing = x0 + (y - y0) * (x1 - x0) / (y1 - y0)
    return bool(np.count_nonzero(straddles & (x < crossing)) % 2)


def _turns_left(vertices: np.ndarray, point: np.ndarray) -> bool:
    """Whether the counter-clockwise outline turns left (a convex corner) at the vertex nearest
    to ``point``."""
    k = int(np.argmin(np.linalg.norm(vertices - point, axis=1)))
    before, after = vertices[k] - vertices[k - 1], vertices[(k + 1) % len(vertices)] - vertices[k]
    return bool(before[0] * after[1] - before[1] * after[0] > 0.0)
