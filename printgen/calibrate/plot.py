"""One PNG per material: every loading branch with its fits and the chosen window.

Left: whole loading branches with the bilinear fits. Right: the region of the modulus window,
with each regression line drawn over the strains it used. matplotlib is imported here only.
"""

from __future__ import annotations

import io
import unicodedata
from pathlib import Path

import numpy as np

from printgen import outputs
from printgen.calibrate.pipeline import Calibration
from printgen.calibrate.waved import WaveCalibration
from printgen.errors import CalibrationError

ZOOM_MARGIN = 1.5  # right panel shows strains up to this factor times the window's upper end


def _pyplot():
    """matplotlib's pyplot on the Agg backend, or a CalibrationError saying how to get it."""
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError as exc:  # pragma: no cover - depends on the install
        raise CalibrationError("plots need matplotlib: pip install 'printgen[plot]'") from exc
    return plt


def _save(plt, fig, path: str | Path) -> Path:
    """Write `fig` to `path` as a PNG, atomically, and close it."""
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=110)
    plt.close(fig)
    return outputs.write_bytes(path, buf.getvalue())


def plot_calibration(cal: Calibration, path: str | Path) -> Path:
    """Write the calibration plot to `path` (PNG) atomically; return the path."""
    plt = _pyplot()
    if not cal.samples:
        raise CalibrationError("nothing to plot: no curves were fitted (force-only files)")
    panel = cal.kind == "panel"
    scale, ylab = (1e-3, "force per width F/w (kN/m)") if panel else (1e-6, "stress (MPa)")
    fig, (ax_all, ax_win) = plt.subplots(1, 2, figsize=(12, 5), constrained_layout=True)
    hi = max(s.linear.hi for s in cal.samples) * ZOOM_MARGIN
    for i, s in enumerate(cal.samples):
        color = f"C{i % 10}"
        label = printable(Path(s.path.split(":")[-1]).name)
        ax_all.plot(s.x * 100, s.y * scale, color=color, lw=1, label=label)
        if s.bilinear is not None:
            ax_all.plot(s.x * 100, s.bilinear(s.x) * scale, color=color, lw=1, ls="--")
        m = s.x <= hi
        ax_win.plot(s.x[m] * 100, s.y[m] * scale, ".", color=color, ms=3)
        xs = np.array([s.linear.lo, s.linear.hi])
        ax_win.plot(xs * 100, (s.linear.slope * xs + s.linear.intercept) * scale, color=color,
                    lw=2)
    o = cal.options
    if o.window is not None:
        for ax in (ax_all, ax_win):
            ax.axvspan(o.window[0] * 100, o.window[1] * 100, color="0.85", zorder=0,
                       label="fit window")
    win = (f"window {o.window[0] * 100:g}-{o.window[1] * 100:g} %" if o.window is not None
           else f"automatic steepest window ({o.auto_span:.0%} of the rise)")
    ax_all.set_title(f"{cal.material}: loading branches, bilinear fits (dashed)")
    ax_win.set_title(f"{'stiffness' if panel else 'modulus'} fits, {win}")
    for ax in (ax_all, ax_win):
        ax.set_xlabel("strain (%)")
        ax.set_ylabel(ylab)
        ax.grid(alpha=0.3)
    ax_all.legend(fontsize=7, loc="lower right")
    return _save(plt, fig, path)


def plot_waved(cal: WaveCalibration, path: str | Path) -> Path:
    """The measured curves against the prediction as assumed (s = 1) and as fitted (s), with
    both bilinear knees marked: one PNG written atomically."""
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(8, 5), constrained_layout=True)
    m = cal.model
    e = np.linspace(0.0, max(s.strain_max for s in cal.samples), 200)
    pred = m.predict(e)  # the coupon's force, or a panel's force per clamp width
    model = "simulated panel test" if m.panel else "beam model"
    for i, s in enumerate(cal.samples):
        ax.plot(s.x * 100, s.force, color=f"C{i % 10}", lw=1,
                label=printable(Path(s.path.split(":")[-1]).name))
    ax.plot(e * 100, pred, "k--", lw=1.5, label=f"{model}, material law as assumed")
    ax.plot(e * 100, cal.scale.mean * pred, "k-", lw=1.5,
            label=f"{model}, law x {cal.scale.mean:.3g} (fitted)")
    (km, kp) = cal.knees()
    ax.axvline(km.mean * 100, color="C3", ls=":", label=f"knee measured {km.mean:.2%}")
    ax.axvline(kp.mean * 100, color="0.4", ls=":", label=f"knee predicted {kp.mean:.2%}")
    if m.panel:
        ax.set_xlabel("panel strain (%)")
        ax.set_ylabel("force per clamp width (N/m)")
        ax.set_title(f"{cal.material}: {'square' if m.straight else 'waved'} test panels "
                     "against their simulated test")
    else:
        ax.set_xlabel("chord strain (%)")
        ax.set_ylabel(f"force, {m.strands} strands (N)")
        ax.set_title(f"{cal.material}: waved coupons against the beam model")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7, loc="upper left")
    return _save(plt, fig, path)


def printable(name: str) -> str:
    """A file name as a plot label: control characters (a name may hold any but '/' and NUL)
    shown as escapes, `\\x1b`, never drawn raw."""
    return "".join(c if unicodedata.category(c) != "Cc" else f"\\x{ord(c):02x}" for c in name)
