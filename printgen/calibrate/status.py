"""Tester status columns (end stop, step loss, overload, ...): which rows an event marks.

A status column holds 0 and 1 (or false and true) per row. Which level means "set" depends on
the tester's wiring: an end stop with a pull-up reads 1 while *not* triggered (active-low), a
step-loss counter flag reads 1 when it fires (active-high). Unless the user says so
(`--flag NAME=active-low|active-high|ignore`, or a sidecar's `[flags]` table), the convention is
decided per column from the data: a column that holds one value through the whole test is a
state, not an event (nothing is marked); a column that changes during the test is idle at its
value at the start of the test, and marks the rows where it differs from that value.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from printgen.calibrate.columns import is_flag_name
from printgen.errors import CalibrationError

ACTIVE_HIGH, ACTIVE_LOW, IGNORE = "active-high", "active-low", "ignore"
CONVENTIONS = (ACTIVE_HIGH, ACTIVE_LOW, IGNORE)


@dataclass(frozen=True)
class StatusColumn:
    """One status column: its convention, who decided it, and the rows it marks as set."""

    name: str
    convention: str  # ACTIVE_HIGH (1 = set) or ACTIVE_LOW (0 = set)
    decided_by: str  # "data" or "user" (--flag / sidecar [flags])
    constant: bool  # one value on every row: a state, not an event
    on: np.ndarray  # bool per row: the event is set

    def record(self) -> dict[str, object]:
        """Plain data for --json."""
        return {"convention": self.convention, "decided_by": self.decided_by,
                "constant": self.constant, "rows_set": int(self.on.sum())}


def decide(levels: Mapping[str, np.ndarray], chosen: Mapping[str, str], where: str
           ) -> tuple[tuple[StatusColumn, ...], tuple[str, ...]]:
    """(status columns, notes): `levels` maps a header to its 0/1 values per row, `chosen` a
    header (any case) to a convention given by the user."""
    picked = _match(levels, chosen, where)
    cols, notes = [], []
    for name, v in levels.items():
        conv = picked.get(name)
        if conv == IGNORE:
            notes.append(f"status column {name!r}: ignored (as asked)")
            continue
        if conv is None and np.all(v == v[0]) and not is_flag_name(name):
            continue  # a constant 0/1 column not named as a flag (a cycle number, ...)
        col = _from_user(name, v, conv) if conv else _from_data(name, v)
        cols.append(col)
        note = _note(col, v)
        if note:
            notes.append(note)
    return tuple(cols), tuple(notes)


def _match(levels: Mapping[str, np.ndarray], chosen: Mapping[str, str], where: str
           ) -> dict[str, str]:
    out = {}
    for key, given in chosen.items():
        conv = given.strip().lower() if isinstance(given, str) else repr(given)
        if conv not in CONVENTIONS:
            raise CalibrationError(f"status column {key!r}: convention {conv!r} (--flag or a "
                                   f"sidecar [flags] table); expected one of "
                                   f"{', '.join(CONVENTIONS)}")
        hit = [h for h in levels if h.strip().lower() == key.strip().lower()]
        if not hit:
            found = ", ".join(repr(h) for h in levels) or "none"
            raise CalibrationError(f"{where}: --flag {key}: no status column of that name (0/1 "
                                   f"or true/false on every row); status columns: {found}")
        out[hit[0]] = conv
    return out


def _from_user(name: str, v: np.ndarray, conv: str) -> StatusColumn:
    on = v == (1 if conv == ACTIVE_HIGH else 0)
    return StatusColumn(name, conv, "user", bool(np.all(v == v[0])), on)


def _from_data(name: str, v: np.ndarray) -> StatusColumn:
    """Idle at the value at the start of the test; constant columns mark nothing."""
    idle = v[0]
    conv = ACTIVE_LOW if idle == 1 else ACTIVE_HIGH
    return StatusColumn(name, conv, "data", bool(np.all(v == idle)), v != idle)


def _note(col: StatusColumn, v: np.ndarray) -> str | None:
    """What was assumed, when it matters: a column reading 1 when idle (active-low)."""
    other = ACTIVE_HIGH if col.convention == ACTIVE_LOW else ACTIVE_LOW
    fix = f"if that is wrong, say --flag {col.name}={other}"
    if col.decided_by == "user":
        return None
    if col.constant and v[0] == 1:
        return (f"status column {col.name!r}: 1 on every row, a state, not an event: read as "
                f"{ACTIVE_LOW} (1 = not set), no sample marked; {fix}")
    if not col.constant and col.convention == ACTIVE_LOW:
        return (f"status column {col.name!r}: 1 at the start of the test, 0 during it: read as "
                f"{ACTIVE_LOW} (0 = set); {fix}")
    return None


def set_text(col: StatusColumn) -> str:
    """How the set rows read, for a flag note: '' for the usual active-high."""
    if col.convention == ACTIVE_HIGH:
        return ""
    return f"; {col.convention}, 0 = set" + ("" if col.decided_by == "data" else ", as asked")
