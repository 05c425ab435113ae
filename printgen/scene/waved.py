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
from functools import lru_cache

import numpy as np

from printgen.barrier.patterns.curved import CurvedStrands, chord, curve_strains
from printgen.scaling.record import Design, check_net_wave
from printgen.scaling.section import area_m2
from printgen.scene.scenes import BarrierScene
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


def waved_curve(straight: Law, d: Design) -> StrandCurve:
    """The solved curve of design `d`'s waved strands whose material law is `straight` (N per
    unit strain of the design's straight strands) over their area (see the module)."""
    n, w = d.net, d.net.wave
    if w is None:
        raise ValueError("waved_curve needs a design with a wave")
    if w.amplitude_mm > 0:  # zero: the straight limit, through the same model
        check_net_wave(n, "design")
    s = CurvedStrands(w.amplitude_mm, w.half_waves, n.strand.bead_width_mm,
                      n.strand.beads_across, n.strand.thickness_mm,
                      straight.scaled(1.0 / area_m2(n.strand)))
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
