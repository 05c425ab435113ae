"""Benchmark: the solver's speed against its error on scene simple-pinned (barrier-physics.md,
section 7) at 61 x 21, 121 x 41 and 241 x 81 nodes, with OpenSeesPy side by side.

    python -m benchmarks.bench_solver --out DIR [--sizes 1 2 4]

Errors are the mid-height centre deflection against a tight-tolerance reference solve of the
same size (relative). Loads at the initial node height (the variant OpenSees can model);
printgen's current-height variant is timed too. Writes bench_solver.json and bench_solver.png.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np

from solver import solve
from solver.loads import total_forces
from solver.scenes import simple_scene

REFERENCE_TOL = 1e-13  # the reference solve: round-off level
TOLERANCES = (1e-4, 1e-6, 1e-8)  # printgen's runs: out-of-balance force / load
SIZES = {1: "61 x 21", 2: "121 x 41", 4: "241 x 81"}


def strand_state(net, disp: np.ndarray) -> tuple[float, float]:
    """(max strand strain, max tension N) of a displacement field, from the geometry."""
    x = net.nodes + disp
    i, j = net.elements[:, 0], net.elements[:, 1]
    length0 = np.linalg.norm(net.nodes[j] - net.nodes[i], axis=1)
    eps = np.linalg.norm(x[j] - x[i], axis=1) / length0 - 1
    return float(eps.max()), float(net.laws[0].slopes[0] * max(eps.max(), 0.0))


def robustness() -> list[dict]:
    """The hard cases of issue 4, each from the flat start with default settings."""
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
                        "iterations": r.iterations, "time_s": r.seconds,
                        "max_strain": float(r.strains.max()), "reason": r.reason})
    return out


def bench_size(refine: int) -> dict:
    sc = simple_scene(refine=refine, current_z=False)
    ref = solve(sc.net, sc.loads_at(1.0), tol=REFERENCE_TOL, strict=True)
    d_ref = float(ref.displacements[sc.centre, 1])
    runs = []
    for tol in TOLERANCES:
        r = solve(sc.net, sc.loads_at(1.0), tol=tol)
        runs.append({"tool": "printgen", "tol": tol, "converged": r.converged,
                     "max_strain": float(r.strains.max()), "max_tension_n": float(r.tensions.max()),
                     "iterations": r.iterations, "time_s": r.seconds,
                     "deflection_m": float(r.displacements[sc.centre, 1]),
                     "error": abs(float(r.displacements[sc.centre, 1]) / d_ref - 1)})
    cur = simple_scene(refine=refine, current_z=True)
    rc = solve(cur.net, cur.loads_at(1.0), tol=1e-8)
    runs.append({"tool": "printgen (load at current node height)", "tol": 1e-8,
                 "converged": rc.converged, "iterations": rc.iterations, "time_s": rc.seconds,
                 "deflection_m": float(rc.displacements[cur.centre, 1]), "error": None})
    runs.append(_opensees(sc, d_ref))
    return {"size": SIZES.get(refine, f"refine {refine}"), "nodes": len(sc.net.nodes),
            "strands": len(sc.net.elements), "reference_deflection_m": d_ref,
            "reference_time_s": ref.seconds, "reference_iterations": ref.iterations,
            "slack_strands_at_reference": int(ref.slack.sum()), "runs": runs}


def _opensees(sc, d_ref: float) -> dict:
    try:
        import openseespy.opensees  # noqa: F401

        from benchmarks.opensees_net import solve_opensees
    except (ImportError, RuntimeError) as exc:
        return {"tool": "OpenSeesPy", "skipped": f"not available: {exc} "
                "(pip install 'printgen[bench]'; Debian needs libblas3 liblapack3)"}
    net = sc.net
    loads = total_forces(sc.loads_at(1.0), net.nodes)[0]
    disp, seconds, ok, note = solve_opensees(net.nodes, net.fixed, net.elements,
                                             net.laws[0].slopes[0], loads)
    d = float(disp[sc.centre, 1])
    strain, tension = strand_state(net, disp)
    return {"tool": "OpenSeesPy", "converged": ok, "time_s": seconds, "note": note,
            "max_strain": strain, "max_tension_n": tension,
            "deflection_m": d, "error": abs(d / d_ref - 1) if ok else None}


def figure(results: list[dict], path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7, 4.5), constrained_layout=True)
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
    ax.legend(fontsize=8)
    fig.savefig(path, dpi=110, metadata={"Software": None})
    plt.close(fig)


def run(out: Path, sizes: list[int]) -> dict:
    out.mkdir(parents=True, exist_ok=True)
    t0 = time.perf_counter()
    results = [bench_size(s) for s in sizes]
    report = {"benchmark": "bench_solver", "scene": "simple-pinned",
              "load": "hydrostatic at h = h_B + drag at 6 m/s, at the initial node height",
              "reference_tol": REFERENCE_TOL, "sizes": results, "robustness": robustness(),
              "total_s": time.perf_counter() - t0}
    (out / "bench_solver.json").write_text(json.dumps(report, indent=1) + "\n")
    figure(results, out / "bench_solver.png")
    return report


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", required=True, type=Path)
    ap.add_argument("--sizes", type=int, nargs="+", default=list(SIZES),
                    help="mesh refinements: 1 = 61 x 21, 2 = 121 x 41, 4 = 241 x 81")
    a = ap.parse_args(argv)
    report = run(a.out, a.sizes)
    for res in report["sizes"]:
        for r in res["runs"]:
            err = r.get("error")
            print(f"{res['size']:9s} {r['tool']:40s} tol {r.get('tol', '-')!s:6s} "
                  f"{r.get('time_s', float('nan')):7.2f} s  error "
                  f"{'-' if err is None else f'{err:.1e}'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
