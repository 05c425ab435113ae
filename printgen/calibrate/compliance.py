"""Machine-compliance correction of crosshead displacement.

The crosshead moves by the specimen's elongation plus the load train's own deflection. The
latter is given as a constant machine stiffness (N/m), or as a measured system-compliance curve:
force -> system displacement from a test on a rigid bar, subtracted point by point.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from printgen.calibrate.reader import read_export
from printgen.errors import CalibrationError

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class Compliance:
    """Either `stiffness` (N/m) or a table `force` (N) -> `displacement` (m), increasing force."""

    stiffness: float | None = None
    force: np.ndarray | None = None
    displacement: np.ndarray | None = None
    source: str = ""

    def machine_displacement(self, force: np.ndarray) -> np.ndarray:
        """System displacement (m) at each force (N); linear beyond the table's ends."""
        f = np.asarray(force, dtype=float)
        if self.stiffness is not None:
            return f / self.stiffness
        assert self.force is not None and self.displacement is not None
        tf, td = self.force, self.displacement
        out = np.interp(f, tf, td)
        hi, lo = f > tf[-1], f < tf[0]
        if hi.any():
            log.warning("compliance curve %s ends at %.4g N; extrapolated linearly to %.4g N",
                        self.source, tf[-1], f.max())
            out[hi] = td[-1] + (f[hi] - tf[-1]) * (td[-1] - td[-2]) / (tf[-1] - tf[-2])
        out[lo] = td[0] + (f[lo] - tf[0]) * (td[1] - td[0]) / (tf[1] - tf[0])
        return out

    def describe(self) -> str:
        if self.stiffness is not None:
            return f"machine compliance: constant stiffness {self.stiffness / 1e3:.6g} N/mm"
        assert self.force is not None
        return (f"machine compliance: measured curve {self.source} "
                f"({self.force.size} points to {self.force[-1]:.4g} N), subtracted point by point")


def from_stiffness(k_n_per_mm: float) -> Compliance:
    """Constant machine stiffness given in N/mm."""
    if not np.isfinite(k_n_per_mm) or k_n_per_mm <= 0:
        raise CalibrationError(f"machine stiffness {k_n_per_mm:g} N/mm must be > 0; "
                               "fix --machine-stiffness")
    return Compliance(stiffness=k_n_per_mm * 1e3, source="constant")


def from_curve(path: str | Path) -> Compliance:
    """Read a rigid-bar test (force and displacement columns) as a compliance curve."""
    rec = read_export(path)
    if not (rec.has("force") and rec.has("displacement")):
        raise CalibrationError(f"{rec.path}: a compliance curve needs force and displacement "
                               f"columns; found {', '.join(rec.headers) or 'unnamed columns'}")
    f, d = rec.channels["force"], rec.channels["displacement"]
    k = int(np.argmax(f))
    f, d = f[: k + 1], d[: k + 1]
    order = np.argsort(f, kind="stable")
    f, d = f[order], d[order]
    keep = np.concatenate([[True], np.diff(f) > 0])
    f, d = f[keep], d[keep]
    if f.size < 2:
        raise CalibrationError(f"{rec.path}: compliance curve needs at least 2 distinct forces")
    if np.any(np.diff(d) < 0):
        log.warning("%s: system displacement is not monotonic in force", rec.path)
    return Compliance(force=f, displacement=d - np.interp(0.0, f, d) if f[0] <= 0 else d,
                      source=rec.path)
