"""What a curved-strand net costs against the straight net of the same layout: print time,
filament and mass of both from their direct toolpaths (`estimate.print_estimate`, the numbers
the G-code header carries), on the same printer, material and attachment.

The time is the estimate's (moves at their set speed, no acceleration; heating, homing and
the prime line not counted: `estimate.NOT_COUNTED`). A waved bead is many short moves, each
turning a few degrees from the last: the ratio assumes the firmware takes them at the set
speed (its junction deviation or jerk allows that at the few mm/s a flexible bead is laid at);
where it slows down, the curved net takes longer than shown.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

from printgen.inputs.materials import Material
from printgen.inputs.printers import Printer, PrintStyle
from printgen.parts.gcode.estimate import NOT_COUNTED, PrintEstimate, print_estimate
from printgen.parts.gcode.netpath import net_toolpath
from printgen.parts.geometry.attach import Attachment
from printgen.scaling.record import NetDesign, Wave


@dataclass(frozen=True)
class WavePrice:
    """Print time, filament and mass of a net with waved strands and of the same net with
    straight ones (`PrintEstimate`s), and the moves each toolpath has."""

    wave: Wave
    curved: PrintEstimate
    straight: PrintEstimate
    curved_moves: int
    straight_moves: int

    @property
    def time_ratio(self) -> float:
        return self.curved.seconds / self.straight.seconds

    @property
    def mass_ratio(self) -> float:
        return self.curved.mass_g / self.straight.mass_g

    def to_record(self) -> dict[str, object]:
        return {"wave": dataclasses.asdict(self.wave), "curved": self.curved.to_record(),
                "straight": self.straight.to_record(), "curved_moves": self.curved_moves,
                "straight_moves": self.straight_moves, "time_ratio": self.time_ratio,
                "mass_ratio": self.mass_ratio, "assumptions": f"print time: {NOT_COUNTED}"}


def wave_price(net: NetDesign, printer: Printer, style: PrintStyle, material: Material, *,
               wave: Wave | None = None, attachment: Attachment | None = None) -> WavePrice:
    """The `WavePrice` of `net` with `wave` (default: the net's own) against the same net
    with straight strands."""
    wave = net.wave if wave is None else wave
    if wave is None:
        raise ValueError("wave_price needs a wave: the net's own or the wave argument")
    curved = dataclasses.replace(net, wave=wave)
    straight = dataclasses.replace(net, wave=None)
    tp_c = net_toolpath(curved, printer, style, material, attachment=attachment)
    tp_s = net_toolpath(straight, printer, style, material, attachment=attachment)
    return WavePrice(wave, print_estimate(tp_c, printer, material),
                     print_estimate(tp_s, printer, material), len(tp_c.kind), len(tp_s.kind))
