"""`Design`: what `printgen select` chose, and what geometry, G-code and verification build.

All dimensions in mm (print-side data); moduli and forces stay SI. A pass is one bead of
`bead_width_mm` laid at one layer height; a section is `beads_across` beads side by side on
each of `len(layer_heights_mm)` stacked layers.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass
from typing import TYPE_CHECKING, Any

from printgen.outputs.display import Shown, Summary

if TYPE_CHECKING:
    from printgen.barrier.graph import NetGraph


@dataclass(frozen=True)
class Section:
    """A printed rectangular section: beads side by side x layers stacked (mm)."""

    bead_width_mm: float
    beads_across: int
    layer_heights_mm: tuple[float, ...]

    @property
    def width_mm(self) -> float:
        return self.bead_width_mm * self.beads_across

    @property
    def thickness_mm(self) -> float:
        return float(sum(self.layer_heights_mm))

    @property
    def passes(self) -> int:
        return self.beads_across * len(self.layer_heights_mm)

    @property
    def area_mm2(self) -> float:
        return self.width_mm * self.thickness_mm


@dataclass(frozen=True)
class Wave:
    """The in-plane wave of every strand between two junctions a chord L apart (mm):
    y = amplitude_mm sin(half_waves pi x / L) (`printgen.barrier.patterns.curved`)."""

    amplitude_mm: float
    half_waves: int


@dataclass(frozen=True)
class NetDesign:
    """A printed net: panel size, mesh diagonals (x across, y up), strand section, border
    frame, its pattern (`printgen.barrier.patterns`; a design file without one: diamond) and
    the strands' wave (None: straight strands; a design file without one: straight)."""

    material: str
    print_style: str
    width_mm: float
    height_mm: float
    mesh_x_mm: float
    mesh_y_mm: float
    strand: Section
    border_width_mm: float
    pattern: str = "diamond"
    wave: Wave | None = None

    def graph(self) -> NetGraph:
        """The net's centre-line graph (mm), built by its pattern."""
        from printgen.barrier.patterns import get_pattern

        return get_pattern(self.pattern).graph(self.width_mm, self.height_mm, self.mesh_x_mm,
                                               self.mesh_y_mm)


def check_net_wave(net: NetDesign, where: str = "net") -> None:
    """GeometryError naming the limit when `net.wave` cannot be printed on its mesh: the
    curved pattern's limits (`curved.check_wave_mm`; a square net's mesh is square, so its
    strands up and across have the same chord and spacing)."""
    if net.wave is None:
        return
    from printgen.barrier.patterns.curved import check_wave_mm

    w, s = net.wave, net.strand
    check_wave_mm(net.pattern, w.amplitude_mm, w.half_waves, s.bead_width_mm, s.beads_across,
                  net.mesh_x_mm, net.mesh_y_mm, f"{where} wave")


CABLE_SIDES = ("top", "bottom", "left", "right")  # a cable's name: the net side it borders


@dataclass(frozen=True)
class CableDesign:
    """A border cable: a straight strip with an eyelet at each end (mm)."""

    name: str
    material: str
    print_style: str
    length_mm: float  # eyelet centre to eyelet centre
    section: Section
    eyelet_inner_mm: float
    eyelet_outer_mm: float


@dataclass(frozen=True, repr=False)
class Design(Shown):
    """A complete printable model at scale 1/lambda on one printer (shown by its net and
    cables; `to_dict()` holds everything)."""

    scale: float
    printer: str
    net: NetDesign
    cables: tuple[CableDesign, ...]

    def to_dict(self) -> dict[str, Any]:
        """The record; a net of straight strands has no `wave` key (the files written before
        nets could be curved, byte for byte)."""
        rec = asdict(self)
        if self.net.wave is None:
            del rec["net"]["wave"]
        return rec

    def summary(self) -> Summary:
        n, s = self.net, self.net.strand
        rows = [("printer", self.printer),
                ("net", f"{n.material} {n.pattern}, {n.width_mm:g} x {n.height_mm:g} mm, mesh "
                        f"{n.mesh_x_mm:g} x {n.mesh_y_mm:g} mm, strand {s.width_mm:g} x "
                        f"{s.thickness_mm:g} mm ({s.passes} passes), print {n.print_style}")]
        rows += [(f"{c.name} cable", f"{c.material}, {c.length_mm:g} mm, {c.section.width_mm:g} "
                                     f"x {c.section.thickness_mm:g} mm ({c.section.passes} "
                                     "passes)") for c in self.cables]
        return Summary(f"Design at 1:{self.scale:g}", tuple(rows))

    @classmethod
    def from_record(cls, rec: Any, *, where: str = "design record") -> Design:
        """The Design of a `to_dict()` record (the design.json that `printgen make` writes);
        InputError naming the missing, unknown or bad entry otherwise."""
        from printgen.scaling.design_file import design_from_dict

        return design_from_dict(rec, where=where)


