"""Slicer profiles: PrusaSlicer .ini and CuraEngine settings for the printed parts."""

from printgen.slicer.prusa import (
    allowed_prusa_keys,
    prusa_ini_text,
    prusa_settings,
    write_prusa_ini,
)

__all__ = ["allowed_prusa_keys", "prusa_ini_text", "prusa_settings", "write_prusa_ini"]
