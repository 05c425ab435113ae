"""Report sections and JSON records of the model's uncertainty band and of a lab's measured
loading test: what varied, the band at h/h_B = 0.5, 1.0, 1.1, the band verdicts,
and the measured points against the band with the fitted factor of the printed net."""

from __future__ import annotations

import html
from typing import Any

import numpy as np

from printgen.report.html import Report
from printgen.report.report import fmt_value, unit_of
from printgen.verification.bands import Band, BandVerdict, band_verdicts
from printgen.verification.central import QUANTILES, RANGE_POINTS, RATIO_FLOOR
from printgen.verification.compare import METRICS, Deformation
from printgen.verification.measured import SCORING, Fit, Measurement, mismatch
from printgen.verification.preprint import SHAPE_LEVELS, Verification

SHOW_LEVELS = SHAPE_LEVELS  # relative loadings shown in the tables and summaries


def _at(levels: np.ndarray, x: float) -> int | None:
    i = int(np.argmin(np.abs(levels - x)))
    return i if abs(levels[i] - x) < 1e-9 else None


def band_sections(rep: Report, v: Verification, band: Band) -> None:
    """What varied, the band at SHOW_LEVELS, and the verdict of each metric."""
    rep.heading("Uncertainty band of the printed model")
    runs = "; ".join(f"{label} ({src})" for label, src in band.sources.items()) or "none"
    mesh = ("the design's own net" if band.coarsen == 1 else
            f"a net {band.coarsen} times coarser (strands {band.coarsen} times stiffer), each "
            "variant's change added to the nominal curves")
    tried = ", ".join(f"x{k}: {c:.1%}" for k, c in band.refinement.items()) or "none"
    rep.paragraph(f"The model is swept for its nominal inputs and for each uncertain input moved "
                  f"alone: {runs}. The envelope is the min/max of those curves (one input "
                  f"at a time; combined extremes are not run). Variants ran on {mesh}: the "
                  f"coarsest net whose nominal curves move by less than 1 % of their peak "
                  f"(refinement test, largest change: {tried}).")
    rep.paragraph(CENTRAL_TEXT)
    _weights_table(rep, band, "model")
    if v.prototype_band is not None:
        _weights_table(rep, v.prototype_band, "prototype")
    _decision_lines(rep, v)
    for note in band.notes:
        rep.paragraph(f"Not in the band: {note}.", "note")
    for label, lv in band.failed.items():
        rep.verdict(False, f"{label}: no converged state at h/h_B = "
                           f"{', '.join(f'{x:g}' for x in lv)}; left out of the band there")
    for label, why in band.refused.items():
        rep.verdict(False, f"{label}: the solver refused this input ({why}); no curves, left "
                           "out of the band (the verdict cannot pass while it is plausible)")
    lo, hi = band.envelope()
    clo, chi = band.central()
    p = v.prototype.deformation.values
    verdicts = {b.metric: b for b in band_verdicts(p, band)}
    start = {b.metric: b for b in band_verdicts(p, band, from_start=True)}
    idx = [_at(band.levels, x) for x in SHOW_LEVELS]
    rows = []
    for key in METRICS:
        cells = [("-" if i is None else f"{fmt_value(key, p[key][i])} (central "
                  f"{fmt_value(key, clo[key][i])} to {fmt_value(key, chi[key][i])}; envelope "
                  f"{fmt_value(key, lo[key][i])} to {fmt_value(key, hi[key][i])})")
                 for i in idx]
        rows.append([f"{METRICS[key]} ({unit_of(key)})", *cells, verdicts[key].text,
                     start[key].text])
    rep.table(["quantity: prototype (model central interval; envelope min to max)",
               *(f"h/h_B = {x:g}" for x in SHOW_LEVELS), "verdict", "counted from h/h_B = 0"],
              rows)
    negative = [METRICS[k].split(" (")[0] for k in METRICS
                if k.startswith("strain") and np.nanmin(lo[k]) < 0]
    if negative:
        rep.paragraph(f"Band below zero ({', '.join(negative)}): in some variant the sensor "
                      "wire is shorter there than at rest; a sensor zeroed at h/h_B = 0 reads "
                      "that as a negative elongation (a computed reading, not an error).", "note")


