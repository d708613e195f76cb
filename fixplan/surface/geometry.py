"""Planar geometry of contact patches: poses, polygons and their triangulation."""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

from fixplan.errors import GeometryError


@dataclass(frozen=True, slots=True, kw_only=True)
class Pose:
    """Placement of a patch's local frame in the contact frame.

    A local point ``q`` lies at ``R(angle) @ M @ q + offset`` in the contact frame, ``M`` the
    identity, or for a ``mirrored`` pose the reflection ``diag(1, -1)``.

    Attributes
    ----------
    angle : float
        Rotation of the local x axis from the contact x axis [rad], counter-clockwise.
    offset : tuple[float, float]
        Position of the local origin in the contact frame [m].
    mirrored : bool
        Whether the local y axis is reversed before the rotation: the local frame seen from the
        other side of the plane (a contact whose normal points the other way; the local frame's
        counter-clockwise is the contact frame's clockwise).
    """

    angle: float = 0.0
    offset: tuple[float, float] = (0.0, 0.0)
    mirrored: bool = False

    @property
    def rotation(self) -> np.ndarray:
        """The 2x2 matrix ``R(angle) @ M`` of the local axes in the contact frame."""
        c, s = math.cos(self.angle), math.sin(self.angle)
        turn = np.array([[c, -s], [s, c]])
        return turn * np.array([1.0, -1.0]) if self.mirrored else turn

    @property
    def is_identity(self) -> bool:
        """Whether the local frame is the contact frame."""
        return self.angle == 0.0 and self.offset == (0.0, 0.0) and not self.mirrored

    def apply(self, points: np.ndarray) -> np.ndarray:
        """Map local points ``(n, 2)`` [m] to the contact frame."""
        return points @ self.rotation.T + np.asarray(self.offset)

    def shifted(self, dx: float, dy: float) -> Pose:
        """This pose followed by a translation by ``(dx, dy)`` [m]."""
        return dataclasses.replace(self, offset=(self.offset[0] + dx, self.offset[1] + dy))

    def then(self, outer: Pose) -> Pose:
        """This pose followed by ``outer``: a local point placed by this pose, then by
        ``outer`` (a mirror reverses the sense of the angles after it)."""
        angle = outer.angle - self.angle if outer.mirrored else outer.angle + self.angle
        offset = outer.apply(np.array([self.offset], dtype=float))[0]
        return Pose(
            angle=math.remainder(angle, 2.0 * math.pi),
            offset=(float(offset[0]), float(offset[1])),
            mirrored=self.mirrored != outer.mirrored,
        )

    def rotated(self, angle: float, about: tuple[float, float]) -> Pose:
        """This pose followed by a rotation by ``angle`` [rad] about the point ``about`` [m]."""
        c, s = math.cos(angle), math.sin(angle)
        ox, oy = self.offset[0] - about[0], self.offset[1] - about[1]
        return Pose(
            angle=math.remainder(self.angle + angle, 2.0 * math.pi),
            offset=(c * ox - s * oy + about[0], s * ox + c * oy + about[1]),
            mirrored=self.mirrored,
        )


def signed_area(vertices: np.ndarray) -> float:
    """Signed area of a polygon ``(n, 2)`` [m^2]; positive when counter-clockwise (the
    shoelace sum about its first vertex: about the origin, a small polygon far from it would
    lose its area to cancellation)."""
    x, y = (vertices - vertices[0]).T
    return 0.5 * float(np.dot(x, np.roll(y, -1)) - np.dot(np.roll(x, -1), y))


def polygon_centroid(vertices: np.ndarray) -> np.ndarray:
    """Area centroid of a simple polygon ``(n, 2)`` [m] (sums about its first vertex)."""
    x, y = (vertices - vertices[0]).T
    xn, yn = np.roll(x, -1), np.roll(y, -1)
    cross = x * yn - xn * y
    area = 0.5 * cross.sum()
    moments = np.array([((x + xn) * cross).sum(), ((y + yn) * cross).sum()])
    return vertices[0] + moments / (6.0 * area)


