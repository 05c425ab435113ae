"""Benchmark: meshes of the 1:40 reference parts (net 330 x 100 mm, four cables).

    python -m benchmarks.bench_parts --out DIR [--repeat N]

Times the net mesh (without and with its loops and corner eyelets) and the cable meshes (outline +
extrusion, best of N), the bed layout and the STL/3MF encoding; compares the volumes with
the analytic ones. Goal: the net mesh in under 5 s. Writes DIR/bench_parts.json.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

from benchmarks.timing import best_of, goal_main

GOAL_S = 5.0  # the 330 mm net's mesh in under five seconds


def _part_record(name, build, analytic, printer, repeat: int) -> tuple[dict, object]:
    from printgen.parts.export import place_mesh, stl_bytes, threemf_bytes

    t_mesh, mesh = best_of(build, repeat)
    t_place, (placed, angle) = best_of(lambda: place_mesh(mesh, printer, name), repeat)
    t_stl, stl = best_of(lambda: stl_bytes(placed, name), repeat)
    t_3mf, tmf = best_of(lambda: threemf_bytes([(name, placed)]), repeat)
    lo, hi = mesh.bounds
    return {"mesh_s": round(t_mesh, 4), "place_s": round(t_place, 4),
            "stl_s": round(t_stl, 4), "threemf_s": round(t_3mf, 4),
            "triangles": len(mesh.faces), "vertices": len(mesh.vertices),
            "size_mm": [round(float(v), 4) for v in hi - lo],
            "volume_mm3": round(float(mesh.volume), 4), "analytic_mm3": round(analytic, 4),
            "volume_error": float(mesh.volume) / analytic - 1,
            "watertight": bool(mesh.is_watertight),
            "bodies": len(mesh.split(only_watertight=False)),
            "bed_angle_deg": angle, "stl_bytes": len(stl), "threemf_bytes": len(tmf)}, mesh


def run(out_dir: Path, repeat: int = 3) -> dict:
    from printgen.inputs.printers import load_printer
    from printgen.outputs import write_text
    from printgen.parts.export import layout_parts, threemf_bytes
    from printgen.parts.geometry.solid import (
        analytic_cable_volume,
        analytic_net_volume,
        attachment_for,
        cable_solid,
        net_solid,
    )
    from tests.conftest import reference_design_1_40

    d = reference_design_1_40()
    printer = load_printer(d.printer)
    att = attachment_for(d, hole_compensation_mm=printer.hole_compensation_mm)
    parts = [("net", lambda: net_solid(d.net), analytic_net_volume(d.net)),
             ("net-eyelets", lambda: net_solid(d.net, att), analytic_net_volume(d.net, att))]
    parts += [(f"cable-{c.name}", lambda c=c: cable_solid(c), analytic_cable_volume(c))
              for c in d.cables]
    results, meshes = {}, {}
    for name, build, analytic in parts:
        results[name], meshes[name] = _part_record(name, build, analytic, printer, repeat)
    cables = [(n, m) for n, m in meshes.items() if n.startswith("cable-")]
    t_plate, placed = best_of(lambda: layout_parts(cables, printer), repeat)
    t_plate_3mf, _ = best_of(lambda: threemf_bytes([(p.name, p.mesh) for p in placed]), repeat)
    report = {"benchmark": "bench_parts", "goal_s": GOAL_S,
              "net_mesh_s": results["net"]["mesh_s"],
              "net_eyelets_mesh_s": results["net-eyelets"]["mesh_s"],
              "goal_met": max(results["net"]["mesh_s"],
                              results["net-eyelets"]["mesh_s"]) < GOAL_S,
              "repeat": repeat, "printer": printer.key, "parts": results,
              "cable_plate": {"layout_s": round(t_plate, 4), "threemf_s": round(t_plate_3mf, 4),
                              "angles_deg": {p.name: p.angle_deg for p in placed}}}
    write_text(Path(out_dir) / "bench_parts.json", json.dumps(report, indent=1) + "\n")
    return report


def main(argv: list[str] | None = None) -> int:
    return goal_main(run, __doc__, argv, repeat=3)


if __name__ == "__main__":
    sys.exit(main())
