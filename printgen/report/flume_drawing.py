"""The sensor and anchor layout of the flume test (mm): a dimensioned drawing of the mounted
model (`printgen.scene.flume`, from report.json's lab.layout record), its table in
the report, and sensor-layout.csv beside it."""

from __future__ import annotations

from typing import Any

import numpy as np

from printgen.report.html import Drawing, Report
from printgen.scene.flume import FlumeLayout

LAYOUT_CSV = "sensor-layout.csv"
WIRE_COLOURS = {"bottom": "C0", "top": "C2", "mid": "C3"}
DIM_GAP = 0.08  # dimension lines stand this fraction of the height off the net
CAPTION = ("Sensor and anchor layout of the flume test, looking downstream (mm; x across from "
           "the net's left edge, z up from the flume bed): anchor pins, held edges, border "
           "cables, and each sensor wire from its anchor over its row to its string "
           "potentiometer.")


def layout_rows(lay: dict[str, Any]) -> list[list[str]]:
    """(item, x mm, z mm, note) of every pin, held edge and sensor wire."""
    rows = [[f"anchor pin {i + 1}", f"{x:.1f}", f"{z:.1f}",
             "net corner eyelet and both cables' eyelets on one pin (M3)"]
            for i, (x, z) in enumerate(lay["anchor_pins_mm"])]
    for side, h in lay["held_edges"].items():
        (x0, z0), (x1, z1) = h["from_mm"], h["to_mm"]
        rows.append([f"{side} edge held", f"{x0:.1f}-{x1:.1f}", f"{z0:.1f}-{z1:.1f}",
                     f"{h['nodes']} nodes held by the {h['by']}"])
    for s in lay["sensors"]:
        (ax, az), (px, pz) = s["anchor_mm"], s["potentiometer_mm"]
        rows.append([f"{s['row']} wire anchor", f"{ax:.1f}", f"{az:.1f}",
                     (f"left edge node; over {s['nodes_passed']} row nodes, "
                      f"{s['along_row_mm']:.1f} mm (the elongation's divisor)")])
        rows.append([f"{s['row']} potentiometer", f"{px:.1f}", f"{pz:.1f}",
                     (f"{s['beyond_edge_mm']:.1f} mm beyond the right edge, in line with "
                      f"the row; wire at {s['force_n']:g} N")])
    return rows


def layout_csv(lay: dict[str, Any]) -> str:
    """sensor-layout.csv: the rows of `layout_rows` with x and z as numbers (mm)."""
    lines = ["item,x_mm,z_mm,x_to_mm,z_to_mm,note"]

    def q(text: str) -> str:
        return '"' + text.replace('"', '""') + '"'

    for i, (x, z) in enumerate(lay["anchor_pins_mm"]):
        lines.append(f"anchor pin {i + 1},{x:g},{z:g},,,{q('net and cable eyelets')}")
    for side, h in lay["held_edges"].items():
        (x0, z0), (x1, z1) = h["from_mm"], h["to_mm"]
        lines.append(f"{side} edge held,{x0:g},{z0:g},{x1:g},{z1:g},{q(h['by'])}")
    for s in lay["sensors"]:
        (ax, az), (px, pz) = s["anchor_mm"], s["potentiometer_mm"]
        lines.append(f"{s['row']} wire,{ax:g},{az:g},{px:g},{pz:g},"
                     + q(f"{s['metric']}: anchor to potentiometer; along the row "
                         f"{s['along_row_mm']:g} mm, beyond the edge {s['beyond_edge_mm']:g} mm"))
    return "\n".join(lines) + "\n"


def layout_section(rep: Report, layout: FlumeLayout) -> None:
    """The layout's heading, drawing and table."""
    lay = layout.to_record()
    strands = layout.strands_mm

    rep.heading("Sensor and anchor layout (mm)")
    rep.paragraph(f"Where the flume test's parts go, from the solver scene the check used "
                  f"(mounting: {lay['mounting']}); the same positions are in {LAYOUT_CSV} and "
                  "in report.json (verification.lab.layout). The routing of the wires is "
                  "printgen's assumption (printgen docs: The flume test as it is run).")
    rep.figure(Drawing(layout_png, (lay, strands)), CAPTION, "sensor-and-anchor-layout")
    rep.table(["item", "x (mm)", "z (mm)", "note"], layout_rows(lay))


def layout_png(lay: dict[str, Any], strands: np.ndarray | None = None) -> bytes:
    """The drawing of `layout_figure` as PNG bytes carrying its SVG."""
    from printgen.report.plots import _png

    return _png(layout_figure(lay, strands))


