"""The test pieces a lab prints before the barrier (`printgen testpieces`): a tensile coupon
of the design's net strand and a net test panel of its mesh, as printable parts (mm).

Coupon: the strand's own section and passes (bead width, beads across, layer heights, the
net's material), a straight strip `COUPON_GAUGE_MM` long between two eyelet rings that are
its grip tabs: the tester's pins (or clevis grips) go through the eyelets. Each ring is
`COUPON_RING_FACTOR` strand widths wide on each side of its hole, so a ring carries the load
in two sections of that width and strains a fraction of the strip: the crosshead strain over
the gauge length reads the strip (the rings' give is an error below about 1/(2 x factor)).
It is a `CableDesign` (the same strip-with-eyelets geometry, toolpath and slicer settings as
the border cables), printed with the print style `COUPON_STYLE`.

Panel: the design's diamond mesh, loaded along one diagonal, sized as the virtual panel test
(`printgen.scene.panel`): clamp edges on two node rows `length` apart and `width`
across (whole half-meshes), with one more mesh row beyond each clamp edge for the clamp
faces to hold and the net's border frame around it. The two side bars of the frame are cut
before the test (the virtual panel's sides are free). A square mesh has no diagonal to choose:
its panel is pulled along one strand family, sized as `printgen.run.squarepieces` argues.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

from printgen.barrier.patterns import get_pattern, panel_test_patterns
from printgen.errors import GeometryError
from printgen.scaling.record import CableDesign, Design, NetDesign

COUPON_GAUGE_MM = 50.0  # free strip between the eyelet rings (ISO 527-2 1A: 50 mm gauge)
COUPON_RING_FACTOR = 2  # ring width each side of the hole, in strand widths
COUPON_PIN_MM = 3.0  # pin hole when the design has no cables (else the cables' eyelet hole)
COUPON_COUNT = 5  # ISO 527-1: at least five specimens per direction
COUPON_STYLE = "coupon-strand"


@dataclass(frozen=True)
class PanelPiece:
    """The printed test panel: its net, the clamp layout and the orientation (mm)."""

    net: NetDesign
    orientation: str  # the mesh diagonal along the load ("short" or "long"; a square net's
    # panel: "strands", pulled along one strand family)
    length_mm: float  # clamp edge to clamp edge, along the load
    width_mm: float  # across the load
    clamp_depth_mm: float  # net held in each clamp beyond its edge (one mesh row)

    def to_record(self) -> dict:
        return {"orientation": self.orientation, "length_mm": self.length_mm,
                "width_mm": self.width_mm, "clamp_depth_mm": self.clamp_depth_mm,
                "printed_mm": [self.net.width_mm, self.net.height_mm],
                "mesh_along_load_mm": self.net.mesh_y_mm,
                "mesh_across_load_mm": self.net.mesh_x_mm}


def coupon_for(d: Design) -> CableDesign:
    """The tensile coupon of design `d`'s net strand (see the module docstring)."""
    sec = d.net.strand
    pin = max((c.eyelet_inner_mm for c in d.cables), default=COUPON_PIN_MM)
    outer = pin + 2 * COUPON_RING_FACTOR * sec.width_mm
    return CableDesign(name="coupon", material=d.net.material, print_style=COUPON_STYLE,
                       length_mm=COUPON_GAUGE_MM + outer, section=sec,
                       eyelet_inner_mm=pin, eyelet_outer_mm=outer)


def coupon_gauge_mm(c: CableDesign) -> float:
    """The coupon's free strip between its rings (mm): pin distance less one ring diameter."""
    return c.length_mm - c.eyelet_outer_mm


def panel_for(d: Design, orientation: str, length_mm: float, width_mm: float) -> PanelPiece:
    """The test panel of design `d`'s mesh loaded along its `orientation` diagonal (a square
    mesh's: along its strands up the panel), with
    clamp edges `length_mm` apart and `width_mm` across (the virtual test's lattice size:
    whole half-meshes)."""
    n = d.net
    if not get_pattern(n.pattern).panel_test:
        tested = panel_test_patterns()
        raise GeometryError(f"a test panel needs a {' or '.join(tested)} net; this design's "
                            f"net is {n.pattern!r} (the virtual panel test models "
                            f"{' and '.join(f'{t}s' for t in tested)} only)")
    lo, hi = sorted((n.mesh_x_mm, n.mesh_y_mm))
    if orientation not in ("short", "long"):
        raise GeometryError(f"panel orientation {orientation!r} is not one of short, long")
    along, across = (lo, hi) if orientation == "short" else (hi, lo)
    depth = along  # one whole mesh beyond each clamp edge: node rows stay on the lattice
    net = replace(n, width_mm=width_mm, height_mm=length_mm + 2 * depth,
                  mesh_x_mm=across, mesh_y_mm=along)
    # a square mesh has no diagonal to choose: its panel is pulled along the strands that run
    # up the printed panel (its strands across are the same section laid the same way)
    shown = "strands" if n.pattern == "square" else orientation
    return PanelPiece(net, shown, length_mm, width_mm, depth)
