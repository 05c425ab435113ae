"""The waved-strand coupon of `printgen testpieces` for a design whose net has a wave: its
printable files (`printgen.parts.geometry.wavecoupon`: STL, 3MF, PrusaSlicer .ini, direct
G-code read back), its sidecar for `printgen calibrate` (kind "waved", with the wave, the
section and the material law the prediction assumed, so that calibrate solves the same beam
model), and its predicted force-extension curve from the beam model
(`printgen.scene.waved.waved_curve`: the design's own strands, with the straight strands'
law the verification gives them) beside the straight strand's at the same strain.

What the lab prints first, and why: the straight coupon of the same material and section
calibrates the material law (it has no geometry to get wrong); the waved coupon then checks
the beam model's knee and slopes against that law (`printgen calibrate` of its export fits the
one parameter the beam model leaves to the material, the law's scale, and compares the shape).
"""

from __future__ import annotations

import csv
import io
from pathlib import Path
from typing import Any

import numpy as np

from printgen.inputs.materials import load_material
from printgen.inputs.printers import load_print_style
from printgen.parts.geometry.wavecoupon import WavedCoupon, waved_coupon_for
from printgen.run.steps import _write_part
from printgen.run.testpieces import _ini_and_gcode
from printgen.scaling.record import Design
from printgen.scaling.testpieces import COUPON_COUNT
from printgen.solver import Law
from printgen.solver.strand_curve import StrandCurve
from printgen.units import MM

NAME = "wave-coupon"
EXPECTED = f"{NAME}-expected.csv"
FIRST = ("Print first: the straight coupon (coupon.*), then the waved coupon "
         f"({NAME}.*). The straight strip has no wave: its test measures the material law "
         "alone (calibrate it as for a straight net). The waved coupon's curve is that law "
         "bent through the wave: where its knee falls and the ratio of its two slopes are set "
         "by the wave's geometry, not by the material's stiffness, so its test checks the "
         f"beam model (against {EXPECTED}); the scale of its curve measures the material "
         "once more, to agree with the straight coupon's.")

CALIBRATE = ("3. calibrate: printgen calibrate EXPORTS --material {mat}-lab --inherits {mat} "
             "--specimen coupon.specimen.toml --save (the straight coupons: the material); "
             f"then printgen calibrate EXPORTS --material {{mat}}-lab --specimen {NAME}.specimen"
             ".toml --plot DIR --save (the waved coupons: the beam model's knee and slopes "
             "checked, the law's scale measured again and written as the law the verification "
             "reads); compare the panel's curve with panel-expected.csv (the diamond's free "
             "panel is a mechanism in the model: its curve lies between the free and blocked "
             "columns)")


def wave_prediction(d: Design) -> tuple[StrandCurve, Law, str]:
    """(the beam model's curve of design `d`'s waved strands, the straight strands' law it
    takes as their material law (N per unit strain), where that law comes from)."""
    from printgen.scene.scenes import model_net_law
    from printgen.scene.waved import waved_curve

    straight, how = model_net_law(load_material(d.net.material), d.net, None)
    return waved_curve(straight, d), straight, how


def wave_coupon_files(stage: Path, d: Design, printer) -> dict[str, Any]:
    """Write the waved coupon's files into `stage`; its record."""
    c = waved_coupon_for(d)
    curve, straight, how = wave_prediction(d)
    rec = _printables(stage, c, d, printer)
    rec["geometry"] = c.to_record()
    rec["expected_curve"] = _expected(stage, c, curve, straight)
    rec["material_law"] = {"source": how, **_law_record(curve)}
    rec["print_first"] = FIRST
    rec["sidecar"] = _sidecar(stage, c, curve, how)
    rec["files"].append(f"{NAME}.specimen.toml")
    return rec


