"""``fixplan.layout``: layout synthesis, the names of :mod:`fixplan.design.layout` and
:func:`~fixplan.design.candidates.sample_surface` together."""

from fixplan.design.candidates import sample_surface
from fixplan.design.layout import Layout, LayoutSearch, SearchStats, search

__all__ = ["Layout", "LayoutSearch", "SearchStats", "sample_surface", "search"]
