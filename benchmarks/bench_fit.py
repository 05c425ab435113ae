"""Benchmark: the fits of the bundled paper test (examples/paper_1_40: the printed 1:40 design
and the flume's loading test of Lambert et al. 2023, doi 10.1061/JHEND8.HYENG-13070, Fig. 6a)
as a user runs them: `printgen verify examples/realistic_barrier.toml --scale 40 --design
examples/paper_1_40/design.json --measured examples/paper_1_40/measured.csv`, with the
default one-factor fit and with `--fit multi`, each a fresh process.

    python -m benchmarks.bench_fit --out DIR [--repeat 1]     (or: printgen bench fit)

For each: the wall time of the whole command (and its CPU, workers included: on a shared
machine, CPU over the cores bounds the quiet wall time) and of the fit alone (timings.json
"fit"), the
sweeps the fit ran (report.json) against the sweeps and the time the run's estimate counted
(timings.json "estimate_fit_sweeps", "estimate"), and the fit's verdict (explained, profile
written). The machine is shared: the load average is recorded beside each run. Goals: the
multi fit within GOAL_MULTI_S, the one-factor fit within GOAL_ONE_S (wall, the fit alone),
and the estimate within ESTIMATE_FACTOR of the measured run. Writes bench_fit.json.
"""

from __future__ import annotations

import json
import os
import resource
import statistics
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PROTOTYPE = ROOT / "examples" / "realistic_barrier.toml"
PAPER = ROOT / "examples" / "paper_1_40"
SCALE = 40.0
GOAL_MULTI_S = 60.0  # --fit multi on the paper test: a minute on 2 cores, quiet
GOAL_ONE_S = 10.0  # the one-factor fit alone
ESTIMATE_FACTOR = 2.0  # the run's estimate within x2 of the measured run
FITS = ("stiffness", "multi")


def one_run(out: Path, fit: str) -> dict:
    """One `printgen verify --measured --fit FIT` process: times, sweeps, estimate, verdict."""
    cmd = [sys.executable, "-m", "printgen", "verify", str(PROTOTYPE), "--scale", f"{SCALE:g}",
           "--design", str(PAPER / "design.json"), "--measured", str(PAPER / "measured.csv"),
           "--fit", fit, "--out", str(out), "--force", "--time-limit", "3600"]
    load = os.getloadavg()[0]
    t, cpu = time.perf_counter(), _children_cpu()
    proc = subprocess.run(cmd, check=False, capture_output=True, text=True, cwd=ROOT,
                          env={**os.environ, "PYTHONPATH": str(ROOT)})
    wall, cpu = time.perf_counter() - t, _children_cpu() - cpu
    if proc.returncode not in (0, 1, 3):  # 1: a mismatch, 3: a verdict on fewer levels
        raise RuntimeError(f"printgen verify failed ({proc.returncode}): {proc.stderr[-2000:]}")
    timings = json.loads((out / "timings.json").read_text())["timings_s"]
    fitted = json.loads((out / "report.json").read_text())["measured"]["fit"]
    return {"fit": fit, "wall_s": round(wall, 2), "cpu_s": round(cpu, 2),
            "fit_s": round(timings["fit"], 2),
            "band_s": round(timings["band"], 2), "estimate_s": round(timings["estimate"], 2),
            "speed_factor": round(timings["estimate_speed_factor"], 3),
            "sweeps": fitted["evaluations"], "sweeps_by_net": fitted.get("sweeps", {}),
            "estimate_sweeps": timings["estimate_fit_sweeps"],
            "explains": fitted.get("explains"),
            "profile_written": bool(fitted.get("profile")),
            "not_determined": fitted.get("not_determined"),
            "sentence": fitted["sentence"], "load_before": round(load, 2),
            "load_after": round(os.getloadavg()[0], 2)}


def _children_cpu() -> float:
    """CPU seconds of this process's finished children (the command and its workers)."""
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def run(out: Path, repeat: int = 1) -> dict:
    out.mkdir(parents=True, exist_ok=True)
    report: dict = {"benchmark": "bench_fit", "cores": os.cpu_count(), "runs": []}
    for fit in FITS:
        rows = []
        for i in range(repeat):
            print(f"verify --fit {fit} ({i + 1}/{repeat}) ...", file=sys.stderr, flush=True)
            rows.append(one_run(out / f"{fit}-{i}", fit))
        report["runs"] += rows
        med = statistics.median(r["fit_s"] for r in rows)
        wall = statistics.median(r["wall_s"] for r in rows)
        est = rows[0]["estimate_s"]
        report[f"{fit}_fit_s"] = med
        report[f"{fit}_wall_s"] = wall
        report[f"{fit}_estimate_over_measured"] = round(est / wall, 2)
    report["goal_met"] = bool(
        report["multi_fit_s"] <= GOAL_MULTI_S and report["stiffness_fit_s"] <= GOAL_ONE_S
        and all(1 / ESTIMATE_FACTOR <= report[f"{f}_estimate_over_measured"] <= ESTIMATE_FACTOR
                for f in FITS))
    (out / "bench_fit.json").write_text(json.dumps(report, indent=1) + "\n")
    return report


def main(argv: list[str] | None = None) -> int:
    from benchmarks.timing import goal_main

    return goal_main(run, __doc__, argv, 1)


if __name__ == "__main__":
    sys.exit(main())
