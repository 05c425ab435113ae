"""The wave stage of `printgen design`: the chosen net printed with waved strands
(`printgen.barrier.patterns.curved`), screened by its law against the target law and verified
by the solver like the straight candidates.

Screen. Every printable wave of the chosen net (amplitudes in steps of WAVE_STEP_MM up to the
printable limits of `curved.check_wave_mm`, 1 to MAX_HALF_WAVES half-waves) is scored by the
RMS of log(model / target) of the blocked, infinite net's law (`curved.blocked_force`: every
chord stretched alike at finite strain), up the barrier (along mesh_y) and across it (along
mesh_x), at LAW_POINTS net strains up to LAW_REACH x the target law's last knee (its knee and
both slopes; a target without knee: the selection's NET_STRAINS). The target in both
directions is the prototype's panel law read as the prototype's scene reads it: turned into a
strand law of the scaled prototype's mesh (its pattern's `strand_law`, along mesh_y) and
stretched the same way, so target and candidate go through one mapping. The waved strands'
material law is the straight strands' law the verification's scene gives the net
(`straight_law`: the material's reading) per unit area, as `printgen.scene.waved` takes it.

Verify. The WAVES_VERIFIED best-scored waves are verified by the solver (the search's
`verifier`); the best is kept when its deformation mismatch is lower than the straight net's.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from printgen.barrier.patterns import get_pattern
from printgen.barrier.patterns.curved import (
    CurvedStrands,
    blocked_force,
    check_wave_mm,
    strand_law,
)
from printgen.errors import GeometryError
from printgen.inputs.materials import load_material
from printgen.inputs.prototype import Prototype
from printgen.scaling.record import Design, NetDesign, Wave
from printgen.scaling.section import net_membrane_law
from printgen.scaling.selection import NET_STRAINS, target_net_law
from printgen.scaling.similitude import ScaledTargets
from printgen.solver import Law
from printgen.units import MM

WAVE_STEP_MM = 0.25  # amplitude grid: a quarter of a typical 0.4-0.6 mm bead
MAX_HALF_WAVES = 3  # more half-waves bend tighter than a bead allows on these meshes
WAVES_VERIFIED = 3  # waves the solver verifies (the best screened)
LAW_REACH = 1.5  # net strains up to 1.5 x the target's last knee: its knee and its second slope
LAW_POINTS = 30  # net strains the laws are compared at (evenly spaced from LAW_FIRST)
LAW_FIRST = 0.01  # first compared strain (the selection's NET_STRAINS start)


@dataclass(frozen=True)
class WaveScreen:
    """One wave of a net screened by its law: RMS log error up and across, and both."""

    wave: Wave
    error_up: float
    error_across: float

    @property
    def error(self) -> float:
        return math.sqrt((self.error_up**2 + self.error_across**2) / 2)


def law_strains(p: Prototype, t: ScaledTargets) -> np.ndarray:
    """Net strains the laws are compared at (see the module)."""
    knees = target_net_law(p, t)[0]
    top = LAW_REACH * knees[-1] if knees else float(NET_STRAINS[-1])
    return np.linspace(LAW_FIRST, top, LAW_POINTS)


def target_laws(p: Prototype, t: ScaledTargets, eps: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The target law up and across the barrier (N/m at `eps`, see the module)."""
    knees, slopes = target_net_law(p, t)
    up, across = t["mesh_y"], t["mesh_x"]
    law = get_pattern(p.net.pattern).strand_law(knees, slopes, up, across)
    return (blocked_force(p.net.pattern, law, up, across, eps),
            blocked_force(p.net.pattern, law, across, up, eps))


def printable_waves(n: NetDesign) -> list[Wave]:
    """Every wave of the grid (see the module) that `check_wave_mm` lets print on net `n`."""
    out = []
    s = n.strand
    for k in range(1, MAX_HALF_WAVES + 1):
        a = WAVE_STEP_MM
        while True:
            try:
                check_wave_mm(n.pattern, a, k, s.bead_width_mm, s.beads_across, n.mesh_x_mm,
                              n.mesh_y_mm)
            except GeometryError:
                break
            out.append(Wave(round(a, 6), k))
            a += WAVE_STEP_MM
    return out


def screen_waves(p: Prototype, t: ScaledTargets, n: NetDesign) -> list[WaveScreen]:
    """Every printable wave of net `n` screened by its law, best first."""
    eps = law_strains(p, t)
    target_up, target_across = target_laws(p, t, eps)
    stress, how = straight_law(n).scaled(1.0 / (n.strand.area_mm2 * MM * MM)), "scene's reading"
    up, across = n.mesh_y_mm * MM, n.mesh_x_mm * MM
    out = []
    for w in printable_waves(n):
        s = CurvedStrands(w.amplitude_mm, w.half_waves, n.strand.bead_width_mm,
                          n.strand.beads_across, n.strand.thickness_mm, stress, how)
        law = strand_law(n.pattern, s, up, across)
        out.append(WaveScreen(
            w, _rms_log(blocked_force(n.pattern, law, up, across, eps), target_up),
            _rms_log(blocked_force(n.pattern, law, across, up, eps), target_across)))
    return sorted(out, key=lambda r: r.error)


