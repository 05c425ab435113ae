"""The scale series in the report: its figure (each output against lambda, with the +-10 %
band around the prototype), its table (HTML, CSV, terminal rows), the sentences and the law
check, and every assumption of the scene and of the scaling."""

from __future__ import annotations

import csv
import io

from printgen.report.html import Report
from printgen.report.plots import _png, _pyplot, lambda_axis
from printgen.verification.series import OUTPUTS
from printgen.verification.series_table import TOLERANCE, Series

COLUMNS = ["row", "lambda", *OUTPUTS, *[f"{k}_ratio" for k in OUTPUTS],
           "pi_f_over_ea", "law_departure_deflection", "law_departure_strain_mid"]


def series_figure(s: Series) -> bytes:
    """Deflection, lowering and mid-height elongation against lambda, one line per row; the
    prototype's value and its +-TOLERANCE band shaded."""
    plt = _pyplot()
    fig, axes = plt.subplots(1, len(OUTPUTS), figsize=(14, 4.4), constrained_layout=True)
    lams = list(s.scales)
    for ax, (key, what) in zip(axes, OUTPUTS.items(), strict=True):
        ref = s.reference[key]
        ax.axhspan(ref * (1 - TOLERANCE), ref * (1 + TOLERANCE), color="0.85", lw=0,
                   label=f"prototype +-{TOLERANCE:.0%}")
        for i, row in enumerate(s.rows):
            ys = [s.point(row.key, lam).values[key] for lam in lams]
            style = "--" if row.kind == "similitude" else "-o"
            ax.plot(lams, ys, style, color=f"C{i}", label=row.label)
        lambda_axis(ax, what)
    axes[0].legend(fontsize=7)
    fig.suptitle(f"{s.prototype}: scale series ({s.scene})")
    return _png(fig)


def table_rows(s: Series) -> list[list[str]]:
    """One line per (row, lambda): the outputs, their ratio to the prototype, Pi and the
    departure from the (F/EA)^(1/3) law."""
    out = []
    labels = {r.key: r.label for r in s.rows}
    for p in s.points:
        out.append([labels[p.row], f"{p.scale:g}",
                    *[f"{p.values[k]:.6f}" for k in OUTPUTS],
                    *[f"{p.ratio[k]:.4f}" for k in OUTPUTS], f"{p.pi:.4g}",
                    f"{p.departure['deflection']:+.4f}", f"{p.departure['strain_mid']:+.4f}"])
    return out


def series_csv(s: Series) -> str:
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(COLUMNS)
    w.writerows(table_rows(s))
    return buf.getvalue()


def series_report(s: Series, figure: bytes) -> Report:
    rep = Report(f"printgen series: {s.prototype}")
    rep.heading("What the series answers")
    for text in s.sentences.values():
        rep.paragraph(text)
    rep.figure(figure, "Scale series: normalised deformations against lambda", "scale-series")
    rep.heading("Table (ratio = value / the prototype's)")
    rep.table(COLUMNS, table_rows(s))
    rep.heading("Check against the (F/EA)^(1/3) law of a pure elastic net")
    rep.paragraph("Pi = F / EA with F = rho g h_B A* and EA the net strands' initial axial "
                  "stiffness; law = prototype x (Pi / Pi_prototype)^n, n = 1/3 for the "
                  "deflection and 2/3 for the elongation (a strain, (w / L)^2); departure = "
                  "value / law - 1.")
    labels = {r.key: r.label for r in s.rows}
    for key, check in s.law.items():
        rep.paragraph(f"{labels[key]}: largest |departure| {check['max_abs_departure']:.2%}; "
                      "local exponents d ln(deflection) / d ln(Pi) "
                      + ", ".join(f"{e:.3f}" for e in check["local_exponents"]["deflection"])
                      + ". " + "; ".join(check["explanation"]) + ".")
    rep.heading("Assumptions")
    rep.table(["what", "value", "source"], [list(a) for a in s.assumptions])
    return rep
