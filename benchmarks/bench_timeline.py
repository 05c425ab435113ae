"""Benchmark: where the wall time of `printgen make` goes, process by process. One make per
example at 1:40 (examples/simple_barrier.toml, the free top; examples/realistic_barrier.toml,
border cables), run as a user runs it, with PRINTGEN_TRACE set: every process appends a line
per span (printgen.trace.span: make's steps, the helper's sweeps and band, each job of a
worker pool, each pool's life in its parent). From them: a Gantt chart per process, the time
before make's first span (interpreter start-up and imports), the wall time when 0, 1 or 2+
worker jobs ran, and the idle core-seconds (cores x wall - the CPU inside the spans:
getrusage of the waited children misses the processes a fork server started).

    python -m benchmarks.bench_timeline --out DIR [--repeat 1]

The machine may be shared: the load average is recorded beside each run; a loaded machine
stretches every span. Writes bench_timeline.json and timeline-<example>.png. Goal: the
simple barrier's make in under GOAL_S on 2 cores.
"""

from __future__ import annotations

import json
import os
import resource
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = {"simple": ROOT / "examples" / "simple_barrier.toml",
            "realistic": ROOT / "examples" / "realistic_barrier.toml"}
SCALE = 40.0
GOAL_S = 15.0  # the simple barrier's make in under 15 s on 2 cores
TRACE = "PRINTGEN_TRACE"  # printgen.trace.TRACE
POOL = "pool of"  # a pool's life in its parent (printgen.executor.local.run_jobs), not a job


def traced_make(example: Path, out: Path) -> dict:
    """One `printgen make` with tracing: wall, CPU of all its processes, the spans."""
    trace = out.with_suffix(".trace.jsonl")
    trace.unlink(missing_ok=True)
    cmd = [sys.executable, "-m", "printgen", "make", str(example), "--scale", f"{SCALE:g}",
           "--out", str(out), "--force", "--time-limit", "3600"]
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    load = os.getloadavg()[0]
    launch = time.time()
    proc = subprocess.run(cmd, check=False, capture_output=True, text=True, cwd=ROOT,
                          env={**os.environ, "PYTHONPATH": str(ROOT), TRACE: str(trace)})
    end = time.time()
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if proc.returncode not in (0, 1, 3):  # 1: a mismatch, 3: a verdict on fewer levels
        raise RuntimeError(f"printgen make failed ({proc.returncode}): {proc.stderr[-2000:]}")
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    spans = [json.loads(line) for line in trace.read_text().splitlines() if line.strip()]
    return {"launch": launch, "end": end, "wall_s": end - launch, "cpu_s": cpu,
            "load_average": [load, os.getloadavg()[0]], "exit": proc.returncode,
            "spans": spans}


def lanes(run: dict) -> dict[int, str]:
    """Process id -> its role: make (the command's process), helper, worker N."""
    spans = run["spans"]
    pids = list(dict.fromkeys(s["pid"] for s in sorted(spans, key=lambda s: s["start"])))
    make = next((s["pid"] for s in spans if s["what"].startswith("make:")), None)
    helper = next((s["pid"] for s in spans if s["what"].startswith("verify: nominal")
                   and s["pid"] != make), None)
    names, k = {}, 0
    for pid in pids:
        if pid == make:
            names[pid] = "make"
        elif pid == helper:
            names[pid] = "helper"
        else:
            k += 1
            parent = "helper" if helper and any(
                s["ppid"] == helper for s in spans if s["pid"] == pid) else "make"
            names[pid] = f"worker {k} (of {parent})"
    return names


def concurrency(run: dict) -> dict[str, float]:
    """Seconds of the run's wall time during which 0, 1 and 2 or more worker jobs ran (the
    jobs: spans in processes other than make and the helper, pools' lives left out)."""
    names = lanes(run)
    jobs = [s for s in run["spans"] if names[s["pid"]].startswith("worker")
            and not s["what"].startswith(POOL)]
    events = sorted([(s["start"], 1) for s in jobs] + [(s["end"], -1) for s in jobs])
    out = {"0": 0.0, "1": 0.0, "2+": 0.0}
    t, n = run["launch"], 0
    for at, step in [*events, (run["end"], 0)]:
        out["0" if n == 0 else "1" if n == 1 else "2+"] += max(at - t, 0.0)
        t, n = at, n + step
    return out


