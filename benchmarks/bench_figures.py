"""Benchmark: the figures of `printgen make`'s report at 1:40, on both examples (the free-top
simple barrier, examples/simple_barrier.toml, and examples/realistic_barrier.toml with its kit
pictures): each figure's CPU time drawn alone (PNG and SVG from one drawing, best of
--repeat), and all of them drawn as make draws them once the sweeps are done: side by side in
the worker processes of a helper process (`printgen.run.steps.draw_all`), wall time and the
CPU time of the helper and its workers.

    python -m benchmarks.bench_figures --out DIR [--repeat 3]

The sweeps run once per example first (not timed). The machine may be shared: the CPU times
(time.process_time, getrusage) are the numbers to compare; wall times are inflated by the
other jobs' load (the load average is recorded). Writes bench_figures.json and
bench_figures.png. Goal (within make of the simple barrier in under 15 s on 2 cores): its
figures drawn side by side in under GOAL_S of wall time.
"""

from __future__ import annotations

import json
import os
import resource
import sys
import time
from pathlib import Path
from tempfile import TemporaryDirectory

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = {"simple": ROOT / "examples" / "simple_barrier.toml",
            "realistic": ROOT / "examples" / "realistic_barrier.toml"}
SCALE = 40.0
GOAL_S = 3.0  # the simple barrier's figures, side by side, of make's 15 s
REPEAT = 3


def drawings(example: Path) -> list:
    """(name, Drawing) of every figure `make` draws for `example` at 1:40 (its sweeps run here,
    in worker processes, untimed)."""
    from printgen.report.build import build_report
    from printgen.run.make import plan_run
    from printgen.run.steps import kit_step, verification_records, verification_sweeps

    ctx = plan_run(example, SCALE)
    with TemporaryDirectory() as tmp:
        ctx.records.steps.update(kit_step(ctx, Path(tmp)))
    v, band = verification_sweeps(ctx.prototype, ctx.design, ctx.options)
    ctx.records.steps["verification"] = verification_records(v, band, SCALE)[0]
    rep, _ = build_report(ctx.records)
    return list(zip([f.name for f in rep.figures], rep.pending(), strict=True))


def alone(named: list, repeat: int) -> dict[str, float]:
    """Each figure's CPU time (s) drawn in this process, best of `repeat`."""
    out = {}
    for name, d in named:
        best = float("inf")
        for _ in range(repeat):
            t = time.process_time()
            d.fn(*d.args, **d.kwargs)
            best = min(best, time.process_time() - t)
        out[name] = best
    return out


def timed_draw(todo: list) -> dict[str, float]:
    """`draw_all` in this (helper) process: its wall time, this process's CPU (matplotlib's
    import, as in make's helper) and that of the workers it started (reaped by then)."""
    from printgen.run.steps import draw_all

    c0, k0 = (resource.getrusage(w) for w in (resource.RUSAGE_SELF, resource.RUSAGE_CHILDREN))
    t = time.perf_counter()
    draw_all(todo)
    wall = time.perf_counter() - t
    c1, k1 = (resource.getrusage(w) for w in (resource.RUSAGE_SELF, resource.RUSAGE_CHILDREN))
    return {"wall_s": wall, "helper_cpu_s": c1.ru_utime + c1.ru_stime - c0.ru_utime - c0.ru_stime,
            "workers_cpu_s": k1.ru_utime + k1.ru_stime - k0.ru_utime - k0.ru_stime}


def side_by_side(named: list, repeat: int) -> dict[str, float]:
    """`timed_draw` in a fresh helper process each time (as make's), the best wall time's."""
    from printgen.executor.local import helper

    runs = []
    for _ in range(repeat):
        with helper() as h:
            runs.append(h.submit(timed_draw, [d for _, d in named]).result())
    return min(runs, key=lambda r: r["wall_s"])


def run(out: Path, repeat: int) -> dict:
    out.mkdir(parents=True, exist_ok=True)
    named, both = {}, {}
    for key, example in EXAMPLES.items():  # first: the helpers import matplotlib, as make's
        print(f"bench figures: {key}: sweeps (not timed)", file=sys.stderr)
        named[key] = drawings(example)
        print(f"bench figures: {key}: {len(named[key])} figures", file=sys.stderr)
        both[key] = side_by_side(named[key], repeat)
    rows = {}
    for key, figures in named.items():
        each = alone(figures, repeat)
        rows[key] = {"figures_cpu_s": each, "serial_cpu_s": sum(each.values()),
                     "side_by_side": both[key]}
    simple = rows["simple"]["side_by_side"]["wall_s"]
    report = {"benchmark": "bench_figures", "scale": SCALE, "repeat": repeat,
              "cores": os.cpu_count(), "load_average": os.getloadavg(), "examples": rows,
              "goal_s": GOAL_S, "goal_met": simple < GOAL_S}
    (out / "bench_figures.json").write_text(json.dumps(report, indent=1) + "\n")
    figure(report, out / "bench_figures.png")
    return report


def figure(report: dict, path: Path) -> None:
    from printgen.report.plots import load_pyplot

    load_pyplot()  # on the Agg backend
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, len(report["examples"]), figsize=(12, 4.2),
                             constrained_layout=True, squeeze=False)
    for ax, (key, row) in zip(axes[0], report["examples"].items(), strict=True):
        each = row["figures_cpu_s"]
        both = row["side_by_side"]
        names = [*each, "all, one after the other (CPU)", "all, side by side (wall)"]
        values = [*each.values(), row["serial_cpu_s"], both["wall_s"]]
        ax.barh(names, values, color=["C0"] * len(each) + ["0.5", "C1"])
        ax.axvline(report["goal_s"], color="C3", ls="--", lw=0.8, label=f"goal {GOAL_S:g} s")
        ax.set_xlabel("time (s): CPU for one figure, wall side by side")
        ax.set_title(f"{key} barrier 1:{report['scale']:g}", fontsize=10)
        ax.invert_yaxis()
        ax.legend(fontsize=8, loc="lower right")
    fig.suptitle(f"printgen make's figures (load average {report['load_average'][0]:.1f} "
                 f"on {report['cores']} cores)", fontsize=10)
    fig.savefig(path, dpi=110, metadata={"Software": None})
    plt.close(fig)


def main(argv: list[str] | None = None) -> int:
    from benchmarks.timing import goal_main

    return goal_main(run, __doc__, argv, REPEAT)


if __name__ == "__main__":
    sys.exit(main())
