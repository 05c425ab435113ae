"""Figures as PNG bytes (matplotlib, Agg backend, imported lazily: the `plot` extra)."""

from __future__ import annotations

import io

import numpy as np

from printgen.errors import PrintgenError
from printgen.scaling.similitude import FORCE_EXPONENT, to_prototype
from printgen.scene.scenes import BarrierScene
from printgen.verification.bands import Band
from printgen.verification.compare import METRICS, Deformation
from printgen.verification.measured import Fit, Measurement

DPI = 110
SVG_SALT = "printgen"  # matplotlib's svg.hashsalt: the same figure gives the same SVG ids
LOADING = "relative loading h / h_B (-)"
# axis label of each METRICS curve as plotted (strains in %), and its factor from the record
AXIS = {"deflection": ("mid-height deflection / width (-)", 1.0),
        "lowering": ("top-centre lowering / height (-)", 1.0),
        "strain_bottom": ("bottom cable elongation (%)", 100.0),
        "strain_top": ("top cable elongation (%)", 100.0),
        "strain_mid": ("mid-height elongation (%)", 100.0)}


class PlotBytes(bytes):
    """A figure's PNG bytes, with its SVG (`svg`) and every visible axis's labels (`labels`:
    (title, [x, y(, z)] label) per axis) for the files beside the report and its tests."""

    svg: bytes
    labels: list[tuple[str, list[str]]]


def _pyplot():
    try:
        import matplotlib
    except ImportError as exc:  # pragma: no cover - depends on the install
        raise PrintgenError("plots need matplotlib: pip install 'printgen[plot]'") from exc
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def load_pyplot() -> None:
    """Import matplotlib's pyplot (Agg) now, e.g. while a worker still computes what the
    figures show."""
    _pyplot()


def _png(fig) -> PlotBytes:
    """The PNG and the SVG of one drawing of `fig` (then closed). The layout (constrained or
    tight) is worked out once, for the PNG, and kept for the SVG: laying out again costs as
    much as drawing. Rasterized artists (dense strand and bead collections) are a PNG inside
    the SVG at the PNG's resolution."""
    import matplotlib

    buf, svg = io.BytesIO(), io.BytesIO()
    # fixed metadata: the same figure gives the same bytes
    fig.savefig(buf, format="png", dpi=DPI, metadata={"Software": None})
    # the axes keep the positions the PNG's layout gave them; no engine at all (not "none",
    # a placeholder engine): savefig lays out a figure that has one in a whole draw first
    with matplotlib.rc_context({"figure.autolayout": False,
                                "figure.constrained_layout.use": False}):
        fig.set_layout_engine(None)
    with matplotlib.rc_context({"svg.hashsalt": SVG_SALT}):
        fig.savefig(svg, format="svg", dpi=DPI, metadata={"Date": None, "Creator": None})
    out = PlotBytes(buf.getvalue())
    out.svg, out.labels = svg.getvalue(), axis_labels(fig)
    _pyplot().close(fig)
    return out


def axis_labels(fig) -> list[tuple[str, list[str]]]:
    """(title, labels) of every visible axis of `fig` (3D axes give x, y and z)."""
    out = []
    for ax in fig.axes:
        if not getattr(ax, "_axis3don", ax.axison):  # a 3D axes turns its 2D frame off
            continue
        names = [ax.get_xlabel(), ax.get_ylabel()]
        if hasattr(ax, "get_zlabel"):
            names.append(ax.get_zlabel())
        out.append((ax.get_title() or ax.get_label(), names))
    return out


def verification_figure(proto: Deformation, model: Deformation, scale: float,
                        title: str, *, band: Band | None = None) -> bytes:
    """Normalised deformations of prototype and model against relative loading, 2 x 3 panels;
    the model's uncertainty band (min/max envelope) shaded when given."""
    plt = _pyplot()
    fig, axes = plt.subplots(2, 3, figsize=(12, 6.6), constrained_layout=True)
    draw_verification(axes, proto, model, scale, band)
    fig.suptitle(title)
    return _png(fig)


