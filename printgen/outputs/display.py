"""What a result shows in a notebook or a terminal: a few lines of text (`repr`) and a compact
HTML table (`_repr_html_`, Jupyter's rich display) of its verdict and key numbers, where the
dataclass's own repr printed every array (a `make` run's ran to megabytes). `to_record()` and
the result's fields keep everything; tables of curves come from `frame`."""

from __future__ import annotations

import html
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

from printgen.errors import PrintgenError

MAX_REPR_CHARS = 2000  # a repr longer than this is cut: a notebook shows a summary, not data
VERDICT_COLOURS = {"PASS": "#1a7f37", "FAIL": "#cf222e"}  # green, red; others: the text's


@dataclass(frozen=True)
class Summary:
    """A result's title, verdict ("" when it has none) and key numbers: (label, value text)
    rows, the values already formatted with their units."""

    title: str
    rows: tuple[tuple[str, str], ...] = ()
    verdict: str = ""

    def text(self) -> str:
        """`Title: VERDICT` then one `label: value` line per row, at most MAX_REPR_CHARS."""
        head = f"{self.title}: {self.verdict}" if self.verdict else self.title
        out = "\n".join([head, *(f"  {label}: {value}" for label, value in self.rows)])
        return out if len(out) <= MAX_REPR_CHARS else out[:MAX_REPR_CHARS - 3] + "..."

    def html(self) -> str:
        """A two-column HTML table under the title and the verdict, every text escaped."""
        colour = VERDICT_COLOURS.get(self.verdict)
        verdict = (f' <span style="color:{colour};font-weight:bold">'
                   f"{html.escape(self.verdict)}</span>" if self.verdict else "")
        cells = "".join(f'<tr><th style="text-align:left">{html.escape(label)}</th>'
                        f'<td style="text-align:left">{html.escape(value)}</td></tr>'
                        for label, value in self.rows)
        return (f"<div><strong>{html.escape(self.title)}</strong>{verdict}"
                f"<table>{cells}</table></div>")


class Shown:
    """A result shown by its `summary()`: `repr` its text, `_repr_html_` its table. A
    dataclass using it is declared with `repr=False` (else the dataclass writes its own)."""

    def summary(self) -> Summary:
        raise NotImplementedError

    def __repr__(self) -> str:
        return self.summary().text()

    def _repr_html_(self) -> str:
        return self.summary().html()


def frame(rows: Sequence[dict[str, Any]], what: str) -> Any:
    """`rows` (dicts of the same keys, in order) as a pandas DataFrame; PrintgenError naming
    the `table` extra when pandas is not installed (`what`: the table, for the message)."""
    try:
        import pandas as pd
    except ImportError as exc:
        raise PrintgenError(f"{what} as a DataFrame needs pandas: pip install "
                            "'printgen[table]' (or use the list of rows it is built from)"
                            ) from exc
    return pd.DataFrame.from_records(list(rows))


def percent(x: float) -> str:
    """A signed share as a percentage: 0.123 -> '+12%'."""
    return f"{x:+.0%}"
