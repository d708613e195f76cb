"""Report documents: blocks (headings, paragraphs, tables, lists, images) rendered to Markdown
and HTML, and a report folder written all at once or not at all.

A report is built once as a list of blocks and rendered to both formats from them; nothing in
the output depends on the time or the machine's paths, so equal inputs give byte-identical files.
"""

from __future__ import annotations

import contextlib
import html
import os
import re
import shutil
import uuid
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path

from fixplan.errors import FixplanError
from fixplan.io import figures

#: The file of a report folder that names the files of the report last written there: the next
#: report into the folder removes those it does not write again (files of others stay).
MANIFEST = ".fixplan-report"

_MARKDOWN_SPECIAL = re.compile(r"([\\`*_<>|])")
_MARKDOWN_LINK = re.compile(r"([\[\]])")
_CSS = """\
body { font-family: sans-serif; max-width: 70em; margin: 2em auto; padding: 0 1em; color: #222; }
table { border-collapse: collapse; margin: 0.5em 0 1em; }
th, td { border: 1px solid #bbb; padding: 0.25em 0.6em; text-align: left; vertical-align: top; }
th { background: #eee; }
code { font-size: 0.9em; background: #f4f4f4; padding: 0 0.2em; }
figure { margin: 1em 0; }
figure img { max-width: 100%; border: 1px solid #ddd; }
figcaption { font-size: 0.9em; color: #444; }
"""


class ReportError(FixplanError, OSError):
    """The report folder cannot be created or written."""


# -- document blocks ----------------------------------------------------------------------------


@dataclass(frozen=True, slots=True)
class Code:
    """Inline code (verbatim text)."""

    text: str


#: Inline text: plain strings and code spans.
Inline = tuple[str | Code, ...]


@dataclass(frozen=True, slots=True)
class Heading:
    level: int
    text: Inline


@dataclass(frozen=True, slots=True)
class Paragraph:
    text: Inline


@dataclass(frozen=True, slots=True)
class Table:
    header: tuple[str, ...]
    rows: tuple[tuple[Inline, ...], ...]


@dataclass(frozen=True, slots=True)
class List:
    items: tuple[Inline, ...]


@dataclass(frozen=True, slots=True)
class Image:
    file: str
    alt: str
    caption: Inline


Block = Heading | Paragraph | Table | List | Image


def inline(*parts: str | Code) -> Inline:
    return tuple(parts)


def _markdown_inline(text: Inline, *, in_table: bool = False) -> str:
    """Markdown of ``text``; in a table cell ``|`` is escaped inside code spans too (GFM)."""
    out = []
    for part in text:
        if isinstance(part, Code):
            body = part.text.replace("|", "\\|") if in_table else part.text
            fence, pad = ("``", " ") if "`" in body else ("`", "")
            out.append(f"{fence}{pad}{body}{pad}{fence}")
        else:
            out.append(_markdown_escape(part))
    return "".join(out).replace("\n", " ")


def _markdown_escape(text: str) -> str:
    """``text`` with Markdown's emphasis, code, HTML and table characters escaped; brackets only
    where they could form a link (so units read ``[N]``)."""
    text = _MARKDOWN_SPECIAL.sub(r"\\\1", text)
    return _MARKDOWN_LINK.sub(r"\\\1", text) if "](" in text else text


def _html_inline(text: Inline) -> str:
    return "".join(
        f"<code>{html.escape(p.text)}</code>" if isinstance(p, Code) else html.escape(p)
        for p in text
    )


def to_markdown(blocks: Sequence[Block]) -> str:
    chunks = []
    for block in blocks:
        if isinstance(block, Heading):
            chunks.append("#" * block.level + " " + _markdown_inline(block.text))
        elif isinstance(block, Paragraph):
            chunks.append(_markdown_inline(block.text))
        elif isinstance(block, List):
            chunks.append("\n".join("- " + _markdown_inline(item) for item in block.items))
        elif isinstance(block, Table):
            header = [_markdown_inline((h,), in_table=True) for h in block.header]
            lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
            for row in block.rows:
                cells = [_markdown_inline(cell, in_table=True) for cell in row]
                lines.append("| " + " | ".join(cells) + " |")
            chunks.append("\n".join(lines))
        else:
            alt = _MARKDOWN_LINK.sub(r"\\\1", _markdown_escape(block.alt))
            chunks.append(f"![{alt}]({block.file})\n\n{_markdown_inline(block.caption)}")
    return "\n\n".join(chunks) + "\n"


