"""Read one tensile-test export into SI channels, with the metadata lines written above the table.

Handles `,` `;` or tab delimiters, decimal commas, quoted numbers with thousands separators,
metadata lines before the table, units in the header or in a units row, footers, upper-case
extensions and zip archives holding one CSV. Bad files raise `CalibrationError` naming the
file, the line and what was expected.
"""

from __future__ import annotations

import csv
import logging
import zipfile
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from printgen.calibrate.columns import (
    ROLES,
    is_units_row,
    normalise_unit,
    role_of,
    split_name_unit,
    unit_factor,
)
from printgen.calibrate.numbers import decimal_of, parse_number
from printgen.errors import CalibrationError

log = logging.getLogger(__name__)

DELIMITERS = (";", "\t", ",")  # preferred first: a decimal comma would split a ',' file
SNIFF_ROWS = 40  # rows from the table's end used to choose the decimal separator
TEXT_SUFFIXES = (".csv", ".txt", ".tsv", ".dat")


@dataclass(frozen=True)
class MetaItem:
    """A `key, value, unit` line written above the table."""

    key: str
    text: str
    number: float | None
    unit: str | None
    line: int


@dataclass(frozen=True)
class TestRecord:
    """One export: channels in SI (N, m, strain as a number, Pa, s) keyed by role."""

    path: str
    channels: dict[str, np.ndarray]
    names: dict[str, str]  # role -> header of the column used
    headers: tuple[str, ...]
    metadata: tuple[MetaItem, ...] = ()
    delimiter: str = ","
    decimal: str = "."
    first_data_line: int = 1
    lines: np.ndarray = field(default_factory=lambda: np.zeros(0, int))  # file line per row

    def has(self, role: str) -> bool:
        return role in self.channels


def read_text(path: str | Path) -> tuple[str, str]:
    """(text, display name) of an export; a zip must hold exactly one text file."""
    p = Path(path)
    if not p.is_file():
        raise CalibrationError(f"{p}: file not found; check the path")
    if p.suffix.lower() == ".zip":
        with zipfile.ZipFile(p) as z:
            names = [n for n in z.namelist()
                     if n.lower().endswith(TEXT_SUFFIXES) and not n.startswith("__MACOSX")]
            if len(names) != 1:
                raise CalibrationError(f"{p}: expected one CSV inside the zip, found {names}")
            return _decode(z.read(names[0]), p), f"{p}:{names[0]}"
    return _decode(p.read_bytes(), p), str(p)


def _decode(data: bytes, p: Path) -> str:
    for enc in ("utf-8-sig", "cp1252"):
        try:
            return data.decode(enc)
        except UnicodeDecodeError:
            continue
    raise CalibrationError(f"{p}: not a text file (neither UTF-8 nor Windows-1252)")


def read_export(path: str | Path, *, columns: Mapping[str, str] | None = None,
                units: Mapping[str, str] | None = None, delimiter: str | None = None,
                decimal: str | None = None) -> TestRecord:
    """Read an export; `columns` maps a role to a header name or 1-based index, `units` a role
    to the unit of its column (overriding the file)."""
    text, where = read_text(path)
    lines = text.splitlines()
    delim = delimiter or _sniff_delimiter(lines, where)
    rows = [(i + 1, next(csv.reader([ln], delimiter=delim), [])) for i, ln in enumerate(lines)]
    rows = [(n, [c.strip() for c in r]) for n, r in rows if any(c.strip() for c in r)]
    tail = [c for _, r in rows[-SNIFF_ROWS:] for c in r]
    dec = decimal or decimal_of(tail)
    start = _table_start(rows, dec, where, delim)
    ncols = len(rows[start][1])
    headers, unit_row, meta_end = _header(rows, start, ncols)
    data, line_no = _body(rows[start:], ncols, dec, where, headers, delim)
    unknown = sorted(set(units or {}) - set(ROLES))
    if unknown:
        raise CalibrationError(f"unknown column role {unknown[0]!r} in the units; roles: "
                               f"{', '.join(ROLES)}")
    roles = _assign(headers, columns or {}, where)
    channels, names = {}, {}
    for role, j in roles.items():
        unit = (units or {}).get(role)
        if unit is not None:
            unit = normalise_unit(unit)
        elif unit_row is not None and unit_row[j].strip():
            unit = normalise_unit(unit_row[j])
        else:
            unit = split_name_unit(headers[j])[1] if headers else None
        col = headers[j] if headers else f"column {j + 1}"
        channels[role] = data[:, j] * unit_factor(role, unit, where=f"{where}: column {col!r}")
        names[role] = col
    meta = tuple(m for n, r in rows[:meta_end] if (m := _meta(n, r, dec)) is not None)
    return TestRecord(where, channels, names, tuple(headers), meta, delim, dec,
                      rows[start][0], line_no)


