"""Read TOML tables against a declared schema: unknown keys, types, ranges and units.

Each key's unit and bounds are defined once, in a `Field`. `read_table` checks a mapping read
from a data file and returns plain values, converted to SI for unit-suffixed keys unless the
field keeps its file unit (`si=False`, used for millimetre print settings).
"""

from __future__ import annotations

import math
import reprlib
import tomllib
import unicodedata
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from printgen.errors import InputError
from printgen.outputs.files import read_input_text
from printgen.units import split_unit_key

TOML_LIMIT_BYTES = 1 << 20  # a prototype or profile is a few kB; 1 MiB is surely not one


@dataclass(frozen=True)
class Field:
    """One allowed key of a data table.

    key : name in the file, ending with its unit (`height_m`); kind : float, int, str, bool,
    list or dict; lo/hi : bounds in file units (lo_open: value must be > lo);
    si : convert to SI and strip the unit from the returned name.
    """

    key: str
    kind: type = float
    lo: float | None = None
    hi: float | None = None
    lo_open: bool = False
    required: bool = True
    default: Any = None
    choices: tuple[str, ...] = ()
    si: bool = True
    help: str = ""
    items: type | None = None  # list fields: the type of every element (str or float)
    max_items: int | None = None  # list fields: at most this many elements
    multiline: bool = False  # str fields: line breaks and tabs allowed (G-code, descriptions)

    @property
    def name(self) -> str:
        return split_unit_key(self.key)[0] if self.si and self.kind is float else self.key

    @property
    def unit(self) -> str:
        return split_unit_key(self.key)[2]


def positive(key: str, hi: float | None = None, least: float | None = None, **kw: Any
             ) -> Field:
    """A float that must be > 0 (and <= hi); with `least`, >= least: the smallest physically
    plausible value, which also keeps 1e-300 or 5e-324 (a zero in disguise) out of the maths."""
    if least is not None:
        return Field(key, float, lo=least, hi=hi, **kw)
    return Field(key, float, lo=0.0, hi=hi, lo_open=True, **kw)


def shown(value: Any) -> str:
    """`value` as a short repr for an error message (a 5000-digit integer, a deep table or a
    long list would otherwise make the one line a page, or fail to print at all)."""
    if isinstance(value, int) and not isinstance(value, bool) and value.bit_length() > 64:
        return f"<an integer of {value.bit_length() * math.log10(2):.0f} digits>"
    try:
        return _SHORT.repr(value)
    except (RecursionError, ValueError):
        return f"<a {type(value).__name__}>"


_SHORT = reprlib.Repr()
_SHORT.maxlevel, _SHORT.maxstring, _SHORT.maxother, _SHORT.maxlist, _SHORT.maxdict = 2, 40, 40, 4, 4


def parse_data(text: str, where: str, what: str = "TOML", parse: Any = tomllib.loads) -> Any:
    """`parse(text)` (TOML by default, or `json.loads`), with what no data file of printgen
    holds refused as one InputError: syntax errors, tables nested too deeply for the parser
    (RecursionError) and integers longer than Python converts (4300 digits, ValueError)."""
    try:
        return parse(text)
    except RecursionError:
        raise InputError(f"{where}: tables or lists nested too deeply to read as {what}; no "
                         "printgen file nests more than a few levels") from None
    except ValueError as exc:  # TOMLDecodeError, JSONDecodeError, too many digits
        raise InputError(f"{where}: not valid {what}: {' '.join(str(exc).split())[:200]}; fix "
                         "the file's syntax") from None


def load_toml(path: str | Path, what: str = "TOML file") -> dict[str, Any]:
    """Read a TOML file; missing, non-regular or oversized files and syntax errors become
    `InputError` (outputs.read_input: a FIFO or /dev/zero is refused, not read)."""
    p = Path(path)
    if p.is_dir():
        some = sorted(p.glob("*.toml"))[:3]
        hint = f" such as {', '.join(str(x) for x in some)}" if some else ""
        raise InputError(f"{p} is a folder, not a TOML file; give the file itself{hint}")
    text = read_input_text(p, what, limit=TOML_LIMIT_BYTES)
    return parse_data(text, str(p))


