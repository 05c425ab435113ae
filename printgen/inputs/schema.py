"""Read TOML tables against a declared schema: unknown keys, types, ranges and units.

Each key's unit and bounds are defined once, in a `Field`. `read_table` checks a mapping read
from a data file and returns plain values, converted to SI for unit-suffixed keys unless the
field keeps its file unit (`si=False`, used for millimetre print settings).
"""

from __future__ import annotations

import math
import tomllib
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

    @property
    def name(self) -> str:
        return split_unit_key(self.key)[0] if self.si and self.kind is float else self.key

    @property
    def unit(self) -> str:
        return split_unit_key(self.key)[2]


def positive(key: str, hi: float | None = None, **kw: Any) -> Field:
    """A float that must be > 0 (and <= hi)."""
    return Field(key, float, lo=0.0, hi=hi, lo_open=True, **kw)


def load_toml(path: str | Path, what: str = "TOML file") -> dict[str, Any]:
    """Read a TOML file; missing, non-regular or oversized files and syntax errors become
    `InputError` (outputs.read_input: a FIFO or /dev/zero is refused, not read)."""
    p = Path(path)
    if p.is_dir():
        some = sorted(p.glob("*.toml"))[:3]
        hint = f" such as {', '.join(str(x) for x in some)}" if some else ""
        raise InputError(f"{p} is a folder, not a TOML file; give the file itself{hint}")
    text = read_input_text(p, what, limit=TOML_LIMIT_BYTES)
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise InputError(f"{p}: not valid TOML: {exc}; fix the file's syntax") from exc


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
    label = f"{where}: {f.key} = {value!r}"
    if f.kind in (float, int):
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise InputError(f"{label} is not a number; write a plain number in {f.unit or 'units'}")
        if f.kind is int and not isinstance(value, int):
            raise InputError(f"{label} must be a whole number")
        if not math.isfinite(value):
            raise InputError(f"{label} is not finite; write a finite number")
        check_range(float(value), f, label)
        _, factor, _ = split_unit_key(f.key)
        return (value * factor if f.si else value) if f.kind is float else int(value)
    if f.kind is str:
        if not isinstance(value, str):
            raise InputError(f"{label} must be a string")
        if f.choices and value not in f.choices:
            raise InputError(f"{label} is not one of: {', '.join(f.choices)}")
        return value
    if not isinstance(value, f.kind):
        raise InputError(f"{label} must be a {f.kind.__name__}")
    return value


def check_range(value: float, f: Field, label: str) -> None:
    """Raise InputError when value is outside [lo, hi] (or (lo, hi] when lo_open)."""
    unit = f" {f.unit}" if f.unit else ""
    if f.lo is not None and (value <= f.lo if f.lo_open else value < f.lo):
        op = ">" if f.lo_open else ">="
        raise InputError(f"{label} is out of range: it must be {op} {f.lo:g}{unit}")
    if f.hi is not None and value > f.hi:
        raise InputError(f"{label} is out of range: it must be <= {f.hi:g}{unit}")
