"""Slicer profiles: PrusaSlicer .ini and CuraEngine settings for the printed parts."""

from printgen.parts.slicer.cura import (
    cura_cfg_text,
    cura_engine_args,
    cura_settings,
    write_cura_cfg,
)
from printgen.parts.slicer.prusa import (
    allowed_prusa_keys,
    prusa_ini_text,
    prusa_settings,
    write_prusa_ini,
)

__all__ = ["allowed_prusa_keys", "cura_cfg_text", "cura_engine_args", "cura_settings",
           "prusa_ini_text", "prusa_settings", "write_cura_cfg", "write_prusa_ini"]
