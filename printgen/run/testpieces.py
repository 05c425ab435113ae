"""`printgen testpieces DESIGN`: the pieces a lab prints and tests before the barrier, written
atomically into one output folder (staged, locked, with its manifest, as `make`'s).

For the design's net (`printgen.scaling.testpieces`): a tensile coupon of its strand section
and passes, and a net test panel of its mesh, each as STL, 3MF, PrusaSlicer .ini and direct
G-code (read back against the toolpath), the sidecar each test's exports need in
`printgen calibrate` (`<piece>.specimen.toml`, the keys of `printgen.calibrate.specimen`), and
the panel's expected force-strain curve from the virtual panel test
(`printgen.scene.panel`, free sides, as printed panels are tested); a square net's panel,
pulled along its strands, with its own curve and sidecar (`printgen.run.squarepieces`). The loop:
print pieces -> test -> calibrate -> verify -> print the barrier (LOOP).
"""

from __future__ import annotations

import csv
import io
from pathlib import Path
from typing import Any

from printgen.inputs.materials import load_material
from printgen.inputs.printers import load_print_style, load_printer
from printgen.inputs.profiles import search_dirs
from printgen.outputs import staged_dir
from printgen.report.jsonout import dumps
from printgen.run.provenance import provenance_record
from printgen.run.steps import _write_part
from printgen.scaling.design_file import load_design
from printgen.scaling.record import Design
from printgen.scaling.testpieces import (
    COUPON_COUNT,
    COUPON_RING_FACTOR,
    PanelPiece,
    coupon_for,
    coupon_gauge_mm,
    panel_for,
)
from printgen.units import MM

RECORD = "testpieces.json"
LOOP = (("1. print the coupons ({n} of coupon.gcode, or slice coupon.stl with coupon.prusa.ini) "
        "and the panel (panel.gcode, or panel.stl with panel.prusa.ini)"),
        ("2. test them: coupons on pins through the eyelets, the panel in clamps (see README.md); "
        "export each test's force and crosshead displacement (or extensometer strain)"),
        ("3. calibrate: printgen calibrate EXPORTS --material {mat}-lab --inherits {mat} "
        "--specimen coupon.specimen.toml --save (the panel: --kind panel --specimen "
        "panel.specimen.toml); compare the panel's curve with panel-expected.csv"),
        ("4. verify: set the net's material to {mat}-lab and run printgen make (its verification "
        "uses the measured modulus)"),
        "5. print the barrier from that run's G-code or STL + .ini")


def testpieces(design_path: str | Path, out: str | Path, *, orientation: str = "short",
               force: bool = False, command: list[str] | None = None) -> dict[str, Any]:
    """Write the test pieces of the design in `design_path` into `out`; their record."""
    d = load_design(design_path)
    printer = load_printer(d.printer)
    coupon = coupon_for(d)
    dp, blocked, piece = _panel(d, orientation)
    inputs = [design_path, *search_dirs()]
    meta: dict[str, Any] = {"design_file": Path(design_path).name,
                            **provenance_record(command, files={"design_file": design_path},
                                                design=d)}
    with staged_dir(out, force=force, meta=meta, inputs=inputs) as stage:
        rec: dict[str, Any] = {"design_file": Path(design_path).name, "material": d.net.material,
               "material_source": material_source(load_material(d.net.material)),
               "coupon": _coupon_files(stage, coupon, printer),
               "panel": _panel_files(stage, piece, printer),
               "loop": [s.format(n=COUPON_COUNT, mat=d.net.material) for s in LOOP]}
        rec["panel"]["geometry"] = piece.to_record()
        rec["coupon"]["geometry"] = _coupon_geometry(coupon)
        if d.net.wave is not None:
            from printgen.run.wavepieces import wave_coupon_files

            rec["wave_coupon"] = wave_coupon_files(stage, d, printer)
        if blocked is None:  # a square net's panel (`printgen.run.squarepieces`)
            _square_files(stage, d, dp, piece, rec)
        else:
            rec["panel"]["expected_curve"] = _expected(stage, dp, blocked)
        if d.net.wave is not None and blocked is not None:
            from printgen.run.wavepieces import CALIBRATE, wave_panel_sidecar

            rec["panel"]["strands"] = dp.strands
            rec["panel"]["sidecar"] = wave_panel_sidecar(stage, d, dp, piece)
            rec["loop"][2] = CALIBRATE.format(mat=d.net.material)
        (stage / "README.md").write_text(readme_text(rec, dp.test.describe()))
        (stage / RECORD).write_text(dumps(rec))
    return rec


