"""The flume's capacity is part of the verdict, and a [model] mesh chosen for another scale is
warned: a test the prototype file's [flume] cannot run (discharge, width, Froude range) is not
a pass, its headline names the limit and by how much, and "Next" is what clears it, computed;
`targets`, `select` and `make` show the mesh's factor and fix."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from proto_files import REALISTIC, SIMPLE, write_variant

from printgen.cli import main
from printgen.inputs.prototype import load_prototype
from printgen.report import summary as summary_module
from printgen.report.build import build_report
from printgen.report.html import Report
from printgen.report.records import CheckRecords, RunRecords
from printgen.report.report import verification_sections
from printgen.report.summary import summarize
from printgen.run.api import plan
from printgen.run.make import plan_run
from printgen.scaling.similitude import MESH_TOLERANCE, scale_targets
from printgen.verification.compare import headlines
from printgen.verification.preprint import verify

SCALE = 25.0
LEVELS = np.array([0.0, 0.5, 1.0, 1.1])  # enough for a verdict; the full sweep is make's
EXACT = 1e-12  # closed-form scaling, round-off only


def user_barrier(tmp_path, discharge_l_per_s: float, **flume) -> str:
    """A user's 8 x 3 m barrier (the simple barrier's net) under a 4 m/s flow, in a 0.5 m
    flume: at 1:25 the scaled flow is 0.8 m/s x 0.12 m x 0.5 m = 48 L/s."""
    edit = {("barrier", "width_m"): 8.0, ("barrier", "height_m"): 3.0,
            ("flow", "velocity_m_per_s"): 4.0,
            ("flume", "width_m"): 0.5, ("flume", "max_discharge_l_per_s"): discharge_l_per_s,
            ("flume", "free_section_m"): 0.4, ("flume", "froude_min"): 0.5,
            ("flume", "froude_max"): 1.4}
    edit.update({("flume", k): v for k, v in flume.items()})
    return str(write_variant(tmp_path, edit, base=SIMPLE, name=f"user-{discharge_l_per_s:g}.toml"))


def test_discharge_limit_names_its_factor_and_the_smallest_scale(tmp_path):
    p = load_prototype(user_barrier(tmp_path, 20.0))
    f = scale_targets(p, SCALE).flow
    assert f.discharge == pytest.approx(4.0 / 5 * 0.12 * 0.5, rel=EXACT)  # 48 L/s
    (lim,) = f.limits
    assert lim.key == "discharge" and lim.factor == pytest.approx(2.4, rel=EXACT)
    assert "48.00 L/s exceeds the flume's 20.00 L/s (2.40x)" in lim.text
    assert lim.text in f.warnings
    # Q ~ lambda^-1.5 at a fixed flume width: the smallest whole scale it runs
    need = math.ceil(SCALE * 2.4 ** (2 / 3))
    assert not scale_targets(p, need).flow.limits and scale_targets(p, need - 1).flow.limits
    assert f"use a scale of 1:{need} or more" in f.fix
    assert "a flume that supplies at least 48.00 L/s" in f.fix


def test_froude_outside_the_range_has_no_scale_fix(tmp_path):
    p = load_prototype(user_barrier(tmp_path, 100.0, froude_max=0.6))
    (lim,) = scale_targets(p, SCALE).flow.limits
    assert lim.key == "froude" and lim.min_scale is None
    assert lim.factor == pytest.approx(4.0 / math.sqrt(9.81 * 3.0) / 0.6, rel=EXACT)
    for lam in (SCALE, 50.0, 100.0):  # Froude similitude: the same at every scale
        assert [x.key for x in scale_targets(p, lam).flow.limits] == ["froude"]
    assert "cannot run the scaled test at any scale" in scale_targets(p, SCALE).flow.fix


def test_one_scale_clears_every_limit_the_widest_need_binds():
    """1:10: a 1.32 m wide model in the 0.4 m flume (1:33 fits it), its 27.8 L/s above 8 L/s
    (1:23 clears that): 1:33 clears both."""
    f = scale_targets(load_prototype(REALISTIC), 10).flow
    assert [x.key for x in f.limits] == ["discharge", "width"]
    assert [math.ceil(x.min_scale) for x in f.limits] == [23, 33]
    assert "use a scale of 1:33 or more" in f.fix  # 13.2 m / 0.4 m
    assert not scale_targets(load_prototype(REALISTIC), 33).flow.limits


@pytest.fixture(scope="module")
def verdicts(tmp_path_factory):
    """The user's barrier at 1:25 in a 20 L/s flume and in a 100 L/s one."""
    tmp = tmp_path_factory.mktemp("flume")
    out = {}
    for q in (20.0, 100.0):
        p = load_prototype(user_barrier(tmp, q))
        out[q] = (p, verify(p, plan(p, SCALE), lv=LEVELS))
    return out