def _printables(stage: Path, c: WavedCoupon, d: Design, printer) -> dict[str, Any]:
    """STL, 3MF (with the .ini), .ini and direct G-code of the coupon; their record (the
    net's material and print style: the coupon's)."""
    from printgen.parts.gcode.couponpath import coupon_toolpath
    from printgen.parts.geometry.wavecoupon import analytic_coupon_volume, coupon_solid
    from printgen.parts.slicer.coupon import coupon_ini_text

    mat, style = load_material(c.material), load_print_style(c.print_style)
    ini = coupon_ini_text(c, d.net, printer, style, mat)
    rec = _write_part(stage, NAME, "net", d.net, coupon_solid(c), printer, None,
                      analytic_coupon_volume(c), ini).to_record()
    tp = coupon_toolpath(c, printer, style, mat)
    rec.update(_ini_and_gcode(stage, NAME, "net", d.net, printer, tp, rec["volume_mm3"], ini))
    rec["files"] += [f"{NAME}.prusa.ini", f"{NAME}.gcode"]
    return rec


def _law_record(curve: StrandCurve) -> dict[str, Any]:
    s = curve.strand.stress
    return {"stress_knees": list(s.knees), "stress_slopes_mpa": [v / 1e6 for v in s.slopes]}


def _expected(stage: Path, c: WavedCoupon, curve: StrandCurve, straight: Law
              ) -> dict[str, Any]:
    """wave-coupon-expected.csv: the coupon's force (all strands) against the chord strain and
    the tabs' separation, one strand's force and tangent, and the straight strand's force at
    the same strain (the straight coupon's: the material law alone)."""
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(["chord_strain", "extension_mm", "force_n", "strand_force_n",
                "strand_tangent_n", "straight_strand_force_n"])
    flat = straight.force_and_tangent(curve.strains)[0]
    for e, f, k, fs in zip(curve.strains, curve.forces, curve.tangents, flat, strict=True):
        w.writerow([f"{e:.6g}", f"{e * c.chord_mm:.6g}", f"{c.strands * f:.6g}", f"{f:.6g}",
                    f"{k:.6g}", f"{fs:.6g}"])
    (stage / EXPECTED).write_text(buf.getvalue())
    n = c.strands
    return {"file": EXPECTED, "points": len(curve.strains),
            "max_strain": float(curve.strains[-1]),
            "excess_length": curve.strand.excess(), "knee_strain": curve.knee,
            "initial_stiffness_n_per_mm": n * curve.initial_slope / c.chord_mm,
            "straightened_stiffness_n_per_mm": n * curve.straight_slope / c.chord_mm,
            "straight_stiffness_n_per_mm": n * float(straight.slopes[0]) / c.chord_mm,
            "force_at_knee_n": float(n * np.interp(curve.knee, curve.strains, curve.forces)),
            "model": ("corotational beam model of one strand, both ends clamped in rotation and "
                      "across the chord by the gripped tabs (printgen.solver.strand_curve), "
                      f"times {n} strands side by side; chord strain = tab separation change / "
                      f"{c.chord_mm:.4g} mm")}


def _sidecar(stage: Path, c: WavedCoupon, curve: StrandCurve, how: str) -> dict[str, Any]:
    """wave-coupon.specimen.toml: kind "waved", the gauge (the chord), the strands' total
    section, and the [wave] table of the beam model's inputs."""
    sec = c.section
    keys = {"kind": "waved", "width_mm": c.strands * sec.width_mm,
            "thickness_mm": sec.thickness_mm, "gauge_length_mm": c.chord_mm,
            "grip_distance_mm": c.chord_mm}
    wave = {**_beam_inputs(curve, how, c.material), "strands": c.strands}
    _write_sidecar(stage, NAME, keys, wave, "strain = tab separation change / the chord (the "
                   "tabs taken as rigid); width: the strands' in-plane widths summed")
    return {**keys, "wave": wave}


def wave_panel_sidecar(stage: Path, d: Design, dp, piece,
                       note: str = "(panel-expected.csv's free column)") -> dict[str, Any]:
    """panel.specimen.toml of a waved design's test panel `piece`: kind "waved", its clamps,
    and the [wave] table of the beam model's inputs with the simulated free test `dp` (what
    `printgen calibrate` fits the material law's scale to); `note` says which column of
    panel-expected.csv that test is."""
    curve, _, how = wave_prediction(d)
    keys = {"kind": "waved", "width_mm": piece.width_mm, "gauge_length_mm": piece.length_mm,
            "grip_distance_mm": piece.length_mm}
    wave = {**_beam_inputs(curve, how, d.net.material), "test": "panel",
            "panel_strains": [float(e) for e in dp.curve.strains],
            "panel_n_per_m": [float(n) for n in dp.curve.force_per_width],
            "panel_hold_share": float(dp.curve.hold_share)}
    _write_sidecar(stage, "panel", keys, wave, "width: across the load at the clamp edges; "
                   f"length: clamp edge to clamp edge; panel_*: the simulated free test {note}")
    return {**keys, "wave": wave}


