"""Read one tensile-test export into SI channels, with the metadata lines written above the table.

Handles `,` `;` or tab delimiters, decimal commas, quoted numbers with thousands separators,
metadata lines before the table, units in the header or in a units row, footers, upper-case
extensions and zip archives holding one CSV. Bad files raise `CalibrationError` naming the
file, the line and what was expected.
"""

from __future__ import annotations

import csv
import io
import logging
import math
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
    unit_class,
    unit_factor,
)
from printgen.calibrate.numbers import decimal_of, parse_number
from printgen.calibrate.status import StatusColumn, decide
from printgen.errors import CalibrationError, InputError
from printgen.outputs.files import INPUT_LIMIT_BYTES, read_input

log = logging.getLogger(__name__)

DELIMITERS = (";", "\t", ",")  # preferred first: a decimal comma would split a ',' file
SNIFF_ROWS = 40  # rows from the table's end used to choose the decimal separator
TEXT_SUFFIXES = (".csv", ".txt", ".tsv", ".dat")
# The most one export may hold, checked before it is parsed (a small zip can unpack to tens of
# millions of rows): a 1 kHz test of 16 minutes has 1 M rows; real exports hold 10^3 to 10^5
# (benchmarks/measurements.md#calibrate-limits).
MAX_ROWS = 1_000_000
# A row of readings is tens of columns (< 1 KiB); Python's csv refuses a field over 128 KiB.
MAX_LINE_CHARS = 64 << 10
EXPORT_LIMIT_BYTES = INPUT_LIMIT_BYTES  # one export, or what a zip of one unpacks to (64 MiB)
_BOOLEAN = {"true": 1.0, "false": 0.0}  # flag columns written as words


class NoTableError(CalibrationError):
    """The file holds no table of numbers (a note, a README): not an export."""


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
    assumed: frozenset[str] = frozenset()  # roles whose unit the file does not give
    alternatives: dict[str, tuple[str, ...]] = field(default_factory=dict)  # role -> others
    notes: tuple[str, ...] = ()  # how columns were chosen, status conventions assumed
    status: tuple[StatusColumn, ...] = ()  # tester status columns (see status.py)

    def has(self, role: str) -> bool:
        return role in self.channels

    @property
    def flags(self) -> dict[str, np.ndarray]:
        """Status column -> bool per row: the event is set."""
        return {c.name: c.on for c in self.status}


def read_text(path: str | Path) -> tuple[str, str]:
    """(text, display name) of an export; a zip must hold exactly one text file."""
    p = Path(path)
    if p.is_dir():
        raise CalibrationError(f"{p}: is a directory; pass it to `printgen calibrate` (which "
                               "reads every export in it) or name the export file")
    try:
        data = read_input(p, "tensile-test export", limit=EXPORT_LIMIT_BYTES)
    except InputError as exc:
        raise CalibrationError(str(exc)) from None
    if p.suffix.lower() == ".zip":
        return _unzip(data, p)
    return _decode(data, p), str(p)


def _unzip(data: bytes, p: Path) -> tuple[str, str]:
    """The one export inside a zip, its uncompressed size capped like a file's."""
    try:
        with zipfile.ZipFile(io.BytesIO(data)) as z:
            names = [n for n in z.namelist()
                     if n.lower().endswith(TEXT_SUFFIXES) and not n.startswith("__MACOSX")]
            if len(names) != 1:
                raise CalibrationError(f"{p}: expected one CSV inside the zip, found {names}")
            with z.open(names[0]) as fh:  # the header's size may lie: read one byte past it
                text = fh.read(EXPORT_LIMIT_BYTES + 1)
    except (zipfile.BadZipFile, OSError, NotImplementedError) as exc:
        raise CalibrationError(f"{p}: not a readable zip archive ({exc})") from None
    if len(text) > EXPORT_LIMIT_BYTES:
        raise CalibrationError(f"{p}:{names[0]} unpacks to more than {EXPORT_LIMIT_BYTES:,} "
                               "bytes, over the limit for one export; is it the right file?")
    return _decode(text, p), f"{p}:{names[0]}"


def _decode(data: bytes, p: Path) -> str:
    for enc in ("utf-8-sig", "cp1252"):
        try:
            return data.decode(enc)
        except UnicodeDecodeError:
            continue
    raise CalibrationError(f"{p}: not a text file (neither UTF-8 nor Windows-1252)")


