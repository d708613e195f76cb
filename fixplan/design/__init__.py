"""Layer 5: a fixture designer's studies built on the planner — layout search over candidate
contacts (:mod:`fixplan.design.layout`, ``fixplan.layout``) and sweeps of a problem's inputs
(designs of experiments, parallel solves with Dask).

Imports only from :mod:`fixplan.planner` and the layers below; problem files enter through
:mod:`fixplan.io.sweep`, which gives each case's problem to :func:`run_cases`.
"""

from fixplan.design.experiment import CASE, METHODS, Range, design, grid, latin_hypercube
from fixplan.design.sweep import (
    CHUNK_SIZE,
    SERIAL,
    STATUS_ERROR,
    STATUS_INVALID,
    CaseSource,
    columns,
    load_column,
    run_cases,
    typed,
)

__all__ = [
    "CASE",
    "CHUNK_SIZE",
    "METHODS",
    "SERIAL",
    "STATUS_ERROR",
    "STATUS_INVALID",
    "CaseSource",
    "Range",
    "columns",
    "design",
    "grid",
    "latin_hypercube",
    "load_column",
    "run_cases",
    "typed",
]
