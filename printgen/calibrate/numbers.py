"""Numbers as test machines write them: decimal point or comma, thousands separators, quotes.

`decimal_of` decides a file's decimal separator from cells that can only be read one way;
`parse_number` reads one cell with it (`"2,554.70532"` -> 2554.70532, `1.234,5` with a decimal
comma -> 1234.5).
"""

from __future__ import annotations

import math
import re
from collections.abc import Iterable

_THOUSANDS_DOT = re.compile(r"^[-+]?\d{1,3}(,\d{3})+(\.\d*)?([eE][-+]?\d+)?$")
_THOUSANDS_COMMA = re.compile(r"^[-+]?\d{1,3}(\.\d{3})+(,\d*)?([eE][-+]?\d+)?$")
# Cells that can only be read one way.
_ONLY_COMMA = (re.compile(r",(\d{1,2}|\d{4,})([eE][-+]?\d+)?$"), re.compile(r"\.\d{3},\d"),
               re.compile(r"^[-+]?0,\d"))
_ONLY_DOT = (re.compile(r"\.(\d{1,2}|\d{4,})([eE][-+]?\d+)?$"), re.compile(r",\d{3}\.\d"),
             re.compile(r"^[-+]?0\.\d"), re.compile(r"\.\d*[eE]"))
_STRIP = str.maketrans("", "", " \u00a0\u202f'\"")


def clean(text: str) -> str:
    """A cell without quotes, spaces and apostrophe or narrow-space thousands separators."""
    return text.strip().translate(_STRIP)


def decimal_of(cells: Iterable[str]) -> str:
    """'.' or ',': the decimal separator the unambiguous cells vote for ('.' on a tie)."""
    comma = dot = 0
    for raw in cells:
        c = clean(raw)
        comma += any(p.search(c) for p in _ONLY_COMMA)
        dot += any(p.search(c) for p in _ONLY_DOT)
    return "," if comma > dot else "."


def parse_number(text: str, decimal: str = ".") -> float | None:
    """The finite float a cell holds with decimal separator `decimal`, or None."""
    c = clean(text)
    if not c:
        return None
    if decimal == ",":
        if _THOUSANDS_COMMA.match(c):
            c = c.replace(".", "")
        if "." in c:
            return None
        c = c.replace(",", ".")
    else:
        if _THOUSANDS_DOT.match(c):
            c = c.replace(",", "")
        if "," in c:
            return None
    try:
        v = float(c)
    except ValueError:
        return None
    return v if math.isfinite(v) else None