def material_source(mat) -> str:
    """What the net's law rests on: 'measured panel law', 'measured' (a printed modulus) or
    'datasheet' (as the selection and the design search flag it)."""
    if mat.panel_law is not None:
        return "measured panel law"
    return mat.modulus()[1]


def _panel(d: Design, orientation: str):
    """The simulated free and blocked tests of the design's panel and the printed piece; a
    waved net's panel is tested with its strands' beam-model law (`scene.panel.curved_panel`),
    sized as that test. A square net's: its free test only (None for the blocked one: the
    strands across carry nothing, so it is the same), sized as `squarepieces` argues."""
    from printgen.scene.panel import curved_panel, design_panel, lattice_size

    w = d.net.wave
    if d.net.pattern == "square":
        from printgen.run.squarepieces import square_panel

        dp, blocked = square_panel(d, orientation), None
    elif w is None:
        dp = design_panel(d, orientation, "free")
        blocked = design_panel(d, orientation, "blocked")
    else:
        dp, blocked = (curved_panel(d, orientation, w.amplitude_mm, w.half_waves, mode)
                       for mode in ("free", "blocked"))
    length, width = lattice_size(dp.test)
    return dp, blocked, panel_for(d, orientation, length / MM, width / MM)


def _square_files(stage: Path, d: Design, dp, piece: PanelPiece, rec: dict[str, Any]) -> None:
    """The square panel's expected curve, sidecar and loop step (`run.squarepieces`), into
    `rec`."""
    from printgen.run.squarepieces import square_calibrate, square_expected, square_sidecar

    rec["panel"]["expected_curve"] = square_expected(stage, dp)
    rec["panel"]["strands"] = dp.strands
    rec["panel"]["sidecar"] = square_sidecar(stage, d, dp, piece)
    rec["loop"][2] = square_calibrate(d)


def _coupon_geometry(c) -> dict[str, Any]:
    return {"gauge_length_mm": coupon_gauge_mm(c), "pin_distance_mm": c.length_mm,
            "pin_hole_mm": c.eyelet_inner_mm, "eyelet_outer_mm": c.eyelet_outer_mm,
            "ring_width_each_side_mm": (c.eyelet_outer_mm - c.eyelet_inner_mm) / 2,
            "ring_factor": COUPON_RING_FACTOR, "width_mm": c.section.width_mm,
            "thickness_mm": c.section.thickness_mm, "beads_across": c.section.beads_across,
            "layer_heights_mm": list(c.section.layer_heights_mm), "count": COUPON_COUNT}


def _coupon_files(stage: Path, c, printer) -> dict[str, Any]:
    from printgen.parts.gcode import cable_toolpath
    from printgen.parts.geometry.solid import analytic_cable_volume, cable_solid

    comp = printer.hole_compensation_mm
    tp = cable_toolpath(c, printer, load_print_style(c.print_style), load_material(c.material))
    sidecar = {"kind": "cable", "width_mm": c.section.width_mm,
               "thickness_mm": c.section.thickness_mm,
               "gauge_length_mm": coupon_gauge_mm(c), "grip_distance_mm": coupon_gauge_mm(c)}
    return _piece_files(stage, "coupon", "cable", c, (cable_solid(c, comp),
                        analytic_cable_volume(c, comp)), tp, printer, sidecar,
                        "strain = crosshead displacement / the free strip between the rings "
                        "(the rings taken as rigid); with an extensometer on the strip, its "
                        "strain is used instead")


def _panel_files(stage: Path, piece: PanelPiece, printer) -> dict[str, Any]:
    from printgen.parts.gcode import net_toolpath
    from printgen.parts.geometry.solid import analytic_net_volume, net_solid

    n = piece.net
    tp = net_toolpath(n, printer, load_print_style(n.print_style), load_material(n.material))
    sidecar = {"kind": "panel", "width_mm": piece.width_mm, "gauge_length_mm": piece.length_mm,
               "grip_distance_mm": piece.length_mm}
    return _piece_files(stage, "panel", "net", n, (net_solid(n), analytic_net_volume(n)), tp,
                        printer, sidecar, "width: across the load at the clamp edges; length: "
                        "clamp edge to clamp edge (the force per width over the length is the "
                        "panel law)")


