"""The printed model's net with waved strands (`NetDesign.wave`): every strand's law is the
chord force-strain curve of one waved strand from the large-deflection beam model
(`printgen.solver.strand_curve`), in place of the straight strand's law.

The curve is solved for the design's own strands: the chord of a strand along the load
(`printgen.barrier.patterns.curved.chord`: the square's side, the diamond's half-diagonals'
hypotenuse; every strand of either layout has that chord), the wave's amplitude and
half-waves, the section's in-plane width (beads x bead width: it bends) and thickness. Its
material law is the straight strands' law the scene already gives these strands (the
material's measured panel law read as the scene's options say, or its modulus), divided by
the strand's area: the straight net and the waved one share one material, and a wave of zero
amplitude is the straight law again at every solved point. Both ends are clamped in rotation
and across the chord, as the printed junctions hold them.

On a coarser net (`SceneOptions.coarsen`) the curve stays the design's strands' (its knee is
the wave's, not a longer chord's); the strands are then made k times stiffer, as the straight
ones are (`printgen.scene.scenes.with_factors`).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from functools import lru_cache
from typing import Any

import numpy as np

from printgen.barrier.patterns.curved import CurvedStrands, blocked_force, chord, curve_strains
from printgen.inputs.laws import piecewise_linear
from printgen.inputs.materials import load_material
from printgen.inputs.prototype import Prototype
from printgen.scaling.record import Design, NetDesign, Wave, check_net_wave
from printgen.scaling.section import area_m2
from printgen.scaling.selection import NET_STRAINS, target_net_law
from printgen.scaling.similitude import ScaledTargets
from printgen.scene.scenes import BarrierScene, model_net_law
from printgen.solver import Law
from printgen.solver.strand_curve import Strand, StrandCurve, strand_curve
from printgen.units import MM

STRAIGHT_TOP = 0.3  # chord strain a straight strand (zero amplitude) is solved to, beyond the
# material law's knees (the curved pattern's TOP_STRAIN: beyond, its last slope goes on)


def solved_strains(strand: Strand) -> np.ndarray:
    """Chord strains the strand is solved at: the curved pattern's points for its excess length
    (`curve_strains`), or STRAIGHT_TOP for a straight strand, with the material law's knees
    added (each a solved point, so the curve keeps the law's kinks)."""
    excess = strand.excess()
    base = curve_strains(excess) if excess > 0 else np.array([STRAIGHT_TOP])
    knees = [k for k in strand.stress.knees if k < base[-1]]
    return np.union1d(base, knees)


@lru_cache(maxsize=32)
def _solved(strand: Strand, strains: tuple[float, ...]) -> StrandCurve:
    return strand_curve(strand, np.array(strains))


def waved_strands(n: NetDesign, straight: Law, amplitude_mm: float, half_waves: int,
                  source: str = "") -> CurvedStrands:
    """Net `n`'s strands with the wave `amplitude_mm`, `half_waves`, their material law
    `straight` (N per unit strain of `n`'s straight strands) over their area (see the
    module); `source` says where that law comes from."""
    return CurvedStrands(amplitude_mm, half_waves, n.strand.bead_width_mm,
                         n.strand.beads_across, n.strand.thickness_mm,
                         straight.scaled(1.0 / area_m2(n.strand)), source)


def waved_curve(straight: Law, d: Design) -> StrandCurve:
    """The solved curve of design `d`'s waved strands whose material law is `straight` (N per
    unit strain of the design's straight strands) over their area (see the module)."""
    n, w = d.net, d.net.wave
    if w is None:
        raise ValueError("waved_curve needs a design with a wave")
    if w.amplitude_mm > 0:  # zero: the straight limit, through the same model
        check_net_wave(n, "design")
    s = waved_strands(n, straight, w.amplitude_mm, w.half_waves)
    strand = s.strand(chord(n.pattern, n.mesh_y_mm, n.mesh_x_mm) * MM)
    return _solved(strand, tuple(float(e) for e in solved_strains(strand)))


def with_wave_law(s: BarrierScene, d: Design) -> BarrierScene:
    """Scene `s` of design `d` (its own meshes, not coarsened) with its net's strand law the
    waved strands' curve, an assumption row stating it; `s` itself when `d` has no wave."""
    if d.net.wave is None:
        return s
    curve = waved_curve(s.laws[0], d)
    laws = list(s.laws)
    laws[0] = curve.law()
    return dataclasses.replace(s, laws=laws, assumptions=(*s.assumptions, wave_row(curve)))


def wave_row(c: StrandCurve) -> tuple[str, str, str]:
    """The scene's assumption of the waved strands' law (what, value, source)."""
    st = c.strand
    shape = (f"initial slope {c.initial_slope / c.straight_slope:.1%} of the straightened one, "
             f"knee at {c.knee:.1%} chord strain" if st.amplitude > 0 else "a straight strand")
    return ("strand wave", (
        f"in-plane wave y = a sin(n pi x / L): a = {st.amplitude / MM:g} mm, n = "
        f"{st.half_waves}, L = {st.chord / MM:.3g} mm chord (excess length {st.excess():.2%}); "
        "strand law the chord force-strain curve of a corotational beam model of the strand, "
        f"{st.width / MM:g} mm in-plane width bending, both ends clamped in rotation and across "
        "the chord (rigid printed junctions), the straight strands' law above per unit area as "
        f"its material law (compression as tension); {shape}; piecewise linear through "
        f"{len(c.strains)} solved points"),
        "design wave; printgen beam model (printgen.solver.strand_curve)")


@dataclass(frozen=True)
class WaveLaws:
    """The net laws of a waved design along its mesh_y diagonal (up the barrier, as `select`
    compares them), in the blocked, infinite net at finite strain
    (`curved.blocked_force`): the target (the prototype's panel law scaled to the model,
    `selection.target_net_law`), the design's net with straight strands (the scene's straight
    strand law) and with its waved ones (the scene's curve), N/m at the net `strains`; and
    the curve's summary (initial and straightened chord slopes, N per unit strain; knee and
    excess length, strand strains)."""

    strains: np.ndarray
    target: np.ndarray
    straight: np.ndarray
    curved: np.ndarray
    wave: Wave
    initial_slope: float
    straight_slope: float
    knee: float
    excess: float

    def error_rms_log(self, law: np.ndarray) -> float:
        """RMS of log(law / target) over the strains (the design search's law error)."""
        return float(np.sqrt(np.mean(np.log(law / self.target) ** 2)))

    def to_record(self) -> dict[str, Any]:
        return {"direction": "mesh_y diagonal (up the barrier), blocked infinite net",
                "wave": dataclasses.asdict(self.wave), "net_strains": self.strains,
                "target_n_per_m": self.target, "straight_n_per_m": self.straight,
                "curved_n_per_m": self.curved,
                "error_rms_log": {"straight": self.error_rms_log(self.straight),
                                  "curved": self.error_rms_log(self.curved)},
                "strand_curve": {"initial_slope_n": self.initial_slope,
                                 "straightened_slope_n": self.straight_slope,
                                 "knee_strain": self.knee, "excess_length": self.excess}}


def wave_laws(p: Prototype, t: ScaledTargets, d: Design) -> WaveLaws:
    """The `WaveLaws` of design `d` (with a wave) at targets `t` of prototype `p`, over the
    strains the design search compares laws on (`selection.NET_STRAINS`)."""
    n, w = d.net, d.net.wave
    if w is None:
        raise ValueError("wave_laws needs a design with a wave")
    straight = model_net_law(load_material(n.material), n, None)[0]  # the nominal scene's
    curve = waved_curve(straight, d)
    along, across = n.mesh_y_mm * MM, n.mesh_x_mm * MM
    eps = NET_STRAINS
    knees, slopes = target_net_law(p, t)
    return WaveLaws(eps, piecewise_linear(eps, knees, slopes),
                    blocked_force(n.pattern, straight, along, across, eps),
                    blocked_force(n.pattern, curve.law(), along, across, eps), w,
                    curve.initial_slope, curve.straight_slope,
                    curve.knee if w.amplitude_mm > 0 else 0.0,  # straight from the start
                    curve.strand.excess())
