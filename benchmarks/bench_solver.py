"""Benchmark: the solver's speed against its error on scene simple-pinned (barrier-physics.md,
section 7) at 61 x 21, 121 x 41, 241 x 81 and 481 x 161 nodes, with OpenSeesPy side by side
(up to 241 x 81) and the reference path (method="reference", the solver before its fast path);
the load paths of the 1:40 verification; the robustness table of the hard cases.

    python -m benchmarks.bench_solver --out DIR [--sizes 1 2 4 8] [--no-paths]
        [--threads N] [--compare-threads 1 2]
        [--backends ldl cholmod [--backend-refine 1 2] [--backend-path-scale 20]]
    python -m benchmarks.bench_solver --out DIR --opensees-only

Errors are the mid-height centre deflection against a tight-tolerance solve of the same size
(relative). Loads at the initial node height (the variant OpenSees can model); printgen's
current-height variant is timed too. Times are wall-clock (perf_counter) and CPU
(process_time), each the best of REPEAT at GOAL_TOL, with BLAS/MKL pinned to --threads
threads (threadpoolctl; default 1); `size_table` lists them per size with the backend and
the microseconds per unknown, and for PARDISO and CHOLMOD their CPU by phase (analysis,
numeric factorizations, solves), and one more solve per size from cold (the shared patterns
forgotten first: `cold_cpu_s`, the goals' `cpu_us_per_unknown_spread_cold`);
--compare-threads 1 2 adds the same solves per thread count (`threads_table`); --backends
ldl cholmod times the same solve with each linear backend in turn (`backend_table`: where
CHOLMOD overtakes qdldl), and with --backend-path-scale S the verification's load paths at
1:S too (`backend_paths`). The ratio to OpenSeesPy at 61 x 21 is
also measured pair by pair (`paired_ratio`: PAIRS pairs, alternating, one thread each; wall
and CPU time of each whole call, median and range, with the load average; in a fresh process
and in this one, see `paired_both`), with where a printgen solve's CPU goes, cold and warm
(`solve_phases`); --opensees-only measures only that.
Writes bench_solver.json and bench_solver.png (--opensees-only: bench_solver_opensees.json).
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
from pathlib import Path

import numpy as np

from printgen.solver import solve, solve_path
from printgen.solver.driver import FastSolver
from printgen.solver.linsolve import Cholmod, Pardiso
from printgen.solver.loads import total_forces
from printgen.solver.newton import MAX_ITER
from printgen.solver.pattern import clear_shared
from printgen.solver.scenes import simple_scene

REFERENCE_TOL = 1e-13  # the reference solve: round-off level
TOLERANCES = (1e-4, 1e-6, 1e-8)  # printgen's runs: out-of-balance force / load
GOAL_TOL = 1e-6  # the solver's speed goals are stated at this tolerance
REPEAT = 3  # timing repeats at GOAL_TOL (best kept)
PAIRS = 7  # printgen / OpenSeesPy timing pairs at 61 x 21, alternating which runs first
SIZES = {1: "61 x 21", 2: "121 x 41", 4: "241 x 81", 8: "481 x 161"}
LINEAR_FROM = 10_000  # goal: cost per unknown within 3x from here (14k) to 228k unknowns
THREADS = 1  # BLAS/MKL threads of the size runs (--threads)
BACKEND_REFINES = (1.0, 1.5, 2.0, 4.0)  # --backends sizes: 3.4k, 7.7k, 14k, 57k unknowns
COMPARED = (1, 2, 4)  # sizes also run by OpenSeesPy and by the reference path
EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "realistic_barrier.toml"
EXAMPLE_SCALE = 40.0  # the 1:40 verification whose load paths are timed


def _load() -> list[float] | None:
    """The 1, 5 and 15 min load averages (`uptime`'s), None where the OS has none."""
    return list(os.getloadavg()) if hasattr(os, "getloadavg") else None


def _threads() -> int | None:
    """Threads of this process now (/proc/self/task; None off Linux)."""
    try:
        return len(os.listdir("/proc/self/task"))
    except OSError:
        return None


def _spread(values: list[float]) -> dict:
    return {"median": float(np.median(values)), "min": float(min(values)),
            "max": float(max(values))}


def paired_ratio(pairs: int = PAIRS) -> dict:
    """OpenSeesPy's time over printgen's at 61 x 21 (tol GOAL_TOL), measured pair by pair in
    this process, alternating which of the two runs first, one thread each: on a shared
    machine the load changes between runs, and a pair taken back to back sees about the same
    load. Each side is timed around its whole call (printgen's `solve`, its NetSystem built
    inside; OpenSees's model built inside), wall (perf_counter) and CPU (process_time: far
    less sensitive to the other processes); OpenSees's test is printgen's (max-norm, tol of
    printgen's force scale: `opensees_net`). Median and range of the per-pair ratios.

    printgen's repeated solves of the one net reuse its tangent pattern and the last solve's
    factorization objects (`shared_pattern`, `shared_extras`: kept per topology and process,
    as along a fit or a band); each pair also times a cold printgen solve (all of those
    forgotten first: the pattern built and the orderings computed inside the call, as
    OpenSees builds its model), reported as `cold_cpu` and `cold_wall`."""
    from threadpoolctl import threadpool_info, threadpool_limits

    sc = simple_scene(refine=1, current_z=False)
    net = sc.net
    try:
        import openseespy.opensees  # noqa: F401

        from benchmarks.opensees_net import STEPS, solve_opensees
    except (ImportError, RuntimeError) as exc:
        return {"skipped": f"OpenSeesPy not available: {exc}"}
    loads = total_forces(sc.loads_at(1.0), net.nodes)[0]

    def printgen_s(cold: bool = False) -> tuple[float, float, float]:
        if cold:
            clear_shared()
        w, c = time.perf_counter(), time.process_time()
        r = solve(net, sc.loads_at(1.0), tol=GOAL_TOL)
        c, w = time.process_time() - c, time.perf_counter() - w
        assert r.converged, r.reason
        return w, c, r.seconds

    scale = solve(net, sc.loads_at(1.0), tol=GOAL_TOL).load_norm  # also: imports, caches

    def opensees_s() -> tuple[float, float]:
        _, seconds, ok, note, cpu = solve_opensees(net.nodes, net.fixed, net.elements,
                                                   net.laws[0].slopes[0], loads,
                                                   force_scale=scale, tol=GOAL_TOL)
        assert ok, note
        return seconds, cpu

    load_before, threads = _load(), {"before": _threads()}
    with threadpool_limits(limits=1):
        pinned = [{k: p[k] for k in ("user_api", "internal_api", "prefix", "num_threads")}
                  for p in threadpool_info()]
        printgen_s()
        times = _alternate(printgen_s, opensees_s, pairs)
        phases = solve_phases(net, sc.loads_at(1.0), pairs)
    threads["after"] = _threads()
    return {"size": SIZES[1], **_summary(times), "phases_cpu_ms": phases,
            "opensees": f"{STEPS} load steps, BandSPD, NormUnbalance (max-norm) at {GOAL_TOL:g}"
                        " x printgen's force scale; each side timed around its whole call",
            "force_scale_n": scale, "threads_per_library": pinned, "opensees_blas": opensees_blas(),
            "process_threads": threads, "load_average_before": load_before,
            "load_average_after": _load()}


def solve_phases(net, loads, runs: int) -> dict:
    """Where a printgen solve's CPU goes, cold (the shared patterns and factorization
    objects forgotten first, as in `paired_ratio`'s cold solve) and warm, measured apart from
    the pairs: the tangent pattern built alone (`Pattern`), the set-up (`FastSolver`: the
    nondimensional net, the pattern, the damping, the incidence, the backend's handle) and
    the solve (`FastSolver.solve`: the membrane start with its Laplacian factorizations,
    then the Newton iterations, whose first factorization orders the tangent when cold).
    Milliseconds, median of `runs`."""
    from printgen.solver.pattern import Pattern

    out = {}
    for kind in ("cold", "warm"):
        times: dict[str, list[float]] = {"pattern": [], "setup": [], "solve": []}
        for _ in range(runs):
            if kind == "cold":
                clear_shared()
            c = time.process_time()
            fs = FastSolver(net)
            times["setup"].append(time.process_time() - c)
            c = time.process_time()
            r = fs.solve(loads, [], GOAL_TOL, MAX_ITER)
            times["solve"].append(time.process_time() - c)
            assert r.converged, r.reason
            ns = fs.ns
            c = time.process_time()
            if kind == "cold":
                Pattern(ns.n, ns.free, ns.bars.i, ns.bars.j, [k.nodes for k in ns.cables])
            times["pattern"].append(time.process_time() - c)  # warm: shared, not built
        out[kind] = {k: 1e3 * float(np.median(v)) for k, v in times.items()}
    return out


def _alternate(printgen_s, opensees_s, pairs: int) -> list[dict]:
    """`pairs` pairs of timings, printgen (then its cold solve) first in the even pairs,
    OpenSees (then printgen's cold solve) in the odd ones."""
    times = []
    for k in range(pairs):
        if k % 2 == 0:
            pg = printgen_s()
            cold = printgen_s(cold=True)
            os_ = opensees_s()
        else:
            os_ = opensees_s()
            cold = printgen_s(cold=True)
            pg = printgen_s()
        times.append({"printgen_wall_s": pg[0], "printgen_cpu_s": pg[1],
                      "printgen_result_s": pg[2], "printgen_cold_wall_s": cold[0],
                      "printgen_cold_cpu_s": cold[1], "opensees_wall_s": os_[0],
                      "opensees_cpu_s": os_[1]})
    return times


def opensees_blas() -> str:
    """What serves OpenSeesPy's LAPACK and BLAS calls in this process: its bundled LAPACK
    binds them through the global symbol scope, so MKL, once loaded (pypardiso), takes them
    over from the system's reference BLAS (seen with LD_DEBUG=bindings: dpbtrf_, dgemm_,
    dtrsm_, dsyrk_ bound to libmkl_intel_lp64)."""
    try:
        with open("/proc/self/maps") as maps:
            loaded = maps.read()
    except OSError:
        return "unknown"
    return "MKL (1 thread)" if "libmkl_intel_lp64" in loaded else "reference BLAS (libblas3)"


def paired_both() -> dict:
    """`paired_ratio` twice: in a fresh process without MKL (OpenSeesPy as packaged, on the
    reference BLAS), then in this one (MKL loaded by then, when installed: OpenSeesPy's
    factorizations about twice as fast)."""
    import multiprocessing

    with multiprocessing.get_context("spawn").Pool(1) as pool:
        fresh = pool.apply(paired_ratio)
    here = paired_ratio()
    return {"fresh_process": fresh, "this_process": here}


def _summary(times: list[dict]) -> dict:
    """The per-pair ratios (OpenSees / printgen), wall and CPU, and their median and range."""
    wall = [t["opensees_wall_s"] / t["printgen_wall_s"] for t in times]
    cpu = [t["opensees_cpu_s"] / t["printgen_cpu_s"] for t in times]
    cold_wall = [t["opensees_wall_s"] / t["printgen_cold_wall_s"] for t in times]
    cold_cpu = [t["opensees_cpu_s"] / t["printgen_cold_cpu_s"] for t in times]
    return {"pairs": times, "wall_ratios": wall, "cpu_ratios": cpu, "wall": _spread(wall),
            "cpu": _spread(cpu), "cold_wall": _spread(cold_wall), "cold_cpu": _spread(cold_cpu),
            "printgen_cpu_s": _spread([t["printgen_cpu_s"] for t in times]),
            "printgen_cold_cpu_s": _spread([t["printgen_cold_cpu_s"] for t in times]),
            "opensees_cpu_s": _spread([t["opensees_cpu_s"] for t in times])}


def strand_state(net, disp: np.ndarray) -> tuple[float, float]:
    """(max strand strain, max tension N) of a displacement field, from the geometry."""
    x = net.nodes + disp
    i, j = net.elements[:, 0], net.elements[:, 1]
    length0 = np.linalg.norm(net.nodes[j] - net.nodes[i], axis=1)
    eps = np.linalg.norm(x[j] - x[i], axis=1) / length0 - 1
    return float(eps.max()), float(net.laws[0].slopes[0] * max(eps.max(), 0.0))


def robustness() -> list[dict]:
    """The hard cases (robustness), each from the flat start with default settings."""
    cases = [("zero pretension, steel, 61 x 21", {}),
             ("very soft strands (0.5 GPa, ~40 % strain)", {"modulus": 5e8}),
             ("lambda = 100, E / lambda", {"scale": 100, "modulus": 1e9}),
             ("slack 0.2 %, lambda = 1", {"slack": 0.002}),
             ("slack 2 %, lambda = 1", {"slack": 0.02}),
             ("slack 0.2 %, lambda = 100", {"slack": 0.002, "scale": 100, "modulus": 1e9}),
             ("slack 2 %, lambda = 100", {"slack": 0.02, "scale": 100, "modulus": 1e9})]
    out = []
    for name, kw in cases:
        for level in (1.0, 1.1):
            sc = simple_scene(**kw)
            r = solve(sc.net, sc.loads_at(level))
            out.append({"case": name, "relative_loading": level, "converged": r.converged,
                        "iterations": r.iterations, "factorizations": r.factorizations,
                        "time_s": r.seconds, "max_strain": float(r.strains.max()),
                        "reason": r.reason})
    return out


def _solve_once(sc, tol: float, method: str, backend: str | None = None, cold: bool = False):
    """(result, CPU s, the backend's CPU by phase or None, set-up CPU s or None): what
    `solver.solve` does, with the fast path's solver kept to read its PARDISO or CHOLMOD
    object's counters (`_phases`); the set-up is the net's NetSystem (pattern, damping,
    incidence). `backend`: the linear backend (None: `choose_backend`'s). `cold`: the shared
    patterns forgotten first, so the pattern, CHOLMOD's or qdldl's analysis and the
    membrane start's ordering are all computed inside the call, as for a net solved once."""
    if cold:
        clear_shared()
    c0 = time.process_time()
    if method != "fast":
        return solve(sc.net, sc.loads_at(1.0), tol=tol, method=method), \
            time.process_time() - c0, None, None
    fs = FastSolver(sc.net, backend)
    setup = time.process_time() - c0
    before = fs.stepper.handle, _counters(fs.stepper.handle)  # a spare handle: counted before
    r = fs.solve(sc.loads_at(1.0), [], tol, MAX_ITER)
    cpu = time.process_time() - c0
    return r, cpu, _phases(fs.stepper.handle, before), setup


def _counters(handle) -> dict | None:
    """A PARDISO or CHOLMOD object's CPU seconds and calls by phase (`linsolve.PHASES`), as
    {"<phase>_cpu_s": ..., "<phase>_calls": ...}; None for other backends."""
    if not isinstance(handle, Pardiso | Cholmod):
        return None
    return ({f"{name}_cpu_s": handle.cpu[name] for name in handle.cpu}
            | {f"{name}_calls": handle.calls[name] for name in handle.calls})


def _phases(handle, before: tuple) -> dict | None:
    """This solve's part of the handle's counters (a handle reused from an earlier net of the
    pattern has counted that net's too), with the backend's name."""
    now = _counters(handle)
    if now is None:
        return None
    start = before[1] if before[0] is handle and before[1] is not None else {}
    return {"backend": "pardiso" if isinstance(handle, Pardiso) else "cholmod",
            **{k: v - start.get(k, 0) for k, v in now.items()}}


def _run(sc, tol: float, d_ref: float, *, method: str = "fast", repeat: int = 1,
         cold: bool = False) -> dict:
    """One printgen solve at `tol` (best wall time and best CPU time of `repeat`; the
    backend's CPU by phase in the run of best CPU). `cold`: one more solve with the shared
    patterns forgotten first (`_solve_once`), its CPU and set-up as `cold_cpu_s` and
    `cold_setup_cpu_s`: a net small enough for the pattern cache (`pattern.SHARED_BYTES`) is
    warm in the repeats (its pattern and analysis from the solves before), a larger one cold
    in every solve, so the per-unknown comparison across sizes needs the cold solve too."""
    best, cpu, work, setup = None, float("inf"), None, None
    for _ in range(repeat):
        r, c, w, s = _solve_once(sc, tol, method)
        if c < cpu:
            cpu, work, setup = c, w, s
        best = r if best is None or r.seconds < best.seconds else best
    d = float(best.displacements[sc.centre, 1])
    out = {"tool": "printgen" if method == "fast" else "printgen reference path (before)",
           "tol": tol, "converged": best.converged, "max_strain": float(best.strains.max()),
           "max_tension_n": float(best.tensions.max()), "iterations": best.iterations,
           "factorizations": best.factorizations, "backend": best.backend,
           "time_s": best.seconds, "cpu_s": cpu, "setup_cpu_s": setup, "phases": work,
           "deflection_m": d,
           "error": abs(d / d_ref - 1)}
    if cold:
        r, c, w, s = _solve_once(sc, tol, method, cold=True)
        out |= {"cold_cpu_s": c, "cold_setup_cpu_s": s, "cold_phases": w,
                "cold_converged": r.converged}
    return out


def bench_size(refine: int) -> dict:
    sc = simple_scene(refine=refine, current_z=False)
    ref = solve(sc.net, sc.loads_at(1.0), tol=REFERENCE_TOL, strict=True)
    d_ref = float(ref.displacements[sc.centre, 1])
    runs = [_run(sc, tol, d_ref, repeat=REPEAT if tol == GOAL_TOL else 1, cold=tol == GOAL_TOL)
            for tol in TOLERANCES]
    if refine in COMPARED:
        runs.append(_run(sc, GOAL_TOL, d_ref, method="reference"))
    cur = simple_scene(refine=refine, current_z=True)
    rc = solve(cur.net, cur.loads_at(1.0), tol=1e-8)
    runs.append({"tool": "printgen (load at current node height)", "tol": 1e-8,
                 "converged": rc.converged, "iterations": rc.iterations,
                 "factorizations": rc.factorizations, "time_s": rc.seconds,
                 "deflection_m": float(rc.displacements[cur.centre, 1]), "error": None})
    if refine in COMPARED:
        runs.append(_opensees(sc, d_ref, ref.load_norm))
    unknowns = int((~sc.net.fixed_dofs).sum())
    goal = next(r for r in runs if r["tool"] == "printgen" and r["tol"] == GOAL_TOL)
    return {"size": SIZES.get(refine, f"refine {refine}"), "nodes": len(sc.net.nodes),
            "strands": len(sc.net.elements), "unknowns": unknowns,
            "reference_deflection_m": d_ref, "reference_time_s": ref.seconds,
            "reference_iterations": ref.iterations,
            "slack_strands_at_reference": int(ref.slack.sum()),
            "us_per_unknown_at_goal_tol": 1e6 * goal["time_s"] / unknowns,
            "cpu_us_per_unknown_at_goal_tol": 1e6 * goal["cpu_s"] / unknowns,
            "cold_cpu_us_per_unknown_at_goal_tol": 1e6 * goal["cold_cpu_s"] / unknowns,
            "runs": runs}


def size_table(results: list[dict], threads: int) -> list[dict]:
    """The size table: printgen at GOAL_TOL per size, best of REPEAT."""
    out = []
    for res in results:
        goal = next(r for r in res["runs"] if r["tool"] == "printgen" and r["tol"] == GOAL_TOL)
        out.append({"size": res["size"], "unknowns": res["unknowns"],
                    "backend": goal["backend"], "blas_threads": threads,
                    "iterations": goal["iterations"], "factorizations": goal["factorizations"],
                    "wall_s": goal["time_s"], "cpu_s": goal["cpu_s"],
                    "setup_cpu_s": goal.get("setup_cpu_s"),
                    "us_per_unknown_wall": res["us_per_unknown_at_goal_tol"],
                    "us_per_unknown_cpu": res["cpu_us_per_unknown_at_goal_tol"],
                    "phases": goal.get("phases"), "cold_cpu_s": goal.get("cold_cpu_s"),
                    "cold_setup_cpu_s": goal.get("cold_setup_cpu_s"),
                    "cold_us_per_unknown_cpu": res.get("cold_cpu_us_per_unknown_at_goal_tol"),
                    "cold_phases": goal.get("cold_phases")})
    return out


def thread_table(sizes: list[int], counts: list[int]) -> list[dict]:
    """printgen at GOAL_TOL per size with BLAS/MKL pinned to each thread count in turn (best
    of REPEAT, wall and CPU): PARDISO's factorizations are what a second thread speeds up."""
    from threadpoolctl import threadpool_limits

    out = []
    for size in sizes:
        sc = simple_scene(refine=size, current_z=False)
        unknowns = int((~sc.net.fixed_dofs).sum())
        for threads in counts:
            with threadpool_limits(limits=threads):
                runs = [_solve_once(sc, GOAL_TOL, "fast") for _ in range(REPEAT)]
            r = runs[0][0]
            out.append({"size": SIZES.get(size, f"refine {size}"), "unknowns": unknowns,
                        "blas_threads": threads, "converged": r.converged,
                        "iterations": r.iterations, "factorizations": r.factorizations,
                        "wall_s": min(x[0].seconds for x in runs),
                        "cpu_s": min(x[1] for x in runs),
                        "load_average": list(os.getloadavg()) if hasattr(os, "getloadavg")
                        else None})
    return out


def backend_table(refines: list[float], backends: list[str], threads: int = THREADS
                  ) -> list[dict]:
    """printgen at GOAL_TOL per size with each linear backend in turn (best CPU of REPEAT,
    the net's set-up included, BLAS pinned to `threads`): where one backend overtakes another
    (`linsolve.CHOLMOD_MIN_DOFS`). A backend that is not installed is listed as skipped."""
    from threadpoolctl import threadpool_limits

    from printgen.solver import linsolve

    installed = {"ldl": linsolve.ldl_available, "cholmod": linsolve.cholmod_available,
                 "pardiso": linsolve.pardiso_available, "lu": lambda: True}
    out = []
    for refine in refines:
        sc = simple_scene(refine=refine, current_z=False)
        unknowns = int((~sc.net.fixed_dofs).sum())
        for backend in backends:
            row: dict = {"refine": refine, "unknowns": unknowns, "backend": backend}
            if not installed.get(backend, lambda: False)():
                out.append({**row, "skipped": f"{backend} not installed"})
                continue
            with threadpool_limits(limits=threads):
                runs = [_solve_once(sc, GOAL_TOL, "fast", backend) for _ in range(REPEAT)]
            r = runs[0][0]
            out.append({**row, "converged": r.converged, "iterations": r.iterations,
                        "factorizations": r.factorizations,
                        "cpu_s": min(x[1] for x in runs),
                        "wall_s": min(x[0].seconds for x in runs),
                        "deflection_m": float(r.displacements[sc.centre, 1]),
                        "load_average": _load()})
    return out


def backend_paths(scale: float, backends: list[str], threads: int = THREADS) -> list[dict]:
    """The verification's load paths at 1:`scale`, each solved with every installed backend in
    turn (CPU, iterations, factorizations, and the largest displacement difference to the
    first backend's, relative to its largest displacement): along a path a backend's
    analysis is paid once, so the crossover differs from a single solve's. The backend is
    imposed by replacing `solver.fast.choose_backend` for the duration of each path."""
    from threadpoolctl import threadpool_limits

    from printgen.solver import fast, linsolve

    installed = {"ldl": linsolve.ldl_available, "cholmod": linsolve.cholmod_available,
                 "pardiso": linsolve.pardiso_available, "lu": lambda: True}
    usable = [b for b in backends if installed.get(b, lambda: False)()]
    out, original = [], fast.choose_backend
    for k, (net, loads_at, levels, kw) in enumerate(capture_verification_paths(scale)):
        first = None
        for backend in usable:
            fast.choose_backend = lambda size, b=backend: b
            try:
                with threadpool_limits(limits=threads):
                    c0 = time.process_time()
                    res = solve_path(net, loads_at, levels, **kw)
                    cpu = time.process_time() - c0
            finally:
                fast.choose_backend = original
            disp = np.array([r.displacements for r in res])
            first = disp if first is None else first
            diff = (float(np.abs(disp - first).max() / np.abs(first).max())
                    if disp.shape == first.shape and np.abs(first).max() > 0 else None)
            out.append({"scale": scale, "path": k, "unknowns": int((~net.fixed_dofs).sum()),
                        "levels": len(levels), "backend": backend, "cpu_s": cpu,
                        "converged_levels": sum(r.converged for r in res),
                        "iterations": sum(r.iterations for r in res),
                        "factorizations": sum(r.factorizations for r in res),
                        "difference_to_first": diff})
    return out


def capture_verification_paths(scale: float = EXAMPLE_SCALE) -> list[tuple]:
    """(net, loads_at, levels, keywords) of every load path the verification at 1:`scale`
    (default 1:40) solves, recorded while it runs (serially, in this process)."""
    from printgen import solver
    from printgen.run.api import verify

    captured, original = [], solver.solve_path

    def recording(net, loads_at, levels, **kw):
        captured.append((net, loads_at, list(levels), kw))
        return original(net, loads_at, levels, **kw)

    os.environ["PRINTGEN_SERIAL"] = "1"
    solver.solve_path = recording
    try:
        verify(EXAMPLE, scale)
    finally:
        solver.solve_path = original
        del os.environ["PRINTGEN_SERIAL"]
    return captured


def bench_tent(net, tol: float) -> dict:
    """The "tent": the 1:40 model net with no water, pulled only by three 1 N sensor loads
    (flow-wise, at the free nodes nearest the bed-centre, the top-centre and the centre).
    Most strands stay slack, many nodes have no stiffness: the hardest start there is."""
    from printgen.solver import PointLoads

    x = np.asarray(net.nodes)
    lo, span = x.min(axis=0), np.ptp(x, axis=0)
    rel = (x - lo) / np.where(span > 0, span, 1.0)
    free = np.flatnonzero(~net.fixed_dofs.all(axis=1))
    picks = [int(free[np.argmin(np.hypot(rel[free, 0] - a, rel[free, 2] - b))])
             for a, b in ((0.5, 0.0), (0.5, 1.0), (0.5, 0.5))]
    loads = [PointLoads(np.array(picks), np.tile([0.0, 1.0, 0.0], (len(picks), 1)))]
    out = {"nodes": len(x), "sensor_nodes": picks, "tol": tol}
    for method in ("fast", "reference"):
        r = solve(net, loads, tol=tol, method=method)
        out[method] = {"converged": r.converged, "iterations": r.iterations,
                       "factorizations": r.factorizations, "time_s": r.seconds}
    return out


def bench_paths(captured: list[tuple]) -> list[dict]:
    """Each verification load path by both paths: time, iterations and factorizations per
    level."""
    out = []
    for k, (net, loads_at, levels, kw) in enumerate(captured):
        row = {"path": k, "nodes": len(net.nodes), "strands": len(net.elements),
               "cables": len(net.cables), "levels": len(levels)}
        for method in ("fast", "reference"):
            t = time.perf_counter()
            res = solve_path(net, loads_at, levels, method=method, **kw)
            row[method] = {"time_s": time.perf_counter() - t,
                           "converged_levels": sum(r.converged for r in res),
                           "iterations": [r.iterations for r in res],
                           "factorizations": [r.factorizations for r in res]}
        fac = row["fast"]["factorizations"]
        row["fast"]["factorizations_per_level"] = sum(fac) / max(len(fac), 1)
        out.append(row)
    return out


def _opensees(sc, d_ref: float, scale: float) -> dict:
    try:
        import openseespy.opensees  # noqa: F401

        from benchmarks.opensees_net import solve_opensees
    except (ImportError, RuntimeError) as exc:
        return {"tool": "OpenSeesPy", "skipped": f"not available: {exc} "
                "(pip install 'printgen[bench]'; Debian needs libblas3 liblapack3)"}
    net = sc.net
    loads = total_forces(sc.loads_at(1.0), net.nodes)[0]
    disp, seconds, ok, note, cpu = solve_opensees(net.nodes, net.fixed, net.elements,
                                                  net.laws[0].slopes[0], loads,
                                                  force_scale=scale, tol=GOAL_TOL)
    d = float(disp[sc.centre, 1])
    strain, tension = strand_state(net, disp)
    return {"tool": "OpenSeesPy", "converged": ok, "time_s": seconds, "cpu_s": cpu,
            "note": f"{note}, {opensees_blas()}",
            "max_strain": strain, "max_tension_n": tension,
            "deflection_m": d, "error": abs(d / d_ref - 1) if ok else None}


def figure(results: list[dict], path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (ax, bx) = plt.subplots(1, 2, figsize=(11, 4.5), constrained_layout=True)
    for k, res in enumerate(results):
        pg = [r for r in res["runs"] if r["tool"] == "printgen"]
        ax.loglog([r["time_s"] for r in pg], [max(r["error"], 1e-16) for r in pg], "-o",
                  color=f"C{k}", label=f"printgen {res['size']}")
        os_ = [r for r in res["runs"] if r["tool"] == "OpenSeesPy" and r.get("error")]
        if os_:
            ax.loglog([os_[0]["time_s"]], [os_[0]["error"]], "s", color=f"C{k}", ms=9,
                      mfc="none", label=f"OpenSeesPy {res['size']}")
    ax.set_xlabel("wall time (s)")
    ax.set_ylabel("relative error, mid-height deflection")
    ax.set_title("simple-pinned: speed against error")
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=7)
    for tool, style in (("printgen", "-o"), ("printgen reference path (before)", "--s"),
                        ("OpenSeesPy", ":^")):
        pts = [(res["unknowns"], r["time_s"]) for res in results for r in res["runs"]
               if r["tool"] == tool and r.get("tol", GOAL_TOL) == GOAL_TOL and "time_s" in r]
        if pts:
            bx.loglog(*zip(*pts, strict=True), style, label=tool)
    if results:
        n0 = results[0]["unknowns"]
        t0 = next(r["time_s"] for r in results[0]["runs"]
                  if r["tool"] == "printgen" and r["tol"] == GOAL_TOL)
        n = np.array([res["unknowns"] for res in results])
        bx.loglog(n, t0 * n / n0, color="0.6", lw=0.8, label="linear in unknowns")
    bx.set_xlabel("unknowns")
    bx.set_ylabel(f"wall time at tol {GOAL_TOL:g} (s)")
    bx.set_title("time against size")
    bx.grid(alpha=0.3, which="both")
    bx.legend(fontsize=7)
    fig.savefig(path, dpi=110, metadata={"Software": None})
    plt.close(fig)


def goals(results: list[dict], paths: list[dict], tent: dict | None,
          paired: dict | None = None) -> dict:
    """The solver's speed targets, each with its measured figure."""
    def at(size: str, tool: str):
        for res in results:
            if res["size"] == size:
                return next((r for r in res["runs"] if r["tool"] == tool
                             and r.get("tol", GOAL_TOL) == GOAL_TOL and r.get("converged")),
                            None)
        return None

    out = {}
    pg, os_ = at("61 x 21", "printgen"), at("61 x 21", "OpenSeesPy")
    if pg and os_:
        out["speedup_vs_opensees_61x21"] = os_["time_s"] / pg["time_s"]
    for run in (paired or {}).values():
        if "cpu" in run:
            out[f"opensees_ratio_61x21_paired ({run['opensees_blas']})"] = {
                k: run[k] for k in ("cpu", "wall", "cold_cpu", "cold_wall")}
    big = at("241 x 81", "printgen")
    if big:
        out["time_241x81_s"] = big["time_s"]
        out["cpu_241x81_s"] = big["cpu_s"]
    per = {res["size"]: res["us_per_unknown_at_goal_tol"] for res in results}
    out["us_per_unknown"] = per
    cpu = {res["size"]: res["cpu_us_per_unknown_at_goal_tol"] for res in results
           if res["unknowns"] >= LINEAR_FROM}
    out["cpu_us_per_unknown"] = cpu
    if len(cpu) > 1:  # goal: within 3x from 14k to 228k unknowns
        out["cpu_us_per_unknown_spread"] = max(cpu.values()) / min(cpu.values())
    # the same from one cold solve per size: the best of REPEAT above reuses the pattern and
    # the factorization's analysis of the solves before it up to pattern.SHARED_BYTES (241 x
    # 81 nodes), and builds them in every solve beyond (481 x 161)
    cold = {res["size"]: res["cold_cpu_us_per_unknown_at_goal_tol"] for res in results
            if res["unknowns"] >= LINEAR_FROM and "cold_cpu_us_per_unknown_at_goal_tol" in res}
    out["cpu_us_per_unknown_cold"] = cold
    if len(cold) > 1:
        out["cpu_us_per_unknown_spread_cold"] = max(cold.values()) / min(cold.values())
    if tent:
        out["tent_iterations"] = {m: tent[m]["iterations"] for m in ("fast", "reference")}
    if paths:
        out["path_time_s"] = {m: [p[m]["time_s"] for p in paths] for m in ("fast", "reference")}
        out["path_factorizations_per_level"] = [p["fast"]["factorizations_per_level"]
                                                for p in paths]
    return out


def run(out: Path, sizes: list[int], with_paths: bool = True, threads: int = THREADS,
        compare_threads: list[int] | None = None, backends: list[str] | None = None,
        backend_refines: list[float] | None = None, path_scale: float | None = None) -> dict:
    from threadpoolctl import threadpool_limits

    from printgen.solver.linsolve import pardiso_available

    out.mkdir(parents=True, exist_ok=True)
    t0 = time.perf_counter()
    results = []
    pardiso_available()  # loads MKL (when installed) before threadpoolctl pins its threads
    with threadpool_limits(limits=threads):
        for k, size in enumerate(sizes, 1):  # progress on stderr: the largest takes minutes
            print(f"[{k}/{len(sizes)}] mesh x{size} ({time.perf_counter() - t0:.0f} s so far)",
                  file=sys.stderr, flush=True)
            results.append(bench_size(size))
    if with_paths:
        print("verification load paths ...", file=sys.stderr, flush=True)
    captured = capture_verification_paths() if with_paths else []
    paths = bench_paths(captured)
    tent = bench_tent(captured[0][0], captured[0][3].get("tol", GOAL_TOL)) if captured else None
    paired = paired_both() if 1 in sizes else None
    by_threads = thread_table(sizes, compare_threads) if compare_threads else []
    by_backend = backend_table(backend_refines or list(BACKEND_REFINES), backends, threads) \
        if backends else []
    by_backend_path = backend_paths(path_scale, backends, threads) \
        if backends and path_scale else []
    report = {"benchmark": "bench_solver", "scene": "simple-pinned",
              "load": "hydrostatic at h = h_B + drag at 6 m/s, at the initial node height",
              "reference_tol": REFERENCE_TOL, "goal_tol": GOAL_TOL, "blas_threads": threads,
              "load_average": _load(),
              "size_table": size_table(results, threads), "threads_table": by_threads,
              "backend_table": by_backend, "backend_paths": by_backend_path,
              "sizes": results,
              "verification_paths": paths, "tent": tent, "robustness": robustness(),
              "opensees_paired": paired, "goals": goals(results, paths, tent, paired),
              "total_s": time.perf_counter() - t0}
    (out / "bench_solver.json").write_text(json.dumps(report, indent=1) + "\n")
    figure(results, out / "bench_solver.png")
    return report


def _phases_note(w: dict | None) -> str:
    """PARDISO's or CHOLMOD's share of a solve's CPU, by phase ("" for other backends)."""
    if not w:
        return ""
    return (f"  ({w['backend'].upper()}: analysis {w['analysis_cpu_s']:.2f} s, "
            f"{w['factorization_calls']} factorizations {w['factorization_cpu_s']:.2f} s, "
            f"{w['solve_calls']} solves {w['solve_cpu_s']:.2f} s)")


def _print_paired(paired: dict | None) -> None:
    for where, pair in (paired or {}).items():
        if "cpu" not in pair:
            print(f"OpenSeesPy pairs ({where}): {pair.get('skipped', 'not run')}")
            continue
        print(f"OpenSeesPy ({pair['opensees_blas']}) / printgen at {pair['size']} ({where}), "
              f"{len(pair['pairs'])} alternating pairs, 1 thread each, load "
              f"{pair['load_average_before'][0]:.1f} -> {pair['load_average_after'][0]:.1f}: "
              + ", ".join(f"{k} median {pair[k]['median']:.1f}x (range {pair[k]['min']:.1f}-"
                          f"{pair[k]['max']:.1f}x)" for k in ("cpu", "wall", "cold_cpu",
                                                              "cold_wall")))
        for kind, ms in pair.get("phases_cpu_ms", {}).items():
            print(f"  printgen {kind} solve, CPU ms (median): " + ", ".join(
                f"{k} {v:.1f}" for k, v in ms.items()))


def _opensees_only(out: Path) -> int:
    """--opensees-only: `paired_both` alone, written to bench_solver_opensees.json."""
    out.mkdir(parents=True, exist_ok=True)
    paired = paired_both()
    path = out / "bench_solver_opensees.json"
    path.write_text(json.dumps({"benchmark": "bench_solver", "scene": "simple-pinned",
                                "goal_tol": GOAL_TOL, "opensees_paired": paired}, indent=1)
                    + "\n")
    _print_paired(paired)
    print(f"all numbers: {path}")
    return 0


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", required=True, type=Path)
    ap.add_argument("--sizes", type=int, nargs="+", default=list(SIZES),
                    help="mesh refinements: 1 = 61 x 21, 2 = 121 x 41, 4 = 241 x 81, 8 = 481 x 161")
    ap.add_argument("--no-paths", action="store_true", help="skip the verification load paths")
    ap.add_argument("--threads", type=int, default=THREADS,
                    help=f"BLAS/MKL threads of the size runs (default {THREADS})")
    ap.add_argument("--compare-threads", type=int, nargs="+", metavar="N",
                    help="also time each size at tol 1e-6 with each of these thread counts")
    ap.add_argument("--backends", nargs="+", metavar="NAME",
                    help="also time each backend (ldl, cholmod, pardiso, lu) at tol 1e-6")
    ap.add_argument("--backend-refine", type=float, nargs="+", metavar="R",
                    help=f"mesh refinements of --backends (default {list(BACKEND_REFINES)})")
    ap.add_argument("--backend-path-scale", type=float, metavar="S",
                    help="with --backends: also solve the verification's load paths at 1:S "
                         "with each backend")
    ap.add_argument("--json", action="store_true", help="print the goals as JSON")
    ap.add_argument("--opensees-only", action="store_true",
                    help="only the paired OpenSeesPy / printgen ratio at 61 x 21")
    a = ap.parse_args(argv)
    if a.opensees_only:
        return _opensees_only(a.out)
    report = run(a.out, a.sizes, not a.no_paths, a.threads, a.compare_threads, a.backends,
                 a.backend_refine, a.backend_path_scale)
    for res in report["sizes"]:
        for r in res["runs"]:
            err = r.get("error")
            if "skipped" in r:  # e.g. OpenSeesPy not installed: say so, not "nan s"
                print(f"{res['size']:9s} {r['tool']:40s} skipped: {r['skipped']}")
                continue
            print(f"{res['size']:9s} {r['tool']:40s} tol {r.get('tol', '-')!s:6s} "
                  f"{r.get('time_s', float('nan')):7.2f} s  it {r.get('iterations', '-')!s:4s} "
                  f"fact {r.get('factorizations', '-')!s:4s} error "
                  f"{'-' if err is None else f'{err:.1e}'}")
    for row in report["size_table"]:
        print(f"{row['size']:9s} {row['unknowns']:7d} unknowns  {row['backend']:8s} "
              f"{row['blas_threads']} thread(s)  wall {row['wall_s']:6.2f} s  cpu "
              f"{row['cpu_s']:6.2f} s  {row['us_per_unknown_cpu']:5.1f} us/unknown (cpu)  it "
              f"{row['iterations']} fact {row['factorizations']} (set-up "
              f"{row['setup_cpu_s']:.2f} s){_phases_note(row['phases'])}")
        if row["cold_cpu_s"] is not None:
            print(f"{'':9s} {'':7s} cold (pattern and analysis in the call): cpu "
                  f"{row['cold_cpu_s']:6.2f} s  {row['cold_us_per_unknown_cpu']:5.1f} us/unknown "
                  f"(cpu)  (set-up {row['cold_setup_cpu_s']:.2f} s)"
                  f"{_phases_note(row['cold_phases'])}")
    for row in report["threads_table"]:
        print(f"{row['size']:9s} {row['blas_threads']} thread(s): wall {row['wall_s']:6.2f} s  "
              f"cpu {row['cpu_s']:6.2f} s  it {row['iterations']} fact {row['factorizations']}")
    for row in report["backend_table"]:
        head = f"{row['unknowns']:7d} unknowns  {row['backend']:8s}"
        if "skipped" in row:
            print(f"{head} skipped: {row['skipped']}")
            continue
        print(f"{head} cpu {row['cpu_s']:7.3f} s  wall {row['wall_s']:7.3f} s  it "
              f"{row['iterations']} fact {row['factorizations']}  deflection "
              f"{row['deflection_m']:.12e} m")
    for row in report["backend_paths"]:
        diff = row["difference_to_first"]
        print(f"path {row['path']} at 1:{row['scale']:g} ({row['unknowns']} unknowns, "
              f"{row['levels']} levels) {row['backend']:8s} cpu {row['cpu_s']:6.2f} s  it "
              f"{row['iterations']} fact {row['factorizations']}  converged "
              f"{row['converged_levels']}  difference {'-' if diff is None else f'{diff:.1e}'}")
    for p in report["verification_paths"]:
        print(f"path {p['path']} ({p['nodes']} nodes, {p['levels']} levels): fast "
              f"{p['fast']['time_s']:.2f} s, {sum(p['fast']['iterations'])} it, "
              f"{p['fast']['factorizations_per_level']:.1f} fact/level; reference "
              f"{p['reference']['time_s']:.2f} s, {sum(p['reference']['iterations'])} it")
    _print_paired(report.get("opensees_paired"))
    if a.json:
        print(json.dumps(report["goals"], indent=1))
    else:
        for key, value in report["goals"].items():
            print(f"goal {key}: {value}")
        print(f"all numbers: {a.out / 'bench_solver.json'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
