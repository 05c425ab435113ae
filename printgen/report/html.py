"""A self-contained HTML report: headings, paragraphs, tables, and PNG figures embedded as
base64, so one file can be mailed or opened offline. Plain data in, text out."""

from __future__ import annotations

import base64
import html
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

CSS = """
body { font-family: system-ui, sans-serif; max-width: 1100px; margin: 2em auto; color: #222;
       line-height: 1.45; padding: 0 1em; }
h1 { font-size: 1.6em; border-bottom: 2px solid #2a6; padding-bottom: .2em; }
h2 { font-size: 1.25em; margin-top: 1.8em; color: #164; }
table { border-collapse: collapse; margin: .8em 0; font-size: .92em; }
th, td { border: 1px solid #ccc; padding: .25em .6em; text-align: right; }
th { background: #eef5f0; } td.t { text-align: left; } td:first-child, th:first-child { text-align: left; }
.pass { color: #fff; background: #2a6; padding: .1em .5em; border-radius: .3em; }
.fail { color: #fff; background: #c33; padding: .1em .5em; border-radius: .3em; }
.undecided { color: #fff; background: #c80; padding: .1em .5em; border-radius: .3em; }
.note { color: #555; font-size: .9em; }
figure { margin: 1em 0; } figcaption { color: #555; font-size: .9em; }
img { max-width: 100%; }
.summary { border: 2px solid #2a6; border-radius: .4em; padding: .2em 1em; background: #f6fbf7; }
.summary h2 { margin-top: .4em; } .verdict { font-size: 1.15em; }
"""


@dataclass(frozen=True)
class FigureFile:
    """A figure of the report as its own files: `name` (no suffix), PNG and SVG bytes."""

    name: str
    caption: str
    png: bytes
    svg: bytes
    labels: tuple[tuple[str, tuple[str, ...]], ...] = ()  # (axis title, its axis labels)
    also: str = ""  # a file beside the report the PNG is written to as well (assembly.png)


@dataclass(frozen=True)
class Drawing:
    """A figure still to be drawn: `fn(*args, **kwargs)` gives its PNG bytes (carrying their
    SVG: printgen.report.plots). A module-level function and picklable arguments, so that
    `Report.draw` can draw a report's figures side by side in worker processes."""

    fn: Callable[..., bytes]
    args: tuple = ()
    kwargs: dict[str, Any] = field(default_factory=dict)
    cost: float = 1.0  # its drawing time relative to the others': the costliest go first

    def job(self) -> tuple:
        """(fn, args, kwargs), as printgen.executor.local.run_jobs takes it."""
        return self.fn, self.args, self.kwargs


class _Slot(str):
    """The place in `Report.blocks` of a figure not drawn yet (its HTML comes with
    `Report.fill`); `file` holds its place in `Report.figures`."""

    drawing: Drawing
    file: FigureFile