def _piece_files(stage: Path, name: str, kind: str, part, solid: tuple, tp, printer,
                 sidecar: dict[str, Any], note: str) -> dict[str, Any]:
    """One piece's files: mesh (`solid`: the mesh and its analytic volume), slicer profile,
    direct G-code and the specimen sidecar; their record."""
    rec = _write_part(stage, name, kind, part, solid[0], printer, None, solid[1]).to_record()
    rec.update(_ini_and_gcode(stage, name, kind, part, printer, tp, rec["volume_mm3"]))
    rec["files"] += [_sidecar(stage, name, sidecar, note)]
    rec["sidecar"] = sidecar
    return rec


def _ini_and_gcode(stage: Path, name: str, kind: str, part, printer, tp, stl_mm3: float,
                   ini: str | None = None) -> dict[str, Any]:
    """The PrusaSlicer .ini (`ini`, else the part's own) and the direct G-code of one piece
    (read back); their record."""
    from printgen.parts.gcode.estimate import print_estimate
    from printgen.parts.gcode.readback import read_gcode_text
    from printgen.parts.gcode.writer import gcode_text
    from printgen.parts.slicer.prusa import prusa_ini_text

    mat, style = load_material(part.material), load_print_style(part.print_style)
    if ini is None:
        ini = prusa_ini_text(kind, part, printer, style, mat)
    (stage / f"{name}.prusa.ini").write_text(ini)
    est = print_estimate(tp, printer, mat)
    text = gcode_text(tp, printer, mat, title=f"test piece {name}", estimate=est)
    (stage / f"{name}.gcode").write_text(text)
    back = read_gcode_text(text, filament_diameter_mm=printer.filament_diameter_mm)
    return {"slicer_profile": f"{name}.prusa.ini", "gcode": f"{name}.gcode",
            "gcode_volume_mm3": tp.volume_mm3, "readback_vs_stl": back.volume_mm3 / stl_mm3 - 1,
            "layers": len(back.layer_z_mm), "print": est.to_record()}


def _sidecar(stage: Path, name: str, keys: dict[str, Any], note: str) -> str:
    """`<name>.specimen.toml`: the specimen keys `printgen calibrate` reads (mm)."""
    lines = [(f"# printgen testpieces: the {name}'s dimensions for printgen calibrate "
             f"(--specimen {name}.specimen.toml, or copy it as specimen.toml beside the exports)"),
             f"# {note}"]
    lines += [f'{k} = "{v}"' if isinstance(v, str) else f"{k} = {v:.6g}" for k, v in keys.items()]
    path = stage / f"{name}.specimen.toml"
    path.write_text("\n".join(lines) + "\n")
    return path.name


def _expected(stage: Path, dp, blocked) -> dict[str, Any]:
    """panel-expected.csv: the virtual panel test's force per width and clamp force against
    strain, free sides (as the printed panel is tested) and sides blocked (every strand
    stretched alike: the barrier's membrane law), with the profile's measured panel law."""
    from printgen.scene.panel import lattice_size

    width = lattice_size(dp.test)[1]
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(["strain", "free_n_per_m", "free_clamp_force_n", "blocked_n_per_m",
                "blocked_clamp_force_n", "profile_panel_law_n_per_m"])
    for i, e in enumerate(dp.curve.strains):
        n, nb = dp.curve.force_per_width[i], blocked.curve.force_per_width[i]
        m = "" if dp.measured is None else f"{dp.measured[i]:.6g}"
        w.writerow([f"{e:.6g}", f"{n:.6g}", f"{n * width:.6g}", f"{nb:.6g}",
                    f"{nb * width:.6g}", m])
    (stage / "panel-expected.csv").write_text(buf.getvalue())
    return {"file": "panel-expected.csv", "test": dp.test.describe(),
            "free_hold_share": dp.curve.hold_share, "points": len(dp.curve.strains),
            "max_strain": float(dp.curve.strains[-1]),
            "blocked_n_per_m_at_max": float(blocked.curve.force_per_width[-1]),
            "free_n_per_m_at_max": float(dp.curve.force_per_width[-1])}


