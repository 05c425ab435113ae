"""Figures as PNG bytes (matplotlib, Agg backend, imported lazily: the `plot` extra)."""

from __future__ import annotations

import io

import numpy as np

from printgen.check.bands import Band
from printgen.check.compare import METRICS, Deformation
from printgen.check.measured import Fit, Measurement
from printgen.check.scenes import BarrierScene
from printgen.design.similitude import FORCE_EXPONENT, to_prototype
from printgen.errors import PrintgenError

DPI = 110


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


def _png(fig) -> bytes:
    buf = io.BytesIO()
    # fixed metadata: the same figure gives the same bytes
    fig.savefig(buf, format="png", dpi=DPI, metadata={"Software": None})
    _pyplot().close(fig)
    return buf.getvalue()


def verification_figure(proto: Deformation, model: Deformation, scale: float,
                        title: str, *, band: Band | None = None) -> bytes:
    """Normalised deformations of prototype and model against relative loading, 2 x 3 panels;
    the model's uncertainty band (min/max envelope) shaded when given."""
    plt = _pyplot()
    fig, axes = plt.subplots(2, 3, figsize=(12, 6.6), constrained_layout=True)
    lo, hi = band.envelope() if band is not None else ({}, {})
    for ax, key in zip(axes.flat, METRICS, strict=False):
        if band is not None:
            ax.fill_between(band.levels, lo[key], hi[key], color="C1", alpha=0.25, lw=0,
                            label="model band")
        ax.plot(proto.levels, proto.values[key], "k-o", ms=3, label="prototype")
        ax.plot(model.levels, model.values[key], "C1-s", ms=3, label=f"model 1:{scale:g}")
        ax.set_xlabel("relative loading h / h_B")
        ax.set_title(METRICS[key], fontsize=10)
        ax.grid(alpha=0.3)
    ax = axes.flat[-1]
    ax.plot(proto.levels, proto.max_cable_tension / 1e3, "k-", label="prototype cables")
    ax.plot(model.levels, to_prototype(model.max_cable_tension, FORCE_EXPONENT, scale) / 1e3,
            "C1--",
            label=f"model cables x {scale:g}^3")
    ax.plot(proto.levels, proto.max_strand_tension / 1e3, "b-", label="prototype strands")
    ax.plot(model.levels, to_prototype(model.max_strand_tension, FORCE_EXPONENT, scale) / 1e3,
            "c--",
            label=f"model strands x {scale:g}^3")
    ax.set_title("max tension, prototype scale (kN)", fontsize=10)
    ax.set_xlabel("relative loading h / h_B")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7)
    axes.flat[0].legend(fontsize=8)
    fig.suptitle(title)
    return _png(fig)


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
        ax.set_xscale("log")
        ax.set_xlabel("scale lambda")
        ax.set_title(what, fontsize=10)
        ax.grid(alpha=0.3, which="both")
    axes[0].legend(fontsize=8)
    fig.suptitle(title)
    return _png(fig)


def measured_figure(m: Measurement, band: Band, fit: Fit | None) -> bytes:
    """Each measured column against relative loading: the predicted band and nominal curve
    (counted from h / h_B = 0), the measured points, and the fitted curve when given."""
    plt = _pyplot()
    keys = list(m.values)
    fig, axes = plt.subplots(1, len(keys), figsize=(4.2 * len(keys), 3.8),
                             constrained_layout=True, squeeze=False)
    lo, hi = band.envelope(from_start=True)
    for ax, key in zip(axes.flat, keys, strict=True):
        unit = 100.0 if key.startswith("strain") else 1.0
        nominal = band.nominal[key] - band.nominal[key][0]
        ax.fill_between(band.levels, lo[key] * unit, hi[key] * unit, color="C1", alpha=0.25,
                        lw=0, label="predicted band")
        ax.plot(band.levels, nominal * unit, "C1-", label="nominal")
        ax.plot(m.levels, m.values[key] * unit, "ko", ms=4, label="measured")
        if fit is not None:
            order = np.argsort(m.levels)
            ax.plot(m.levels[order], fit.predicted[key][order] * unit, "C0--",
                    label=f"fitted {fit.kind} {fit.value:.3g}")
        ax.set_xlabel("relative loading h / h_B")
        ax.set_title(m.columns[key], fontsize=10)
        ax.grid(alpha=0.3)
    axes.flat[0].legend(fontsize=8)
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
        ax.add_collection3d(Line3DCollection(x[s.elements], colors=f"C{k}", linewidths=0.4))
        for nodes, _ in s.cables.values():
            ax.plot(*x[nodes].T, color="k", lw=1.2)
        ax.set_xlim(0, 1), ax.set_ylim(0, depth), ax.set_zlim(0, 1)
        ax.set_box_aspect((1.0, 0.5, 0.5))
        ax.yaxis.set_major_locator(MaxNLocator(3))
        ax.set_xlabel("x / width"), ax.set_ylabel("deflection / width"), ax.set_zlabel("z / height")
        ax.view_init(elev=20, azim=-60)
        ax.set_title(label, fontsize=10)
    fig.suptitle(f"Deformed at h/h_B = {level:g} (same normalised axes)")
    return _png(fig)
