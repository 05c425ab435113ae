"""From the selection's winners to a printable `Design` (mm): net panel, strand, cables."""

from __future__ import annotations

from printgen.barrier.patterns import get_pattern
from printgen.errors import DesignError
from printgen.inputs.prototype import Prototype
from printgen.scaling.record import CableDesign, Design, NetDesign, Section
from printgen.scaling.selection import Selection, model_mesh, printed_pattern
from printgen.scaling.similitude import ScaledTargets

EYELET_INNER_MM = 3.2  # clearance for the M3 screws that hold the cables on the flume anchors
EYELET_RING_BEADS = 4  # the eyelet ring is 4 cable beads wide (1.8 mm at 0.45 mm beads)
BORDER_BEADS = 2  # the net's border frame is two beads wide: the cables thread along it


def make_design(prototype: Prototype, targets: ScaledTargets, selection: Selection) -> Design:
    """The Design of the winners of `selection` at the targets' scale (mm).

    Net: the barrier's model width x height rounded to the lattice of the printed pattern
    (`printed_pattern`: the diamond's whole half-meshes, the square's whole meshes keep the
    mesh exact: its `span`), the model mesh, the winning strand section and a border frame of
    BORDER_BEADS beads; a square net without border cables gets a frame of the strand's own
    section instead (its edge rows are strands of the prototype's net, `edge_strands`). Cables
    (when the prototype has a border): top and bottom span the net's width anchor to anchor (its
    corner nodes sit on the anchors), the lateral ones its height, so the parts meet at every scale.
    """
    net_c = selection.net[0]
    if not net_c.feasible:
        raise DesignError(f"no printable net: {net_c.reasons[0]}")
    mesh_x, mesh_y = model_mesh(prototype, targets)
    mesh_x_mm, mesh_y_mm = round(mesh_x * 1e3, 6), round(mesh_y * 1e3, 6)
    pattern = get_pattern(printed_pattern(prototype))
    width = pattern.span(targets["width"] * 1e3, mesh_x_mm)
    height = pattern.span(targets["height"] * 1e3, mesh_y_mm)
    net = NetDesign(material=net_c.material, print_style=selection.net_print,
                    width_mm=round(width, 6), height_mm=round(height, 6),
                    mesh_x_mm=mesh_x_mm, mesh_y_mm=mesh_y_mm,
                    strand=net_c.section,
                    border_width_mm=_border_width(pattern.edge_strands and not selection.cables,
                                                  net_c.section),
                    pattern=pattern.name)
    cables: tuple[CableDesign, ...] = ()
    if selection.cables:
        c = selection.cables[0]
        if not c.feasible:
            raise DesignError(f"no printable border cable: {c.reasons[0]}")
        cables = tuple(
            CableDesign(name=name, material=c.material, print_style=selection.cable_print,
                        length_mm=round(length, 6), section=c.section,
                        eyelet_inner_mm=EYELET_INNER_MM,
                        eyelet_outer_mm=round(EYELET_INNER_MM + 2 * EYELET_RING_BEADS
                                              * c.section.bead_width_mm, 6))
            for name, length in (("top", width), ("bottom", width), ("left", height),
                                 ("right", height)))
    return Design(scale=targets.scale, printer=selection.printer, net=net, cables=cables)



def _border_width(edge_strands: bool, strand: Section) -> float:
    """Width (mm) of the net's border frame: the strand's own when the frame stands for the
    prototype's edge strands, else BORDER_BEADS beads (the cables thread along it)."""
    return strand.width_mm if edge_strands else BORDER_BEADS * strand.bead_width_mm
