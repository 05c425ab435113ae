"""Benchmark: `printgen make` on the 1:40 example (examples/realistic_barrier.toml --scale 40,
every output but STEP), the whole command line as a user runs it, median of 3; then once on
the free-top simple barrier (examples/simple_barrier.toml --scale 40). For both: make's own
estimate (timings.json) against the measured wall time, the solver work it predicted against
the work the run counted (report.json "size" / "verification" -> "solver_work"), and the
sweeps' CPU (each sweep's process time, timings.json) against the estimate's.

    python -m benchmarks.bench_make --out DIR [--repeat 3]

The machine is shared: the load average is recorded beside each run, and the constants of
printgen/run/budget.py are refitted from CPU time and counted work (`constants`): Newton
iterations per load level by kind of net, and the CPU of one iteration (ITERATION_S +
ITERATION_S_PER_UNKNOWN x unknowns, least squares on every sweep's relative error).

Each run is a fresh process (imports included) writing into its own folder; the time of each
step comes from the run's own timings.json. The verification runs in make's helper process
alongside the other steps ("helper: ..." bars, orange); a step that waits for it says how long
("waiting ...", grey, part of that step's time). Writes bench_make.json and bench_make.png.
Goals: median total < 3 s on this machine; the estimate within x2 of the measured time on both
examples (`estimate_within_x2`, on the wall time and on the CPU).
"""

from __future__ import annotations

import json
import os
import statistics
import sys
from pathlib import Path

from benchmarks.timing import run_printgen

ROOT = Path(__file__).resolve().parents[1]
EXAMPLE = ROOT / "examples" / "realistic_barrier.toml"
SIMPLE = ROOT / "examples" / "simple_barrier.toml"  # free top: estimate checked, not timed x3
SCALE = 40.0
GOAL_S = 3.0  # make at 1:40 in under 3 s
ESTIMATE_FACTOR = 2.0  # the estimate within x2 of the measured run
REPEAT = 3
HELPER = "helper:"  # steps run in make's helper process, alongside the others (orange)
WAITING = "waiting"  # time a step spent waiting for the helper (grey; inside that step's bar)
ESTIMATES = ("estimate", "estimate_verification", "estimate_parts")  # not steps: no bars


def one_run(out: Path, example: Path = EXAMPLE) -> dict:
    """Wall time of one `printgen make` process, the step times and solver work it recorded."""
    wall, load, code = run_printgen(["make", str(example), "--scale", f"{SCALE:g}", "--out",
                               str(out)])
    timings = json.loads((out / "timings.json").read_text())
    record = json.loads((out / "report.json").read_text())
    steps = timings.get("timings_s", timings)
    counted = record["verification"]["solver_work"]
    cpu = timings["verification"]["solver_work"]["runs"]
    rows = [{**r, "cpu_s": cpu[str(i)]["time_s"]} for i, r in enumerate(counted["runs"])]
    return {"wall_s": wall, "exit": code,
            "load_average": [load, os.getloadavg()[0]],
            "estimate_s": float(steps.get("estimate", float("nan"))),
            "steps_s": {k: float(v) for k, v in steps.items() if isinstance(v, (int, float))},
            "steps_cpu_s": steps.get("cpu_s", {}),  # make's own process, step by step
            "work": {"predicted": record["size"]["solver_work"],
                     "counted": {k: v for k, v in counted.items() if k != "runs"}},
            "sweeps_cpu_s": sum(r["cpu_s"] for r in rows), "sweeps": rows}


def predicted_cpu(example: Path) -> float:
    """The estimate's CPU of the verification's sweeps on one core (printgen.run.budget)."""
    from printgen.run.budget import sweeps
    from printgen.run.make import plan_run
    from printgen.run.speed import speed_factor

    ctx = plan_run(example, SCALE)
    return speed_factor() * sum(s.seconds for s in sweeps(ctx.prototype, ctx.design))


def fitted_constants(runs: list[dict]) -> dict:
    """budget.py's constants from the runs: iterations per level by kind of net (its growth
    with the unknowns, ITERATION_GROWTH, kept), and the CPU per iteration (least squares of
    every sweep's relative error), in the reference machine's seconds: this machine's over
    its speed factor (printgen.run.speed), as budget.py keeps them."""
    import numpy as np

    from printgen.run import budget
    from printgen.run.speed import speed_factor

    per_level = {}  # at budget.REFERENCE_UNKNOWNS: scaled by the counted / predicted totals
    for kind, rs in runs_by_kind(runs).items():
        counted = sum(r["work"]["counted"]["iterations"] for r in rs)
        predicted = sum(r["work"]["predicted"]["iterations"] for r in rs)
        per_level[kind] = budget.ITERATIONS_PER_LEVEL[kind] * counted / predicted
    rows = [s for r in runs for s in r["sweeps"] if s["iterations"] and s["cpu_s"] > 0]
    it = np.array([s["iterations"] for s in rows], float)
    n = np.array([s["unknowns"] for s in rows], float)
    factor = speed_factor()
    cpu = np.array([s["cpu_s"] for s in rows]) / factor
    a = np.c_[it, it * n] / cpu[:, None]
    (per_it, per_unknown), *_ = np.linalg.lstsq(a, np.ones(len(rows)), rcond=None)
    ratio = a @ np.array([per_it, per_unknown])
    return {"ITERATIONS_PER_LEVEL": per_level, "ITERATION_S": per_it,
            "ITERATION_S_PER_UNKNOWN": per_unknown, "speed_factor": factor,
            "sweep_cpu_over_fit": [float(ratio.min()), float(ratio.max())], "sweeps": len(rows),
            "in_budget_py": {"ITERATIONS_PER_LEVEL": budget.ITERATIONS_PER_LEVEL,
                             "ITERATION_S": budget.ITERATION_S,
                             "ITERATION_S_PER_UNKNOWN": budget.ITERATION_S_PER_UNKNOWN}}


