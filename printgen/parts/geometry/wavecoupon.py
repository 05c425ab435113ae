"""The waved-strand coupon (`printgen testpieces` of a design with `NetDesign.wave`): a few of
the net's waved strands side by side between two printed grip tabs (mm), so that a tensile
test reads the strand's own force-extension curve, which the beam model predicts
(`printgen.solver.strand_curve`).

Each strand is one junction-to-junction chord L of the net's loaded strands
(`barrier.patterns.curved.chord`) with the net's wave y = a sin(n pi x / L), section (beads
across x bead width, the net's layers), material and print style. The tabs' inner edges are
the junctions: a tab is gripped, so it neither turns nor moves across the load, which holds
both strand ends clamped in rotation and across the chord, as the beam model's ends are (in
the net, the junctions of a net stretched alike). The wave's curvature is zero at its ends
(sin 0 = 0), so the strand meets the tab edge as a straight band.

Neighbouring strands are mirror images (strand j's wave has the sign (-1)^j): with an even
count the coupon is symmetric about its axis, so the strands' end moments and across-the-load
forces on a tab cancel and the grips need not hold them. Their centre lines are
`COUPON_PITCH` apart: the band each wave sweeps (2 a + W, W the strand width) plus one strand
width of clear gap, so neighbouring strands never fuse.

Its volume in closed form: two tabs plus, per strand, its width times the wave's arc length
(`wave.wave_length`; a band's area is its width times its centre line's length while its
radius exceeds its half-width, which the printable-wave limit ensures, and the band meets the
tab edges where it is straight).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from printgen.barrier.patterns.curved import chord
from printgen.errors import GeometryError
from printgen.parts.geometry.cable import check_positive_mm, require_shapely
from printgen.parts.geometry.wave import WavedStrand, wave_length
from printgen.scaling.record import Design, Section, Wave, check_net_wave

COUPON_STRANDS = 4  # even: mirrored pairs (the tabs feel no net moment); four strands carry
# four times one strand's force, so the soft bending branch still reads on a load cell
TAB_LENGTH_MM = 20.0  # each grip tab along the load: a wedge grip's 20 mm face holds it whole
TAB_LAP_BEADS = 1.0  # strand beads run on into the tab by this many strand widths (lap joint)


@dataclass(frozen=True)
class WavedCoupon:
    """The waved-strand coupon (mm): `strands` waved strands of `section` and `wave` over a
    `chord_mm` gauge between two tabs `tab_mm` long, centre lines `pitch_mm` apart; the
    load along x, the gauge from x = 0 to x = chord_mm, the coupon centred on y = 0."""

    name: str
    material: str
    print_style: str
    chord_mm: float
    wave: Wave
    section: Section
    strands: int
    pitch_mm: float
    tab_mm: float

    @property
    def width_mm(self) -> float:
        """Across the load: the tabs' width (the strands' pitch each)."""
        return self.strands * self.pitch_mm

    @property
    def length_mm(self) -> float:
        """Along the load: tab, gauge, tab."""
        return self.chord_mm + 2 * self.tab_mm

    def offsets_mm(self) -> np.ndarray:
        """(strands,) y of each strand's chord."""
        return (np.arange(self.strands) - (self.strands - 1) / 2) * self.pitch_mm

    def centre_line(self, j: int) -> WavedStrand:
        """Strand j's waved centre line (t along the chord from the left tab's edge; the
        wave's sign (-1)^j: neighbours mirrored)."""
        return WavedStrand(np.array([0.0, float(self.offsets_mm()[j])]), np.array([1.0, 0.0]),
                           np.array([0.0, 1.0]), np.array([0.0, self.chord_mm]), self.wave,
                           np.array([1.0 if j % 2 == 0 else -1.0]))

    def lap_mm(self) -> float:
        return TAB_LAP_BEADS * self.section.width_mm

    def to_record(self) -> dict:
        return {"chord_mm": self.chord_mm, "gauge_length_mm": self.chord_mm,
                "amplitude_mm": self.wave.amplitude_mm, "half_waves": self.wave.half_waves,
                "strands": self.strands, "pitch_mm": self.pitch_mm, "tab_mm": self.tab_mm,
                "width_mm": self.width_mm, "length_mm": self.length_mm,
                "strand_width_mm": self.section.width_mm,
                "thickness_mm": self.section.thickness_mm,
                "beads_across": self.section.beads_across,
                "layer_heights_mm": list(self.section.layer_heights_mm),
                "arc_length_mm": wave_length(self.chord_mm, self.wave)}


def waved_coupon_for(d: Design, strands: int = COUPON_STRANDS) -> WavedCoupon:
    """The waved-strand coupon of design `d` (with a wave): its loaded strands' chord, wave,
    section, material and print style (see the module); GeometryError when `d` has none or
    its wave cannot be printed."""
    n = d.net
    if n.wave is None:
        raise GeometryError("a waved-strand coupon needs a design with a net wave "
                            "(NetDesign.wave); this design's strands are straight")
    if strands < 1:
        raise GeometryError(f"waved coupon: {strands} strands; give at least one")
    check_net_wave(n, "waved coupon")
    w = n.strand.width_mm
    return WavedCoupon("wave-coupon", n.material, n.print_style,
                       chord(n.pattern, n.mesh_y_mm, n.mesh_x_mm), n.wave, n.strand, strands,
                       2 * n.wave.amplitude_mm + 2 * w, TAB_LENGTH_MM)


def coupon_outline(c: WavedCoupon):
    """Plan view of the coupon: one shapely Polygon (mm)."""
    check_positive_mm(c.section.width_mm, "waved coupon strand width")
    check_positive_mm(c.section.thickness_mm, "waved coupon thickness")
    shapely = require_shapely()
    from shapely.geometry import LineString, box

    half = c.width_mm / 2
    lap = c.lap_mm()
    pieces = [box(-c.tab_mm, -half, 0.0, half), box(c.chord_mm, -half, c.length_mm - c.tab_mm,
                                                    half)]
    for j in range(c.strands):
        line = c.centre_line(j).polyline(-lap, c.chord_mm + lap)
        pieces.append(LineString(line).buffer(c.section.width_mm / 2, cap_style="flat"))
    return shapely.unary_union(pieces)


def analytic_coupon_area(c: WavedCoupon) -> float:
    """Plan area (mm^2): two tabs plus each strand's width x arc length (see the module)."""
    return 2 * c.tab_mm * c.width_mm + c.strands * c.section.width_mm * wave_length(c.chord_mm,
                                                                                   c.wave)


def analytic_coupon_volume(c: WavedCoupon) -> float:
    return analytic_coupon_area(c) * c.section.thickness_mm


def coupon_solid(c: WavedCoupon):
    """The coupon as one watertight trimesh (mm, z from 0 to the section's thickness)."""
    from printgen.parts.geometry.solid import extrude

    return extrude(coupon_outline(c), c.section.thickness_mm, "waved coupon")
