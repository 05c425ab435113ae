"""Figure of a design search: the objective against the similitude it breaks and the print time,
with the Pareto set, the chosen net and `select`'s pick marked (PNG bytes)."""

from __future__ import annotations

import numpy as np

from printgen.report.plots import _png, _pyplot
from printgen.search.nets import SearchResult

MAX_CLOUD = 4000  # candidates drawn in the background cloud (every k-th beyond this)


def pareto_figure(res: SearchResult) -> bytes:
    """Three panels: objective vs |dPi2|, |dPi3| and print time (min)."""
    plt = _pyplot()
    sc = res.screened
    if res.objective == "deformation":
        idx = sorted(res.verified)
        label, sel_y = ("deformation mismatch, RMS of the solver (-)",
                        None if res.select_score is None else res.select_score.mismatch)
    else:
        idx = [s.point.index for s in sc if s.feasible]
        label = "membrane-law error, RMS log over 1-40 % strain (-)"
        sel_y = res.select_screened.error_rms_log
    idx = idx[::max(1, len(idx) // MAX_CLOUD)]
    y = np.array([res.objective_value(i) for i in idx])
    cols = [("|dPi2| = |mesh / h_B deviation| (-)", lambda s: abs(s.d_pi2)),
            ("|dPi3| = |strand d / h_B deviation| (-)", lambda s: abs(s.d_pi3)),
            ("net print time (min)", lambda s: s.print_time_s / 60)]
    fig, axes = plt.subplots(1, 3, figsize=(13, 4.2), constrained_layout=True, sharey=True)
    for ax, (xlabel, f) in zip(axes, cols, strict=True):
        ax.scatter([f(sc[i]) for i in idx], y, s=8, c="0.7", label="printable candidates",
                   rasterized=True)
        if res.pareto:
            ax.scatter([f(sc[i]) for i in res.pareto],
                       [res.objective_value(i) for i in res.pareto], s=22, c="C0",
                       label="Pareto set")
        if res.chosen is not None:
            ax.scatter([f(sc[res.chosen])], [res.objective_value(res.chosen)], s=90,
                       marker="*", c="C3", label="chosen")
        if sel_y is not None:
            ax.scatter([f(res.select_screened)], [sel_y], s=50, marker="s", c="k",
                       label="select's pick")
        ax.set_xlabel(xlabel)
        ax.set_ylabel(label)
        ax.grid(alpha=0.3)
    axes[0].legend(fontsize=8)
    fig.suptitle(f"{res.prototype}: design search at 1:{res.scale:g} "
                 f"({len(sc)} candidates, objective: {res.objective})")
    return _png(fig)
