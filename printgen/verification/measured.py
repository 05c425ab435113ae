"""A lab's loading test brought back to the pre-print check: read its CSV, compare it with the
predicted curves, and fit the one factor of the printed net that best explains it.

The CSV (`,` or `;` separated; with `;`, decimal commas are accepted; lines starting with `#`
are comments) has a column `h_over_hb` and any of the columns in `COLUMNS`; given the printed
model's lengths, also the raw readings in mm (`water_depth_mm` for the level, the sensors'
wire change, deflection and top lowering: printgen.scene.readings.RAW_COLUMNS). Columns
named `expected_*` (the model's readings on printgen's measurement sheet) are skipped, and so
are columns left empty when others hold values. Elongations are
read as what the extension sensors record: counted from h / h_B = 0 (sensors zeroed before
the water arrives), so they are compared with the predicted curves counted from there too.
An empty cell is a reading that was not taken. A cell `<x` is an upper bound (a source that
says only "below x", e.g. "negligible, all below 0.5 %"): it counts in the mismatch only by how
far a prediction exceeds it, and is never used as a value.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from printgen.barrier.loads import OVERFLOW
from printgen.errors import InputError
from printgen.inputs.profiles import profile_name
from printgen.outputs.files import read_input_text
from printgen.scaling.record import Design
from printgen.scene.options import SceneOptions
from printgen.scene.readings import DEPTH_COLUMN, RAW_COLUMNS, FlumeUnits
from printgen.verification.bands import Band, curves, run_variant
from printgen.verification.variants import Variant

LEVEL_COLUMN = "h_over_hb"
# CSV column -> (METRICS key of printgen.verification.compare, factor from the CSV unit to the
# key's)
COLUMNS = {
    "bottom_cable_elongation_pct": ("strain_bottom", 0.01),
    "top_cable_elongation_pct": ("strain_top", 0.01),
    "mid_height_elongation_pct": ("strain_mid", 0.01),
    "deflection_over_width": ("deflection", 1.0),
    "lowering_over_height": ("lowering", 1.0),
}
MEASURED_LIMIT_BYTES = 4 << 20  # a loading test is tens of lines; 4 MiB is surely not one
# A column is fitted worse when its RMS grows by more than this share (round-off is below)
WORSE_TOL = 1e-3
MAX_LEVEL = OVERFLOW  # the sweep's last relative loading: no prediction beyond it
IGNORED_PREFIX = "expected_"  # columns of the measurement sheet that hold the model's readings
LEVEL_AGREE = 0.01  # h_over_hb and water_depth_mm / h_B may differ by this much (h / h_B)
RAW_LIMIT_MM = 1000.0  # a raw reading beyond +-1 m is not a flume model's: check the unit
LIMITS = {  # plausible range of each column (CSV units): beyond it the unit is wrong
    "bottom_cable_elongation_pct": (-100.0, 100.0),
    "top_cable_elongation_pct": (-100.0, 100.0),
    "mid_height_elongation_pct": (-100.0, 100.0),
    "deflection_over_width": (-2.0, 2.0),
    "lowering_over_height": (-2.0, 2.0),
}


class MeasurementError(InputError):
    """A measured-data file cannot be read (bad column, number, range, or no data)."""


@dataclass(frozen=True)
class Measurement:
    """A lab's loading test: levels (k,) h / h_B; values : METRICS key -> (k,) in the model's
    units (strain, deflection / width), NaN where the cell was empty; columns : CSV names."""

    path: str
    levels: np.ndarray
    values: dict[str, np.ndarray]
    columns: dict[str, str]  # METRICS key -> CSV column
    bounds: dict[str, np.ndarray] | None = None  # METRICS key -> (k,) upper bounds, NaN: none

    def bound(self, key: str) -> np.ndarray:
        """(k,) upper bounds of column `key` (NaN where the cell is a value or empty)."""
        if self.bounds is None or key not in self.bounds:
            return np.full(len(self.levels), np.nan)
        return self.bounds[key]


def read_measured(path: str | Path, units: FlumeUnits | None = None) -> Measurement:
    """Read and check a measured loading test (see the module docstring for the format).

    With `units` (the printed model's lengths, printgen.scene.readings) the raw columns in mm
    (RAW_COLUMNS, and DEPTH_COLUMN for the level) are read too; `expected_*` columns (the
    model's readings on the measurement sheet) are skipped.
    """
    p = Path(path)
    text = read_input_text(p, "measured data", limit=MEASURED_LIMIT_BYTES, encoding="utf-8-sig")
    lines = [(i + 1, ln) for i, ln in enumerate(text.splitlines())
             if ln.strip() and not ln.lstrip().startswith("#")]
    if not lines:
        raise MeasurementError(f"{p}: empty file; give a header line with {LEVEL_COLUMN} and "
                               f"any of {', '.join(COLUMNS)}, then one line per level")
    sep = ";" if ";" in lines[0][1] else ","
    header = [h.strip().lower() for h in lines[0][1].split(sep)]
    cols = _columns(units)
    _check_header(p, header, cols, units)
    rows = lines[1:]
    if not rows:
        raise MeasurementError(f"{p}: a header but no data lines; give one line per level")
    parsed = [_row(p, n, ln, sep, header) for n, ln in rows]
    table = np.array([[v for v, _ in r] for r in parsed])
    upper = np.array([[b for _, b in r] for r in parsed])
    data = {h: c for h, c in zip(header, table.T, strict=True)
            if not h.startswith(IGNORED_PREFIX)}
    bounds = {h: c for h, c in zip(header, upper.T, strict=True)
              if not h.startswith(IGNORED_PREFIX)}
    if units is not None and DEPTH_COLUMN in data:
        data = _level_from_depth(p, data, units)
    read = [c for c in data if c in cols]
    if len(read) > 1:  # a sheet's unfilled columns are dropped; a lone empty one is an error
        read = [c for c in read
                if not (np.all(np.isnan(data[c])) and np.all(np.isnan(bounds[c])))] or read
    _check_ranges(p, {LEVEL_COLUMN: data[LEVEL_COLUMN],
                      **{c: np.where(np.isnan(bounds[c]), data[c], bounds[c]) for c in read}},
                  [n for n, _ in rows])
    keys = {cols[c][0]: c for c in read}
    if len(keys) < len(read):
        raise MeasurementError(f"{p}: two columns measure the same quantity ({', '.join(read)});"
                               " keep one of each")
    values = {cols[c][0]: data[c] * cols[c][1] for c in read}
    limits = {cols[c][0]: bounds[c] * cols[c][1] for c in read}
    if values and all(np.all(np.isnan(v)) for v in values.values()) \
            and not all(np.all(np.isnan(b)) for b in limits.values()):
        raise MeasurementError(f"{p}: only bounds ('<x'), no measured value; give at least "
                               "one reading")
    return Measurement(str(p), data[LEVEL_COLUMN], values, keys, limits)


def _columns(units: FlumeUnits | None) -> dict[str, tuple[str, float]]:
    """Readable columns -> (METRICS key, factor to its unit): COLUMNS, and with `units` the
    raw columns in mm."""
    if units is None:
        return dict(COLUMNS)
    return {**COLUMNS, **{c: (k, 1.0 / units.length_mm(k)) for c, k in RAW_COLUMNS.items()}}


def _level_from_depth(p: Path, data: dict[str, np.ndarray], units: FlumeUnits
                      ) -> dict[str, np.ndarray]:
    """h_over_hb from the water depth in mm (h_B = the net's height), checked against an
    h_over_hb column when both are given."""
    level = data.pop(DEPTH_COLUMN) / units.height_mm
    given = data.get(LEVEL_COLUMN)
    if given is not None:
        ok = ~np.isnan(level)
        if np.any(np.abs(level[ok] - given[ok]) > LEVEL_AGREE):
            i = int(np.flatnonzero(ok & (np.abs(np.nan_to_num(level) - given) > LEVEL_AGREE))[0])
            raise MeasurementError(
                f"{p}: {DEPTH_COLUMN} {level[i] * units.height_mm:g} mm is h/h_B = {level[i]:.3f}"
                f" (h_B = {units.height_mm:g} mm) but {LEVEL_COLUMN} says {given[i]:g}; fix "
                "one or leave the depth cell empty")
        return data
    if np.any(np.isnan(level)):
        raise MeasurementError(f"{p}: an empty {DEPTH_COLUMN} cell; give the depth of every "
                               "reading (or an h_over_hb column)")
    return {LEVEL_COLUMN: level, **data}


def _check_header(p: Path, header: list[str], cols: dict[str, tuple[str, float]],
                  units: FlumeUnits | None) -> None:
    header = [h for h in header if not h.startswith(IGNORED_PREFIX)]
    if units is not None and DEPTH_COLUMN in header and LEVEL_COLUMN not in header:
        header = [LEVEL_COLUMN if h == DEPTH_COLUMN else h for h in header]
    elif units is not None:
        header = [h for h in header if h != DEPTH_COLUMN]
    allowed = [LEVEL_COLUMN, *cols]
    for h in header:
        if h not in allowed:
            raise MeasurementError(f"{p}: unknown column {h!r}; allowed: {', '.join(allowed)}")
    dup = sorted({h for h in header if header.count(h) > 1})
    if dup:
        raise MeasurementError(f"{p}: column {dup[0]!r} appears twice; keep one")
    if LEVEL_COLUMN not in header:
        raise MeasurementError(f"{p}: missing column {LEVEL_COLUMN!r} (relative loading "
                               f"h / h_B); columns found: {', '.join(header)}")
    if len(header) < 2:
        raise MeasurementError(f"{p}: no measured column; add any of {', '.join(cols)}")


def _row(p: Path, n: int, line: str, sep: str, header: list[str]
         ) -> list[tuple[float, float]]:
    """(value, upper bound) per cell: (x, NaN) for a reading, (NaN, x) for `<x`."""
    cells = [c.strip() for c in line.split(sep)]
    if len(cells) != len(header):
        raise MeasurementError(f"{p}, line {n}: {len(cells)} cells for {len(header)} columns "
                               f"({', '.join(header)})")
    out = []
    for col, cell in zip(header, cells, strict=True):
        if cell == "" and col != LEVEL_COLUMN:
            out.append((math.nan, math.nan))  # a reading that was not taken
            continue
        bound = cell.startswith("<") and col != LEVEL_COLUMN
        text = cell[1:].strip() if bound else cell
        text = text.replace(",", ".") if sep == ";" else text
        try:
            v = float(text)
        except ValueError:
            v = math.nan
        if not math.isfinite(v):
            raise MeasurementError(f"{p}, line {n}, column {col!r}: {cell!r} is not a finite "
                                   "number (or '<number' for an upper bound)")
        out.append((math.nan, v) if bound else (v, math.nan))
    return out


def _check_ranges(p: Path, data: dict[str, np.ndarray], line_numbers: list[int]) -> None:
    lv = data[LEVEL_COLUMN]
    bad = np.flatnonzero((lv < 0) | (lv > MAX_LEVEL))
    if bad.size:
        i = int(bad[0])
        raise MeasurementError(f"{p}, line {line_numbers[i]}: {LEVEL_COLUMN} = {lv[i]:g} outside "
                               f"0 to {MAX_LEVEL:g} (the predicted range; h / h_B, not mm)")
    limits = {**LIMITS, **{c: (-RAW_LIMIT_MM, RAW_LIMIT_MM) for c in RAW_COLUMNS}}
    for col, (lo, hi) in limits.items():
        if col not in data:
            continue
        v = data[col]
        bad = np.flatnonzero((v < lo) | (v > hi))
        if bad.size:
            i = int(bad[0])
            raise MeasurementError(f"{p}, line {line_numbers[i]}, column {col!r}: {v[i]:g} "
                                   f"outside {lo:g} to {hi:g}; check the unit of the column")
        if np.all(np.isnan(v)):
            raise MeasurementError(f"{p}: column {col!r} holds no value; fill or remove it")
        if np.all(v[~np.isnan(v)] == 0):  # its mismatch is relative to its peak: nothing to fit
            raise MeasurementError(f"{p}: column {col!r} holds only zeros: nothing to compare or "
                                   "fit (a sensor not connected?); fill or remove it")
    if not np.any(lv > 0):
        raise MeasurementError(f"{p}: every {LEVEL_COLUMN} is 0: the net was never loaded, so "
                               "there is nothing to compare or fit")
    _check_levels_once(p, lv, line_numbers)
    _check_stretching(p, data, line_numbers)


def _check_levels_once(p: Path, lv: np.ndarray, line_numbers: list[int]) -> None:
    """MeasurementError when a level is given twice: a test reads each level once, and two
    lines at one level cannot both be compared with the one prediction there."""
    order = np.argsort(lv, kind="stable")
    same = np.flatnonzero(np.diff(lv[order]) == 0)
    if same.size:
        i, j = sorted((int(order[same[0]]), int(order[same[0] + 1])))
        raise MeasurementError(f"{p}, lines {line_numbers[i]} and {line_numbers[j]}: "
                               f"{LEVEL_COLUMN} = {lv[i]:g} twice; keep one line per level "
                               "(average repeated readings)")


def _check_stretching(p: Path, data: dict[str, np.ndarray], line_numbers: list[int]) -> None:
    """MeasurementError when an elongation column's largest reading is negative: the water
    stretches every sensor wire, so a column that reads mostly shortening comes from a sensor
    wired or zeroed backwards (a small negative reading near zero is noise and is kept)."""
    for col, key in {**{c: k for c, (k, _) in COLUMNS.items()}, **RAW_COLUMNS}.items():
        if col not in data or not key.startswith("strain_"):
            continue
        v = data[col]
        i = int(np.nanargmax(np.abs(v)))
        if v[i] < 0:
            raise MeasurementError(f"{p}, line {line_numbers[i]}, column {col!r}: {v[i]:g} is "
                                   "its largest reading and it is negative, but the water "
                                   "stretches every sensor wire; a sensor wired or zeroed "
                                   "backwards? flip the column's sign")



@dataclass(frozen=True)
class Mismatch:
    """Measured vs predicted for one column: RMS of the difference (model units), and the
    RMS of the scored misses (`scored`: a value's over the column's measured peak, a bound's
    excess over the bound); inside : points within the predicted band; bounds : how many of
    the `points` are bounds ('<x'), the rest are measured values."""

    metric: str
    column: str
    rms: float
    rms_rel: float
    points: int
    inside: int
    bounds: int = 0

    @property
    def values(self) -> int:
        """Measured values (not bounds) the column compares."""
        return self.points - self.bounds


SCORING = ("relative mismatch: a measured value's miss over its column's measured peak; a "
           "bound's excess over the bound itself (a prediction 3.4 x its '< 0.5 %' bound "
           "misses by 240 %, not by its small share of the column's peak)")


def scored(m: Measurement, key: str, pred: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Every point of column `key` against `pred` (values, then bounds): (the miss in the
    model's units, the scored miss of SCORING); NaN where `pred` is NaN. A bound counts by its
    excess only, over the bound: a breach of an onset bound weighs as the breach it is."""
    meas, cap = m.values[key], m.bound(key)
    ok, capped = ~np.isnan(meas), ~np.isnan(cap)
    peak = float(np.abs(meas[ok]).max()) if ok.any() else 0.0
    miss = meas[ok] - pred[ok]
    excess = np.maximum(pred[capped] - cap[capped], 0.0)
    excess = np.where(np.isnan(pred[capped]), np.nan, excess)
    # a bound of zero or below has no scale of its own: its column's peak, else 1
    scale = np.where(cap[capped] > 0, cap[capped], peak if peak > 0 else 1.0)
    rel = np.concatenate([miss / peak if peak > 0 else miss, excess / scale])
    return np.concatenate([miss, excess]), rel


def mismatch(m: Measurement, predicted: dict[str, np.ndarray],
             lo: dict[str, np.ndarray] | None = None, hi: dict[str, np.ndarray] | None = None
             ) -> list[Mismatch]:
    """Mismatch of every measured column against `predicted` (METRICS key -> values at the
    measured levels), and how many points fall inside the band [lo, hi] when one is given."""
    out = []
    for key, col in m.columns.items():
        meas, pred, cap = m.values[key], predicted[key], m.bound(key)
        ok = ~np.isnan(meas) & ~np.isnan(pred)
        capped = ~np.isnan(cap) & ~np.isnan(pred)
        diff, rel = scored(m, key, pred)
        keep = ~np.isnan(rel)
        rms = float(np.sqrt(np.mean(diff[keep]**2))) if keep.any() else math.nan
        rms_rel = float(np.sqrt(np.mean(rel[keep]**2))) if keep.any() else math.nan
        inside = 0
        if lo is not None and hi is not None:
            inside = int(np.sum((meas[ok] >= lo[key][ok] - 1e-12)
                                & (meas[ok] <= hi[key][ok] + 1e-12)))
        out.append(Mismatch(key, col, rms, rms_rel, int(ok.sum() + capped.sum()), inside,
                            int(capped.sum())))
    return out


def objective(m: Measurement, predicted: dict[str, np.ndarray]) -> float:
    """Mean over columns of the squared RMS of the scored misses (`scored`: columns of
    different units weigh the same, a bound by its breach)."""
    return float(np.nanmean([mm.rms_rel**2 for mm in mismatch(m, predicted)]))


def not_improved(before: list[Mismatch], after: list[Mismatch]
                 ) -> list[tuple[str, float, float]]:
    """(column, scored RMS before, after) of every column a fit does not improve: one with
    measured values whose mismatch does not fall (by more than WORSE_TOL), or one whose
    mismatch grows (a bound it breaks more). A fit that leaves a measured column as it was, or
    buys one column with another, explains neither: no profile is written from it."""
    out = []
    for b, a in zip(before, after, strict=True):
        if a.points == 0 or math.isnan(a.rms_rel) or math.isnan(b.rms_rel):
            continue
        worse = a.rms_rel > b.rms_rel * (1 + WORSE_TOL)
        flat = a.values > 0 and b.rms_rel > 0 and a.rms_rel > b.rms_rel * (1 - WORSE_TOL)
        if worse or flat:
            out.append((a.column, b.rms_rel, a.rms_rel))
    return out


Predictor = Callable[[float], dict[str, np.ndarray]]
FIT_KINDS = ("stiffness", "slack", "multi")  # multi: printgen.verification.fit
STIFFNESS_RANGE = (0.2, 5.0)  # net stiffness factors searched: a printed net 5x off is a misprint
SLACK_RANGE = (0.0, 0.03)  # initial slack searched: 3 % sags visibly, a lab would see it
XTOL_LOG = 0.005  # stiffness factor known to 0.5 % (bounded Brent on log factor)
XTOL_SLACK = 1e-4  # slack known to 0.01 %
# sweeps of a one-factor fit, at most: the bounded Brent search's evaluations (golden section
# to XTOL_LOG over the stiffness range takes about 14; the parabolic steps fewer), plus the
# nominal it is compared with, and the nominal on the band's coarse net when it has one
# (benchmarks/measurements.md#fit-paper-test)
FACTOR_EVALUATIONS = 20
AT_BOUND = 0.01  # a result this close to a range end (fraction of the range) is "at the bound"


@dataclass(frozen=True)
class Fit:
    """The factor of the printed net that best explains the measurement.

    kind : "stiffness" (multiplier on the net's force law) or "slack" (relative initial
    slack); value : the fitted factor; before, after : mismatches at the nominal (1 or 0) and
    at the fitted value; predicted : METRICS key -> (k,) at the measured levels, fitted;
    evaluations : solver sweeps run; at_bound : the best value is at the searched range's end.
    """

    kind: str
    value: float
    before: list[Mismatch]
    after: list[Mismatch]
    predicted: dict[str, np.ndarray]
    evaluations: int
    at_bound: bool

    @property
    def worsened(self) -> list[tuple[str, float, float]]:
        """(column, scored RMS before, after) of every column with measured
        values that the fitted factor fits worse than the nominal: a factor that buys one
        column with another explains neither, and its profile is not written."""
        return [(a.column, b.rms_rel, a.rms_rel) for b, a in zip(self.before, self.after,
                                                                 strict=True)
                if a.points > 0 and a.rms_rel > b.rms_rel * (1 + WORSE_TOL)]

    @property
    def unimproved(self) -> list[tuple[str, float, float]]:
        """`not_improved`: the columns the fitted factor leaves unimproved or worsens."""
        return not_improved(self.before, self.after)

    @property
    def writes_profile(self) -> bool:
        """A profile is fed back only from a factor inside its range that improves every
        measured column (`not_improved`)."""
        return not self.at_bound and not self.unimproved


def fit_factor(m: Measurement, predict: Predictor, kind: str = "stiffness") -> Fit:
    """Minimise the measured-vs-predicted mismatch (`objective`) over one factor:
    scipy's bounded Brent search on log(factor) for stiffness, on the slack itself for slack.
    `predict(value)` returns the predicted curves at the measured levels (from h / h_B = 0)."""
    from scipy.optimize import minimize_scalar

    if kind not in FIT_KINDS[:2]:
        raise InputError(f"fit {kind!r} unknown; choose one of {', '.join(FIT_KINDS)}")
    cache: dict[float, dict[str, np.ndarray]] = {}

    def curves_at(value: float) -> dict[str, np.ndarray]:
        if value not in cache:
            cache[value] = predict(value)
        return cache[value]

    if kind == "stiffness":
        lo, hi = (math.log(v) for v in STIFFNESS_RANGE)
        to_value, nominal, xtol = math.exp, 1.0, XTOL_LOG
    else:
        (lo, hi), to_value, nominal, xtol = SLACK_RANGE, float, 0.0, XTOL_SLACK
    res = minimize_scalar(lambda x: objective(m, curves_at(to_value(x))), bounds=(lo, hi),
                          method="bounded", options={"xatol": xtol,
                                                     "maxiter": FACTOR_EVALUATIONS})
    value = to_value(float(res.x))
    edge = AT_BOUND * (hi - lo)
    return Fit(kind, value, mismatch(m, curves_at(nominal)), mismatch(m, curves_at(value)),
               curves_at(value), len(cache), bool(res.x - lo < edge or hi - res.x < edge))


def fitted_profile(material: str, kind: str, value: float, *, panel_kappas: tuple | None,
                   modulus_gpa: float | None, source: str) -> str:
    """TOML text of the material profile `<material>-fitted` that feeds a fitted stiffness
    factor back: it inherits `material` and scales its panel law (or its measured modulus);
    written and checked by calibrate's writer (it must load). "" for a slack fit."""
    from printgen.calibrate.profile_writer import validated_text

    material = profile_name(material, "fitted profile: inherits")
    if kind != "stiffness":
        return ""
    prov = {"source": f"printgen verify --measured {source}",
            "conditions": f"effective law of the printed net fitted to the loading test {source}"}
    if panel_kappas:
        table = {"panel_law": {"kappa_kn_per_m_per_m": [float(f"{k * value / 1e3:.4g}")
                                                        for k in panel_kappas]} | prov}
    else:
        table = {"tensile_modulus": {"value_gpa": float(f"{modulus_gpa * value:.4g}")} | prov}
    data = {"inherits": material,
            "description": (f"the printed net of {source}, fitted by printgen verify --measured: "
                            f"effective stiffness {value:.3f} x the '{material}' profile"),
            "measured": table}
    return validated_text(data, name=f"{material}-fitted")[0]


def model_predictor(d: Design, band: Band, m: Measurement, kind: str = "stiffness", *,
                    load_kw: dict | None = None) -> Predictor:
    """`predict(value)` for `fit_factor`: the printed model swept with the net's stiffness
    times `value` (or `value` initial slack) up to the highest measured level, on the band's
    solver net (a coarse net adds its change to the nominal curves, as the band does), counted
    from h / h_B = 0 at the measured levels. Each sweep solves only h / h_B = 0 and the
    measured levels (`measured_path`): the solver's states do not depend on the path (an
    elastic net; a level it cannot reach in one step it reaches by sub-steps)."""
    lv, k = measured_path(m), band.coarsen
    nominal = Variant(options=SceneOptions(mounting=band.mounting,
                                           sensor_force=band.sensor_force))
    base = curves(run_variant(d, nominal, lv, k, load_kw)) if k > 1 else None
    band_nominal = {key: np.interp(lv, band.levels, band.nominal[key]) for key in m.values
                    } if k > 1 else {}

    def predict(value: float) -> dict[str, np.ndarray]:
        if kind == "stiffness":
            v = Variant("fit", options=dataclasses.replace(nominal.options, net_factor=value,
                                                           frame_factor=value))
        else:
            v = dataclasses.replace(nominal, label="fit", slack=value)
        c = curves(run_variant(d, v, lv, k, load_kw))
        out = {}
        for key in m.values:
            y = c[key] if base is None else band_nominal[key] + c[key] - base[key]
            out[key] = np.interp(m.levels, lv, y - y[0])
        return out

    return predict


def measured_path(m: Measurement) -> np.ndarray:
    """The load path a fit's sweep solves: h / h_B = 0 (the sensors' zero) and every measured
    level, in order."""
    return np.union1d([0.0], m.levels)
