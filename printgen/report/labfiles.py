"""Files a lab takes to the flume, beside the report: the curves (curves.csv), the expected readings
in flume units (expected-readings.csv) and a blank measurement sheet in the columns `printgen verify
--measured` reads, with the model's expected readings beside them (measurement-sheet.csv), where the
sensors and anchors go (sensor-layout.csv, printgen.report.flume_drawing), and with `make --loads
A,B` each load case's expected readings (expected-readings-<case>.csv: the nominal model at the
case's own levels, with what the case used at each level, e.g. the jam's discharge in L/s). Column
names carry their unit (`_pct`, `_mm`, `_n`, `_kn`; no suffix: normalised, dimensionless). The
numbers are the record's (`lab_record`, in report.json under "lab"), so the files and the JSON say
the same.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from printgen.report.flume_drawing import LAYOUT_CSV, layout_csv
from printgen.scene.flume import flume_layout
from printgen.scene.readings import DEPTH_COLUMN, RAW_COLUMNS, flume_units
from printgen.units import MM
from printgen.verification.bands import Band
from printgen.verification.compare import METRICS
from printgen.verification.measured import LEVEL_COLUMN
from printgen.verification.preprint import Verification
from printgen.verification.tables import CURVE_COLUMNS, curve_column, nearest

DIGITS = 8  # significant digits of every number in the CSV files
NOISE = 1e-6  # |value| below this (in the column's unit: %, mm, N, kN or -) is written as 0
CURVES, READINGS, SHEET = "curves.csv", "expected-readings.csv", "measurement-sheet.csv"


def lab_record(v: Verification, band: Band, scale: float) -> dict[str, Any]:
    """Curves (prototype, model nominal, band min/max) and the model's expected readings in
    flume units at the band's levels; the record of report.json's "lab"."""
    units = flume_units(v.model.scene)
    lv = band.levels
    ip = nearest(v.prototype.deformation.levels, lv)
    im = nearest(v.model.deformation.levels, lv)
    p, m = v.prototype.deformation, v.model.deformation
    lo, hi = band.envelope()
    lo0, hi0 = band.envelope(from_start=True)
    curves = {"levels": lv}
    for key in METRICS:
        curves[key] = {"prototype": p.values[key][ip], "model": m.values[key][im],
                       "band_min": lo[key], "band_max": hi[key]}
    curves["tension"] = {
        "prototype_strand_kn": p.max_strand_tension[ip] / 1e3,
        "prototype_cable_kn": p.max_cable_tension[ip] / 1e3,
        "model_strand_n": m.max_strand_tension[im], "model_cable_n": m.max_cable_tension[im],
        "model_strand_scaled_kn": m.max_strand_tension[im] * scale**3 / 1e3,
        "model_cable_scaled_kn": m.max_cable_tension[im] * scale**3 / 1e3}
    readings: dict[str, Any] = {"levels": lv, "water_depth_mm": lv * units.height_mm}
    for col, key in RAW_COLUMNS.items():
        nominal = band.nominal[key] - (band.nominal[key][0] if key.startswith("strain") else 0)
        low, high = (lo0, hi0) if key.startswith("strain") else (lo, hi)
        f = units.length_mm(key)
        readings[col] = {"nominal": nominal * f, "min": low[key] * f, "max": high[key] * f}
    readings["max_strand_tension_n"] = m.max_strand_tension[im]
    readings["max_cable_tension_n"] = m.max_cable_tension[im]
    by_load = {name: case_readings(c.model, c.load.get("model", {}), units.length_mm)
               for name, c in v.by_load.items()}
    return {"units": units.to_record(), "curves": curves, "readings": readings,
            "layout": flume_layout(v.model.scene).to_record(), "by_load": by_load,
            "files": [CURVES, READINGS, SHEET, LAYOUT_CSV,
                      *(case_file(name) for name in by_load)]}


def case_file(name: str) -> str:
    return f"expected-readings-{name}.csv"


def case_readings(run: Any, used: dict[str, Any], mm_per: Any) -> dict[str, Any]:
    """The nominal model's readings (mm, sensors zeroed at the first level, h/h_B = 0) at
    its levels, with the per-level values its load case used (`used`: name -> values)."""
    d = run.deformation
    out: dict[str, Any] = {LEVEL_COLUMN: d.levels, DEPTH_COLUMN: d.levels * run.scene.height / MM}
    for name, values in used.items():
        if name != "levels" and np.ndim(values) == 1 and len(values) == len(d.levels):
            out[name] = values
    for col, key in RAW_COLUMNS.items():
        x = d.values[key] - (d.values[key][0] if key.startswith("strain") else 0)
        out[col] = x * mm_per(key)
    out["max_strand_tension_n"] = d.max_strand_tension
    out["max_cable_tension_n"] = d.max_cable_tension
    return out


def lab_files(lab: dict[str, Any]) -> dict[str, str]:
    """The CSV texts of `lab_record`'s output, by file name."""
    files = {CURVES: curves_csv(lab), READINGS: readings_csv(lab), SHEET: sheet_csv(lab),
             LAYOUT_CSV: layout_csv(lab["layout"])}
    for name, r in lab.get("by_load", {}).items():
        files[case_file(name)] = _csv(list(r), list(r.values()))
    return files