@dataclass
class Report:
    """Blocks of HTML in order; `add_*` append, `html()` renders. `lead` (the summary box)
    comes first, right under the title; `figures` are the figures added, for their files."""

    title: str
    blocks: list[str] = field(default_factory=list)
    lead: str = ""
    figures: list[FigureFile] = field(default_factory=list)

    def heading(self, text: str) -> None:
        self.blocks.append(f"<h2>{html.escape(text)}</h2>")

    def paragraph(self, text: str, cls: str = "") -> None:
        attr = f' class="{cls}"' if cls else ""
        self.blocks.append(f"<p{attr}>{html.escape(text)}</p>")

    def verdict(self, ok: bool | str, text: str) -> None:
        """A verdict line: `ok` True/False (PASS/FAIL) or the verdict's word (PASS, FAIL,
        UNDECIDED)."""
        word = ok if isinstance(ok, str) else ("PASS" if ok else "FAIL")
        tag = f'<span class="{word.lower()}">{html.escape(word)}</span>'
        self.blocks.append(f"<p>{tag} {html.escape(text)}</p>")

    def table(self, columns: list[str], rows: list[list[str]]) -> None:
        head = "".join(f"<th>{html.escape(c)}</th>" for c in columns)
        body = "".join("<tr>" + "".join(_cell(v) for v in r) + "</tr>" for r in rows)
        self.blocks.append(f"<table><thead><tr>{head}</tr></thead><tbody>{body}</tbody></table>")

    def figure(self, png: bytes | Drawing, caption: str, name: str = "", also: str = ""
               ) -> None:
        """Embed `png`; when it carries its SVG (printgen.report.plots), keep both as the
        figure `name` (default: from the caption) for the files beside the report (and the
        PNG as `also` too, when given). A `Drawing` keeps its places (in `blocks` and
        `figures`) until `fill` puts it in."""
        name = name or slug(caption)
        if isinstance(png, Drawing):
            slot = _Slot(f"<!-- figure {name}: to be drawn -->")
            slot.drawing, slot.file = png, FigureFile(name, caption, b"", b"", also=also)
            self.blocks.append(slot)
            self.figures.append(slot.file)
            return
        file = _figure_file(png, caption, name, also)
        if file is not None:
            self.figures.append(file)
        self.blocks.append(_figure_block(png, caption))

    def pending(self) -> list[Drawing]:
        """The drawings of the figures not drawn yet, in report order."""
        return [b.drawing for b in self.blocks if isinstance(b, _Slot)]

    def fill(self, pngs: list[bytes]) -> None:
        """Put in the figures of `pending`, drawn (`pngs`, in its order)."""
        slots = [(k, b) for k, b in enumerate(self.blocks) if isinstance(b, _Slot)]
        if len(pngs) != len(slots):
            raise ValueError(f"{len(pngs)} figures drawn for {len(slots)} to draw")
        for (k, slot), png in zip(slots, pngs, strict=True):
            at = next(i for i, f in enumerate(self.figures) if f is slot.file)
            file = _figure_file(png, slot.file.caption, slot.file.name, slot.file.also)
            self.figures[at:at + 1] = [] if file is None else [file]
            self.blocks[k] = _figure_block(png, slot.file.caption)

    def draw(self) -> None:
        """Draw the figures not drawn yet, side by side in worker processes when there are
        several and two cores (printgen.executor.local.run_jobs), and put them in."""
        todo = self.pending()
        if todo:
            self.fill(drawn(todo))

    def html(self) -> str:
        self.draw()
        body = "\n".join(self.blocks)
        return (f"<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">"
                f"<title>{html.escape(self.title)}</title><style>{CSS}</style></head>\n"
                f"<body><h1>{html.escape(self.title)}</h1>\n{self.lead}\n{body}\n</body></html>\n")


def drawn(drawings: list[Drawing]) -> list[bytes]:
    """Each drawing's PNG, side by side in worker processes when there are several and two
    cores (printgen.executor.local.run_jobs), the costliest started first (the worker that takes the
    last one should not start a long one late); in the drawings' order."""
    from printgen.executor.local import run_jobs

    order = sorted(range(len(drawings)), key=lambda i: -drawings[i].cost)
    pngs = run_jobs([drawings[i].job() for i in order])
    return [pngs[order.index(i)] for i in range(len(drawings))]


def _figure_file(png: bytes, caption: str, name: str, also: str) -> FigureFile | None:
    """The figure's files when `png` carries its SVG (printgen.report.plots), else None."""
    svg = getattr(png, "svg", None)
    if svg is None:
        return None
    labels = tuple((t, tuple(names)) for t, names in getattr(png, "labels", ()))
    return FigureFile(name, caption, bytes(png), svg, labels, also)


def _figure_block(png: bytes, caption: str) -> str:
    data = base64.b64encode(png).decode("ascii")
    return (f'<figure><img alt="{html.escape(caption)}" src="data:image/png;base64,{data}">'
            f"<figcaption>{html.escape(caption)}</figcaption></figure>")


def _cell(v: object) -> str:
    """A table cell; text that is not a number is left-aligned."""
    text = str(v)
    numeric = text.replace("%", "").replace("+", "").replace("x", "").strip()
    try:
        float(numeric.split()[0] if numeric else "")
        cls = ""
    except ValueError:
        cls = ' class="t"'
    return f"<td{cls}>{html.escape(text)}</td>"


def slug(text: str, words: int = 5) -> str:
    """A file name from the first `words` words of `text`: lower case, a-z0-9 and '-'."""
    kept = "".join(ch if ch.isalnum() else " " for ch in text.lower()).split()[:words]
    return "-".join(kept) or "figure"