def draw_verification(axes, proto: Deformation, model: Deformation, scale: float,
                      band: Band | None = None) -> None:
    """The 2 x 3 `axes` of `verification_figure`: each curve that shows (`draw_metric`), then
    the largest tensions at prototype scale."""
    keys = [k for k in METRICS if _shows(proto.values[k]) or _shows(model.values[k])]
    envelope = band.envelope() if band is not None else None
    for ax, key in zip(axes.flat, keys, strict=False):
        draw_metric(ax, key, proto, model, scale, band, envelope)
    for ax in axes.flat[len(keys):-1]:
        ax.set_axis_off()
    ax = axes.flat[-1]
    ax.plot(proto.levels, proto.max_cable_tension / 1e3, "k-", label="prototype cables")
    ax.plot(model.levels, to_prototype(model.max_cable_tension, FORCE_EXPONENT, scale) / 1e3,
            "C1--",
            label=f"model cables x {scale:g}^3")
    ax.plot(proto.levels, proto.max_strand_tension / 1e3, "b-", label="prototype strands")
    ax.plot(model.levels, to_prototype(model.max_strand_tension, FORCE_EXPONENT, scale) / 1e3,
            "c--",
            label=f"model strands x {scale:g}^3")
    ax.set_title("max tension, prototype scale", fontsize=10)
    ax.set_xlabel(LOADING)
    ax.set_ylabel("max tension (kN)")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7)
    axes.flat[0].legend(fontsize=8)


def draw_metric(ax, key: str, proto: Deformation, model: Deformation, scale: float,
                band: Band | None = None, envelope: tuple[dict, dict] | None = None) -> None:
    """Curve `key` (a METRICS key, strains in %) of prototype and model against relative
    loading on `ax`, the band's min/max envelope shaded when given (`envelope`: the band's,
    when already computed)."""
    label, f = AXIS[key]
    if band is not None:
        lo, hi = envelope or band.envelope()
        ax.fill_between(band.levels, lo[key] * f, hi[key] * f, color="C1", alpha=0.25,
                        lw=0, label="model band")
    ax.plot(proto.levels, proto.values[key] * f, "k-o", ms=3, label="prototype")
    ax.plot(model.levels, model.values[key] * f, "C1-s", ms=3, label=f"model 1:{scale:g}")
    ax.set_xlabel(LOADING)
    ax.set_ylabel(label)
    ax.set_title(METRICS[key].split(" (")[0], fontsize=10)
    ax.grid(alpha=0.3)


def _shows(curve: np.ndarray) -> bool:
    """Whether a curve has anything to draw (a bottom row pinned to the bed reads 0 at every
    level: a barrier without border cables gets no empty panel)."""
    return bool(np.any(np.abs(np.nan_to_num(np.asarray(curve, dtype=float))) > 0))


def series_figure(lams: np.ndarray, curves: dict[str, dict[str, np.ndarray]],
                  title: str) -> bytes:
    """Scale series: for each variant, normalised deflection and lowering against lambda."""
    plt = _pyplot()
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.2), constrained_layout=True)
    for i, (label, c) in enumerate(curves.items()):
        axes[0].plot(lams, c["deflection"], "-o", color=f"C{i}", label=label)
        axes[1].plot(lams, c["lowering"], "-o", color=f"C{i}", label=label)
    for ax, what in zip(axes, ("mid-height deflection / width", "top-centre lowering / height"),
                        strict=True):
        lambda_axis(ax, what)
    axes[0].legend(fontsize=8)
    fig.suptitle(title)
    return _png(fig)


def lambda_axis(ax, what: str) -> None:
    """An axis of `what` (a normalised quantity) against the scale lambda, log-scaled."""
    ax.set_xscale("log")
    ax.set_xlabel("scale lambda (-)")
    ax.set_ylabel(f"{what} (-)")
    ax.set_title(what, fontsize=10)
    ax.grid(alpha=0.3, which="both")