def test_a_flume_too_small_is_not_a_pass(verdicts, monkeypatch):
    _, small = verdicts[20.0]
    _, large = verdicts[100.0]
    assert small.mismatches == large.mismatches  # the same net, the same deformations
    assert small.verdict == "FAIL" and not small.runnable
    first = small.headline.split("\n")[0]
    assert first.startswith("the flume cannot run this test: model discharge 48.00 L/s exceeds "
                            "the flume's 20.00 L/s (2.40x)")
    rec = small.to_record()
    assert rec["verdict"] == "FAIL" and rec["flume"]["limits"][0].key == "discharge"
    # the summary's verdict, reason and next step (band verdicts aside: not this test's)
    monkeypatch.setattr(summary_module, "band_verdicts", lambda values, band: [])
    s = summarize(RunRecords("t", plan(verdicts[20.0][0], SCALE),
                             steps={"verification": CheckRecords(small, None, SCALE)}))
    assert s.verdict == "FAIL" and s.reason == small.headline
    assert s.next.startswith("Change the scale or the flume before printing: use a scale of 1:45")
    rep = Report("t")  # the report's verification section: the limit, then what clears it
    verification_sections(rep, small, None, SCALE)
    html = "\n".join(rep.blocks)
    assert html.index("the flume cannot run this test") < html.index("What clears it: use a")


def test_a_flume_large_enough_leaves_the_verdict_unchanged(verdicts):
    _, large = verdicts[100.0]
    assert large.runnable and large.to_record()["flume"] == {"limits": [], "fix": ""}
    assert large.verdict == ("PASS" if large.ok else "FAIL")
    assert large.headline == "\n".join(headlines(large.mismatches))


def _mesh_warnings(scale: float) -> list[str]:
    return [w for w in scale_targets(load_prototype(REALISTIC), scale).warnings
            if w.startswith("[model] mesh")]


def test_the_1_40_mesh_is_not_warned_at_1_40():
    """The paper's printed diamond (20.6 x 9.4 mm) against the water-drop mesh scaled to 1:40
    (15.75 x 8.75 mm): reshaped, 1.18x in size, within MESH_TOLERANCE."""
    size = math.sqrt(20.6 / 15.75 * 9.4 / 8.75)
    assert abs(size - 1) <= MESH_TOLERANCE
    assert _mesh_warnings(40) == [] and scale_targets(load_prototype(REALISTIC), 40).warnings == ()


def test_the_1_40_mesh_reused_at_1_100_is_warned_with_its_factor(capsys):
    fx, fy = 20.6 / 6.3, 9.4 / 3.5  # over the prototype's 630 x 350 mm scaled to 1:100
    (w,) = _mesh_warnings(100)
    assert f"is {math.sqrt(fx * fy):.2f}x the prototype's mesh scaled to 1:100" in w
    assert f"{fx:.2f}x across, {fy:.2f}x up: Pi2 = a / h_B +227% off" in w
    assert "Drop [model] mesh_x_mm and mesh_y_mm" in w and "chosen for 1:100" in w
    for command in ("targets", "select"):  # the tables and their --json
        assert main([command, str(REALISTIC), "--scale", "100"]) == 0
        assert "[model] mesh 20.6 x 9.4 mm is 2.96x" in capsys.readouterr().out.replace("\n", " ")
        assert main([command, str(REALISTIC), "--scale", "100", "--json"]) == 0
        assert w in json.loads(capsys.readouterr().out)["warnings"]


def test_make_shows_the_mesh_warning_in_report_summary_and_json():
    """make's plan: the report's targets, the summary box, report.json's summary (the warning
    holds before any verification)."""
    ctx = plan_run(REALISTIC, 100)
    (w,) = _mesh_warnings(100)
    assert w in ctx.record["targets"]["warnings"]
    rep, s = build_report(ctx.records)
    assert w in s.to_record()["warnings"]
    html = "\n".join(rep.blocks) + rep.lead
    assert html.count("[model] mesh 20.6 x 9.4 mm is 2.96x") == 2  # targets section, summary