def read_export(path: str | Path, *, columns: Mapping[str, str] | None = None,
                units: Mapping[str, str] | None = None, delimiter: str | None = None,
                decimal: str | None = None, flags: Mapping[str, str] | None = None
                ) -> TestRecord:
    """Read an export; `columns` maps a role to a header name or 1-based index, `units` a role
    to the unit of its column (overriding the file), `flags` a status column to its
    convention (status.CONVENTIONS; default: decided from the data)."""
    text, where = read_text(path)
    lines = text.splitlines()
    if len(lines) > MAX_ROWS:
        raise CalibrationError(f"{where}: {len(lines):,} lines, more than {MAX_ROWS:,} (a 1 kHz "
                               "test of 16 minutes); thin the rows (every 10th) or split the file")
    long = next((n for n, ln in enumerate(lines, start=1) if len(ln) > MAX_LINE_CHARS), None)
    if long is not None:
        raise CalibrationError(f"{where}, line {long}: {len(lines[long - 1]):,} characters, more "
                               f"than the {MAX_LINE_CHARS:,} a tester's export line holds (one "
                               "row of readings); is it the right file, or is it one line "
                               "without line breaks?")
    delim = delimiter or _sniff_delimiter(lines, where)
    rows = list(enumerate(_split(lines, delim), start=1))
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
    col_units = _column_units(headers, unit_row, ncols)
    roles, alternatives, notes = _assign(headers, col_units, data, columns or {}, where)
    channels, names, assumed = {}, {}, set()
    for role, j in roles.items():
        unit = (units or {}).get(role)
        unit = normalise_unit(unit) if unit is not None else col_units[j]
        if unit is None:
            assumed.add(role)
        col = headers[j] if headers else f"column {j + 1}"
        channels[role] = data[:, j] * unit_factor(role, unit, where=f"{where}: column {col!r}")
        names[role] = col
    if "time" in channels:
        _check_time_order(channels["time"], line_no, where)
    meta = tuple(m for n, r in rows[:meta_end] if (m := _meta(n, r, dec)) is not None)
    status, status_notes = decide(_levels(headers, data, set(roles.values())), flags or {},
                                  where)
    return TestRecord(where, channels, names, tuple(headers), meta, delim, dec,
                      rows[start][0], line_no, frozenset(assumed), alternatives,
                      (*notes, *status_notes), status)


def _check_time_order(t: np.ndarray, line_no: np.ndarray, where: str) -> None:
    """Refuse rows whose time goes back. Sorting them is not safe: a spreadsheet sort on
    another column would be undone by it, but two tests in one file, or a tester that restarted
    its clock, would be interleaved into one curve whose modulus is wrong (a 1.3 GPa file gave
    0.386 GPa out of order); only the lab knows which, so it is asked to fix the file."""
    back = np.flatnonzero(np.diff(t) < 0)
    if back.size:
        i = int(back[0])
        raise CalibrationError(
            f"{where}, line {line_no[i + 1]}: time {t[i + 1]:g} s is before the line above "
            f"({t[i]:g} s); {back.size} rows go back in time. Sort the rows by time, or split "
            "the file if it holds more than one test")


def _column_units(headers: list[str], unit_row: list[str] | None, ncols: int
                  ) -> list[str | None]:
    """Each column's unit label from the units row, else from its header, else None."""
    out: list[str | None] = []
    for j in range(ncols):
        if unit_row is not None and unit_row[j].strip():
            out.append(normalise_unit(unit_row[j]))
        else:
            out.append(split_name_unit(headers[j])[1] if headers else None)
    return out


def _levels(headers: list[str], data: np.ndarray, used: set[int]) -> dict[str, np.ndarray]:
    """Candidate status columns: unused columns holding only 0 and 1, with their values."""
    out = {}
    for j, h in enumerate(headers):
        col = data[:, j] if data.size else np.zeros(0)
        if j in used or col.size < 2 or not np.all((col == 0) | (col == 1)):
            continue
        out[h] = col
    return out


def _sniff_delimiter(lines: list[str], where: str) -> str:
    """The first of DELIMITERS that splits most lines into the same number (>= 2) of fields."""
    body = [ln for ln in lines if ln.strip()]
    for d in DELIMITERS:
        counts = np.array([len(r) for r in _split(body, d)])
        if counts.size == 0:
            break
        values, freq = np.unique(counts, return_counts=True)
        mode = values[np.argmax(freq)]
        if mode >= 2 and freq.max() * 2 >= counts.size:
            return d
    raise NoTableError(
        f"{where}: no table found; expected rows of at least 2 values separated by ',', ';' "
        "or tab, the same number on most rows (give --delimiter if the file uses another)"
    )