def to_html(blocks: Sequence[Block], title: str) -> str:
    body = []
    for block in blocks:
        if isinstance(block, Heading):
            level = block.level
            body.append(f"<h{level}>{_html_inline(block.text)}</h{level}>")
        elif isinstance(block, Paragraph):
            body.append(f"<p>{_html_inline(block.text)}</p>")
        elif isinstance(block, List):
            items = "".join(f"<li>{_html_inline(item)}</li>" for item in block.items)
            body.append(f"<ul>{items}</ul>")
        elif isinstance(block, Table):
            header = "".join(f"<th>{html.escape(h)}</th>" for h in block.header)
            rows = "\n".join(
                "<tr>" + "".join(f"<td>{_html_inline(cell)}</td>" for cell in row) + "</tr>"
                for row in block.rows
            )
            body.append(
                f"<table>\n<thead><tr>{header}</tr></thead>\n<tbody>\n{rows}\n</tbody>\n</table>"
            )
        else:
            body.append(
                f'<figure><img src="{html.escape(block.file)}" alt="{html.escape(block.alt)}">'
                f"<figcaption>{_html_inline(block.caption)}</figcaption></figure>"
            )
    return (
        '<!DOCTYPE html>\n<html lang="en">\n<head>\n<meta charset="utf-8">\n'
        f"<title>{html.escape(title)}</title>\n<style>\n{_CSS}</style>\n</head>\n<body>\n"
        + "\n".join(body)
        + "\n</body>\n</html>\n"
    )


class Writer:
    """Writes the files of one report and keeps the list of what it wrote."""

    def __init__(self, directory: Path):
        self.directory = directory
        self.written: list[Path] = []

    def save(self, name: str, save: Callable[[Path], object]) -> None:
        """Write the file ``name`` with ``save(path)``; an OS error becomes a ReportError."""
        path = self.directory / name
        try:
            save(path)
        except OSError as exc:
            raise ReportError(f"cannot write {path}: {exc.strerror or exc}") from exc
        self.written.append(path)

    def write(self, name: str, content: bytes) -> None:
        self.save(name, lambda path: path.write_bytes(content))

    def figure(self, name: str, draw: Callable[[], object]) -> None:
        self.save(name, lambda path: figures.save_png(draw(), path))

    def document(self, blocks: Sequence[Block], title: str) -> None:
        """``report.md`` and ``report.html`` of ``blocks``."""
        self.write("report.md", to_markdown(blocks).encode("utf-8"))
        self.write("report.html", to_html(blocks, title).encode("utf-8"))


@contextlib.contextmanager
def staged_folder(directory: Path) -> Iterator[Path]:
    """A temporary folder for the files of the report folder ``directory``; on success its
    files are moved there (the folder is created) and the files of the report written there
    before that this one does not write again are removed (:data:`MANIFEST`), on failure it is
    removed."""
    if directory.is_file():
        raise ReportError(f"cannot write the report folder {directory}: a file has its name")
    try:
        parent = next(p for p in directory.absolute().parents if p.exists())
        staging = parent / f".{directory.name[:40]}.partial-{uuid.uuid4().hex[:12]}"
        staging.mkdir()
    except (OSError, ValueError) as exc:
        raise ReportError(f"cannot create the report folder {directory}: {exc}") from exc
    try:
        yield staging
        names = sorted(path.name for path in staging.iterdir())
        (staging / MANIFEST).write_text("".join(f"{name}\n" for name in names), "utf-8")
        if directory.is_dir():
            # Stale files first: on a file system that ignores case, a figure renamed only in
            # case is the same file as the new one.
            for name in _reported(directory) - set(names):
                (directory / name).unlink(missing_ok=True)
            for name in names:
                os.replace(staging / name, directory / name)
            if not (directory / MANIFEST).is_dir():  # (the list last: a folder of its name stays)
                os.replace(staging / MANIFEST, directory / MANIFEST)
        else:
            directory.parent.mkdir(parents=True, exist_ok=True)
            os.replace(staging, directory)
    except OSError as exc:
        raise ReportError(f"cannot write the report folder {directory}: {exc}") from exc
    finally:
        shutil.rmtree(staging, ignore_errors=True)


def _reported(directory: Path) -> set[str]:
    """The files of the report last written into ``directory`` (:data:`MANIFEST`) that are
    still there: plain names of files in it (a name with a path in it is not one; a name the
    file system refuses, such as one too long, names none)."""
    try:
        listed = (directory / MANIFEST).read_text("utf-8").splitlines()
    except (OSError, UnicodeDecodeError):
        return set()
    return {
        name for name in listed
        if name not in ("", ".", "..", MANIFEST) and Path(name).name == name
        and "\\" not in name and os.path.isfile(directory / name)
    }  # fmt: skip