def _sniff_delimiter(lines: list[str], where: str) -> str:
    """The first of DELIMITERS that splits most lines into the same number (>= 2) of fields."""
    body = [ln for ln in lines if ln.strip()]
    for d in DELIMITERS:
        counts = np.array([len(next(csv.reader([ln], delimiter=d))) for ln in body])
        if counts.size == 0:
            break
        values, freq = np.unique(counts, return_counts=True)
        mode = values[np.argmax(freq)]
        if mode >= 2 and freq.max() * 2 >= counts.size:
            return d
    raise CalibrationError(
        f"{where}: no table found; expected rows of at least 2 values separated by ',', ';' "
        "or tab, the same number on most rows (give --delimiter if the file uses another)"
    )


def _numeric(cells: list[str], dec: str) -> bool:
    return all(parse_number(c, dec) is not None for c in cells)


def _table_start(rows: list[tuple[int, list[str]]], dec: str, where: str, delim: str) -> int:
    for k in range(len(rows) - 1):
        r, nxt = rows[k][1], rows[k + 1][1]
        if len(r) >= 2 and len(nxt) == len(r) and _numeric(r, dec) and _numeric(nxt, dec):
            return k
    raise CalibrationError(
        f"{where}: no numeric table found; expected at least two rows of numbers separated by "
        f"{_show(delim)} with decimal {dec!r} (give --delimiter / --decimal if detection failed)"
    )


def _header(rows, start: int, ncols: int) -> tuple[list[str], list[str] | None, int]:
    """(headers or [], units row or None, index where metadata lines end)."""
    k = start - 1
    units = None
    if k >= 0 and len(rows[k][1]) == ncols and is_units_row(rows[k][1]):
        units, k = rows[k][1], k - 1
    if k >= 0 and len(rows[k][1]) == ncols and not any(
            parse_number(c, ".") is not None for c in rows[k][1]):
        return rows[k][1], units, k
    return [], units, k + 1


def _body(rows, ncols: int, dec: str, where: str, headers: list[str], delim: str):
    out, line_no = [], []
    for idx, (n, r) in enumerate(rows):
        vals = [parse_number(c, dec) for c in r] if len(r) == ncols else None
        if vals is not None and None not in vals:
            out.append(vals)
            line_no.append(n)
            continue
        if not any(len(r2) == ncols and _numeric(r2, dec) for _, r2 in rows[idx + 1:]):
            log.info("%s: table ends at line %d (footer follows)", where, n)
            break
        if vals is None:
            raise CalibrationError(f"{where}:{n}: expected {ncols} values separated by "
                                   f"{_show(delim)}, found {len(r)}: {delim.join(r)!r}")
        j = vals.index(None)
        col = headers[j] if headers else f"column {j + 1}"
        raise CalibrationError(f"{where}:{n}: column {col!r} holds {r[j]!r}; expected a number "
                               f"with decimal {dec!r}")
    return np.array(out, dtype=float), np.array(line_no, dtype=int)


def _assign(headers: list[str], chosen: Mapping[str, str], where: str) -> dict[str, int]:
    """role -> column index, from the options first, then from the header names."""
    roles: dict[str, int] = {}
    for role, key in chosen.items():
        if role not in ROLES:
            raise CalibrationError(f"unknown column role {role!r}; roles: {', '.join(ROLES)}")
        roles[role] = _find_column(headers, key, where)
    for j, h in enumerate(headers):
        role = role_of(split_name_unit(h)[0])
        if role is not None and role not in roles and j not in roles.values():
            roles[role] = j
    if "force" not in roles and "stress" not in roles:
        raise CalibrationError(
            f"{where}: no force or stress column among {headers or 'the unnamed columns'}; "
            "name one with --column force=NAME (or a 1-based index)"
        )
    return roles


def _find_column(headers: list[str], key: str, where: str) -> int:
    if key.isdigit():
        j = int(key) - 1
        if headers and not 0 <= j < len(headers):
            raise CalibrationError(f"{where}: column {key} out of range 1..{len(headers)}")
        return j
    for j, h in enumerate(headers):
        if key.strip().lower() in (h.strip().lower(), split_name_unit(h)[0].lower()):
            return j
    raise CalibrationError(f"{where}: no column named {key!r}; columns: {', '.join(headers)}")


def _meta(line: int, cells: list[str], dec: str) -> MetaItem | None:
    if len(cells) == 1:
        for sep in (":", "="):
            if sep in cells[0]:
                cells = [s.strip() for s in cells[0].split(sep, 1)]
                break
    key = cells[0].strip().rstrip(":=").strip()
    rest = [c for c in cells[1:] if c.strip()]
    if not key or not rest:
        return None
    text, unit = rest[0], (normalise_unit(rest[1]) if len(rest) > 1 else None)
    number = parse_number(text, dec)
    if number is None and unit is None:
        parts = text.strip().split()
        if len(parts) == 2 and parse_number(parts[0], dec) is not None:
            number, unit = parse_number(parts[0], dec), normalise_unit(parts[1])
    return MetaItem(key, text, number, unit, line)


def _show(delim: str) -> str:
    return {"\t": "tab", ",": "','", ";": "';'"}.get(delim, repr(delim))
