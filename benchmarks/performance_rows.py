"""Rows of the README's performance table, emitted by the benchmarks as they measure.

A benchmark calls :func:`emit` for each headline figure; when the environment variable
``FIXPLAN_PERFORMANCE_ROWS`` names a file (as ``performance_table.py`` sets it), the row is
appended there as one JSON line, otherwise nothing happens (a benchmark run by hand only
prints).
"""

from __future__ import annotations

import json
import os
import sys
from pathlib import Path

ROWS_VARIABLE = "FIXPLAN_PERFORMANCE_ROWS"


def emit(figure: str, fixplan: str, baseline: str = "", ratio: str = "") -> None:
    """Record one row: what was measured, fixplan's figure, the baseline measured in the same
    run, and their ratio (all as printed text)."""
    path = os.environ.get(ROWS_VARIABLE)
    if not path:
        return
    row = {
        "script": Path(sys.argv[0]).name,
        "figure": figure,
        "fixplan": fixplan,
        "baseline": baseline,
        "ratio": ratio,
    }
    with open(path, "a", encoding="utf-8") as rows:
        rows.write(json.dumps(row) + "\n")