CENTRAL_TEXT = (
    f"The central interval is {QUANTILES[0]:.0%} to {QUANTILES[1]:.0%} of the weighted "
    "combinations of the variants: each variant's change from the nominal (a ratio where every "
    f"weighted curve is positive at that level and the nominal reaches {RATIO_FLOOR:.0%} of "
    "its peak, else a difference) is an independent "
    "contribution; the answers of one question are exclusive, each with its weight (the "
    "nominal the rest), a range uniform between the nominal and its end (taken at "
    f"{RANGE_POINTS} points); the contributions add (first order: the combinations are not "
    "run), and the interval always holds the nominal. A variant with a reason to be excluded "
    "shows in the envelope only. The three-valued verdict compares the model's central "
    "interval with the prototype's: PASS when every pair within them keeps every quantity "
    "within the tolerance, FAIL when none does, UNDECIDED when they straddle it.")


def _weights_table(rep: Report, band: Band, who: str) -> None:
    """Each variant's question, weight and its argument, or why it carries none."""
    excluded = band.excluded
    rows = [[label, info.question, ("excluded" if label in excluded else
             f"uniform to it, weight {info.weight:g}" if info.spread == "range" else
             f"{info.weight:.2g}"), excluded.get(label, info.weight_source)]
            for label, info in band.info.items() if label in band.variants]
    if rows:
        rep.table([f"{who} variant", "question", "weight", "why (or why excluded)"], rows)


def _decision_lines(rep: Report, v: Verification) -> None:
    """The bands' verdict per quantity, and for UNDECIDED what decides and the test."""
    d = v.decision
    if d is None:
        return
    for m in d.metrics:
        turns = f"; turns on {', '.join(m.deciding)}" if m.deciding else ""
        rep.verdict(m.status, f"{METRICS[m.metric].split(' (')[0]}: mismatch within the central "
                              f"bands {m.best:.0%} to {m.worst:.0%} of the prototype's peak "
                              f"(tolerance {d.tolerance:.0%}){turns}")
    if d.verdict == "UNDECIDED":
        rep.paragraph(f"Cheapest test that settles it: {d.test}.")


def band_record(v: Verification, band: Band) -> dict[str, Any]:
    """The band in report.json: every curve's min/max (absolute and from h/h_B = 0), the
    central interval (`central_definition`), the variants with their weights and notes, the
    refinement test, the verdicts, and the prototype's band."""
    lo, hi = band.envelope()
    lo0, hi0 = band.envelope(from_start=True)
    clo, chi = band.central()
    p = v.prototype.deformation.values
    at = {f"{x:g}": {key: {"min": lo[key][i], "max": hi[key][i], "nominal": band.nominal[key][i],
                           "central_min": clo[key][i], "central_max": chi[key][i],
                           "prototype": p[key][i]} for key in METRICS}
          for x in SHOW_LEVELS if (i := _at(band.levels, x)) is not None}
    pb = v.prototype_band
    return {
        "levels": band.levels, "nominal": band.nominal, "min": lo, "max": hi,
        "min_from_start": lo0, "max_from_start": hi0, "at": at,
        "central_min": clo, "central_max": chi, "central_definition": CENTRAL_TEXT,
        "weights": weights_record(band),
        "prototype": None if pb is None else {
            "central_min": pb.central()[0], "central_max": pb.central()[1],
            "min": pb.envelope()[0], "max": pb.envelope()[1], "weights": weights_record(pb),
            "variant_curves": pb.variants, "not_converged": pb.failed},
        "variants": band.sources, "variant_curves": band.variants, "notes": band.notes,
        "coarsen": band.coarsen, "refinement_change": {str(k): c for k, c in
                                                       band.refinement.items()},
        "not_converged": band.failed, "refused": band.refused,
        "verdicts": [_verdict(b) for b in band_verdicts(p, band)],
        "verdicts_from_start": [_verdict(b) for b in band_verdicts(p, band, from_start=True)],
    }  # its wall time (band.seconds) goes to the run's timings


def weights_record(band: Band) -> dict[str, dict[str, Any]]:
    """label -> its question, weight, spread, the weight's argument, and the reason it is
    excluded ("" when it carries its weight)."""
    excluded = band.excluded
    return {label: {"question": i.question, "weight": 0.0 if label in excluded else i.weight,
                    "spread": i.spread, "weight_source": i.weight_source,
                    "excluded": excluded.get(label, "")}
            for label, i in band.info.items() if label in band.variants}


def _verdict(b: BandVerdict) -> dict[str, Any]:
    return {"metric": b.metric, "kind": b.kind, "least": b.least, "most": b.most,
            "inside_levels": b.inside_levels, "levels": b.levels, "text": b.text}


def predicted_at(m: Measurement, band: Band) -> tuple[dict, dict, dict]:
    """(nominal, band min, band max) counted from h/h_B = 0, at the measured levels."""
    lo, hi = band.envelope(from_start=True)
    nom = {k: band.nominal[k] - band.nominal[k][0] for k in METRICS}
    return tuple({k: np.interp(m.levels, band.levels, c[k]) for k in m.values}
                 for c in (nom, lo, hi))


