"""The multi-parameter fit of a measured test in the report: the best parameters
against their bounds, the best of each discrete choice, what the data determine (the
identifiability and each parameter's profile) and how the mismatch is scored."""

from __future__ import annotations

from printgen.report.html import Report
from printgen.verification.fit import BOUNDS, IDLE, PROFILE_RISE, MultiFit
from printgen.verification.measured import SCORING


def _value(key: str, v: float) -> str:
    return f"{v:.3g}" if key == "net_factor" else f"{v:.2%}"


def _fitted(fit: MultiFit, key: str) -> str:
    v = _value(key, getattr(fit.params, key))
    return f"{IDLE[key]} ({v} or more)" if key in fit.idle else v


def _allowed(fit: MultiFit, key: str) -> str:
    pr = fit.profiles.get(key)
    if pr is None:
        return "held"
    lo, hi = pr.allowed
    if not pr.determined:
        return "flat: not determined"
    return f"{_value(key, lo)} to {_value(key, hi)}"


def multi_fit_sections(rep: Report, fit: MultiFit) -> None:
    """Tables of the fitted parameters, the discrete choices, the profiles and the
    identifiability."""
    ident = fit.identifiability
    rep.table(["parameter", "fitted", "low", "high", "nominal", "sensitivity",
               "allowed by the data"],
              [[k, _fitted(fit, k), _value(k, lo), _value(k, hi), _value(k, nom),
                f"{ident.sensitivity[k]:.3g}", _allowed(fit, k)]
               for k, (lo, hi, nom) in BOUNDS.items()])
    rep.table(["mounting", "panel-test orientation", "span", "bottom row", "best objective",
               "net factor", "net slack", "cable slack", "found on"],
              [[m, o or "as profiled", "printed width" if s is None else f"{s * 1e3:g} mm",
                b, f"{obj:.3g}", f"{p.net_factor:.3g}", f"{p.net_slack:.2%}",
                f"{p.cable_slack:.2%}", fit.net_of((m, o, s, b))]
               for (m, o, s, b), (p, obj) in fit.choices.items()])
    if fit.profiles:
        rep.table(["parameter", *[f"value {i + 1}" for i in range(len(
            next(iter(fit.profiles.values())).values))], "determined"],
                  [[k, *[f"{_value(k, v)}: {r:.0%}" for v, r in zip(pr.values, pr.rms,
                                                                       strict=True)],
                    "yes" if pr.determined else "no (flat)"]
                   for k, pr in fit.profiles.items()])
    sv = ", ".join(f"{v:.3g}" for v in ident.singular_values)
    flat = fit.flat()
    runs = ", ".join(f"{n} on the {k}" for k, n in fit.sweeps.items())
    rep.paragraph(
        f"Scoring: {SCORING}. Profiles: the scored RMS mismatch along each parameter over its "
        "range, the others held at the best set; a parameter is determined by the data when "
        f"the mismatch rises by more than {PROFILE_RISE:.0%} above the best somewhere in its "
        "range, and the values within that rise are what the data allow; not determined "
        f"(flat): {', '.join(flat) or 'none'}. Identifiability at the best set: singular "
        f"values of the scaled residuals' Jacobian {sv}; determined directions: "
        f"{', '.join(ident.determined()) or 'none'}. {fit.evaluations} solver sweeps"
        f"{f' ({runs})' if runs else ''}, each over h/h_B = 0 and the measured levels. Only "
        "the printed model is fitted; the prototype stays a prediction.")