def layout_figure(lay: dict[str, Any], strands: np.ndarray | None = None):
    """The dimensioned drawing as a matplotlib figure (closed by the caller's `_png`)."""
    from printgen.report.plots import _pyplot

    plt = _pyplot()
    w, h = lay["width_mm"], lay["height_mm"]
    pot_x = max((s["potentiometer_mm"][0] for s in lay["sensors"]), default=w)
    fig, ax = plt.subplots(figsize=(12, 4.8), constrained_layout=True)
    if strands is not None and len(strands):
        from matplotlib.collections import LineCollection

        ax.add_collection(LineCollection(strands, colors="0.8", linewidths=0.4,
                                         label="net strands", rasterized=True))
    ax.plot([0, w, w, 0, 0], [0, 0, h, h, 0], c="0.5", lw=0.8)
    ax.axhline(0, c="saddlebrown", lw=2.5, zorder=1, label="flume bed (z = 0)")
    shown = set()
    for e in lay["held_edges"].values():
        (x0, z0), (x1, z1) = e["from_mm"], e["to_mm"]
        what = "held by the flume bed" if x0 != x1 else "held by the side sheets"
        ax.plot([x0, x1], [z0, z1], c="k", lw=4, alpha=0.35, solid_capstyle="butt",
                label=None if what in shown else what)
        shown.add(what)
    for k, c in enumerate(lay["cables"].values()):
        (x0, z0), (x1, z1) = c["from_mm"], c["to_mm"]
        ax.plot([x0, x1], [z0, z1], c="C1", lw=2, label=None if k else "border cables")
    pins = np.asarray(lay["anchor_pins_mm"]).reshape(-1, 2)
    if len(pins):
        ax.scatter(pins[:, 0], pins[:, 1], s=70, c="k", zorder=5, label="anchor pins")
        for x, z in pins:  # outside the net: above the top pins, below the bottom ones
            ax.annotate(f"pin ({x:.1f}, {z:.1f})", (x, z), xytext=(0, 8 if z > h / 2 else -11),
                        textcoords="offset points", fontsize=7,
                        ha="right" if x < w / 2 else "left")
    _sensors(ax, lay["sensors"], h)
    _dimensions(ax, w, h, pot_x, lay["sensors"])
    ax.set_xlabel("x across the flume, from the net's left edge (mm)")
    ax.set_ylabel("z above the flume bed (mm)")
    ax.set_aspect("equal")
    ax.set_xlim(-0.12 * w, pot_x + 0.16 * w)
    ax.set_ylim(-3.2 * DIM_GAP * h - 0.05 * w, h * (1 + 3 * DIM_GAP) + 0.02 * w)
    ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.0, 1.0))
    ax.set_title("Sensor and anchor layout (looking downstream)")
    return fig


def _sensors(ax, sensors: list[dict[str, Any]], h: float) -> None:
    for s in sensors:
        c = WIRE_COLOURS.get(s["row"], "C4")
        (ax0, az), (px, pz) = s["anchor_mm"], s["potentiometer_mm"]
        dz = -11 if az > h - 1e-9 else 3  # the top row's labels below its line, inside
        ax.plot([ax0, px], [az, pz], c=c, lw=1.2, ls="--", label=f"{s['row']} sensor wire")
        ax.scatter([ax0], [az], marker="X", s=60, c=c, zorder=6)
        ax.scatter([px], [pz], marker="s", s=80, c=c, edgecolors="k", zorder=6)
        ax.annotate(f"{s['row']} anchor ({ax0:.1f}, {az:.1f})", (ax0, az), xytext=(6, dz),
                    textcoords="offset points", fontsize=7, color=c)
        ax.annotate(f"potentiometer ({px:.1f}, {pz:.1f})", (px, pz), xytext=(-10, dz),
                    textcoords="offset points", fontsize=7, color=c, ha="right")


def _dimension(ax, p0, p1, text: str, offset=(0, 0)) -> None:
    ax.annotate("", p0, p1, arrowprops={"arrowstyle": "<->", "lw": 0.8, "color": "0.2"})
    mid = ((p0[0] + p1[0]) / 2, (p0[1] + p1[1]) / 2)
    ax.annotate(text, mid, xytext=offset, textcoords="offset points", fontsize=8,
                ha="center", va="center", backgroundcolor="white")


def _dimensions(ax, w: float, h: float, pot_x: float, sensors: list[dict[str, Any]]) -> None:
    """Width and height of the net, the potentiometers' distance beyond it, each row's
    height above the bed."""
    gap = DIM_GAP * h
    _dimension(ax, (0, -2 * gap), (w, -2 * gap), f"net width {w:.1f} mm")
    if pot_x > w:
        _dimension(ax, (w, -2 * gap), (pot_x, -2 * gap), f"{pot_x - w:.1f}", (0, -9))
    _dimension(ax, (-0.06 * w, 0), (-0.06 * w, h), f"{h:.1f} mm", (-16, 0))
    for k, s in enumerate(sorted(sensors, key=lambda s: s["anchor_mm"][1])):
        z = s["anchor_mm"][1]
        if z > 0:
            x = pot_x + (0.03 + 0.03 * k) * w
            _dimension(ax, (x, 0), (x, z), f"{z:.1f}", (12, 0))
