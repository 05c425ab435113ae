"""printgen's public plot helpers for a notebook or a script: each returns a matplotlib `Figure`
(made without pyplot: no global state, nothing shown twice, nothing to close) or draws on the
`ax` it is given and returns that axes' figure. The report's PNGs draw with the same functions
(`printgen.report.plots`). Needs the `plot` extra (matplotlib)."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any, cast

from printgen.errors import InputError, PrintgenError
from printgen.report.plots import draw_metric, draw_verification
from printgen.scaling.record import Design
from printgen.verification.compare import METRICS
from printgen.verification.preprint import Verification

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

    from printgen.verification.bands import Band

FAMILY_COLOURS = ((0, "black"), (1, "tab:blue"), (-1, "tab:orange"))  # border, two diagonals


def new_figure(**kw: Any) -> Figure:
    """A matplotlib Figure (constrained layout), not registered with pyplot."""
    try:
        from matplotlib.figure import Figure
    except ImportError as exc:
        raise PrintgenError("plots need matplotlib: pip install 'printgen[plot]'") from exc
    return Figure(layout="constrained", **kw)


def curve_source(result: Any) -> tuple[Verification, Band | None]:
    """The verification (and band) of `result`: a Verification, or a run holding one (the
    results of `printgen.make` and `printgen.verify_design`)."""
    if isinstance(result, Verification):
        return result, None
    if hasattr(result, "curve_source"):
        source: tuple[Verification, Band | None] = result.curve_source()
        return source
    raise InputError(f"plot_curves takes a Verification or the result of make or "
                     f"verify_design, not {type(result).__name__}")


def plot_curves(result: Any, ax: Axes | None = None, *, metric: str | None = None,
                title: str | None = None) -> Figure:
    """Prototype and model against relative loading h / h_B (strains in %), with the model's
    band when the result has one. With `ax` (or `metric`), one quantity on one axes:
    `metric` a key of `printgen.verification.compare.METRICS` (default "deflection");
    without either, the report's six panels (every curve and the largest tensions)."""
    v, band = curve_source(result)
    p, m, scale = v.prototype.deformation, v.model.deformation, v.model.scene.scale
    if ax is None and metric is None:
        fig = new_figure(figsize=(12, 6.6))
        draw_verification(fig.subplots(2, 3), p, m, scale, band)
        fig.suptitle(title or f"Prototype vs printed model, 1:{scale:g}")
        return fig
    key = metric or "deflection"
    if key not in METRICS:
        raise InputError(f"metric {key!r}; expected one of {', '.join(METRICS)}")
    if ax is None:
        ax = new_figure(figsize=(5.5, 3.8)).add_subplot()
    draw_metric(ax, key, p, m, scale, band)
    ax.legend(fontsize=8)
    if title:
        ax.set_title(title)
    return cast("Figure", ax.figure)


def plot_net(design: Any, ax: Axes | None = None) -> Figure:
    """The printed net's strand centre lines (mm) as `make` meshes and prints them: the
    border black, the two strand families blue and orange. `design`: a `Design`, or a result
    holding one (`make`, `verify_design`)."""
    d = design if isinstance(design, Design) else getattr(design, "design", None)
    if not isinstance(d, Design):
        raise InputError(f"plot_net takes a Design or a result holding one, not "
                         f"{type(design).__name__}")
    net, graph = d.net, d.net.graph()
    if ax is None:
        ax = new_figure(figsize=(10, 3.4)).add_subplot()
    for fam, colour in FAMILY_COLOURS:
        for a, b in graph.segments[graph.family == fam]:
            ax.plot(*graph.nodes_mm[[a, b]].T, color=colour, lw=0.8)
    ax.set_aspect("equal")
    ax.set_xlabel("across the barrier (mm)")
    ax.set_ylabel("up (mm)")
    ax.set_title(f"{net.material.upper()} {net.pattern} net at 1:{d.scale:g}, mesh "
                 f"{net.mesh_x_mm:g} x {net.mesh_y_mm:g} mm, strand {net.strand.width_mm:g} x "
                 f"{net.strand.thickness_mm:g} mm")
    return cast("Figure", ax.figure)
