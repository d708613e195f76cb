"""Regenerate the README's performance table from the benchmarks.

Run: ``python benchmarks/performance_table.py`` (``--dry-run`` prints the table without
writing the README; ``--only SCRIPT`` reruns one benchmark and keeps the other rows). Each
benchmark of ``BENCHMARKS`` runs in its own process with ``FIXPLAN_PERFORMANCE_ROWS`` set; the
rows it emits (:mod:`performance_rows`) replace the table between the README's markers, in the
order of ``BENCHMARKS``, with the date and the machine's load average before each run. Figures
are those of one run on a shared machine: compare the ratios, not the absolute times.
"""

from __future__ import annotations

import argparse
import datetime
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

from performance_rows import ROWS_VARIABLE

HERE = Path(__file__).resolve().parent
README = HERE.parent / "README.md"
START = "<!-- performance-table:start -->"
END = "<!-- performance-table:end -->"

#: The benchmarks behind the table, with their arguments, in the table's order.
BENCHMARKS = (
    ("bench_limit_surface.py", ()),
    ("bench_models.py", ()),
    ("bench_planner.py", ()),
    ("bench_exact.py", ()),
    ("bench_realtime.py", ()),
    ("bench_pushing.py", ()),
)


def run(script: str, arguments: tuple[str, ...]) -> list[dict]:
    """The rows ``script`` emits, with the load average before it ran."""
    with tempfile.TemporaryDirectory() as folder:
        rows_path = Path(folder) / "rows.jsonl"
        environment = dict(os.environ, **{ROWS_VARIABLE: str(rows_path)})
        load = os.getloadavg()[0]
        command = [sys.executable, str(HERE / script), *arguments]
        subprocess.run(command, check=True, cwd=HERE, env=environment, stdout=subprocess.DEVNULL)
        lines = rows_path.read_text(encoding="utf-8").splitlines() if rows_path.exists() else []
    rows = [json.loads(line) for line in lines]
    for row in rows:
        row["load"] = load
    return rows


def render(rows: list[dict]) -> str:
    """The markdown table of ``rows``."""
    stamp = datetime.date.today().isoformat()
    lines = [
        START,
        f"Regenerated on {stamp} by `python benchmarks/performance_table.py` (one run per "
        "benchmark on this 2-core machine; load average before each run in the last column).",
        "",
        "| figure | fixplan | baseline in the same run | ratio | benchmark (load) |",
        "|---|---|---|---|---|",
    ]
    for row in rows:
        cells = (row["figure"], row["fixplan"], row["baseline"], row["ratio"])
        source = f"`{row['script']}` ({row['load']:.1f})"
        lines.append("| " + " | ".join((*cells, source)) + " |")
    lines.append(END)
    return "\n".join(lines)


def current_rows(text: str) -> list[dict]:
    """The rows of the table now in the README (for ``--only``)."""
    block = text.split(START, 1)[1].split(END, 1)[0]
    rows = []
    for line in block.splitlines():
        cells = [cell.strip() for cell in line.strip().strip("|").split("|")]
        if len(cells) != 5 or cells[0] in ("figure", "---"):
            continue
        script, load = cells[4].rsplit(" (", 1)
        rows.append(dict(zip(("figure", "fixplan", "baseline", "ratio"), cells[:4], strict=True),
                         script=script.strip("`"), load=float(load.rstrip(")"))))  # fmt: skip
    return rows


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--dry-run", action="store_true", help="print, do not write the README")
    parser.add_argument("--only", help="rerun this benchmark script only, keep the other rows")
    args = parser.parse_args()
    text = README.read_text(encoding="utf-8")
    if START not in text or END not in text:
        sys.exit(f"{README}: the markers {START} and {END} are missing")
    kept = current_rows(text) if args.only else []
    rows = []
    for script, arguments in BENCHMARKS:
        if args.only and script != args.only:
            rows += [row for row in kept if row["script"] == script]
            continue
        print(f"running {script} ...", flush=True)
        rows += run(script, arguments)
    table = render(rows)
    print(table)
    if not args.dry_run:
        before, rest = text.split(START, 1)
        README.write_text(before + table + rest.split(END, 1)[1], encoding="utf-8")
        print(f"wrote {README}")


if __name__ == "__main__":
    main()
