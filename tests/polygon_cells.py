"""The exact kernel of piecewise-uniform polygon cells, built in the tests from the edge sums
(shared by the polygon-kernel and function-kernel tests)."""

from __future__ import annotations

import numpy as np

from fixplan.surface.closed_form import EdgeSumKernel
from fixplan.surface.geometry import signed_area, triangulate
from fixplan.surface.point_kernel import PointSetKernel
from fixplan.surface.polygon_kernel import polygon_edges
from fixplan.surface.rules import triangle_rule


def edge_sum_kernel(cells):
    """Exact kernel of uniform polygon cells ``[(vertices, pressure)]`` (unit total force)."""
    force = sum(pressure * signed_area(vertices) for vertices, pressure in cells)
    starts, ends, weights, points, far_weights = [], [], [], [], []
    for vertices, pressure in cells:
        s, e = polygon_edges(vertices)
        starts.append(s)
        ends.append(e)
        weights.append(np.full(len(s), pressure / force))
        pts, w = triangle_rule(triangulate(vertices), 12)
        points.append(pts)
        far_weights.append(w * pressure / force)
    far = PointSetKernel(np.concatenate(points), np.concatenate(far_weights))
    return EdgeSumKernel(np.concatenate(starts), np.concatenate(ends), np.concatenate(weights), far)
