"""Specimen orientation of each export, from its metadata or its file name, and the statistics
per orientation when one set mixes them.

Printed specimens are far weaker across the layers (printed standing, `z`) than along them
(printed flat, `xy`): a set mixing both is two materials, and its pooled mean is neither. The
orientation is a metadata line (`Orientation`, `Build direction`, `Axis`, ...) or a word of the
file name (`xy-trial-1.csv`, `PLA_z_3.csv`, `coupon-90deg-2.csv`).
"""

from __future__ import annotations

import re
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path

from printgen.calibrate.aggregate import Stats, summarise
from printgen.calibrate.reader import MetaItem

# File-name words that name a print orientation or a loading direction on the build plate.
WORDS = frozenset({"xy", "yx", "xz", "zx", "yz", "zy", "x", "y", "z", "flat", "upright",
                   "edge", "onedge", "vertical", "horizontal", "standing"})
_ANGLE = re.compile(r"^\d{1,3}deg$")  # raster or build angle: 0deg, 45deg, 90deg
_META_KEY = re.compile(r"orientation|build dir|print dir|direction|axis|richtung|ausrichtung")
NONE = "(none)"  # label of files that name no orientation in a set where others do


@dataclass(frozen=True)
class Group:
    """The kept samples of one orientation and their statistics."""

    label: str
    files: tuple[str, ...]
    modulus: Stats | None
    strength: Stats | None


def orientation(path: str, metadata: Sequence[MetaItem]) -> str | None:
    """The orientation a metadata line or the file name gives, lower case, or None."""
    for m in metadata:
        if m.number is None and _META_KEY.search(m.key.lower()) and m.text.strip():
            return m.text.strip().lower()
    for word in re.split(r"[^a-z0-9]+", Path(path).name.lower()):
        if word in WORDS or _ANGLE.match(word):
            return word
    return None


def by_orientation(samples: Sequence, orient: dict[str, str | None]) -> tuple[Group, ...]:
    """One group per orientation among `samples` (SampleFit or StrengthSample); () when they
    all share one (or none names any)."""
    labels = {orient.get(s.path) for s in samples}
    if len(labels) < 2:
        return ()
    out = []
    for label in sorted(labels, key=lambda v: (v is None, v or "")):
        members = [s for s in samples if orient.get(s.path) == label]
        out.append(Group(label or NONE, tuple(s.path for s in members),
                         _stats(members, lambda s: getattr(s, "modulus", None), "modulus"),
                         _stats(members, lambda s: s.strength, "strength")))
    return tuple(out)


def _stats(members: Sequence, value: Callable, what: str) -> Stats | None:
    vals = [value(s) for s in members]
    return None if not vals or any(v is None for v in vals) else summarise(vals, what=what)


def mixed_warning(groups: tuple[Group, ...], modulus: tuple[str, float],
                  strength: tuple[str, float]) -> str | None:
    """The warning for a set mixing orientations, with each orientation's statistics."""
    if not groups:
        return None
    parts = []
    for g in groups:
        vals = [f"{what} {_ms(st, f)} {u}" for what, st, (u, f) in
                (("modulus", g.modulus, modulus), ("strength", g.strength, strength)) if st]
        parts.append(f"{g.label}: {len(g.files)} files" + "".join(f", {v}" for v in vals))
    return ("the files mix specimen orientations (from their metadata or file names): "
            + "; ".join(parts) + ". The statistics above pool them; calibrate one orientation "
            "at a time (name only its files, e.g. xy-*)")


def _ms(st: Stats, f: float) -> str:
    return f"{st.mean / f:.4g}" + ("" if st.sd is None else f" ± {st.sd / f:.4g}")
