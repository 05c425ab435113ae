"""What `make` adds around the report once every step ran: the summary box at the top of
report.html (and "summary" in report.json), each figure as its own PNG and SVG under
figures/ (and the kit's pictures beside the report: assembly.png, preview-*.png), and the
lab's CSV files (printgen.report.labfiles)."""

from __future__ import annotations

from typing import Any

from printgen.report.html import Report
from printgen.report.labfiles import lab_files
from printgen.report.summary import summary_html, summary_record

FIGURES = "figures"  # folder of the figure files in the output


def report_files(record: dict[str, Any], rep: Report) -> dict[str, bytes]:
    """Set the report's summary box and record["summary"]; the extra files by relative path.

    Figures are numbered in report order: figures/NN-name.png and .svg; those not drawn yet
    are drawn first (`Report.draw`).
    """
    record["summary"] = summary_record(record)
    rep.lead = summary_html(record["summary"])
    rep.draw()
    out: dict[str, bytes] = {}
    for k, f in enumerate(rep.figures, 1):
        stem = f"{FIGURES}/{k:02d}-{f.name}"
        out[f"{stem}.png"], out[f"{stem}.svg"] = f.png, f.svg
        if f.also:
            out[f.also] = f.png
    lab = (record.get("verification") or {}).get("lab")
    if lab:
        out.update({name: text.encode("utf-8") for name, text in lab_files(lab).items()})
    return out
