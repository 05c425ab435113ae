"""PrusaSlicer settings of the waved-strand coupon (`printgen.parts.geometry.wavecoupon`): the
net's own settings (its section, print style and material: the strands print as the net's
do, `prusa.prusa_presets` of the net), with the grip tabs filled solid.

The net's settings lay every band as perimeters alone (`fill_density` 0 %: a strand or the
border frame is a few beads wide); a grip tab is a solid block many beads wide, so the coupon
sets `fill_density` to 100 %, which PrusaSlicer lays as solid infill inside the tab's
perimeters. The strands stay perimeters only (Arachne fills a band of the strand's width with
its beads before any infill is left).
"""

from __future__ import annotations

import dataclasses

from printgen.inputs.materials import Material
from printgen.inputs.printers import Printer, PrintStyle
from printgen.parts.geometry.wavecoupon import WavedCoupon
from printgen.parts.slicer.prusa import presets_ini_text, prusa_presets
from printgen.scaling.record import NetDesign

TAB_FILL = "100%"  # solid grip tabs


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
    settings = {**p.settings, "print": {**p.settings["print"], "fill_density": TAB_FILL}}
    header = (f"# printgen: PrusaSlicer 2.5 profile for the waved-strand coupon {c.name}: the "
              "net's settings, grip tabs filled solid", *p.header[1:])
    return presets_ini_text(dataclasses.replace(p, settings=settings, header=header))
