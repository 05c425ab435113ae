"""Mesh exports: binary STL, 3MF with embedded PrusaSlicer settings, STEP (cadquery)."""

from printgen.export.layout import place_mesh
from printgen.export.stl import stl_bytes
from printgen.export.threemf import prusa_config_from_ini, threemf_bytes

__all__ = ["place_mesh", "prusa_config_from_ini", "stl_bytes", "threemf_bytes"]