def measured_figure(m: Measurement, band: Band, fit: Fit | None,
                    prototype: Deformation | None = None) -> bytes:
    """Each measured column against relative loading: the predicted band and nominal curve
    (counted from h / h_B = 0), the prototype's curve (counted alike) when given, the
    measured points, and the fitted curve when given."""
    plt = _pyplot()
    keys = list(m.values)
    fig, axes = plt.subplots(1, len(keys), figsize=(4.2 * len(keys), 3.8),
                             constrained_layout=True, squeeze=False)
    lo, hi = band.envelope(from_start=True)
    for ax, key in zip(axes.flat, keys, strict=True):
        label, unit = AXIS[key]
        nominal = band.nominal[key] - band.nominal[key][0]
        ax.fill_between(band.levels, lo[key] * unit, hi[key] * unit, color="C1", alpha=0.25,
                        lw=0, label="predicted band")
        ax.plot(band.levels, nominal * unit, "C1-", label="model nominal")
        if prototype is not None:
            pv = prototype.values[key] - prototype.values[key][0]
            ax.plot(prototype.levels, pv * unit, "k-", lw=1, label="prototype")
        for i, (name, c) in enumerate(band.variants.items()):  # each variant's own curve
            ax.plot(band.levels, (c[key] - c[key][0]) * unit, color=f"C{2 + i % 8}", lw=0.8,
                    alpha=0.8, label=name)
        ax.plot(m.levels, m.values[key] * unit, "ko", ms=4, label="measured")
        cap = m.bound(key)
        ax.plot(m.levels, cap * unit, "kv", ms=5, mfc="none", label="measured: below")
        if fit is not None:
            order = np.argsort(m.levels)
            fit_label = getattr(fit, "label", None) or f"fitted {fit.kind} {fit.value:.3g}"
            ax.plot(m.levels[order], fit.predicted[key][order] * unit, "C0--", lw=2,
                    label=fit_label)
        ax.set_xlabel(LOADING)
        ax.set_ylabel(label)
        ax.set_title(f"column {m.columns[key]}", fontsize=10)
        ax.grid(alpha=0.3)
    axes.flat[0].legend(fontsize=6)
    fig.suptitle("Measured loading test against the prediction")
    return _png(fig)


def deformed_figure(shapes: list[tuple[str, BarrierScene, np.ndarray]], level: float) -> bytes:
    """Each barrier's net deformed at relative loading `level`, in 3D, on the same normalised
    axes: x / width across, deflection y / width downstream, z / height up.

    shapes : (label, scene, positions (n, 3) m) per barrier.
    """
    plt = _pyplot()
    from matplotlib.ticker import MaxNLocator
    from mpl_toolkits.mplot3d.art3d import Line3DCollection

    fig = plt.figure(figsize=(6 * len(shapes), 5.2), constrained_layout=True)
    norm = [(label, s, x / [s.width, s.width, s.height]) for label, s, x in shapes]
    depth = max(float(np.abs(x[:, 1]).max()) for _, _, x in norm) or 1.0
    for k, (label, s, x) in enumerate(norm):
        ax = fig.add_subplot(1, len(norm), k + 1, projection="3d")
        ax.add_collection3d(Line3DCollection(x[s.elements], colors=f"C{k}", linewidths=0.4,
                                             rasterized=True))  # every strand: a raster in the SVG
        for nodes, _ in s.cables.values():
            ax.plot(*x[nodes].T, color="k", lw=1.2)
        ax.set_xlim(0, 1), ax.set_ylim(0, depth), ax.set_zlim(0, 1)
        ax.set_box_aspect((1.0, 0.5, 0.5))
        ax.yaxis.set_major_locator(MaxNLocator(3))
        ax.set_xlabel("x / width (-)"), ax.set_ylabel("deflection / width (-)")
        ax.set_zlabel("z / height (-)")
        ax.view_init(elev=20, azim=-60)
        ax.set_title(label, fontsize=10)
    fig.suptitle(f"Deformed at h/h_B = {level:g} (same normalised axes)")
    return _png(fig)