def _segments_cross(p1, p2, q1, q2) -> bool:
    """Whether closed segments p1p2 and q1q2 intersect."""

    def orient(a, b, c):
        return (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])

    def on_segment(a, b, c):
        return min(a[0], b[0]) <= c[0] <= max(a[0], b[0]) and min(a[1], b[1]) <= c[1] <= max(
            a[1], b[1]
        )

    d1, d2 = orient(q1, q2, p1), orient(q1, q2, p2)
    d3, d4 = orient(p1, p2, q1), orient(p1, p2, q2)
    if ((d1 > 0) != (d2 > 0)) and d1 != 0 and d2 != 0 and ((d3 > 0) != (d4 > 0)) and d3 and d4:
        return True
    return (
        (d1 == 0 and on_segment(q1, q2, p1))
        or (d2 == 0 and on_segment(q1, q2, p2))
        or (d3 == 0 and on_segment(p1, p2, q1))
        or (d4 == 0 and on_segment(p1, p2, q2))
    )


def simple_polygon(name: str, vertices: np.ndarray) -> np.ndarray:
    """Check that ``vertices`` form a simple polygon; return them counter-clockwise.

    Raises
    ------
    GeometryError
        With fewer than 3 vertices, repeated vertices, zero area or crossing edges.
    """
    n = len(vertices)
    if n < 3:
        raise GeometryError(f"{name} needs at least 3 vertices, got {n}")
    scale = float(np.max(np.ptp(vertices, axis=0)))
    edges = np.roll(vertices, -1, axis=0) - vertices
    if scale == 0.0 or np.any(np.hypot(edges[:, 0], edges[:, 1]) <= 1e-12 * scale):
        raise GeometryError(f"{name} has repeated consecutive vertices (a zero-length edge)")
    for i in range(n):
        for j in range(i + 2, n):
            if i == 0 and j == n - 1:
                continue
            if _segments_cross(
                vertices[i], vertices[(i + 1) % n], vertices[j], vertices[(j + 1) % n]
            ):
                raise GeometryError(
                    f"{name} is self-intersecting: edge {i} crosses edge {j}; "
                    "give the vertices of a simple polygon in order around its boundary"
                )
    area = signed_area(vertices)
    if abs(area) <= 1e-12 * scale * scale:
        raise GeometryError(f"{name} is degenerate: its area is zero")
    return vertices if area > 0 else vertices[::-1].copy()


def triangulate(vertices: np.ndarray) -> np.ndarray:
    """Ear-clipping triangulation of a simple counter-clockwise polygon.

    Returns
    -------
    numpy.ndarray
        Triangles ``(n - 2, 3, 2)`` [m], each counter-clockwise.
    """
    remaining = list(range(len(vertices)))
    triangles = []

    def cross(o, a, b):
        return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])

    while len(remaining) > 3:
        m = len(remaining)
        for k in range(m):
            ia, ib, ic = remaining[k - 1], remaining[k], remaining[(k + 1) % m]
            a, b, c = vertices[ia], vertices[ib], vertices[ic]
            if cross(a, b, c) <= 0.0:
                continue
            others = (vertices[i] for i in remaining if i not in (ia, ib, ic))
            if any(
                cross(a, b, p) >= 0 and cross(b, c, p) >= 0 and cross(c, a, p) >= 0 for p in others
            ):
                continue
            triangles.append((a, b, c))
            del remaining[k]
            break
        else:  # pragma: no cover - simple polygons always have an ear
            raise GeometryError("polygon could not be triangulated; is it simple?")
    triangles.append(tuple(vertices[i] for i in remaining))
    return np.array(triangles, dtype=float)


def merged_points(xy: np.ndarray, weights: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Distinct points of ``xy`` ``(n, 2)`` [m] in order of first appearance, each with the sum
    of the ``weights`` ``(n,)`` given to it."""
    xy = xy + 0.0  # -0.0 and 0.0 are one coordinate
    unique, first, inverse = np.unique(xy, axis=0, return_index=True, return_inverse=True)
    if len(unique) == len(xy):
        return xy, weights
    order = np.argsort(first)
    rank = np.empty_like(order)
    rank[order] = np.arange(len(order))
    summed = np.bincount(rank[inverse.ravel()], weights=weights, minlength=len(unique))
    return unique[order], summed
