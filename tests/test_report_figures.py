"""Figures drawn later (printgen.report.html.Drawing): a report keeps each one's place among
its blocks and figure files until it is drawn, side by side in worker processes, and the
result is the report drawn one figure at a time."""

from __future__ import annotations

import pytest

from printgen.report.html import Drawing, Report
from printgen.report.plots import _png, _pyplot


def line_figure(slope: float) -> bytes:
    fig, ax = _pyplot().subplots(figsize=(3, 2), constrained_layout=True)
    ax.plot([0, 1], [0, slope])
    ax.set_xlabel("x (-)")
    ax.set_title(f"slope {slope:g}")
    return _png(fig)


def report(later: bool) -> Report:
    rep = Report("t")
    rep.paragraph("before")
    for k, slope in enumerate((1.0, 2.0, 3.0)):
        drawn = Drawing(line_figure, (slope,)) if later and k != 1 else line_figure(slope)
        rep.figure(drawn, f"figure {k}", f"f{k}", also=f"f{k}.png" if k == 2 else "")
        rep.paragraph(f"after {k}")
    return rep


@pytest.mark.slow
def test_drawings_keep_their_place_and_give_the_same_report(monkeypatch):
    monkeypatch.delenv("PRINTGEN_SERIAL", raising=False)
    now, later = report(False), report(True)
    assert len(later.pending()) == 2 and len(later.figures) == 3
    assert [f.png for f in later.figures][::2] == [b"", b""]  # places kept, not drawn yet
    later.draw()
    assert later.pending() == [] and later.blocks == now.blocks
    assert later.figures == now.figures
    assert [f.name for f in later.figures] == ["f0", "f1", "f2"]
    assert later.figures[2].also == "f2.png" and later.figures[2].svg.startswith(b"<?xml")


def test_fill_needs_one_figure_per_drawing():
    rep = report(True)
    with pytest.raises(ValueError, match="1 figures drawn for 2"):
        rep.fill([b"png"])
