"""Scale series of the simple barrier (scene simple-free-top; Lambert et al. 2023, Fig. 2):
lambda = 1, 10, 30, 50, 100 with steel at every scale, with E scaled by 1/lambda, and with
printed PETG (measured 1.30 GPa) at every scale. Normalised mid-height deflection and top
lowering under hydrostatic load at h = h_B.

Run `python examples/scale_series.py [OUTDIR]` to also write scale_series.png/json.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

from printgen.inputs.materials import load_material
from printgen.solver import solve
from printgen.solver.scenes import SIMPLE, simple_scene

LAMBDAS = np.array([1.0, 10.0, 30.0, 50.0, 100.0])
SIMILAR = 1e-9  # scaled-E models match the prototype to solver round-off
TOL = 1e-12  # solver force tolerance


def normalised(scale: float, modulus: float) -> tuple[float, float]:
    sc = simple_scene(scale=scale, modulus=modulus, pinned_top=False, drag=False)
    r = solve(sc.net, sc.loads_at(1.0), tol=TOL, strict=True)
    return (float(r.displacements[sc.centre, 1] / sc.width),
            float(-r.displacements[sc.top_centre, 2] / sc.height))


def run() -> dict[str, dict[str, np.ndarray]]:
    """Curves {variant: {"deflection": (5,), "lowering": (5,)}}; asserts the headlines."""
    petg = load_material("petg").modulus()[0]
    variants = {"steel at every scale": lambda lam: SIMPLE["modulus"],
                "E scaled by 1/lambda": lambda lam: SIMPLE["modulus"] / lam,
                "printed PETG (1.30 GPa) at every scale": lambda lam: petg}
    curves = {}
    for name, modulus in variants.items():
        pts = np.array([normalised(lam, modulus(lam)) for lam in LAMBDAS])
        curves[name] = {"deflection": pts[:, 0], "lowering": pts[:, 1]}
    proto = curves["E scaled by 1/lambda"]
    np.testing.assert_allclose(proto["deflection"], proto["deflection"][0], rtol=SIMILAR)
    np.testing.assert_allclose(proto["lowering"], proto["lowering"][0], rtol=SIMILAR)
    steel = curves["steel at every scale"]["deflection"]
    assert np.all(np.diff(steel) < 0), "steel models must deflect less as lambda grows"
    assert steel[-1] < 0.3 * steel[0]
    # PETG matches E/lambda where 100 GPa / lambda = 1.30 GPa, i.e. lambda ~ 77
    gap = curves["printed PETG (1.30 GPa) at every scale"]["deflection"] - proto["deflection"]
    assert gap[3] > 0 > gap[4], "PETG crosses the prototype between 1:50 and 1:100"
    return curves


if __name__ == "__main__":
    from printgen.outputs import write_bytes, write_text
    from printgen.report.jsonout import dumps
    from printgen.report.plots import series_figure

    out = Path(sys.argv[1] if len(sys.argv) > 1 else "out/examples")
    curves = run()
    write_text(out / "scale_series.json", dumps({"lambda": LAMBDAS, "curves": curves}))
    write_bytes(out / "scale_series.png", series_figure(
        LAMBDAS, curves, "Simple barrier (simple-free-top), hydrostatic at h = h_B"))
    for name, c in curves.items():
        print(f"{name:40s} deflection/width {np.round(c['deflection'], 4)}")
    print(f"wrote {out}/scale_series.png and .json")