def phases(run: dict) -> dict[str, float]:
    """Wall time (s) of make's own spans and the helper's, by name; `start-up`: launch to
    make's first span (the interpreter, printgen's imports, the command line)."""
    names = lanes(run)
    mine = [s for s in run["spans"] if names[s["pid"]] in ("make", "helper")]
    first = min((s["start"] for s in mine), default=run["end"])
    out = {"start-up (imports, CLI)": first - run["launch"]}
    for s in mine:
        key = f"{names[s['pid']]}: {s['what']}"
        out[key] = out.get(key, 0.0) + s["end"] - s["start"]
    return out


def span_cpu(run: dict) -> float:
    """CPU seconds inside the spans: per process, its outermost spans' (getrusage of the
    children misses the processes of a fork server, which make does not wait for)."""
    total = 0.0
    for pid in {s["pid"] for s in run["spans"]}:
        mine = [s for s in run["spans"] if s["pid"] == pid]
        total += sum(s["cpu"] for s in mine if not any(
            o is not s and o["start"] <= s["start"] and s["end"] <= o["end"] for o in mine))
    return total


def summary(run: dict, cores: int) -> dict:
    rows = [{"process": lanes(run)[s["pid"]], "what": s["what"],
             "start_s": s["start"] - run["launch"], "end_s": s["end"] - run["launch"],
             "cpu_s": s["cpu"]} for s in sorted(run["spans"], key=lambda s: s["start"])]
    cpu = max(run["cpu_s"], span_cpu(run))
    return {"wall_s": run["wall_s"], "cpu_s": cpu, "cores": cores,
            "idle_core_s": cores * run["wall_s"] - cpu,
            "load_average": run["load_average"], "exit": run["exit"],
            "phases_s": phases(run), "worker_jobs_running_s": concurrency(run), "spans": rows}


def figure(name: str, s: dict, path: Path) -> None:
    """Gantt chart: one row per process, its spans (nested ones thinner)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    procs = list(dict.fromkeys(r["process"] for r in s["spans"]))
    fig, ax = plt.subplots(figsize=(12, 0.5 + 0.55 * len(procs)), constrained_layout=True)
    for y, proc in enumerate(procs):
        rows = [r for r in s["spans"] if r["process"] == proc]
        for r in rows:
            depth = sum(o is not r and o["start_s"] <= r["start_s"] and r["end_s"] <= o["end_s"]
                        for o in rows)
            h = 0.8 / (1 + depth)
            w = r["end_s"] - r["start_s"]
            colour = "0.8" if r["what"].startswith(POOL) else f"C{hash(r['what']) % 10}"
            ax.barh(y, w, left=r["start_s"], height=h, color=colour, edgecolor="k", lw=0.3)
            if w > 0.04 * s["wall_s"]:
                ax.text(r["start_s"] + w / 2, y + (0.25 if depth else 0), r["what"][:28],
                        ha="center", va="center", fontsize=6)
    ax.set_yticks(range(len(procs)), procs)
    ax.invert_yaxis()
    ax.set_xlabel("s since launch")
    ax.set_title(f"printgen make {name} 1:{SCALE:g}: {s['wall_s']:.1f} s wall, CPU "
                 f"{s['cpu_s']:.1f} s, idle {s['idle_core_s']:.1f} core-s "
                 f"(load {max(s['load_average']):.1f})", fontsize=9)
    fig.savefig(path, dpi=110, metadata={"Software": None})
    plt.close(fig)


def run(out: Path, repeat: int) -> dict:
    from printgen.executor.start import cores

    out.mkdir(parents=True, exist_ok=True)
    report: dict = {"benchmark": "bench_timeline", "scale": SCALE, "goal_s": GOAL_S,
                    "examples": {}}
    for name, example in EXAMPLES.items():
        runs = [summary(traced_make(example, out / f"{name}{k}"), cores())
                for k in range(repeat)]
        best = min(runs, key=lambda r: r["wall_s"])
        figure(name, best, out / f"timeline-{name}.png")
        report["examples"][name] = {"best": best, "walls_s": [r["wall_s"] for r in runs]}
    report["simple_wall_s"] = report["examples"]["simple"]["best"]["wall_s"]
    report["realistic_wall_s"] = report["examples"]["realistic"]["best"]["wall_s"]
    report["goal_met"] = report["simple_wall_s"] < GOAL_S
    (out / "bench_timeline.json").write_text(json.dumps(report, indent=1) + "\n")
    return report


def main(argv: list[str] | None = None) -> int:
    from benchmarks.timing import goal_main

    return goal_main(run, __doc__, argv, 1)


if __name__ == "__main__":
    sys.exit(main())
