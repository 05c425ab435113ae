"""How the printed kit goes together, and the check that it closes (plan view, mm).

Net coordinates: origin at the net's lower-left corner node, x across the flume, y up. The
four anchors (flume pins) are the net's corner nodes: the net's corner eyelets and both
cables' eyelets go on each pin. A cable runs straight from anchor to anchor along its side and
threads every loop of that side. The kit closes when each cable's eyelet spacing equals its
anchors' spacing (to `CLOSE_TOL_MM`), every loop of a side lies on its cable's line, and
every loop leaves the stated clearance around the strip.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from printgen.errors import GeometryError
from printgen.inputs.printers import Printer
from printgen.parts.geometry.attach import Attachment, attachment_for, corner_nodes, holes
from printgen.scaling.record import Design

CLOSE_TOL_MM = 0.1  # the kit closes: attachment points and anchor spacing agree to 0.1 mm
SIDE_ANCHORS = {"bottom": (0, 1), "right": (1, 2), "top": (3, 2), "left": (0, 3)}

CHECKLIST = (
    ("Pin holes: every eyelet (cables and net corners) takes the anchor pin (M3 screw) "
    "by hand; nominal {pin:.2f} mm."),
    ("Loops: {loops} loops on the net's border, none closed or stringed over; each "
    "{loop:.2f} mm across (the strip, {strip}, passes with {clear:.2f} mm each side)."),
    ("Joints: pull each cable's strip against its eyelet by hand; the strip's beads run "
    "into the ring (no seam where strip meets ring)."),
    ("Lengths: cable eyelets {top:.1f} mm (top, bottom) and {side:.1f} mm (left, right) "
    "apart centre to centre; the net's corner eyelets the same; the flume's anchor pins "
    "drilled at these spacings."),
    "Net: every strand continuous through its crossings, no strings across the openings.",
)


@dataclass(frozen=True)
class CableFit:
    """One cable on its side of the net (mm, net coordinates).

    anchors_mm : (2, 2) the pins its eyelets go on; loops_mm : (k, 2) the loops it threads
    loop_offset_mm : (k,) distance of each loop centre from the cable's centre line
    """

    name: str
    length_mm: float
    anchors_mm: np.ndarray
    loops_mm: np.ndarray
    loop_offset_mm: np.ndarray

    @property
    def anchor_spacing_mm(self) -> float:
        return float(np.hypot(*(self.anchors_mm[1] - self.anchors_mm[0])))

    @property
    def mismatch_mm(self) -> float:
        return self.length_mm - self.anchor_spacing_mm


@dataclass(frozen=True)
class Assembly:
    """The kit: net size, the four anchors, each cable's fit and the loop sizes (mm)."""

    scale: float
    net_size_mm: tuple[float, float]
    anchors_mm: np.ndarray
    attachment: Attachment
    cables: tuple[CableFit, ...]

    @property
    def loop_count(self) -> int:
        return sum(len(c.loops_mm) for c in self.cables)

    def problems(self, tol_mm: float = CLOSE_TOL_MM) -> list[str]:
        """Why the kit does not close (empty when it does)."""
        out = []
        for c in self.cables:
            if abs(c.mismatch_mm) > tol_mm:
                out.append(f"cable {c.name}: eyelets {c.length_mm:.2f} mm apart, anchors "
                           f"{c.anchor_spacing_mm:.2f} mm ({c.mismatch_mm:+.2f} mm)")
            if len(c.loops_mm) and np.max(c.loop_offset_mm) > tol_mm:
                out.append(f"cable {c.name}: a loop sits {np.max(c.loop_offset_mm):.2f} mm "
                           "off the cable's line")
        a = self.attachment
        if a.strip_clearance_mm() < a.clearance_mm - 1e-9:
            out.append(f"loops leave {a.strip_clearance_mm():.2f} mm around the strip, "
                       f"less than {a.clearance_mm:.2f} mm")
        return out

    def checklist(self) -> list[str]:
        """What to check after printing, with this kit's numbers."""
        a = self.attachment
        sx, sy = self.net_size_mm
        vals = {"pin": a.pin_hole_mm, "loops": self.loop_count, "loop": a.loop_hole_mm,
                "strip": f"{a.strip_width_mm:g} x {a.strip_thickness_mm:g} mm",
                "clear": a.strip_clearance_mm(), "top": sx, "side": sy}
        return [line.format(**vals) for line in CHECKLIST]

    def to_record(self) -> dict[str, object]:
        a = self.attachment
        return {
            "net_size_mm": [round(v, 4) for v in self.net_size_mm],
            "anchors_mm": np.round(self.anchors_mm, 4).tolist(),
            "loops": self.loop_count,
            "loop_hole_mm": round(a.loop_hole_mm, 4),
            "loop_hole_modelled_mm": round(a.loop_hole_mm + a.hole_compensation_mm, 4),
            "pin_hole_mm": a.pin_hole_mm, "hole_compensation_mm": a.hole_compensation_mm,
            "strip_clearance_mm": round(a.strip_clearance_mm(), 4),
            "cables": {c.name: {"length_mm": c.length_mm,
                                "anchor_spacing_mm": round(c.anchor_spacing_mm, 4),
                                "mismatch_mm": round(c.mismatch_mm, 4),
                                "loops": len(c.loops_mm)} for c in self.cables},
            "closes": not self.problems(),
        }


def assemble(design: Design, printer: Printer) -> Assembly:
    """The kit of `design`: anchors at the net's corner nodes, each cable on its side."""
    n = design.net
    g = n.graph()
    att = attachment_for(design, hole_compensation_mm=printer.hole_compensation_mm)
    hs = holes(n, g, att)
    anchors = g.nodes_mm[corner_nodes(g)]
    loops = np.array([h.centre_mm for h in hs if not h.corner])
    fits = []
    for c in design.cables:
        if c.name not in SIDE_ANCHORS:
            raise GeometryError(f"cable {c.name!r} has no side of the net; name the cables "
                                f"{', '.join(SIDE_ANCHORS)}")
        i, j = SIDE_ANCHORS[c.name]
        a0, a1 = anchors[i], anchors[j]
        u = (a1 - a0) / np.hypot(*(a1 - a0))
        rel = loops - a0
        along = rel @ u
        off = np.abs(rel @ np.array([-u[1], u[0]]))
        mine = (off < min(n.mesh_x_mm, n.mesh_y_mm) / 4) & (along > 0) \
            & (along < np.hypot(*(a1 - a0)))
        fits.append(CableFit(c.name, c.length_mm, np.array([a0, a1]), loops[mine], off[mine]))
    return Assembly(design.scale, g.size_mm, anchors, att, tuple(fits))
