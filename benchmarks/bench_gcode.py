"""Benchmark: direct G-code for the 1:40 reference net (330 x 100 mm) and its cables.

    python -m benchmarks.bench_gcode --out DIR [--repeat N]

Times toolpath building, G-code writing and read-back (best of N), writes the G-code and
`bench_gcode.json` into DIR and prints the JSON. Goal: the net's G-code in under 1 s.
"""

from __future__ import annotations

import json
import sys
from functools import partial
from pathlib import Path

from benchmarks.timing import best_of, goal_main

GOAL_S = 1.0  # the brief: G-code for the 330 mm net in under a second



def run(out_dir: Path, repeat: int = 5) -> dict:
    from printgen.inputs.materials import load_material
    from printgen.inputs.printers import load_print_style, load_printer
    from printgen.outputs import write_text
    from printgen.parts.gcode import (
        cable_toolpath,
        cable_volume_budget,
        gcode_text,
        net_toolpath,
        net_volume_budget,
        read_gcode_text,
    )
    from tests.conftest import reference_design_1_40

    d = reference_design_1_40()
    printer = load_printer(d.printer)
    half = 0.5  # crossing_flow_factor variant: every crossing splits the strand move
    parts = [("net", d.net, net_toolpath, net_volume_budget),
             ("net-crossing-flow-0.5", d.net,
              partial(net_toolpath, crossing_flow_factor=half),
              partial(net_volume_budget, crossing_flow_factor=half))]
    parts += [(f"cable-{c.name}", c, cable_toolpath,
               lambda p, s: cable_volume_budget(p, s.crossing_flow_factor,
                                                printer.hole_compensation_mm))
              for c in d.cables]
    results = {}
    for name, part, build, budget in parts:
        style, mat = load_print_style(part.print_style), load_material(part.material)
        t_path, tp = best_of(partial(build, part, printer, style, mat), repeat)
        t_text, text = best_of(partial(gcode_text, tp, printer, mat), repeat)
        t_read, rb = best_of(partial(read_gcode_text, text,
                                   filament_diameter_mm=printer.filament_diameter_mm), repeat)
        write_text(out_dir / f"{name}.gcode", text)
        b = budget(part, style)
        flow = float((tp.area_mm2() * tp.speed_mm_per_s).max())
        results[name] = {
            "toolpath_s": round(t_path, 5), "write_s": round(t_text, 5),
            "gcode_total_s": round(t_path + t_text, 5), "readback_s": round(t_read, 5),
            "moves": len(tp.width_mm), "lines": text.count("\n"), "bytes": len(text),
            "layers": len(tp.layer_z_mm), "paths": rb.path_count,
            "toolpath_volume_mm3": round(tp.volume_mm3, 3),
            "readback_volume_mm3": round(rb.volume_mm3, 3),
            "design_deposit_mm3": round(b.deposit_mm3, 3),
            "design_solid_mm3": round(b.solid_mm3, 3),
            "readback_vs_deposit": round(rb.volume_mm3 / b.deposit_mm3 - 1, 6),
            "max_flow_mm3_per_s": round(flow, 4),
            "flow_limit_mm3_per_s": mat.print.max_volumetric_flow_mm3_per_s,
            "print_time_feed_only_s": round(float(
                (tp.lengths_mm() / tp.speed_mm_per_s).sum()), 1),
        }
    net = results["net"]
    report = {"benchmark": "bench_gcode", "python": sys.version.split()[0],
              "goal_s": GOAL_S, "net_gcode_s": net["gcode_total_s"],
              "goal_met": net["gcode_total_s"] < GOAL_S, "repeat": repeat, "parts": results}
    write_text(out_dir / "bench_gcode.json", json.dumps(report, indent=1) + "\n")
    return report


def main(argv: list[str] | None = None) -> int:
    return goal_main(run, __doc__, argv, repeat=5)


if __name__ == "__main__":
    sys.exit(main())
