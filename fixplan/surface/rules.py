"""One-dimensional and triangle quadrature rules on reference intervals."""

from __future__ import annotations

from functools import cache

import numpy as np
from scipy.special import roots_jacobi


@cache
def gauss_jacobi_unit(
    n: int, alpha: float = 0.0, beta: float = 0.0
) -> tuple[np.ndarray, np.ndarray]:
    """Gauss rule on ``[0, 1]`` for the weight ``(1 - t)^alpha * t^beta``.

    Exact for polynomials of degree ``2n - 1`` times the weight. Weights sum to the weight's
    integral over ``[0, 1]``.
    """
    x, w = roots_jacobi(n, alpha, beta)
    nodes = 0.5 * (x + 1.0)
    weights = w * 0.5 ** (1.0 + alpha + beta)
    nodes.setflags(write=False)
    weights.setflags(write=False)
    return nodes, weights


@cache
def tanh_sinh_unit(level: int = 6) -> tuple[np.ndarray, np.ndarray]:
    """Tanh-sinh (double exponential) rule on ``[0, 1]`` with step ``2**-level`` (wrap range 3.5).

    Converges double-exponentially even with integrable endpoint singularities
    (logarithmic kinks, square roots), which Gauss rules handle poorly.
    """
    step = 2.0**-level
    k = np.arange(-int(3.5 / step), int(3.5 / step) + 1) * step
    u = 0.5 * np.pi * np.sinh(k)
    # 1 - tanh(u) and 1 + tanh(u) computed without cancellation near the ends.
    one_minus = 2.0 / (np.exp(2.0 * u) + 1.0)
    one_plus = 2.0 - one_minus
    nodes = 0.5 * one_plus
    weights = step * 0.5 * np.pi * np.cosh(k) / np.cosh(u) ** 2 * 0.5
    keep = (nodes > 0.0) & (nodes < 1.0) & (weights > 0.0)
    nodes, weights = nodes[keep], weights[keep]
    nodes.setflags(write=False)
    weights.setflags(write=False)
    return nodes, weights


def triangle_rule(triangles: np.ndarray, order: int) -> tuple[np.ndarray, np.ndarray]:
    """Collapsed (Duffy) Gauss rule on triangles ``(T, 3, 2)``: ``order**2`` points each.

    Returns points ``(T * order**2, 2)`` [m] and weights [m^2] that sum to the total area.
    Exact for polynomials of degree ``2 * order - 2``.
    """
    u, wu = gauss_jacobi_unit(order, 0.0, 1.0)  # weight u (the Duffy Jacobian)
    v, wv = gauss_jacobi_unit(order)
    uu, vv = np.meshgrid(u, v, indexing="ij")
    ww = np.outer(wu, wv)
    a, b, c = triangles[:, 0], triangles[:, 1], triangles[:, 2]
    area = 0.5 * ((b - a)[:, 0] * (c - a)[:, 1] - (b - a)[:, 1] * (c - a)[:, 0])
    uu, vv = uu.ravel(), vv.ravel()
    points = (
        a[:, None, :]
        + uu[None, :, None] * (b - a)[:, None, :]
        + (uu * vv)[None, :, None] * (c - b)[:, None, :]
    )
    weights = 2.0 * area[:, None] * ww.ravel()[None, :]
    return points.reshape(-1, 2), weights.ravel()