def curves_csv(lab: dict[str, Any]) -> str:
    c = lab["curves"]
    header, cols = [LEVEL_COLUMN], [c["levels"]]
    for key, (stem, f) in CURVE_COLUMNS.items():
        for who in ("prototype", "model", "band_min", "band_max"):
            header.append(curve_column(stem, who))
            cols.append(np.asarray(c[key][who]) * f)
    for name, values in c["tension"].items():
        header.append(f"max_{name}")
        cols.append(values)
    return _csv(header, cols)


def readings_csv(lab: dict[str, Any]) -> str:
    r = lab["readings"]
    header, cols = [LEVEL_COLUMN, DEPTH_COLUMN], [r["levels"], r["water_depth_mm"]]
    for col in RAW_COLUMNS:
        stem = col.removesuffix("_mm")
        for what in ("nominal", "min", "max"):
            header.append(f"{stem}_{what}_mm")
            cols.append(r[col][what])
    header += ["max_strand_tension_n", "max_cable_tension_n"]
    cols += [r["max_strand_tension_n"], r["max_cable_tension_n"]]
    return _csv(header, cols)


def sheet_csv(lab: dict[str, Any]) -> str:
    """The blank sheet: the level and depth filled in, an empty cell for each reading, and
    each reading's expected model value (nominal, band min and max) beside it."""
    r = lab["readings"]
    header, cols = [LEVEL_COLUMN, DEPTH_COLUMN], [r["levels"], r["water_depth_mm"]]
    blank = np.full(len(r["levels"]), np.nan)
    for col in RAW_COLUMNS:
        header.append(col)
        cols.append(blank)
        for what in ("nominal", "min", "max"):
            header.append(f"expected_{col.removesuffix('_mm')}_{what}_mm")
            cols.append(r[col][what])
    note = ("# printgen measurement sheet: fill the empty columns with the readings in mm "
            "(sensors zeroed at h/h_B = 0; deflection and top lowering from rest); leave a "
            "column empty if not measured. expected_* columns: the printed model's prediction "
            "(nominal / band min / band max) and skipped when read back. Read with: printgen "
            "verify PROTOTYPE --scale S --design design.json --measured this-file.csv\n")
    return note + _csv(header, cols)  # the note holds no comma: one cell to any CSV reader


def _csv(header: list[str], cols: list[Any]) -> str:
    lines = [",".join(header)]
    for row in zip(*(np.asarray(c, dtype=float) for c in cols), strict=True):
        lines.append(",".join(_num(x) for x in row))
    return "\n".join(lines) + "\n"


def _num(x: float) -> str:
    if not math.isfinite(x):
        return ""
    return "0" if abs(x) < NOISE else f"{x:.{DIGITS}g}"  # solver round-off, "-0" included