def read_table(data: Any, fields: Sequence[Field], *, where: str) -> dict[str, Any]:
    """Check `data` against `fields`; return {field.name: value (SI if field.si)}.

    Raises InputError naming the key, the value, the limit and the place to fix it.
    """
    if not isinstance(data, Mapping):
        raise InputError(f"{where}: expected a table of keys, got {type(data).__name__}")
    allowed = {f.key: f for f in fields}
    unknown = sorted(set(data) - set(allowed))
    if unknown:
        raise InputError(
            f"{where}: unknown key {unknown[0]!r}; allowed keys: {', '.join(sorted(allowed))}"
        )
    out: dict[str, Any] = {}
    for f in fields:
        if f.key not in data:
            if f.required:
                hint = f" ({f.help})" if f.help else ""
                raise InputError(f"{where}: missing key {f.key!r}{hint}; add it to the file")
            out[f.name] = f.default
            continue
        out[f.name] = check_value(data[f.key], f, where=where)
    return out


def check_value(value: Any, f: Field, *, where: str) -> Any:
    """Type- and range-check one value; convert to SI when the field asks for it."""
    label = f"{where}: {f.key} = {shown(value)}"
    if f.kind in (float, int):
        x = number(value, label, f.unit, whole=f.kind is int)
        check_range(x, f, label)
        _, factor, _ = split_unit_key(f.key)
        return (value * factor if f.si else value) if f.kind is float else int(value)
    if f.kind is str:
        if not isinstance(value, str):
            raise InputError(f"{label} must be a string")
        check_text(value, label, multiline=f.multiline)
        if f.choices and value not in f.choices:
            raise InputError(f"{label} is not one of: {', '.join(f.choices)}")
        return value
    if not isinstance(value, f.kind):
        raise InputError(f"{label} must be a {f.kind.__name__}")
    if isinstance(value, list):  # a list field: value is an f.kind
        check_items(value, f, label)
    return value


def number(value: Any, label: str, unit: str = "", *, whole: bool = False) -> float:
    """`value` as a finite float, or InputError: not a number (a string, a bool, a list), not
    a whole number when `whole`, not finite, or an integer too large for a float (400 digits)."""
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise InputError(f"{label} is not a number; write a plain number in {unit or 'units'}")
    if whole and not isinstance(value, int):
        raise InputError(f"{label} must be a whole number")
    try:
        x = float(value)
    except OverflowError:
        raise InputError(f"{label} is too large for a number; write one below 1e308") from None
    if not math.isfinite(x):
        raise InputError(f"{label} is not finite; write a finite number")
    return x


def check_text(text: str, label: str, *, multiline: bool = False) -> None:
    """InputError when `text` holds a control character (an escape, a NUL, a bell; a line
    break or tab too unless `multiline`): it would reach report.html and the plots raw."""
    allowed = "\n\t\r" if multiline else ""
    bad = next((c for c in text if unicodedata.category(c) == "Cc" and c not in allowed), None)
    if bad is not None:
        raise InputError(f"{label} holds the control character U+{ord(bad):04X}; write plain "
                         "text" + ("" if multiline else " on one line"))


def check_items(values: list, f: Field, label: str) -> None:
    """A list field: at most `f.max_items` elements, each of type `f.items` when given."""
    if f.max_items is not None and len(values) > f.max_items:
        raise InputError(f"{label} has {len(values)} entries; at most {f.max_items} are allowed")
    for i, v in enumerate(values):
        where = f"{label}: entry {i + 1} ({shown(v)})"
        if f.items is str:
            if not isinstance(v, str):
                raise InputError(f"{where} must be a string (a name in quotes)")
            check_text(v, where)
        elif f.items is float:
            number(v, where, f.unit)


def check_range(value: float, f: Field, label: str) -> None:
    """Raise InputError when value is outside [lo, hi] (or (lo, hi] when lo_open)."""
    unit = f" {f.unit}" if f.unit else ""
    if f.lo is not None and (value <= f.lo if f.lo_open else value < f.lo):
        op = ">" if f.lo_open else ">="
        raise InputError(f"{label} is out of range: it must be {op} {f.lo:g}{unit}")
    if f.hi is not None and value > f.hi:
        raise InputError(f"{label} is out of range: it must be <= {f.hi:g}{unit}")
