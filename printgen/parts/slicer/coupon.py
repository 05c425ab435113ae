"""PrusaSlicer settings of the waved-strand coupon (`printgen.parts.geometry.wavecoupon`): the
net's own settings (its section, print style and material: the strands print as the net's
do, `prusa.prusa_presets` of the net), with the grip tabs filled solid.

The net's settings lay every band as perimeters alone (`fill_density` 0 %), as many loops as
fill its widest band (`toolpath.wall_loops`); a grip tab is many beads wide, so the coupon
asks for as many loops as fill a tab across (its beads across, two a loop): the tabs are laid
as concentric beads of the strand's bead width, the strands as the net's (Arachne lays no more
loops than a band holds). Solid infill would lay the tabs too, but in lines whose section is
not the strand bead's.
"""

from __future__ import annotations

import dataclasses

from printgen.inputs.materials import Material
from printgen.inputs.printers import Printer, PrintStyle
from printgen.parts.gcode.couponpath import tab_beads
from printgen.parts.geometry.wavecoupon import WavedCoupon
from printgen.parts.slicer.prusa import presets_ini_text, prusa_presets
from printgen.scaling.record import NetDesign


def coupon_ini_text(c: WavedCoupon, net: NetDesign, printer: Printer, style: PrintStyle,
                    material: Material) -> str:
    """The coupon's .ini: net `net`'s settings (checked on the coupon's footprint) with the
    tabs filled solid (see the module)."""
    side = min(c.length_mm, c.width_mm)
    # the net's section and border on a square net of the coupon's footprint: the checks of
    # its passes, layers and size on the bed are the coupon's
    footprint = dataclasses.replace(net, pattern="square", width_mm=c.length_mm,
                                    height_mm=c.width_mm, mesh_x_mm=side, mesh_y_mm=side,
                                    wave=None)
    p = prusa_presets("net", footprint, printer, style, material)
    loops = -(-tab_beads(c)[0] // 2)  # a tab's beads across, two a loop
    settings = {**p.settings, "print": {**p.settings["print"], "perimeters": str(loops)}}
    header = (f"# printgen: PrusaSlicer 2.5 profile for the waved-strand coupon {c.name}: the "
              "net's settings, grip tabs filled solid", *p.header[1:])
    return presets_ini_text(dataclasses.replace(p, settings=settings, header=header))