def _beam_inputs(curve: StrandCurve, how: str, material: str) -> dict[str, Any]:
    """The beam model's inputs (mm, MPa) of the design's strands and the material law the
    prediction assumed."""
    st = curve.strand
    return {"chord_mm": st.chord / MM, "amplitude_mm": st.amplitude / MM,
            "half_waves": st.half_waves, "strand_width_mm": st.width / MM,
            "thickness_mm": st.thickness / MM, "material": material, "law_source": how,
            **_law_record(curve)}


def _write_sidecar(stage: Path, name: str, keys: dict[str, Any], wave: dict[str, Any],
                   note: str, table: str = "wave",
                   what: str = "the beam model's inputs") -> None:
    """`<name>.specimen.toml`: the specimen `keys` and the `[table]` of the prediction's
    inputs `wave` (`what` they are)."""
    lines = [(f"# printgen testpieces: the {name}'s sidecar for printgen calibrate "
              f"(--specimen {name}.specimen.toml)"),
             f"# {note}; [{table}]: {what} and the material law the prediction "
             "assumed (stress knees, slopes in MPa)"]
    lines += [_toml_line(k, v) for k, v in keys.items()]
    lines += ["", f"[{table}]", *(_toml_line(k, v) for k, v in wave.items())]
    (stage / f"{name}.specimen.toml").write_text("\n".join(lines) + "\n")


def _toml_line(key: str, v: Any) -> str:
    if isinstance(v, str):
        return f"{key} = {_quoted(v)}"
    if isinstance(v, list):
        return f"{key} = [{', '.join(f'{x:.9g}' for x in v)}]"
    if isinstance(v, int):
        return f"{key} = {v}"
    return f"{key} = {v:.9g}"


def _quoted(s: str) -> str:
    return '"' + s.replace("\\", "\\\\").replace('"', '\\"') + '"'


def wave_readme(rec: dict[str, Any]) -> list[str]:
    """The README section of the waved coupon."""
    g, e = rec["geometry"], rec["expected_curve"]
    return [
        f"## Waved-strand coupon (print {COUPON_COUNT})",
        (f"{g['strands']} waved strands side by side (neighbours mirrored), each one chord "
         f"{g['chord_mm']:.4g} mm of the net's loaded strands with its wave ({g['amplitude_mm']:g} "
         f"mm amplitude, {g['half_waves']} half-wave(s), arc {g['arc_length_mm']:.4g} mm), "
         f"{g['strand_width_mm']:g} x {g['thickness_mm']:.4g} mm ({g['beads_across']} bead(s) "
         f"across, layers {g['layer_heights_mm']} mm, the net's print settings), between two "
         f"grip tabs {g['tab_mm']:g} x {g['width_mm']:.4g} mm. Grip each tab whole, its inner "
         "edge at the grip's edge: the tabs must not turn or slide across (the strands' ends "
         "are clamped, as at the net's junctions)."),
        (f"Predicted ({EXPECTED}, {e['model']}): excess length {e['excess_length']:.2%}, "
         f"initial stiffness {e['initial_stiffness_n_per_mm']:.3g} N/mm, knee at "
         f"{e['knee_strain']:.1%} chord strain ({e['force_at_knee_n']:.3g} N), straightened "
         f"{e['straightened_stiffness_n_per_mm']:.3g} N/mm (the straight strands alone: "
         f"{e['straight_stiffness_n_per_mm']:.3g} N/mm). Material law assumed: "
         f"{rec['material_law']['source']}. Test with a load cell that resolves 1 % of the "
         f"force at the knee ({e['force_at_knee_n'] / 100:.2g} N)."),
        rec["print_first"],
        (f"Calibrate: printgen calibrate EXPORTS --material MAT-lab --inherits MAT --specimen "
         f"{NAME}.specimen.toml --save fits the material law's scale through the beam model "
         "(the wave's geometry as designed assumed), compares knee and slopes with the "
         "prediction, and writes the scaled law into the profile the verification reads."),
        ""]
