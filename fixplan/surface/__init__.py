"""Layer 1: pressure fields and their exact limit surfaces.

Pressure fields (:mod:`~fixplan.surface.pressure`), the exact limit surface
(:class:`~fixplan.surface.limit_surface.LimitSurface`) with its closed-form and compiled
kernels, and the inverse map. Imports only the top-level ``errors``, ``tolerances`` and
``validation``.
"""

from fixplan.surface import pressure
from fixplan.surface.limit_surface import LimitSurface

__all__ = ["LimitSurface", "pressure"]
