"""The square net's test panel of `printgen testpieces` (straight or waved strands): its
simulated test, its expected curve and the sidecar `printgen calibrate` fits its exports with.

The test: the printed panel clamped on two opposite edges (node rows) and pulled along one
strand family, its sides free. The strands along the load carry it, each strained as the panel
(they lie along the load from the start: no mechanism); the strands across carry nothing (their
ends move alike), so holding the sides would change nothing. The panel measures the strands laid
up the printed panel (along the printer's y); the strands across are the same section and passes
laid along x, the two families taking turns at being laid first in a layer
(`printgen.parts.gcode.netpath`): between the junctions they are alike, and only the junctions
differ (with an odd number of passes one family is laid first once more). So one panel serves
both directions of the net; that the printer's x and y lay the same bead is assumed, not
checked by this test. Size and clamps (`printgen.scene.panel.square_panel_size`): at least 8
loaded strands and 4 meshes between the clamps, so that the outer strands and the rows in the
jaws are small parts of the whole. The frame's two side bars are cut after clamping: they are
the printed border, not strands, so the prediction counts the loaded strands left between them
(`loaded_strands`: nx - 1 of the simulated panel's nx + 1).

The prediction is the solver's virtual panel test (`printgen.scene.panel`) with the strand law
the verification gives the design (`model_net_law`; a waved net's: its beam-model curve,
`curved_panel`). `printgen calibrate` of the panel's exports with its sidecar fits the scale of
that law (`printgen.calibrate.waved`: the panel's force is linear in it) and writes the scaled
law into the profile the verification reads.
"""

from __future__ import annotations

import csv
import dataclasses
import io
import math
from pathlib import Path
from typing import Any

from printgen.inputs.materials import load_material
from printgen.run.wavepieces import _write_sidecar, wave_panel_sidecar
from printgen.scaling.record import Design
from printgen.scaling.section import area_m2
from printgen.scene.panel import (
    DesignPanel,
    PanelTest,
    curved_panel,
    lattice_size,
    law_strains,
    loaded_strands,
    simulate,
    square_panel_size,
)
from printgen.units import MM

EXPECTED = "panel-expected.csv"
TESTED = ("(panel-expected.csv's tested column: the loaded strands left once the side bars "
          "are cut)")
CALIBRATE = ("3. calibrate: printgen calibrate EXPORTS --material {mat}-lab --inherits {mat} "
             "--specimen coupon.specimen.toml --save (the straight coupons: the material){wave}; "
             "then printgen calibrate PANEL-EXPORTS --material {mat}-lab --specimen "
             "panel.specimen.toml --plot DIR --save (the square panel: the scale of the law its "
             "simulated test assumed, fitted to its curve and written last, as the law the "
             "net's strands carry in the net, which the verification reads); compare the "
             "panel's curve with panel-expected.csv (its tested column)")
WAVE_STEP = (", then printgen calibrate EXPORTS --material {mat}-lab --specimen "
             "wave-coupon.specimen.toml --save (the waved coupons: the beam model's knee and "
             "slopes checked)")


def square_panel(d: Design, orientation: str) -> DesignPanel:
    """The simulated free test of design `d`'s square test panel (its size:
    `square_panel_size`): straight strands with the verification's strand law, waved ones
    with their beam-model curve."""
    from printgen.scene.scenes import model_net_law

    n = d.net
    mesh = n.mesh_x_mm * MM
    size = square_panel_size(mesh)
    w = n.wave
    if w is not None:
        return curved_panel(d, orientation, w.amplitude_mm, w.half_waves, "free", size=size)
    mat = load_material(n.material)
    law, how = model_net_law(mat, n, None)
    t = PanelTest(mesh, mesh, size[0], size[1], "free", n.pattern)
    eps, top = law_strains(law.knees), failure_strain(law, area_m2(n.strand), mat)
    if top < eps[-1]:  # the test ends where the strands break: no prediction beyond
        eps = eps * top / eps[-1]
        how += (f"; up to {top:.2%}, where the strands reach {mat.name}'s failure stress "
                f"({mat.failure_stress()[0] / 1e6:.3g} MPa, {mat.failure_stress()[1]})")
    return DesignPanel("strands", t, law, simulate(law, t, eps), None,
                       f"straight strands, {how}")


def failure_strain(law, area: float, mat) -> float:
    """The strain (inf if none) at which a strand of `area` m^2 following `law` (N per unit
    strain) reaches material `mat`'s failure stress: its slopes are positive, so the force
    rises through the law's knees to it once."""
    target = mat.failure_stress()[0] * area
    lo, force = 0.0, 0.0
    for knee, slope in zip((*law.knees, math.inf), law.slopes, strict=True):
        if force + slope * (knee - lo) >= target:
            return lo + (target - force) / slope
        force, lo = force + slope * (knee - lo), knee
    return math.inf


def as_tested(dp: DesignPanel) -> DesignPanel:
    """`dp` as the printed panel is tested: its force times the loaded strands left once the
    side bars are cut over the simulated ones (every loaded strand carries the same force)."""
    k, m = loaded_strands(dp.test)
    curve = dataclasses.replace(dp.curve, force_per_width=dp.curve.force_per_width * k / m)
    return dataclasses.replace(dp, curve=curve)


