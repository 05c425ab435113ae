"""The multi-parameter fit of a measured test in the report: the best parameters
against their bounds, the best of each discrete choice, and what the data determine."""

from __future__ import annotations

from printgen.report.html import Report
from printgen.verification.fit import BOUNDS, MultiFit


def _value(key: str, v: float) -> str:
    return f"{v:.3g}" if key == "net_factor" else f"{v:.2%}"


def multi_fit_sections(rep: Report, fit: MultiFit) -> None:
    """Tables of the fitted parameters, the discrete choices and the identifiability."""
    ident = fit.identifiability
    rep.table(["parameter", "fitted", "low", "high", "nominal", "sensitivity"],
              [[k, _value(k, getattr(fit.params, k)), _value(k, lo), _value(k, hi),
                _value(k, nom), f"{ident.sensitivity[k]:.3g}"]
               for k, (lo, hi, nom) in BOUNDS.items()])
    rep.table(["mounting", "panel-test orientation", "span", "bottom row", "best objective",
               "net factor", "net slack", "cable slack"],
              [[m, o or "as profiled", "printed width" if s is None else f"{s * 1e3:g} mm",
                b, f"{obj:.3g}", f"{p.net_factor:.3g}", f"{p.net_slack:.2%}",
                f"{p.cable_slack:.2%}"] for (m, o, s, b), (p, obj) in fit.choices.items()])
    sv = ", ".join(f"{v:.3g}" for v in ident.singular_values)
    rep.paragraph(f"Identifiability: singular values of the scaled residuals' Jacobian {sv}; "
                  f"determined by the data: {', '.join(ident.determined()) or 'none'} "
                  f"({fit.evaluations} solver sweeps). Only the printed model is fitted; the "
                  "prototype stays a prediction.")