def straight_screen(p: Prototype, t: ScaledTargets, n: NetDesign) -> tuple[float, float]:
    """(error up, across) of net `n` with straight strands, scored as the waves are."""
    eps = law_strains(p, t)
    target_up, target_across = target_laws(p, t, eps)
    law = straight_law(n)
    up, across = n.mesh_y_mm * MM, n.mesh_x_mm * MM
    return (_rms_log(blocked_force(n.pattern, law, up, across, eps), target_up),
            _rms_log(blocked_force(n.pattern, law, across, up, eps), target_across))


def straight_law(n: NetDesign) -> Law:
    """The straight strands' law of net `n` as the verification's scene gives them (the
    material's reading of its panel law, `net_membrane_law`, up the barrier, turned into its
    pattern's strand law, as `scene.scenes.model_net_law`)."""
    up, across = n.mesh_y_mm * MM, n.mesh_x_mm * MM
    knees, slopes, _ = net_membrane_law(load_material(n.material), n.strand, up, across,
                                        n.pattern)
    return get_pattern(n.pattern).strand_law(knees, slopes, up, across)


def _rms_log(model: np.ndarray, target: np.ndarray) -> float:
    return float(np.sqrt(np.mean(np.log(model / target) ** 2)))


@dataclass(frozen=True)
class WaveChoice:
    """The wave stage's outcome: the screened waves (best first), the verified ones' deformation
    mismatch by wave, the straight net's, the kept wave (None: none beat the straight net)
    and the straight net's law errors (up, across)."""

    screened: tuple[WaveScreen, ...]
    verified: dict[Wave, float]
    straight_mismatch: float
    kept: Wave | None
    straight_errors: tuple[float, float]

    def sentence(self) -> str:
        su, sa = self.straight_errors
        if not self.screened:
            return "waved strands: no printable wave on the chosen net's mesh"
        best = self.screened[0]
        tried = ", ".join(f"{w.amplitude_mm:g} mm x {w.half_waves}: {m:.3f}"
                          for w, m in self.verified.items())
        head = (f"waved strands: {len(self.screened)} printable waves screened by the net law "
                f"(RMS log error up/across: straight {su:.2f}/{sa:.2f}, best wave "
                f"{best.wave.amplitude_mm:g} mm x {best.wave.half_waves} half-wave(s) "
                f"{best.error_up:.2f}/{best.error_across:.2f}); solver mismatch {tried} against "
                f"{self.straight_mismatch:.3f} straight")
        if self.kept is None:
            return f"{head}: the straight strands are kept"
        return (f"{head}: printed with the {self.kept.amplitude_mm:g} mm x "
                f"{self.kept.half_waves} wave")

    def to_record(self) -> dict:
        return {"screened": [{"amplitude_mm": s.wave.amplitude_mm,
                              "half_waves": s.wave.half_waves, "error_up": s.error_up,
                              "error_across": s.error_across} for s in self.screened],
                "verified": [{"amplitude_mm": w.amplitude_mm, "half_waves": w.half_waves,
                              "mismatch": m} for w, m in self.verified.items()],
                "straight": {"mismatch": self.straight_mismatch,
                             "error_up": self.straight_errors[0],
                             "error_across": self.straight_errors[1]},
                "kept": None if self.kept is None else {"amplitude_mm": self.kept.amplitude_mm,
                                                        "half_waves": self.kept.half_waves}}


def with_wave(d: Design, w: Wave | None) -> Design:
    """Design `d` with its net's strands waved by `w` (None: straight)."""
    return dataclasses.replace(d, net=dataclasses.replace(d.net, wave=w))


def wave_stage(p: Prototype, t: ScaledTargets, d: Design, straight_mismatch: float,
               verify: Callable[[list[Design]], list[float]]) -> WaveChoice:
    """Screen the waves of design `d`'s net, verify the WAVES_VERIFIED best with `verify`
    (designs -> deformation mismatches) and keep the best when lower than `straight_mismatch`
    (the straight net's)."""
    screened = screen_waves(p, t, d.net)
    picks = [s.wave for s in screened[:WAVES_VERIFIED]]
    found = dict(zip(picks, verify([with_wave(d, w) for w in picks]), strict=True))
    best = min(found, key=lambda w: found[w], default=None)
    kept = best if best is not None and found[best] < straight_mismatch else None
    return WaveChoice(tuple(screened), found, straight_mismatch, kept,
                      straight_screen(p, t, d.net))
