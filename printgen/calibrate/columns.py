"""Column names and units of tensile-test exports: which channel a column is, and its SI factor.

A column's unit comes from its header (`Load (kN)`, `force_N`, `Strain [%]`, `Weg in mm`) or from
a units row under the header (`(s),(mm),(N),(%),(MPa)`). Roles: time, force, displacement
(crosshead or extension), strain (extensometer) and stress.
"""

from __future__ import annotations

import re
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    import numpy as np

# Unit label (lower case, no brackets) -> factor to SI for each kind of quantity.
FORCE_UNITS = {"n": 1.0, "kn": 1e3, "mn": 1e-3, "lbf": 4.4482216152605, "kgf": 9.80665}
LENGTH_UNITS = {"mm": 1e-3, "m": 1.0, "cm": 1e-2, "um": 1e-6, "µm": 1e-6, "in": 0.0254}
STRAIN_UNITS = {"%": 1e-2, "mm/mm": 1.0, "m/m": 1.0, "-": 1.0, "": 1.0,
                "ue": 1e-6, "µε": 1e-6, "microstrain": 1e-6, "percent": 1e-2}
STRESS_UNITS = {"mpa": 1e6, "n/mm2": 1e6, "n/mm²": 1e6, "n/mm^2": 1e6, "kpa": 1e3, "pa": 1.0,
                "gpa": 1e9, "psi": 6894.757293168}
TIME_UNITS = {"s": 1.0, "ms": 1e-3, "min": 60.0, "h": 3600.0}
ROLE_UNITS = {"force": FORCE_UNITS, "displacement": LENGTH_UNITS, "strain": STRAIN_UNITS,
              "stress": STRESS_UNITS, "time": TIME_UNITS}
# The unit assumed when a column gives none.
DEFAULT_UNIT = {"force": "n", "displacement": "mm", "strain": "", "stress": "mpa", "time": "s"}
ROLES = tuple(ROLE_UNITS)
MAX_UNIT_LEN = 8  # a bracketed header word longer than this is taken as part of the name

# Name patterns per role, tried in this order (stress and strain before force and
# displacement, so "Tensile stress" is not taken for a force column).
_ROLE_PATTERNS = (
    ("stress", r"stress|spannung|contrainte|sigma"),
    ("strain", r"strain|dehnung|d[ée]formation|epsilon|extensometer"),
    ("force", r"force|load|kraft|effort|charge"),
    ("displacement", (r"displacement|extension|elongation|crosshead|position|weg|stroke|"
                      r"traverse|deplacement|déplacement|travel")),
    ("time", r"time|zeit|temps"),
)

_UNIT_IN_NAME = (
    re.compile(r"^(?P<name>.*?)\s*[\(\[](?P<unit>[^\)\]]*)[\)\]]\s*$"),  # Load (kN), Load [kN]
    re.compile(r"^(?P<name>.*?)\s+in\s+(?P<unit>\S+)\s*$", re.IGNORECASE),  # Kraft in N
    re.compile(r"^(?P<name>.*?)[_ ](?P<unit>[A-Za-z%/µ²^0-9]+)\s*$"),  # force_N, Strain %
)


def normalise_unit(unit: str) -> str:
    """Lower-case unit label without brackets or spaces (`(N/mm²)` -> `n/mm²`)."""
    return unit.strip().strip("()[]").replace(" ", "").lower()


def split_name_unit(header: str) -> tuple[str, str | None]:
    """(name, unit or None) from a header cell: `Load (kN)` -> ('Load', 'kn')."""
    text = header.strip()
    for k, pattern in enumerate(_UNIT_IN_NAME):
        m = pattern.match(text)
        if m and m.group("name"):
            unit = normalise_unit(m.group("unit"))
            if any(unit in table for table in ROLE_UNITS.values()):
                return m.group("name").strip(), unit
            if k == 0 and " " not in m.group("unit").strip() and len(unit) <= MAX_UNIT_LEN:
                return m.group("name").strip(), unit  # bracketed and unit-like: check it later
    return text, None


