"""Figures as PNG bytes (matplotlib, Agg backend, imported lazily: the `plot` extra)."""

from __future__ import annotations

import io

import numpy as np

from printgen.check.compare import METRICS, Deformation
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


def _png(fig) -> bytes:
    buf = io.BytesIO()
    # fixed metadata: the same figure gives the same bytes
    fig.savefig(buf, format="png", dpi=DPI, metadata={"Software": None})
    _pyplot().close(fig)
    return buf.getvalue()


def verification_figure(proto: Deformation, model: Deformation, scale: float,
                        title: str) -> bytes:
    """Normalised deformations of prototype and model against relative loading, 2 x 3 panels."""
    plt = _pyplot()
    fig, axes = plt.subplots(2, 3, figsize=(12, 6.6), constrained_layout=True)
    for ax, key in zip(axes.flat, METRICS, strict=False):
        ax.plot(proto.levels, proto.values[key], "k-o", ms=3, label="prototype")
        ax.plot(model.levels, model.values[key], "C1-s", ms=3, label=f"model 1:{scale:g}")
        ax.set_xlabel("relative loading h / h_B")
        ax.set_title(METRICS[key], fontsize=10)
        ax.grid(alpha=0.3)
    ax = axes.flat[-1]
    ax.plot(proto.levels, proto.max_cable_tension / 1e3, "k-", label="prototype cables")
    ax.plot(model.levels, model.max_cable_tension * scale**3 / 1e3, "C1--",
            label=f"model cables x {scale:g}^3")
    ax.plot(proto.levels, proto.max_strand_tension / 1e3, "b-", label="prototype strands")
    ax.plot(model.levels, model.max_strand_tension * scale**3 / 1e3, "c--",
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
