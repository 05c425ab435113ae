"""`printgen panel`: the simulated tensile test of a design's printed net panel
(printgen.scene.panel), one per diagonal asked, with the strain at which its meshes
lie along the load."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from printgen.inputs.materials import load_material
from printgen.scaling.design_file import load_design
from printgen.scaling.reading import Reading, panel_reading
from printgen.scene.panel import MODES, DesignPanel, design_panel, panel_lockup
from printgen.scene.scenes import ORIENTATIONS

__all__ = ["MODES", "ORIENTATIONS", "PanelRun", "panel_tests"]


@dataclass(frozen=True)
class PanelRun:
    """One simulated panel test: the test and its curve (`panel`), the panel strain at
    which the strands lie along the load (`lockup`, a fraction) and how the material's panel
    law is read (`reading`: each diagonal's checks and the one chosen; None without one)."""

    panel: DesignPanel
    lockup: float
    reading: Reading | None = None


def panel_tests(design_path: str | Path, orientations: tuple[str, ...] | None = None,
                mode: str = "free") -> list[PanelRun]:
    """The panel test of the design in `design_path` along each of `orientations` (default:
    both diagonals), clamped `mode` (free or blocked)."""
    d = load_design(design_path)
    reading = panel_reading(load_material(d.net.material))
    runs = []
    for o in orientations or ORIENTATIONS:
        dp = design_panel(d, o, mode)
        runs.append(PanelRun(dp, panel_lockup(dp.test), reading))
    return runs
