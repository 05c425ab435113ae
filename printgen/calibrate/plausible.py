"""Plausibility of one sample: values no specimen printgen tests can give point at a wrong
column, unit or size. A stop names the value, the limit, the columns and units used (and the
other candidates) and the fix: the usual cause is raw load-cell counts taken for newtons.
"""

from __future__ import annotations

from printgen.calibrate.reader import TestRecord
from printgen.calibrate.specimen import Specimen
from printgen.errors import CalibrationError

# 0.001-500 GPa: from soft TPE (about 0.01 GPa) to beyond carbon-fibre composites (about
# 300 GPa); a printed polymer lies near 0.01-5 GPa.
MODULUS_RANGE_PA = (1e6, 500e9)
MAX_STRESS_PA = 10e9  # above the strength of any polymer, fibre composite or steel wire
FORCE_FIX = ("choose the newton column with --column force=NAME or give its unit with "
             "--unit force=kN")


def check_stress(rec: TestRecord, spec: Specimen, strength_pa: float | None) -> None:
    """Stop when the peak stress is above MAX_STRESS_PA (cables and dog-bones)."""
    if spec.kind == "panel" or strength_pa is None or strength_pa <= MAX_STRESS_PA:
        return
    raise CalibrationError(f"{rec.path}: peak stress {strength_pa / 1e6:.4g} MPa is above "
                           f"{MAX_STRESS_PA / 1e9:g} GPa, more than any material gives. "
                           f"{_suspects(rec, spec)}")


def check_modulus(rec: TestRecord, spec: Specimen, modulus_pa: float) -> None:
    """Stop when the modulus is outside MODULUS_RANGE_PA (cables and dog-bones)."""
    lo, hi = MODULUS_RANGE_PA
    if spec.kind == "panel" or lo <= modulus_pa <= hi:
        return
    raise CalibrationError(f"{rec.path}: modulus {modulus_pa / 1e9:.4g} GPa is outside the "
                           f"plausible {lo / 1e9:g}-{hi / 1e9:g} GPa. {_suspects(rec, spec)}")


def _suspects(rec: TestRecord, spec: Specimen) -> str:
    """What to check: the force (or stress) column and its unit, the strain, the section."""
    parts = []
    for role, fix in (("force", FORCE_FIX),
                      ("stress", "give its unit with --unit stress=MPa"),
                      ("strain", "give its unit with --unit strain=%"),
                      ("displacement", "give its unit with --unit displacement=mm")):
        if not rec.has(role) or (role == "stress" and rec.has("force")):
            continue
        unit = "no unit in the file, SI default assumed" if role in rec.assumed else \
            "unit from the file"
        text = f"{role} from column {rec.names[role]!r} ({unit})"
        others = rec.alternatives.get(role, ())
        if others:
            text += f"; other {role} columns: {', '.join(map(repr, others))}"
        if role == "force":
            text += " - raw load-cell counts are not newtons"
        parts.append(f"{text}: {fix}")
    area = spec.cross_section()
    if area is not None:
        src = spec.sources.get("area") or spec.sources.get("width") or "options"
        parts.append(f"cross-section {area * 1e6:.4g} mm2 (from {src})")
    return "Check: " + "; ".join(parts)
