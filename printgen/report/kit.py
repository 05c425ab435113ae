"""Figures of the kit for the report (PNG bytes, and `kit_figures`' drawings of them): how
the parts go together, and top views of the direct toolpaths per pass with every bead at its
true width, coloured by path."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from printgen.parts.assembly import Assembly
from printgen.parts.gcode.toolpath import Toolpath
from printgen.report.html import Drawing
from printgen.report.plots import _png, _pyplot

if TYPE_CHECKING:
    from shapely.geometry import Polygon

CABLE_COLOURS = {"top": "#1f77b4", "bottom": "#d62728", "left": "#2ca02c", "right": "#9467bd"}
NET_ZOOM_MM = (44.0, 26.0)  # corner window of the net preview: a loop or two and the eyelet
CABLE_ZOOM_MM = (16.0, 10.0)  # window around a cable's eyelet


def assembly_figure(a: Assembly, outline: Polygon) -> bytes:
    """The net (`outline`, shapely polygon in net coordinates), the four cables threading its
    loops, and the eyelets on the flume's anchor pins; a corner enlarged below."""
    plt = _pyplot()
    fig, (ax, zoom) = plt.subplots(2, 1, figsize=(10, 7.6), layout="tight",
                                   gridspec_kw={"height_ratios": [1.0, 1.25]})
    r_pin = a.attachment.pin_hole_mm / 2
    for axis in (ax, zoom):
        _polygon(axis, outline, "#cfcfcf", "#7a7a7a")
        for c in a.cables:
            (x0, y0), (x1, y1) = c.anchors_mm
            axis.plot([x0, x1], [y0, y1], color=CABLE_COLOURS.get(c.name, "k"), lw=2.2,
                      solid_capstyle="butt", zorder=3)
        for x, y in a.anchors_mm:
            axis.add_patch(plt.Circle((x, y), r_pin, color="k", zorder=4))
    sx, sy = a.net_size_mm
    for c in a.cables:
        mid = c.anchors_mm.mean(axis=0)
        off = {"top": (0, 6), "bottom": (0, -9), "left": (-8, 0), "right": (8, 0)}[c.name]
        ax.annotate(f"{c.name} cable, {c.length_mm:.1f} mm, {len(c.loops_mm)} loops",
                    mid, xytext=(mid[0] + off[0], mid[1] + off[1]), ha="center",
                    va="center", fontsize=8, color=CABLE_COLOURS.get(c.name, "k"),
                    rotation=90 if c.name in ("left", "right") else 0)
    ax.annotate("anchor pin: net and cable eyelets", a.anchors_mm[0], xytext=(sx * 0.12, -14),
                fontsize=8, arrowprops={"arrowstyle": "->"})
    ax.text(sx / 2, sy / 2, f"net {sx:.1f} x {sy:.1f} mm", ha="center", va="center",
            fontsize=9, bbox={"fc": "white", "alpha": 0.8, "lw": 0})
    ax.set_xlim(-18, sx + 18)
    ax.set_ylim(-18, sy + 14)
    ax.set_title(f"Kit at 1:{a.scale:g}: net, four cables, eyelets on the flume anchors")
    _corner_labels(zoom, a)
    for axis in (ax, zoom):
        axis.set_aspect("equal")
        axis.set_xlabel("across the flume (mm)")
        axis.set_ylabel("up (mm)")
    return _png(fig)


def _corner_labels(zoom, a: Assembly) -> None:
    att = a.attachment
    bottom = next((c for c in a.cables if c.name == "bottom" and len(c.loops_mm)), None)
    loop = bottom.loops_mm[np.argmin(bottom.loops_mm[:, 0])] if bottom else a.anchors_mm[0]
    zoom.set_xlim(-8, max(loop[0] + 8, 22))
    zoom.set_ylim(-7, 12)
    zoom.annotate(f"loop: {att.loop_hole_mm:.2f} mm hole, strip "
                  f"{att.strip_width_mm:g} x {att.strip_thickness_mm:g} mm threads through "
                  f"({att.strip_clearance_mm():.2f} mm each side)", loop,
                  xytext=(loop[0] - 6, -5.5), fontsize=8, arrowprops={"arrowstyle": "->"})
    zoom.annotate(f"corner eyelet + cable eyelets on the pin ({att.pin_hole_mm:.2f} mm)",
                  a.anchors_mm[0], xytext=(1.5, 9.5), fontsize=8,
                  arrowprops={"arrowstyle": "->"})
    zoom.set_title("lower-left corner enlarged (holes printed "
                   f"{att.hole_compensation_mm:g} mm larger: printer hole compensation)",
                   fontsize=9)