def _split(lines: list[str], delim: str) -> list[list[str]]:
    """Each line's fields, every line read on its own (a quote left open ends with its line);
    one reader over all lines when that gives the same, a line per row."""
    rows = list(csv.reader(lines, delimiter=delim))
    if len(rows) == len(lines):
        return rows
    return [next(csv.reader([ln], delimiter=delim), []) for ln in lines]


def _numeric(cells: list[str], dec: str) -> bool:
    return all(_value(c, dec) is not None for c in cells)


def _value(cell: str, dec: str) -> float | None:
    """A cell's number, or 1/0 for true/false (flag columns)."""
    if dec == "." or "." not in cell:  # a plain number reads alike either way: the fast path
        try:
            v = float(cell)
        except ValueError:
            pass
        else:
            return v if math.isfinite(v) else None
    parsed = parse_number(cell, dec)
    return _BOOLEAN.get(cell.strip().strip('"').lower()) if parsed is None else parsed


def _table_start(rows: list[tuple[int, list[str]]], dec: str, where: str, delim: str) -> int:
    for k in range(len(rows) - 1):
        r, nxt = rows[k][1], rows[k + 1][1]
        if len(r) >= 2 and len(nxt) == len(r) and _numeric(r, dec) and _numeric(nxt, dec):
            return k
    raise NoTableError(
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
        vals = [_value(c, dec) for c in r] if len(r) == ncols else None
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


def _assign(headers: list[str], col_units: list[str | None], data: np.ndarray,
            chosen: Mapping[str, str], where: str
            ) -> tuple[dict[str, int], dict[str, tuple[str, ...]], list[str]]:
    """(role -> column index, role -> other candidate headers, notes): the options first, then
    the header names, preferring a column whose unit belongs to the role; raw counts are never
    taken and two unitless force columns are an error, not a guess."""
    roles: dict[str, int] = {}
    for role, key in chosen.items():
        if role not in ROLES:
            raise CalibrationError(f"unknown column role {role!r}; roles: {', '.join(ROLES)}")
        roles[role] = _find_column(headers, key, where)
    cands: dict[str, list[int]] = {r: [] for r in ROLES}
    for j, h in enumerate(headers):
        named = role_of(split_name_unit(h)[0])
        if named is not None and named not in roles and j not in roles.values():
            cands[named].append(j)
    alternatives: dict[str, tuple[str, ...]] = {}
    notes: list[str] = []
    for role, js in cands.items():
        if not js:
            continue
        why = {j: unit_class(role, headers[j], col_units[j], data[:, j]) for j in js}
        best = min(js, key=lambda j: why[j][0])
        _refuse_guess(role, [headers[j] for j in js if why[j][0] == why[best][0]], why[best],
                      where)
        if why[best][0] < 3:
            roles[role] = best
        others = [j for j in js if j != best or why[j][0] == 3]
        if others:
            alternatives[role] = tuple(headers[j] for j in others)
            used = f"column {headers[best]!r} used ({why[best][1]})" if best in roles.values() \
                else "no column used"
            notes.append(f"{role}: {used}; also found "
                         + ", ".join(f"{headers[j]!r} ({why[j][1]})" for j in others)
                         + f"; choose another with --column {role}=NAME")
    if "force" not in roles and "stress" not in roles:
        raise CalibrationError(
            f"{where}: no force or stress column among {headers or 'the unnamed columns'}; "
            "name one with --column force=NAME (or a 1-based index)"
        )
    return roles, alternatives, notes


def _refuse_guess(role: str, best: list[str], why: tuple[int, str], where: str) -> None:
    """A force column is never guessed: only raw counts, or several without a unit, stop."""
    if role != "force":
        return
    if why[0] == 3:
        raise CalibrationError(
            f"{where}: force column {best[0]!r} holds {why[1]}, and no other column gives "
            "newtons; convert it to N, or name a force column with --column force=NAME (add "
            "--unit force=N if it is in newtons)")
    if why[0] == 1 and len(best) > 1:
        raise CalibrationError(
            f"{where}: force columns {', '.join(map(repr, best))} give no unit, so which one is "
            "in newtons cannot be told; choose with --column force=NAME (and --unit force=kN "
            "if it is not in N)")


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
