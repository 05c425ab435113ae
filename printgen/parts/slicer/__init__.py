"""Slicer profiles: PrusaSlicer .ini, presets and config bundle; CuraEngine settings, a Cura
profile and its settings table for the printed parts."""

from printgen.parts.slicer.cura import (
    cura_cfg_text,
    cura_engine_args,
    cura_settings,
    cura_table_csv,
    curaprofile_bytes,
    write_cura_cfg,
)
from printgen.parts.slicer.prusa import (
    PrusaPresets,
    allowed_prusa_keys,
    design_presets,
    presets_ini_text,
    prusa_bundle_text,
    prusa_ini_text,
    prusa_presets,
    prusa_settings,
    write_prusa_ini,
)

__all__ = ["PrusaPresets", "allowed_prusa_keys", "cura_cfg_text", "cura_engine_args",
           "cura_settings", "cura_table_csv", "curaprofile_bytes", "design_presets",
           "presets_ini_text", "prusa_bundle_text", "prusa_ini_text", "prusa_presets",
           "prusa_settings", "write_cura_cfg", "write_prusa_ini"]
