"""`printgen panel`: the simulated tensile test of a design's printed net panel
(printgen.scene.panel), one per diagonal asked, with the strain at which its meshes
lie along the load."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from printgen.errors import InputError
from printgen.inputs.materials import load_material
from printgen.outputs.display import Shown, Summary
from printgen.scaling.design_file import load_design
from printgen.scaling.reading import Reading, panel_reading
from printgen.scene.panel import MODES, DesignPanel, curved_panel, design_panel, panel_lockup
from printgen.scene.scenes import ORIENTATIONS

__all__ = ["MODES", "ORIENTATIONS", "PanelRun", "panel_tests", "wave_of"]


@dataclass(frozen=True, repr=False)
class PanelRun(Shown):
    """One simulated panel test: the test and its curve (`panel`), the panel strain at
    which the strands lie along the load (`lockup`, a fraction) and how the material's panel
    law is read (`reading`: each diagonal's checks and the one chosen; None without one)."""

    panel: DesignPanel
    lockup: float
    reading: Reading | None = None

    def summary(self) -> Summary:
        t = self.panel.test
        return Summary(f"PanelRun: {self.panel.orientation} diagonal, sides {t.mode}",
                       (("mesh along x across", f"{t.mesh_along * 1e3:.3g} x "
                                                f"{t.mesh_across * 1e3:.3g} mm"),
                        ("panel", f"{t.length * 1e3:.3g} mm long, {t.width * 1e3:.3g} mm wide"),
                        ("strands along the load at", f"{self.lockup:.1%} strain")))


def wave_of(amplitude_mm: float | None, half_waves: int | None) -> tuple[float, int] | None:
    """The wave of the command line's --wave and --half-waves (default 1), None for straight
    strands; InputError for half-waves without an amplitude (its range is the pattern's:
    `barrier.patterns.curved.check_wave`)."""
    if amplitude_mm is None:
        if half_waves is not None:
            raise InputError(f"--half-waves {half_waves} needs --wave (the amplitude, mm)")
        return None
    return amplitude_mm, 1 if half_waves is None else half_waves


def panel_tests(design_path: str | Path, orientations: tuple[str, ...] | None = None,
                mode: str = "free", wave: tuple[float, int] | None = None) -> list[PanelRun]:
    """The panel test of the design in `design_path` along each of `orientations` (default:
    both diagonals), clamped `mode` (free or blocked); `wave` (amplitude mm, half-waves): its
    net printed with curved strands instead (`scene.panel.curved_panel`)."""
    d = load_design(design_path)
    reading = panel_reading(load_material(d.net.material))
    runs = []
    for o in orientations or ORIENTATIONS:
        dp = design_panel(d, o, mode) if wave is None else curved_panel(d, o, *wave, mode)
        runs.append(PanelRun(dp, panel_lockup(dp.test), reading))
    return runs
