"""Part exports: bed layout, binary STL, 3MF with embedded PrusaSlicer settings (STEP:
`printgen.parts.geometry.cad`). Every writer checks its input before writing, atomically."""

from printgen.parts.export.bed import (
    Placement,
    fit_angle,
    layout_parts,
    place_mesh,
    usable_bed_mm,
)
from printgen.parts.export.stl import check_mesh, stl_bytes, write_stl
from printgen.parts.export.threemf import (
    prusa_config_from_ini,
    threemf_bytes,
    write_3mf,
    write_plate,
)

__all__ = ["Placement", "check_mesh", "fit_angle", "layout_parts", "place_mesh",
           "prusa_config_from_ini", "stl_bytes", "threemf_bytes", "usable_bed_mm", "write_3mf",
           "write_plate", "write_stl"]
