"""The verification curves as a tidy table: one row per relative loading h / h_B, one column per
quantity and barrier, named and scaled as in curves.csv (strains in %, `_pct`; normalised
deflection and lowering dimensionless; tensions with their unit), with the model's band
columns when a band was run. `curve_rows` gives plain dicts (no pandas needed);
`CurveTable.curves_table()` the same as a pandas DataFrame (the `table` extra)."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from printgen.outputs.display import Summary, frame
from printgen.verification.compare import METRICS, UPPER_RANGE
from printgen.verification.measured import COLUMNS, LEVEL_COLUMN

if TYPE_CHECKING:
    from printgen.verification.bands import Band
    from printgen.verification.preprint import Verification

# METRICS key -> (column stem with its unit, factor from the record's unit: strain -> %)
CURVE_COLUMNS = {key: (col, 100.0 if col.endswith("_pct") else 1.0)
                 for col, (key, _) in COLUMNS.items()}
# (column, Deformation field, barrier, factor from N): the largest tensions, each in its unit
TENSIONS = (("max_prototype_strand_kn", "max_strand_tension", "prototype", 1e-3),
            ("max_prototype_cable_kn", "max_cable_tension", "prototype", 1e-3),
            ("max_model_strand_n", "max_strand_tension", "model", 1.0),
            ("max_model_cable_n", "max_cable_tension", "model", 1.0))


def curve_column(stem: str, who: str) -> str:
    """The column of quantity `stem` (a CURVE_COLUMNS stem) for `who` (prototype, model,
    band_min, band_max): its unit suffix kept last, `bottom_cable_elongation_model_pct`."""
    return f"{stem.removesuffix('_pct')}_{who}" + ("_pct" if stem.endswith("_pct") else "")


def nearest(levels: np.ndarray, keep: np.ndarray) -> np.ndarray:
    """Indices into `levels` of each value of `keep` (the band's levels are the sweep's)."""
    return np.array([int(np.argmin(np.abs(levels - x))) for x in keep], dtype=int)


def curve_rows(v: Verification, band: Band | None = None) -> list[dict[str, float]]:
    """One dict per relative loading: `h_over_hb`, then each quantity of prototype and model
    (and the band's min and max with `band`, at its levels), then the largest tensions. The
    levels are those compared (both barriers converged), or the band's."""
    p, m = v.prototype.deformation, v.model.deformation
    lv = np.asarray(band.levels if band is not None else m.levels, dtype=float)
    ip, im = nearest(p.levels, lv), nearest(m.levels, lv)
    cols: dict[str, np.ndarray] = {LEVEL_COLUMN: lv}
    lo, hi = band.envelope() if band is not None else ({}, {})
    for key, (stem, f) in CURVE_COLUMNS.items():
        cols[curve_column(stem, "prototype")] = p.values[key][ip] * f
        cols[curve_column(stem, "model")] = m.values[key][im] * f
        if band is not None:
            cols[curve_column(stem, "band_min")] = np.asarray(lo[key]) * f
            cols[curve_column(stem, "band_max")] = np.asarray(hi[key]) * f
    for col, name, who, f in TENSIONS:
        d, idx = (p, ip) if who == "prototype" else (m, im)
        cols[col] = np.asarray(getattr(d, name))[idx] * f
    return [{k: float(c[i]) for k, c in cols.items()} for i in range(len(lv))]


def verification_summary(v: Verification) -> Summary:
    """The verdict, the load case, the levels compared and each quantity's mismatch."""
    rows = [("load case", v.load_case),
            ("levels compared", f"{v.compared} of {v.asked or v.compared}, h/h_B "
                                f"{v.model.deformation.levels[0]:g} to "
                                f"{v.model.deformation.levels[-1]:g}")]
    rows += [(METRICS[m.metric].split(" (")[0],
              f"max mismatch {m.max_rel:.0%} of the prototype's peak, model/prototype "
              f"{m.ratio_high:.2f} above h/h_B {UPPER_RANGE:g}{'' if m.ok else ' (off)'}")
             for m in v.mismatches]
    rows += [("verdict", line) for line in v.headlines]
    return Summary(f"Verification ({v.model.scene.name})", tuple(rows), v.verdict)


class CurveTable:
    """A result holding a verification (and perhaps its band): its curves as rows
    (`curve_rows`) or a DataFrame (`curves_table`)."""

    def curve_source(self) -> tuple[Verification, Band | None]:
        raise NotImplementedError

    def curve_rows(self) -> list[dict[str, float]]:
        """The curves, one dict per relative loading (see `printgen.verification.tables`)."""
        return curve_rows(*self.curve_source())

    def curves_table(self) -> Any:
        """The curves as a pandas DataFrame, one row per relative loading h / h_B: strains in
        % (`_pct` columns), deflection and lowering normalised, tensions in N or kN, band
        columns when the band was run; needs the `table` extra (pandas)."""
        return frame(self.curve_rows(), "the verification curves")