def _polygon(ax, poly, face: str, edge: str) -> None:
    from matplotlib.patches import PathPatch
    from matplotlib.path import Path

    verts, codes = [], []
    for ring in [poly.exterior, *poly.interiors]:
        xy = np.asarray(ring.coords)
        verts.append(xy)
        codes += [Path.MOVETO] + [Path.LINETO] * (len(xy) - 2) + [Path.CLOSEPOLY]
    # thousands of holes: a raster in the SVG; add_artist, not add_patch: the axes' limits
    # are set by the caller, and add_patch's data limits walk every hole's outline in Python
    # (half of the figure's time)
    ax.add_artist(PathPatch(Path(np.vstack(verts), codes), fc=face, ec=edge, lw=0.3, zorder=1,
                            rasterized=True))


def toolpath_preview(tp: Toolpath, title: str, *, window_mm: tuple[float, float] | None = None
                     ) -> bytes:
    """One top view per pass (layer) of `tp`: every extrusion as a rectangle of its bead width
    (paler where the flow is reduced), coloured by path; with `window_mm` (w, h) each view is
    the part's lower-left corner (a cable's first eyelet), else the whole part."""
    plt = _pyplot()
    from matplotlib.collections import PolyCollection

    n = len(tp.layer_z_mm)
    fig, axes = plt.subplots(1, n, figsize=(4.6 * n, 3.8), squeeze=False, layout="tight")
    ext = np.flatnonzero(tp.extruding)
    new_path = np.concatenate([[True], np.diff(ext) > 1])
    path_id = np.cumsum(new_path)
    p0, p1 = tp.xyz_mm[ext - 1, :2], tp.xyz_mm[ext, :2]
    d = p1 - p0
    nrm = np.column_stack([-d[:, 1], d[:, 0]]) / np.maximum(np.hypot(*d.T), 1e-12)[:, None]
    half = (tp.width_mm[ext] / 2)[:, None] * nrm
    quads = np.stack([p0 + half, p1 + half, p1 - half, p0 - half], axis=1)
    colours = plt.get_cmap("tab20")(path_id % 20)
    colours[:, 3] = np.where(tp.flow[ext] < 1.0, 0.45, 1.0)
    lo, hi = quads.reshape(-1, 2).min(axis=0) - 1, quads.reshape(-1, 2).max(axis=0) + 1
    if window_mm is not None:
        lo = tp.xyz_mm[ext][np.argmin(tp.xyz_mm[ext, 0] + tp.xyz_mm[ext, 1]), :2] - 2
        hi = lo + window_mm
    seen = _overlaps(quads, lo, hi)  # the beads in view: the others are clipped away anyway
    for k, ax in enumerate(axes[0]):
        on = tp.layer[ext] == k
        ax.add_collection(PolyCollection(quads[on & seen], facecolors=colours[on & seen],
                                         edgecolors=colours[on & seen], linewidths=0.3,
                                         rasterized=True))  # every bead: a raster in the SVG
        ax.set_xlim(lo[0], hi[0])
        ax.set_ylim(lo[1], hi[1])
        ax.set_aspect("equal")
        ax.set_title(f"pass {k + 1}: z = {tp.layer_z_mm[k]:.2f} mm, "
                     f"{len(np.unique(path_id[on]))} paths", fontsize=9)
        ax.set_xlabel("bed x (mm)")
        ax.set_ylabel("bed y (mm)")
    fig.suptitle(title, fontsize=10)
    return _png(fig)


def _overlaps(quads: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """Which quads ((m, 4, 2) mm) have a bounding box that meets the window lo..hi (mm)."""
    qlo, qhi = quads.min(axis=1), quads.max(axis=1)
    return np.all((qhi >= lo) & (qlo <= hi), axis=1)


def kit_figures(a: Assembly, outline: Polygon, net_tp: Toolpath, cable_tp: Toolpath,
                cable_name: str) -> list[tuple[str, Drawing, str]]:
    """(file name, drawing, caption) of the assembly picture and the toolpath previews (their
    Drawing.cost: CPU seconds, bench timeline on the 1:40 example)."""
    return [
        ("assembly.png", Drawing(assembly_figure, (a, outline), cost=1.3),
         ("How the kit goes together: the net's corner eyelets and both cables' eyelets on "
          "each anchor pin, each cable threaded through the loops of its side.")),
        ("preview-net.png", Drawing(toolpath_preview, (net_tp, "net, lower-left corner"),
                                    {"window_mm": NET_ZOOM_MM}, cost=0.8),
         ("Direct net G-code per pass, beads at true width, one colour per path (pale: "
          "reduced flow over crossings and rings).")),
        ("preview-net-whole.png", Drawing(toolpath_preview, (net_tp, "net, whole"), cost=0.8),
         "Direct net G-code per pass, whole net."),
        (f"preview-cable-{cable_name}.png",
         Drawing(toolpath_preview, (cable_tp, f"cable {cable_name}, first eyelet"),
                 {"window_mm": CABLE_ZOOM_MM}, cost=0.8),
         "Direct cable G-code per pass: the strip's beads run into the eyelet ring."),
    ]
