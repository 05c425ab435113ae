"""Timing helper shared by the benchmarks."""

from __future__ import annotations

import contextlib
import os
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def best_of(fn, repeat: int):
    """(best wall time in s over `repeat` calls, the last result)."""
    best, out = float("inf"), None
    for _ in range(repeat):
        t = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - t)
    return best, out


def machine() -> dict:
    """Where a benchmark ran: the CPU, its cores, the load average (1 min) at the start, the
    Python and the solver's linear backends installed (each `linsolve.<name>_available()`
    that is true, and SciPy's `lu`), so that numbers from two machines or loads are not mixed up."""
    import platform

    from printgen.solver import linsolve

    cpu = platform.processor() or platform.machine()
    with contextlib.suppress(OSError):
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    backends = [name.removesuffix("_available") for name in sorted(dir(linsolve))
                if name.endswith("_available") and getattr(linsolve, name)()] + ["lu"]
    return {"cpu": cpu, "cores": os.cpu_count() or 1, "load_average": os.getloadavg()[0],
            "python": platform.python_version(), "solver_backends": backends}


def goal_main(run, doc: str, argv: list[str] | None, repeat: int) -> int:
    """Command line of a goal benchmark: --out DIR [--repeat N]; prints the JSON report and
    exits 0 when its goal is met, else 1."""
    import argparse
    import json
    from pathlib import Path

    ap = argparse.ArgumentParser(description=doc.splitlines()[0])
    ap.add_argument("--out", required=True, type=Path, help="folder for the outputs and JSON")
    ap.add_argument("--repeat", type=int, default=repeat, help="timing repeats (best is kept)")
    ap.add_argument("--json", action="store_true", help="print the whole report as JSON")
    a = ap.parse_args(argv)
    report = run(a.out, a.repeat)
    if a.json:
        print(json.dumps(report, indent=1))
    else:
        flat = {k: v for k, v in report.items() if not isinstance(v, (dict, list))}
        for key, value in flat.items():
            print(f"{key}: {value}")
        print(f"goal {'met' if report['goal_met'] else 'NOT met'}; all numbers in {a.out}/")
    return 0 if report["goal_met"] else 1


def run_printgen(args: list[str], force: bool = True) -> tuple[float, float, int]:
    """Run `printgen ARGS` from this checkout in its own process, time-limited only by an
    hour: (wall time s, the load average just before, the exit code); an exit other than 0,
    1 (a mismatch) or 3 (a verdict on fewer levels) raises with its last error lines.
    `force`: replace the output folder (`--force`; `design` has no such option: give it a
    new folder)."""
    cmd = [sys.executable, "-m", "printgen", *args, *(["--force"] if force else []),
           "--time-limit", "3600"]
    load = os.getloadavg()[0]
    t = time.perf_counter()
    proc = subprocess.run(cmd, check=False, capture_output=True, text=True, cwd=ROOT,
                          env={**os.environ, "PYTHONPATH": str(ROOT)})
    wall = time.perf_counter() - t
    if proc.returncode not in (0, 1, 3):
        raise RuntimeError(f"printgen {args[0]} failed ({proc.returncode}): "
                           f"{proc.stderr[-2000:]}")
    return wall, load, proc.returncode
