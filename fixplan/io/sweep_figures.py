"""Figures of a sweep: the objective value and the smallest safety factor against each varied
key, one PNG per key (Agg canvas, no date metadata: equal tables give equal files).

Every case is a dot; where the other keys vary too, the dots above one value of the key show
their spread. Cases without a solution (infeasible, invalid input, errors) are counted in the
title.
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from pathlib import Path

import numpy as np
import pandas as pd

from fixplan.io.figures import DPI, save_png
from fixplan.planner.problem import FIXED_FORCE_OBJECTIVES


def figure_name(key: str) -> str:
    """The file name of ``key``'s figure, e.g. ``objective-vs-contacts-1-mu.png``."""
    return "objective-vs-" + re.sub(r"[^A-Za-z0-9]+", "-", key).strip("-") + ".png"


def write_sweep_figures(
    folder: Path, table: pd.DataFrame, keys: Sequence[str], objective: str
) -> list[Path]:
    """One figure per key of ``table`` in ``folder`` (created); returns the files written."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    folder.mkdir(parents=True, exist_ok=True)
    unit = "" if objective in FIXED_FORCE_OBJECTIVES else " [N]"
    solved = table["status"] == "optimal"
    written = []
    for key in keys:
        fig = Figure(figsize=(6.4, 5.6), dpi=DPI, layout="constrained")
        FigureCanvasAgg(fig)
        top, bottom = fig.subplots(2, 1, sharex=True)
        x = table.loc[solved, key].to_numpy(float)
        top.plot(x, table.loc[solved, "objective_value"].to_numpy(float), ".", color="tab:blue")
        top.set_ylabel(f"{objective}{unit}")
        safety = table.loc[solved, "safety_factor"].to_numpy(float)
        bottom.plot(x, np.where(np.isinf(safety), np.nan, safety), ".", color="tab:red")
        bottom.axhline(1.0, color="0.5", linewidth=0.8)
        finite = safety[np.isfinite(safety)]
        bottom.set_ylim(0.0, max(1.2, 1.1 * finite.max()) if finite.size else 1.2)
        bottom.set_ylabel("smallest safety factor")
        bottom.set_xlabel(key)
        failed = int((~solved).sum())
        top.set_title(f"{int(solved.sum())} cases solved" + (f", {failed} not" if failed else ""))
        path = folder / figure_name(key)
        save_png(fig, path)
        written.append(path)
    return written


__all__ = ["figure_name", "write_sweep_figures"]