def runs_by_kind(runs: list[dict]) -> dict[str, list[dict]]:
    return {"border cables": [r for r in runs if r["example"] == EXAMPLE.name],
            "free top": [r for r in runs if r["example"] == SIMPLE.name]}


def comparison(rs: list[dict], example: Path) -> dict:
    """Estimate against measured (median over `rs`): wall, sweeps' CPU, solver work."""
    wall = statistics.median(r["wall_s"] for r in rs)
    cpu = statistics.median(r["sweeps_cpu_s"] for r in rs)
    est, est_cpu = rs[0]["estimate_s"], predicted_cpu(example)
    work = rs[0]["work"]
    parts = statistics.median(sum(v for k, v in r["steps_cpu_s"].items()
                                  if not k.startswith("verification")) for r in rs)
    return {"estimate_s": est, "measured_s": wall, "measured_over_estimate": wall / est,
            "sweeps_cpu_estimate_s": est_cpu, "sweeps_cpu_s": cpu,
            "cpu_measured_over_estimate": cpu / est_cpu,
            "parts_estimate_s": rs[0]["steps_s"]["estimate_parts"], "parts_cpu_s": parts,
            "verification_step_cpu_s": statistics.median(
                sum(v for k, v in r["steps_cpu_s"].items() if k.startswith("verification"))
                for r in rs),
            "load_average": [r["load_average"] for r in rs],
            "work": work, "iterations_counted_over_predicted":
                work["counted"]["iterations"] / work["predicted"]["iterations"],
            "estimate_within_x2": {
                "wall": 1 / ESTIMATE_FACTOR <= wall / est <= ESTIMATE_FACTOR,
                "cpu": 1 / ESTIMATE_FACTOR <= cpu / est_cpu <= ESTIMATE_FACTOR},
            "exit": [r["exit"] for r in rs]}


def summary(estimates: dict) -> str:
    """One line per example for the terminal: estimate, measured, CPU, work, load."""
    return "; ".join(
        f"{name}: estimate {e['estimate_s']:.0f} s, measured {e['measured_s']:.0f} s "
        f"(load {max(x for pair in e['load_average'] for x in pair):.1f}), sweeps' CPU "
        f"{e['sweeps_cpu_estimate_s']:.0f} s estimated / {e['sweeps_cpu_s']:.0f} s, iterations "
        f"{e['work']['predicted']['iterations']} / {e['work']['counted']['iterations']}"
        for name, e in estimates.items())


def run(out: Path, repeat: int) -> dict:
    out.mkdir(parents=True, exist_ok=True)
    runs = [{**one_run(out / f"run{k}"), "example": EXAMPLE.name} for k in range(repeat)]
    walls = [r["wall_s"] for r in runs]
    labels = list(runs[0]["steps_s"])
    median_steps = {k: statistics.median(r["steps_s"].get(k, 0.0) for r in runs)
                    for k in labels}
    median = statistics.median(walls)
    simple = {**one_run(out / "simple", SIMPLE), "example": SIMPLE.name}
    estimates = {EXAMPLE.name: comparison(runs, EXAMPLE), SIMPLE.name: comparison([simple], SIMPLE)}
    report = {"benchmark": "bench_make", "example": EXAMPLE.name, "scale": SCALE,
              "repeat": repeat, "cores": os.cpu_count(), "runs": runs, "simple_run": simple,
              "median_wall_s": median, "median_steps_s": median_steps,
              "outside_steps_s": median - median_steps.get("total", 0.0),
              "estimate_vs_measured": estimates, "estimates": summary(estimates),
              "constants": fitted_constants([*runs, simple]),
              "goal_s": GOAL_S, "goal_met": median < GOAL_S}
    (out / "bench_make.json").write_text(json.dumps(report, indent=1) + "\n")
    figure(report, out / "bench_make.png")
    return report


def figure(report: dict, path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    steps = {k: v for k, v in report["median_steps_s"].items()
             if k not in ("total", *ESTIMATES)}
    steps["start-up (imports, CLI)"] = max(report["outside_steps_s"], 0.0)
    fig, ax = plt.subplots(figsize=(9, 4.4), constrained_layout=True)
    names = sorted(steps, key=_bar_order)
    colours = ["C1" if k.startswith(HELPER) else "0.6" if k.startswith(WAITING) else "C0"
               for k in names]
    ax.barh(names, [steps[k] for k in names], color=colours)
    ax.axvline(report["goal_s"], color="C3", ls="--", label=f"goal {report['goal_s']:g} s total")
    ax.set_xlabel("median time (s); orange: in the helper process, alongside the blue steps")
    ax.set_title(f"printgen make 1:{report['scale']:g}: {report['median_wall_s']:.2f} s total "
                 f"(median of {report['repeat']})", fontsize=10)
    ax.invert_yaxis()
    ax.legend(fontsize=8, loc="lower right")
    fig.savefig(path, dpi=110, metadata={"Software": None})
    plt.close(fig)


def _bar_order(name: str) -> tuple[int, int]:
    """Start-up, make's steps in their order, the waiting, then the helper's work."""
    from printgen.run.make import default_steps

    labels = [label for label, _ in default_steps()]
    if name.startswith(HELPER):
        return 3, 0
    if name.startswith(WAITING):
        return 2, 0
    return (1, labels.index(name)) if name in labels else (0, 0)


def main(argv: list[str] | None = None) -> int:
    from benchmarks.timing import goal_main

    return goal_main(run, __doc__, argv, REPEAT)


if __name__ == "__main__":
    sys.exit(main())
