"""Benchmark: the design search's two stages, serially, on this machine's pool of 1 to all cores
and on a Dask scheduler (a LocalCluster of this machine's cores, the `--scheduler` route).

    python -m benchmarks.bench_design --out DIR [--repeat N]      (or: printgen bench design)

Stage 1: the default 1:40 grid (every material x section x mesh within +-25 % x border) screened
by the membrane law: candidates per second. Stage 2: solver verifications per second, as the
search runs them: the prototype's sweep made once (timed apart, `prototype_sweep_s`), then the
stage-two designs of the 1:40 example (the best net of the `VERIFY_NETS` best material x
section pairs, each with every border width, and select's pick) verified against it at load
step `LEVEL_STEP`, in the search's jobs (`solver_batches`: the designs of one net graph per
job, warm-started from each other). Each row also gives the model sweeps' CPU seconds and
Newton iterations per verified design (what the machine's load does not change much), the
serial row the whole stage's CPU seconds per design. Pools and
clusters are started before the timing; each stage's best of `--repeat` runs is kept (the
first also loads the solver in each worker). Writes bench_design.json and bench_design.png
into DIR and prints the JSON. Goals: all cores screen the grid in under `GOAL_SCREEN_S` and
verify at least `GOAL_VERIFIED_PER_S` designs a second.
"""

from __future__ import annotations

import dataclasses
import os
import sys
import time
from pathlib import Path

from benchmarks.timing import goal_main, machine

GOAL_SCREEN_S = 10.0  # the default 1:40 grid (~42 000 nets) screened within 10 s on all cores
GOAL_VERIFIED_PER_S = 10.0  # solver stage: 10 designs a second on all cores
VERIFY_NETS = 6  # stage-two nets: 6 x 2 border widths + select's pick = 13 designs per timing
LEVEL_STEP = 0.1  # coarser than the verification's 0.05: a benchmark, not a verdict


def _setup():
    from printgen.executor import open_runner
    from printgen.inputs.prototype import load_prototype
    from printgen.scaling.plan import make_design
    from printgen.scaling.selection import select
    from printgen.scaling.similitude import scale_targets
    from printgen.search.nets import candidate_design, screen_all, stage_two
    from printgen.search.space import default_space, grid, search_context

    p = load_prototype(Path(__file__).resolve().parents[1] / "examples/realistic_barrier.toml")
    t = scale_targets(p, 40)
    space = default_space(p, t)
    ctx = search_context(p, t, space)
    base = make_design(p, t, select(p, t))
    points = grid(ctx, space)
    with open_runner(serial=True) as runner:
        picks = stage_two(screen_all(runner, ctx, points), VERIFY_NETS)
    designs = [candidate_design(ctx, s.point, base) for s in picks] + [base]
    return p, ctx, points, designs


def _prototype_run(p, design):
    """The prototype's sweep, once, as the search makes it (and its time)."""
    from printgen.run.search import prototype_sweep
    from printgen.search.nets import VerifyShared

    shared = VerifyShared(p, LEVEL_STEP)
    t0 = time.perf_counter()
    run = prototype_sweep(shared, design)
    return dataclasses.replace(shared, prototype_run=run), time.perf_counter() - t0


def _stage_times(runner, ctx, points, designs, shared, repeat: int) -> dict:
    from printgen.run.search import verify_batch
    from printgen.search.nets import VerifyTask, screen_all, solver_batches

    best_screen = min(_timed(lambda: screen_all(runner, ctx, points))[0] for _ in range(repeat))
    jobs = solver_batches([VerifyTask(str(i), d) for i, d in enumerate(designs)])
    runs = [_timed(lambda: runner.map(verify_batch, jobs, shared=shared)) for _ in range(repeat)]
    wall, cpu, parts = min(runs, key=lambda r: r[0])
    scores = [v for part in parts for v in part]
    row = {"where": runner.where, "screen_s": round(best_screen, 4),
           "screened_per_s": round(len(points) / best_screen, 1),
           "verify_s": round(wall, 3), "verify_jobs": len(jobs),
           "verified_per_s": round(len(designs) / wall, 3),
           "sweep_cpu_s_per_verified": round(sum(v.cpu_s for v in scores) / len(designs), 4),
           "iterations_per_verified": round(sum(v.iterations for v in scores) / len(designs), 1)}
    if runner.pool is None and runner.client is None:  # the work ran in this process
        row["cpu_s_per_verified"] = round(cpu / len(designs), 4)
    return row


