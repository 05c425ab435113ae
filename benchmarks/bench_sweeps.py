"""Benchmark: Newton iterations and factorizations per load level on the free-top simple
barrier (scene simple-free-top, barrier-physics.md section 7; Lambert et al. 2023,
doi 10.1061/JHEND8.HYENG-13070): the two sweeps `verify` solves for examples/simple_barrier.toml
at 1:40 (printed model and prototype, h/h_B = 0 to 1.1 by 0.05), and with `--petg30` also
a PETG barrier at 1:30 (tests/data/petg-1-30, a 500 mm bed printer).

    python -m benchmarks.bench_sweeps --out DIR [--petg30]     (or: printgen bench sweeps)

The machine is shared: work is counted (iterations, factorizations per level) and timed by
`time.process_time()` (CPU of this process), not wall time. Goal: every level of
every sweep converges in fewer than GOAL_ITERATIONS Newton iterations.
Writes bench_sweeps.json.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SIMPLE = (ROOT / "examples" / "simple_barrier.toml", 40.0, None)
PETG30 = (ROOT / "tests" / "data" / "petg-1-30" / "simple_petg_1to30.toml", 30.0, "bed-500")
GOAL_ITERATIONS = 50  # Newton iterations per load level, at most
SWEEPS = ("printed model", "prototype")  # the order `verify` solves them in (longest first)


def sweeps(example: Path, scale: float, printer: str | None) -> list[dict]:
    """Per level iterations, factorizations and convergence of each sweep `verify` solves
    (serially, in this process), with each sweep's CPU time."""
    from printgen import solver
    from printgen.run.api import verify

    rows, original = [], solver.solve_path

    def recording(net, loads_at, levels, **kw):
        t = time.process_time()
        res = original(net, loads_at, levels, **kw)
        rows.append({"sweep": SWEEPS[len(rows)] if len(rows) < len(SWEEPS) else "other",
                     "nodes": len(net.nodes), "unknowns": int((~net.fixed_dofs).sum()),
                     "cpu_s": round(time.process_time() - t, 3),
                     "levels": [float(r.level) for r in res],
                     "converged": [bool(r.converged) for r in res],
                     "iterations": [int(r.iterations) for r in res],
                     "factorizations": [int(r.factorizations) for r in res]})
        return res

    env = {"PRINTGEN_SERIAL": "1"}
    if printer:
        env["PRINTGEN_PROFILES"] = str(example.parent)
    old = {k: os.environ.get(k) for k in env}
    os.environ.update(env)
    solver.solve_path = recording
    try:
        verify(example, scale, printer=printer)
    finally:
        solver.solve_path = original
        for k, v in old.items():
            if v is None:
                os.environ.pop(k, None)
            else:
                os.environ[k] = v
    for row in rows:
        its = row["iterations"]
        row["max_iterations"] = max(its, default=0)
        row["total_iterations"] = sum(its)
        row["factorizations_per_iteration"] = round(
            sum(row["factorizations"]) / max(sum(its), 1), 2)
    return rows


def run(out: Path, petg30: bool = False) -> dict:
    out.mkdir(parents=True, exist_ok=True)
    cases = {"simple_barrier 1:40": SIMPLE, **({"PETG 1:30": PETG30} if petg30 else {})}
    report: dict = {"benchmark": "bench_sweeps", "scene": "simple-free-top",
                    "goal_iterations_per_level": GOAL_ITERATIONS, "cases": {}}
    for name, (example, scale, printer) in cases.items():
        print(f"{name} ...", file=sys.stderr, flush=True)
        report["cases"][name] = sweeps(example, scale, printer)
    every = [r for rows in report["cases"].values() for r in rows]
    report["goal_met"] = bool(every) and all(
        all(r["converged"]) and r["max_iterations"] < GOAL_ITERATIONS for r in every)
    (out / "bench_sweeps.json").write_text(json.dumps(report, indent=1) + "\n")
    return report


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", required=True, type=Path)
    ap.add_argument("--petg30", action="store_true",
                    help="also the PETG barrier at 1:30 (500 mm bed)")
    ap.add_argument("--json", action="store_true", help="print the whole report as JSON")
    a = ap.parse_args(argv)
    report = run(a.out, a.petg30)
    if a.json:
        print(json.dumps(report, indent=1))
        return 0
    for name, rows in report["cases"].items():
        for r in rows:
            print(f"{name} {r['sweep']:13s} ({r['unknowns']} unknowns): "
                  f"{sum(r['converged'])}/{len(r['levels'])} levels, iterations max "
                  f"{r['max_iterations']} total {r['total_iterations']}, "
                  f"{r['factorizations_per_iteration']} factorizations/iteration, "
                  f"CPU {r['cpu_s']:.1f} s; per level {r['iterations']}")
    print(f"goal (< {GOAL_ITERATIONS} iterations per level, all converged) "
          f"{'met' if report['goal_met'] else 'NOT met'}; all numbers in {a.out}/")
    return 0


if __name__ == "__main__":
    sys.exit(main())
