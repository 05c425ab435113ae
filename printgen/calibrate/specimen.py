"""Specimen dimensions: from the export's metadata lines, else from options, else a TOML sidecar.

Kinds: `cable` (printed strand, width x thickness), `dogbone` (narrow section width x thickness),
`panel` (net panel: width across and length along the load); a sidecar may also name `waved`
(a waved-strand coupon, `printgen.calibrate.waved`, with its `[wave]` table), and a square test
panel's sidecar a `[prediction]` table (its simulated test, fitted the same way). Sidecar:
`<export>.toml` beside the export, or `specimen.toml` in its folder, or the file given with
--specimen; keys are the fields of `SIDECAR` (mm), plus optional `[columns]` and `[units]`
tables (role -> name/unit) and a `[flags]` table (status column -> active-high, active-low or
ignore).
"""

from __future__ import annotations

import logging
import re
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

from printgen.calibrate.reader import MetaItem
from printgen.errors import CalibrationError
from printgen.inputs.schema import Field, load_toml, positive, read_table

log = logging.getLogger(__name__)

KINDS = ("cable", "dogbone", "panel")
WAVED = "waved"  # a waved-strand coupon: its sidecar (printgen testpieces) holds the beam
# model's inputs in a [wave] table (`printgen.calibrate.waved`), so it is a sidecar kind only
SIDECAR = [
    Field("kind", str, choices=(*KINDS, WAVED), required=False),
    positive("width_mm", 1e4, si=False, required=False),
    positive("thickness_mm", 1e3, si=False, required=False),
    positive("area_mm2", 1e6, si=False, required=False),
    positive("gauge_length_mm", 1e4, si=False, required=False),
    positive("grip_distance_mm", 1e4, si=False, required=False),
    Field("columns", dict, required=False, default={}),
    Field("units", dict, required=False, default={}),
    Field("flags", dict, required=False, default={}),
    Field("wave", dict, required=False, default={}),
    Field("prediction", dict, required=False, default={}),  # a square test panel's simulated
    # test (`printgen.calibrate.waved`: fitted as the waved pieces are)
]
DIMENSIONS = ("width", "thickness", "area", "gauge_length", "grip_distance")
# Metadata key patterns (lower case) per dimension; the first match wins.
_META_KEYS = {
    "width": r"^(specimen )?width|breite|largeur",
    "thickness": r"thickness|dicke|[ée]paisseur",
    "area": r"area|cross.?section|querschnitt|section",
    "grip_distance": r"grip (distance|separation)|einspannl",
    "gauge_length": r"gauge length|gage length|^length$|messl|^l0",
}
_LENGTH = {"mm": 1e-3, "m": 1.0, "cm": 1e-2, "in": 0.0254, None: 1e-3}
_AREA = {"mm2": 1e-6, "mm²": 1e-6, "mm^2": 1e-6, "m2": 1.0, "m²": 1.0, "m^2": 1.0,
         "cm2": 1e-4, "cm²": 1e-4, None: 1e-6}
_MODULUS = {"mpa": 1e6, "gpa": 1e9, "pa": 1.0, "n/mm2": 1e6, "n/mm²": 1e6, "kpa": 1e3,
            None: 1e6}


@dataclass(frozen=True)
class Specimen:
    """Dimensions in m (area m^2); `sources` says where each came from."""

    kind: str = "cable"
    width: float | None = None
    thickness: float | None = None
    area: float | None = None
    gauge_length: float | None = None
    grip_distance: float | None = None
    sources: dict[str, str] = field(default_factory=dict)

    def cross_section(self) -> float | None:
        """Area in m^2: given, or width x thickness (None for panels and unknown sections)."""
        if self.area is not None:
            return self.area
        if self.width is not None and self.thickness is not None:
            return self.width * self.thickness
        return None

    def strain_length(self) -> float | None:
        """Length that turns crosshead displacement into strain: grip distance, else gauge."""
        return self.grip_distance if self.grip_distance is not None else self.gauge_length


def from_metadata(meta: tuple[MetaItem, ...], where: str) -> dict[str, float]:
    """Dimensions (SI) found in the metadata lines."""
    out: dict[str, float] = {}
    for m in meta:
        if m.number is None:
            continue
        key = m.key.lower()
        for dim, pattern in _META_KEYS.items():
            if dim in out or not re.search(pattern, key):
                continue
            table = _AREA if dim == "area" else _LENGTH
            if m.unit not in table:
                raise CalibrationError(f"{where}:{m.line}: {m.key} in {m.unit!r}; expected "
                                       f"{', '.join(k for k in table if k)}")
            out[dim] = m.number * table[m.unit]
            break
    return out


def machine_modulus(meta: tuple[MetaItem, ...]) -> float | None:
    """The machine software's own modulus (Pa) from the metadata, if written."""
    for m in meta:
        if (m.number is not None and re.search(r"modul|young", m.key.lower())
                and m.unit in _MODULUS):
            return m.number * _MODULUS[m.unit]
    return None


def find_sidecar(export: Path) -> Path | None:
    """`<stem>.toml` beside the export (any case, .csv.zip stripped), else `specimen.toml`."""
    stem = export.name
    for _ in range(2):
        stem = stem.rsplit(".", 1)[0] if "." in stem else stem
        for cand in (export.with_name(stem + ".toml"), export.with_name(stem + ".TOML")):
            if cand.is_file():
                return cand
    folder = export.parent / "specimen.toml"
    return folder if folder.is_file() else None


def read_sidecar(path: Path) -> dict[str, Any]:
    """The sidecar's keys: dimensions in SI, `kind`, `columns`, `units`."""
    t = read_table(load_toml(path), SIDECAR, where=str(path))
    out: dict[str, Any] = {k: t[k] for k in ("kind", "columns", "units", "flags") if t[k]}
    for dim in DIMENSIONS:
        key = "area_mm2" if dim == "area" else f"{dim}_mm"
        if t[key] is not None:
            out[dim] = t[key] * (1e-6 if dim == "area" else 1e-3)
    return out


def resolve(meta_dims: dict[str, float], options: dict[str, Any], sidecar: dict[str, Any],
            *, sidecar_path: str | None = None) -> Specimen:
    """Merge the sources, metadata first, then options, then the sidecar."""
    spec = Specimen(kind=options.get("kind") or sidecar.get("kind") or "cable")
    values: dict[str, Any] = {}
    sources: dict[str, str] = {}
    for name, src in (("file metadata", meta_dims), ("options", options),
                      (f"sidecar {sidecar_path}", sidecar)):
        for dim in DIMENSIONS:
            v = src.get(dim)
            if v is None:
                continue
            if dim in values:
                if abs(v - values[dim]) > 1e-9 * max(abs(v), 1.0):
                    log.warning("%s from %s (%g) ignored: %s gives %g", dim, name, v,
                                sources[dim], values[dim])
                continue
            values[dim], sources[dim] = float(v), name
    return replace(spec, sources=sources, **values)
