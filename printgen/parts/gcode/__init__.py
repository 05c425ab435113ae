"""Direct G-code: toolpaths (arrays of moves), the text writer and a G-code reader."""

from printgen.parts.gcode.cablepath import cable_toolpath, cable_volume_budget
from printgen.parts.gcode.netpath import net_toolpath, net_volume_budget
from printgen.parts.gcode.readback import Readback, read_gcode, read_gcode_text
from printgen.parts.gcode.toolpath import Toolpath, VolumeBudget, check_part
from printgen.parts.gcode.writer import gcode_text, write_gcode

__all__ = [
    "Readback", "Toolpath", "VolumeBudget", "cable_toolpath", "cable_volume_budget",
    "check_part", "gcode_text", "net_toolpath", "net_volume_budget", "read_gcode",
    "read_gcode_text", "write_gcode",
]