def measured_sections(rep: Report, m: Measurement, band: Band, fit: Fit | None,
                      profile: str, *, prototype: Deformation | None = None) -> None:
    """Measured points against the band, their mismatch, the fitted factor and its profile."""
    from printgen.report.plots import measured_figure

    rep.heading(f"Measured loading test: {m.path}")
    nom, lo, hi = predicted_at(m, band)
    before = mismatch(m, nom, lo, hi)
    after = {mm.metric: mm for mm in fit.after} if fit else {}
    rep.paragraph("Measured values are taken as the sensors read them, counted from h/h_B = 0, "
                  f"and compared with the predicted curves counted from there. Scored {SCORING}.")
    rows = [[mm.column, str(mm.points), f"{mm.inside} of {mm.points}", _fmt(mm),
             f"{mm.rms_rel:.0%}"] + ([_fmt(after[mm.metric]), f"{after[mm.metric].rms_rel:.0%}"]
                                     if fit else []) for mm in before]
    cols = ["column", "points", "inside the band", "RMS mismatch (nominal)", "scored"]
    if fit:
        cols += [f"RMS, fitted {fit.kind}", "scored"]
    rep.table(cols, rows)
    if fit:
        rep.paragraph(fit_sentence(fit))
        if fit.kind == "multi":
            from printgen.report.fitreport import multi_fit_sections

            multi_fit_sections(rep, fit)
    rep.figure(measured_figure(m, band, fit, prototype), "Measured points (black dots; open "
               "triangles: 'below' bounds) on the predicted band (orange: model nominal, shaded: "
               "band; thin lines: each variant), with the prototype (black line), all counted "
               "from h/h_B = 0; dashed: fitted.", "measured")
    if profile:
        rep.paragraph("To feed it back, save this in a profile folder of your own as "
                      "materials/<name>.toml, add the folder to $PRINTGEN_PROFILES, and name "
                      "it as the net's material:")
        rep.blocks.append(f"<pre>{html.escape(profile)}</pre>")


def _fmt(mm) -> str:
    scale, unit = (100.0, " %") if mm.metric.startswith("strain") else (1.0, "")
    return f"{mm.rms * scale:.3g}{unit}"


def fit_sentence(fit: Fit) -> str:
    """What the fitted factor says, in one sentence."""
    if fit.kind == "multi":
        return fit.sentence()
    what = (f"net stiffness {fit.value:.3f} x its profile" if fit.kind == "stiffness"
            else f"initial slack {fit.value:.2%} of the net")
    edge = (" The best value is at the end of the searched range: the measurement is outside "
            "what this factor can explain." if fit.at_bound else "")
    worse = "; ".join(f"{col} {before:.1%} -> {after:.1%}"
                      for col, before, after in fit.worsened)
    flat = "; ".join(f"{col} {before:.1%} -> {after:.1%}"
                     for col, before, after in fit.unimproved if (col, before, after)
                     not in fit.worsened)
    if worse:
        edge += (f" It fits some columns at the price of others (scored RMS, nominal -> "
                 f"fitted: {worse}): this one factor does not explain the test, so no profile "
                 "is written (--fit multi tries several).")
    elif flat:
        edge += (f" It does not improve every measured column (scored RMS, nominal -> fitted: "
                 f"{flat}): this one factor does not explain the test, so no profile is "
                 "written (--fit multi tries several).")
    return (f"The printed net behaved like a model with {what} (one-factor fit, "
            f"{fit.evaluations} solver sweeps).{edge}")


def measured_record(m: Measurement, band: Band, fit: Fit | None, profile: str
                    ) -> dict[str, Any]:
    """The measured comparison in report.json."""
    nom, lo, hi = predicted_at(m, band)
    rec: dict[str, Any] = {"file": m.path, "levels": m.levels, "values": m.values,
                           "columns": m.columns, "predicted_nominal": nom,
                           "band_min": lo, "band_max": hi,
                           "mismatch": mismatch(m, nom, lo, hi), "scoring": SCORING,
                           "fit": None}
    if fit and fit.kind == "multi":
        rec["fit"] = {**fit.to_record(), "profile": profile}
    elif fit:
        rec["fit"] = {"kind": fit.kind, "value": fit.value, "at_bound": fit.at_bound,
                      "evaluations": fit.evaluations, "mismatch_nominal": fit.before,
                      "mismatch_fitted": fit.after, "predicted": fit.predicted,
                      "not_improved": [{"column": c, "before": b, "after": a}
                                       for c, b, a in fit.unimproved],
                      "sentence": fit_sentence(fit), "profile": profile}
    return rec
