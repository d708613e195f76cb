"""A layout search's report: ``report.md`` and ``report.html`` with a table of the best layouts,
what the search did, and one PNG figure per layout (``layout-N.png``: the candidates, the chosen
ones and the fixed contacts seen from above and from the side)."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from fixplan.design.layout import Layout, SearchStats
from fixplan.io.problem_file import ProblemFile
from fixplan.io.report_document import (
    Heading,
    Image,
    Paragraph,
    Table,
    Writer,
    inline,
    staged_folder,
)

_ROLE_COLOURS = {"locator": "tab:blue", "support": "tab:cyan", "clamp": "tab:red",
                 "finger": "tab:orange"}  # fmt: skip
#: Resolution of the figures [dots per inch].
FIGURE_DPI = 110
#: Views of the figure: (title, the two world axes drawn).
_VIEWS = (("top view (x, y)", (0, 1)), ("side view (x, z)", (0, 2)))


@dataclass(frozen=True, slots=True)
class _Points:
    """The figure's data: positions [m] and inward normals of every contact, whether each is a
    candidate and chosen, their roles, and the centre of mass [m]."""

    positions: np.ndarray
    normals: np.ndarray
    candidate: np.ndarray
    chosen: np.ndarray
    roles: tuple[str, ...]
    center: np.ndarray


def _number(value: float) -> str:
    return "inf" if np.isinf(value) else f"{value + 0.0:.6g}"


def _points(problem_file: ProblemFile, layout: Layout) -> _Points:
    problem = problem_file.problem
    candidates = {c.name for c in problem_file.candidates}
    contacts = problem.contacts
    return _Points(
        positions=np.array([c.position for c in contacts]),
        normals=np.array([c.normal for c in contacts]),
        candidate=np.array([c.name in candidates for c in contacts]),
        chosen=np.array([c.name in layout.contacts for c in contacts]),
        roles=tuple(c.role for c in contacts),
        center=problem.body.center_of_mass,
    )


def layout_figure(problem_file: ProblemFile, layout: Layout, rank: int):
    """The figure of ``layout``: unused candidates grey, chosen ones coloured by role with their
    normals, fixed contacts black, the centre of mass a cross."""
    data = _points(problem_file, layout)
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=(9.0, 4.2), dpi=FIGURE_DPI, layout="constrained")
    FigureCanvasAgg(fig)
    axes = fig.subplots(1, len(_VIEWS))
    spread = np.ptp(data.positions, axis=0).max() if len(data.positions) > 1 else 1.0
    arrow = 0.12 * max(spread, 1e-6)
    for ax, (title, (a, b)) in zip(axes, _VIEWS, strict=True):
        unused = data.candidate & ~data.chosen
        ax.scatter(data.positions[unused, a], data.positions[unused, b], s=14, color="0.75",
                   label="candidate")  # fmt: skip
        used = data.chosen | ~data.candidate
        for i in np.flatnonzero(used):
            colour = _ROLE_COLOURS[data.roles[i]] if data.candidate[i] else "black"
            p, n = data.positions[i], data.normals[i]
            ax.scatter(p[a], p[b], s=40, color=colour, zorder=3)
            ax.annotate("", xy=(p[a], p[b]), xytext=(p[a] - arrow * n[a], p[b] - arrow * n[b]),
                        arrowprops={"arrowstyle": "->", "color": colour})  # fmt: skip
        ax.scatter(*data.center[[a, b]], marker="x", s=60, color="black", label="centre of mass")
        ax.set_title(title)
        ax.set_xlabel("xyz"[a] + " [m]")
        ax.set_ylabel("xyz"[b] + " [m]")
        ax.set_aspect("equal", adjustable="datalim")
        ax.grid(alpha=0.3)
    for role, colour in _ROLE_COLOURS.items():
        if role in data.roles:
            axes[0].scatter([], [], color=colour, label=f"chosen {role}")
    axes[0].legend(fontsize=7, loc="best")
    value = _number(layout.objective_value)
    fig.suptitle(f"layout {rank}: {layout.plan.objective} = {value}")
    return fig


def write_layout_report(
    directory: Path,
    problem_file: ProblemFile,
    layouts: Sequence[Layout],
    stats: SearchStats,
) -> list[Path]:
    """Write the report of a layout search into ``directory``; returns the files written."""
    blocks = [
        Heading(1, inline(f"Layout search: {problem_file.name}")),
        Paragraph(
            inline(
                f"{len(problem_file.candidates)} candidates, "
                f"{len(problem_file.problem.contacts) - len(problem_file.candidates)} fixed contacts, "
                f"{len(problem_file.problem.loads)} load cases; objective "
                f"{problem_file.problem.objective}; file SHA-256 {problem_file.sha256}."
            )
        ),
        Heading(2, inline("Search")),
        Table(
            (
                "mode",
                "layouts",
                "merged by symmetry",
                "symmetries",
                "invalid",
                "pruned",
                "solved",
                "held",
            ),
            (
                (
                    stats.mode,
                    str(stats.layouts),
                    str(stats.merged),
                    str(stats.symmetries),
                    str(stats.invalid),
                    str(stats.pruned),
                    str(stats.solved),
                    str(stats.feasible),
                ),
            ),
        ),
        Heading(2, inline("Best layouts")),
    ]
    if not layouts:
        blocks.append(Paragraph(inline("No layout of the candidates holds every load case.")))
    rows = tuple(
        (str(rank), _number(layout.objective_value), ", ".join(layout.contacts),
         str(len(layout.equivalents)))
        for rank, layout in enumerate(layouts, start=1)
    )  # fmt: skip
    if rows:
        blocks.append(Table(("rank", "objective", "candidates used", "symmetric twins"), rows))
    for rank, layout in enumerate(layouts, start=1):
        caption = inline(f"Layout {rank}: {', '.join(layout.contacts)}.")
        blocks.append(Image(f"layout-{rank}.png", f"layout {rank}", caption))
    with staged_folder(directory) as staging:
        writer = Writer(staging)
        for rank, layout in enumerate(layouts, start=1):
            writer.figure(f"layout-{rank}.png",
                          lambda layout=layout, rank=rank: layout_figure(problem_file, layout, rank))  # fmt: skip
        writer.document(blocks, f"fixplan layouts: {problem_file.name}")
        names = [path.name for path in writer.written]
    return [directory / name for name in names]