def square_expected(stage: Path, dp: DesignPanel) -> dict[str, Any]:
    """panel-expected.csv of the square panel: against strain, the tested panel's force per
    clamp width and clamp force, the simulated panel's force per width and one loaded
    strand's force; its record."""
    k, m = loaded_strands(dp.test)
    width = lattice_size(dp.test)[1]
    strand = dp.curve.force_per_width * width / m
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(["strain", "tested_n_per_m", "tested_clamp_force_n", "simulated_n_per_m",
                "strand_force_n"])
    for e, n, f in zip(dp.curve.strains, dp.curve.force_per_width, strand, strict=True):
        w.writerow([f"{e:.6g}", f"{k * f / width:.6g}", f"{k * f:.6g}", f"{n:.6g}", f"{f:.6g}"])
    (stage / EXPECTED).write_text(buf.getvalue())
    return {"file": EXPECTED, "test": dp.test.describe(),
            "free_hold_share": dp.curve.hold_share, "points": len(dp.curve.strains),
            "max_strain": float(dp.curve.strains[-1]), "loaded_strands": k,
            "simulated_strands": m, "tested_clamp_force_n_at_max": float(k * strand[-1]),
            "tested_n_per_m_at_max": float(k * strand[-1] / width),
            "strand_force_n_at_max": float(strand[-1]),
            "model": (f"{m} strands along the load in the pin-jointed simulated panel (its edge "
                      f"columns are strands), {k} once the printed frame's side bars are cut; "
                      "sides free (blocked gives the same: the strands across carry nothing)")}


def square_sidecar(stage: Path, d: Design, dp: DesignPanel, piece) -> dict[str, Any]:
    """panel.specimen.toml of the square test panel `piece`: a waved net's as the waved
    panels' (kind "waved", its [wave] table); a straight net's kind "panel" with the
    [prediction] table (its simulated test as tested, the strand law it assumed); its
    record."""
    t = as_tested(dp)
    if d.net.wave is not None:
        return wave_panel_sidecar(stage, d, t, piece, TESTED)
    n = d.net
    stress = t.law.scaled(1.0 / area_m2(n.strand))
    keys = {"kind": "panel", "width_mm": piece.width_mm, "gauge_length_mm": piece.length_mm,
            "grip_distance_mm": piece.length_mm}
    pred = {"material": n.material, "law_source": t.strands,
            "stress_knees": list(stress.knees),
            "stress_slopes_mpa": [v / 1e6 for v in stress.slopes],
            "strands": loaded_strands(t.test)[0], "strand_width_mm": n.strand.width_mm,
            "thickness_mm": n.strand.thickness_mm, "mesh_mm": n.mesh_x_mm,
            "panel_strains": [float(e) for e in t.curve.strains],
            "panel_n_per_m": [float(v) for v in t.curve.force_per_width],
            "panel_hold_share": float(t.curve.hold_share)}
    _write_sidecar(stage, "panel", keys, pred, "width: across the load at the clamp edges; "
                   "length: clamp edge to clamp edge; panel_*: the simulated free test "
                   f"{TESTED}", table="prediction", what="the panel's simulated test")
    return {**keys, "prediction": pred}


def square_calibrate(d: Design) -> str:
    """The loop's calibrate step for a square design's pieces."""
    wave = WAVE_STEP.format(mat=d.net.material) if d.net.wave is not None else ""
    return CALIBRATE.format(mat=d.net.material, wave=wave)


def square_readme(rec: dict[str, Any], panel_test: str) -> list[str]:
    """The README paragraphs of the square test panel."""
    p, e = rec["panel"]["geometry"], rec["panel"]["expected_curve"]
    return [
        "## Net test panel (print 1 or more)",
        (f"Square mesh {p['mesh_along_load_mm']:.4g} mm, pulled along the strands that run up "
         "the printed panel: they carry the load, each strained as the panel; the strands "
         "across carry nothing. One panel serves both directions of the net: its strands "
         "across are the same section and passes, laid along the printer's x, the two "
         "families taking turns at being laid first in a layer, so they differ only at the "
         "junctions (that the printer's x and y lay the same bead is assumed, not checked by "
         f"this test). Printed {p['printed_mm'][0]:.4g} x "
         f"{p['printed_mm'][1]:.4g} mm with a border frame. Clamps {p['width_mm']:.4g} mm "
         f"wide, their edges on the node rows {p['length_mm']:.4g} mm apart, each holding "
         f"{p['clamp_depth_mm']:.4g} mm of net and the frame bar beyond. Cut the two side bars "
         f"of the frame after clamping, before the test: {e['loaded_strands']} strands along "
         "the load remain (sized for at least 8, so that an outer pair 20 % off moves the "
         "force 5 %, and at least 4 meshes between the clamps, so that the rows in the jaws "
         "are a small part of the gauge)."),
        (f"Expected curve (panel-expected.csv): the virtual panel test, {panel_test}; "
         f"{e['model']}. Compare the measured force per clamp width with its tested column "
         f"(at {e['max_strain']:.0%}: {e['tested_n_per_m_at_max']:.4g} N/m, clamp force "
         f"{e['tested_clamp_force_n_at_max']:.4g} N)."),
        f"The panel's strands in the simulated test: {rec['panel']['strands']}.", ""]
