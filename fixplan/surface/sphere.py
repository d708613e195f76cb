"""Evenly spread directions on the unit sphere and circle."""

from __future__ import annotations

import numpy as np


def fibonacci_sphere(n: int) -> np.ndarray:
    """``n`` nearly evenly spread unit vectors ``(n, 3)`` (Fibonacci lattice, deterministic)."""
    if n < 1:
        raise ValueError(f"n must be >= 1, got {n}")
    k = np.arange(n) + 0.5
    z = 1.0 - 2.0 * k / n
    radius = np.sqrt(np.maximum(0.0, 1.0 - z * z))
    angle = np.pi * (3.0 - np.sqrt(5.0)) * k
    return np.column_stack([radius * np.cos(angle), radius * np.sin(angle), z])


def circle(n: int) -> np.ndarray:
    """``n`` evenly spread unit vectors ``(n, 2)``, starting at angle 0."""
    angle = 2.0 * np.pi * np.arange(n) / n
    return np.column_stack([np.cos(angle), np.sin(angle)])