def role_of(name: str) -> str | None:
    """The role a column name suggests, or None."""
    low = name.lower()
    for role, pattern in _ROLE_PATTERNS:
        if re.search(pattern, low):
            return role
    return None


def is_units_row(cells: list[str]) -> bool:
    """True when every non-empty cell is a known unit label (a units row under the header)."""
    labels = [normalise_unit(c) for c in cells if c.strip()]
    known = set().union(*ROLE_UNITS.values())
    return bool(labels) and all(lab in known for lab in labels)


def unit_factor(role: str, unit: str | None, *, where: str) -> float:
    """Factor converting a column of `role` in `unit` to SI (strain: to a pure number)."""
    from printgen.errors import CalibrationError

    table = ROLE_UNITS[role]
    key = DEFAULT_UNIT[role] if unit is None else unit
    if key not in table:
        raise CalibrationError(
            f"{where}: unit {unit!r} is not a {role} unit; expected one of "
            f"{', '.join(sorted(k for k in table if k))}; fix the header or units row"
        )
    return table[key]


# Columns that are not physical units by their name or unit label: raw load-cell counts, ADC
# readings, bridge voltages. They are never taken for a role unless --column names them.
RAW_UNITS = frozenset({"counts", "count", "cnt", "raw", "adc", "digits", "digit", "bits", "lsb",
                       "mv", "v", "mv/v"})
# An unlabelled force column of whole numbers reaching this is load-cell counts, not newtons: a
# printed specimen breaks far below 10 kN, and a tester's newtons carry decimals.
RAW_COUNTS_MIN = 1e4
_RAW_NAME = re.compile(r"(?<![a-z])(raw|counts?|cnt|adc|digits?|bits|lsb|voltage)(?![a-z])")
# Tester flag columns (0/1 or true/false per row): step loss, end stop, overload, ...
_FLAG_NAME = re.compile(r"flag|loss|stop|limit|error|fault|alarm|warn|overload|slip|skip|abort|"
                        r"trip|status|event|break")


def is_raw(name: str, unit: str | None) -> bool:
    """True when a column is raw counts or a voltage by its name or unit label."""
    return (unit is not None and unit in RAW_UNITS) or bool(_RAW_NAME.search(name.lower()))


def unit_class(role: str, name: str, unit: str | None, values: np.ndarray | None = None
               ) -> tuple[int, str]:
    """(rank, reason) of a candidate column for `role`: 0 a unit of the role, 1 no unit (the
    default assumed), 2 another unit label (an error when used), 3 raw (never taken): raw by
    its name or unit label, or an unlabelled force column of whole numbers reaching
    RAW_COUNTS_MIN (load-cell counts by their magnitude)."""
    if is_raw(name, unit):
        kind = "counts" if unit is None else unit
        return 3, f"raw {kind}, not {_show_unit(DEFAULT_UNIT[role])} by its name"
    if unit is None and role == "force" and values is not None and values.size:
        top = float(abs(values).max())
        if top >= RAW_COUNTS_MIN and bool((values == values.round()).all()):
            return 3, f"whole numbers up to {top:.6g}: raw counts by magnitude, not N"
    if unit is None:
        return 1, f"no unit: {_show_unit(DEFAULT_UNIT[role])} assumed"
    if unit in ROLE_UNITS[role]:
        return 0, f"unit {_show_unit(unit)}"
    return 2, f"unit {unit!r}"


def is_flag_name(name: str) -> bool:
    """True when a header names a tester flag (step loss, end stop, overload, ...)."""
    return bool(_FLAG_NAME.search(name.lower()))


def _show_unit(unit: str) -> str:
    return {"n": "N", "kn": "kN", "mn": "mN", "mpa": "MPa", "kpa": "kPa", "gpa": "GPa",
            "pa": "Pa", "": "none"}.get(unit, unit)