def _timed(fn) -> tuple[float, float, object]:
    """(wall, this process's CPU) seconds of `fn()`, and what it returned."""
    t0, c0 = time.perf_counter(), time.process_time()
    out = fn()
    return time.perf_counter() - t0, time.process_time() - c0, out


def run(out_dir: Path, repeat: int = 2) -> dict:
    from printgen.executor import open_runner
    from printgen.outputs import write_bytes, write_text
    from printgen.report.jsonout import dumps

    before = machine()
    p, ctx, points, designs = _setup()
    shared, proto_s = _prototype_run(p, designs[-1])
    cores = os.cpu_count() or 1
    rows = {}
    with open_runner(serial=True) as runner:
        rows["serial"] = _stage_times(runner, ctx, points, designs, shared, repeat)
    for n in range(1, cores + 1):
        with open_runner(workers=n) as runner:
            rows[f"{n} worker(s)"] = _stage_times(runner, ctx, points, designs, shared, repeat)
    scheduler = _on_scheduler(cores, ctx, points, designs, shared, repeat)
    if scheduler is not None:
        rows[f"Dask scheduler ({cores} local workers)"] = scheduler
    full = rows[f"{cores} worker(s)"]
    report = {"candidates": len(points), "verified_designs": len(designs),
              "verify_nets": VERIFY_NETS, "level_step": LEVEL_STEP, "cores": cores,
              "prototype_sweep_s": round(proto_s, 3), "runs": rows,
              "machine": {**before, "load_after": os.getloadavg()[0]},
              "goal": {"screen_s": GOAL_SCREEN_S, "verified_per_s": GOAL_VERIFIED_PER_S},
              "goal_met": bool(full["screen_s"] < GOAL_SCREEN_S
                               and full["verified_per_s"] >= GOAL_VERIFIED_PER_S)}
    write_text(out_dir / "bench_design.json", dumps(report))
    write_bytes(out_dir / "bench_design.png", _figure(rows))
    return report


def _on_scheduler(cores: int, ctx, points, designs, shared, repeat: int) -> dict | None:
    """The stages on a Dask LocalCluster of `cores` single-threaded worker processes, reached
    by its address as `--scheduler` reaches one (None without dask.distributed)."""
    try:
        from distributed import LocalCluster
    except ImportError:
        return None
    from printgen.executor import open_runner

    with LocalCluster(n_workers=cores, threads_per_worker=1, processes=True,
                      dashboard_address=None) as cluster, \
            open_runner(scheduler=cluster.scheduler_address) as runner:
        return _stage_times(runner, ctx, points, designs, shared, repeat)


def _figure(rows: dict) -> bytes:
    from printgen.report.plots import _png, _pyplot

    plt = _pyplot()
    names = list(rows)
    fig, axes = plt.subplots(1, 2, figsize=(11, 3.8), constrained_layout=True)
    for ax, key, label in ((axes[0], "screened_per_s", "candidates screened / s"),
                           (axes[1], "verified_per_s", "designs verified by the solver / s")):
        ax.bar(names, [rows[n][key] for n in names], color="C0")
        ax.set_ylabel(label)
        ax.grid(axis="y", alpha=0.3)
        ax.tick_params(axis="x", labelrotation=20)
    axes[1].axhline(GOAL_VERIFIED_PER_S, color="C3", lw=1, ls="--", label="goal")
    axes[1].legend()
    fig.suptitle("printgen design: the two stages, serial, local pool, Dask (1:40 example)")
    return _png(fig)


def main(argv: list[str] | None = None) -> int:
    return goal_main(run, __doc__, argv, repeat=2)


if __name__ == "__main__":
    sys.exit(main())