def readme_text(rec: dict[str, Any], panel_test: str) -> str:
    """README.md of the folder: what each piece is, how to test it, the loop."""
    c = rec["coupon"]["geometry"]
    lines = [f"# Test pieces for {rec['design_file']} ({rec['material']})", ""]
    if rec["material_source"] == "datasheet":
        lines += [(f"The net's material {rec['material']} rests on datasheet values: print the "
                  "test pieces below and calibrate before printing the barrier."), ""]
    lines += [
        f"## Tensile coupon (print {c['count']})",
        (f"Strip {c['width_mm']:.4g} x {c['thickness_mm']:.4g} mm ({c['beads_across']} bead(s) "
        f"across, layers {c['layer_heights_mm']} mm: the net strand's passes), gauge length "
        f"{c['gauge_length_mm']:.4g} mm (the free strip between the eyelet rings). Grip tabs: "
        f"eyelet rings, pin hole {c['pin_hole_mm']:.4g} mm, outer {c['eyelet_outer_mm']:.4g} mm "
        f"({c['ring_width_each_side_mm']:.4g} mm each side = {c['ring_factor']} strand widths), "
        f"pin centres {c['pin_distance_mm']:.4g} mm apart: load it on two pins."), "",
        *_panel_section(rec, panel_test), *_wave_section(rec), "## The loop", *rec["loop"], ""]
    return "\n".join(lines)


def _panel_section(rec: dict[str, Any], panel_test: str) -> list[str]:
    """The README's test-panel section: a square net's (`run.squarepieces`), else the
    diamond's."""
    p = rec["panel"]["geometry"]
    if p["orientation"] == "strands":
        from printgen.run.squarepieces import square_readme

        return square_readme(rec, panel_test)
    return [
        "## Net test panel (print 1 or more)",
        (f"Loaded along the {p['orientation']} diagonal (mesh {p['mesh_along_load_mm']:.4g} mm "
        f"along x {p['mesh_across_load_mm']:.4g} mm across). Printed {p['printed_mm'][0]:.4g} x "
        f"{p['printed_mm'][1]:.4g} mm with a border frame. Clamps {p['width_mm']:.4g} mm wide, "
        f"their edges on the node rows {p['length_mm']:.4g} mm apart, each holding "
        f"{p['clamp_depth_mm']:.4g} mm of net and the frame bar beyond. Cut the two side bars of "
        "the frame after clamping, before the test (free sides, as simulated)."),
        (f"Expected curve (panel-expected.csv): the virtual panel test, {panel_test}; "
        "columns free (sides free, as tested) and blocked (every strand stretched alike, the "
        "barrier's membrane law: the upper bound)."), *_strands_note(rec),
        *_mechanism_note(rec), ""]


def _strands_note(rec: dict[str, Any]) -> list[str]:
    """How a waved net's panel test takes its strands (the beam model's curve)."""
    strands = rec["panel"].get("strands")
    return [f"The panel's strands in the simulated test: {strands}."] if strands else []


def _wave_section(rec: dict[str, Any]) -> list[str]:
    """The waved coupon's section (a design with a net wave), with what to print first."""
    if "wave_coupon" not in rec:
        return []
    from printgen.run.wavepieces import wave_readme

    return ["", *wave_readme(rec["wave_coupon"])]


def _mechanism_note(rec: dict[str, Any]) -> list[str]:
    """The warning when the free pin-jointed panel is a mechanism (its curve is the hold)."""
    e = rec["panel"]["expected_curve"]
    if e["free_hold_share"] <= 0.5:
        return []
    return [(f"The pin-jointed free panel is a mechanism up to its lock-up strain: "
            f"the solver's hold carries a share {e['free_hold_share']:.2g} of its simulated "
            "clamp force (printgen panel's measure; over 0.5: a mechanism), "
            "not the strands, so the free column is a lower bound near zero; a printed panel's "
            "low-strain force comes from its rigid junctions. Read the measured curve between "
            f"the two columns (at {e['max_strain']:.0%}: free {e['free_n_per_m_at_max']:.3g}, "
            f"blocked {e['blocked_n_per_m_at_max']:.3g} N/m).")]
