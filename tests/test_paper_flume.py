"""The paper's flume test as bundled data (issue 25): the printed design, the measured points
with "negligible" as a bound, and the panel-test orientation option of the scenes."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from printgen.errors import GeometryError
from printgen.scaling.design_file import load_design
from printgen.scene import SceneOptions, build_scene
from printgen.scene.scenes import panel_axes
from printgen.verification.measured import MeasurementError, mismatch, read_measured

HERE = Path(__file__).resolve().parents[1] / "examples" / "paper_1_40"
EXACT = 1e-12  # values read from the CSV: only round-off
MM = 1e-3


def test_bundled_measurement_holds_only_the_stated_values():
    m = read_measured(HERE / "measured.csv")
    np.testing.assert_allclose(m.levels, [0.5, 0.8, 1.0])
    mid = m.values["strain_mid"]
    assert np.isnan(mid[0]) and mid[1:] == pytest.approx([0.05, 0.105], abs=EXACT)
    assert np.isnan(m.values["strain_bottom"]).all()  # the paper gives no bottom value
    for key in ("strain_bottom", "strain_top", "strain_mid"):
        assert m.bound(key)[0] == pytest.approx(0.005, abs=EXACT)


def test_a_bound_counts_only_by_its_excess():
    m = read_measured(HERE / "measured.csv")
    under = {k: np.array([0.004, 0.05, 0.105]) for k in m.values}
    over = {k: np.array([0.015, 0.05, 0.105]) for k in m.values}
    mid_under = next(x for x in mismatch(m, under) if x.metric == "strain_mid")
    mid_over = next(x for x in mismatch(m, over) if x.metric == "strain_mid")
    assert mid_under.rms == pytest.approx(0.0, abs=EXACT)
    assert mid_over.rms == pytest.approx(np.sqrt(0.01**2 / 3), rel=1e-9)


def test_bounds_only_is_refused(tmp_path):
    f = tmp_path / "m.csv"
    f.write_text("h_over_hb,mid_height_elongation_pct\n0.5,<0.5\n")
    with pytest.raises(MeasurementError, match="no measured value"):
        read_measured(f)


def test_orientation_reads_the_panel_law_along_the_chosen_diagonal():
    d = load_design(HERE / "design.json", scale=40)
    short, long_ = (build_scene(d, SceneOptions(orientation=o)).laws[0]
                    for o in ("short", "long"))
    # the nominal is the reading the material can produce (printgen.scaling.reading): the
    # long diagonal, though the TPE profile records the short one
    assert build_scene(d).laws[0] == long_
    sin_s, sin_l = 4.7 / np.hypot(4.7, 10.3), 10.3 / np.hypot(4.7, 10.3)
    # strand EA = kappa L a_across / (2 sin^3): the two readings differ by this ratio
    ratio = (9.4 / sin_l**3) / (20.6 / sin_s**3)
    assert long_.slopes[0] / short.slopes[0] == pytest.approx(ratio, rel=1e-9)
    assert panel_axes(20.6 * MM, 9.4 * MM, "long") == (20.6 * MM, 9.4 * MM)
    with pytest.raises(GeometryError, match="orientation"):
        panel_axes(1.0, 2.0, "diagonal")


def test_make_with_the_paper_design_shows_its_own_net_error():
    """`make --design` reports the design file's own net, not select's pick: the paper's net is
    the panel law's tested net, so its small-strain membrane stiffness is the measured
    kappa_0 x panel length with no geometric rescaling."""
    from printgen.inputs.materials import load_material
    from printgen.report.build import build_report
    from printgen.report.summary import chosen_parts
    from printgen.run.make import plan_run
    from printgen.run.options import RunOptions

    realistic = HERE.parent / "realistic_barrier.toml"
    ctx = plan_run(realistic, 40, options=RunOptions(design_file=HERE / "design.json"))
    own = ctx.record["design_net"]
    law = load_material(ctx.design.net.material).panel_law
    assert own["stiffness"] == pytest.approx(law.kappas[0] * law.panel_length, rel=EXACT)
    assert own["error"] == pytest.approx(own["stiffness"] / own["target"] - 1, rel=EXACT)
    assert abs(own["error"] - ctx.selection.net[0].error) > 0.5  # not select's pick
    assert chosen_parts(ctx.design, ctx.records.plan)[0]["stiffness_error"] == own["error"]
    assert f"({own['error']:+.0%})" in build_report(ctx.records)[0].html()
