"""The report built once from the run's records (printgen.report.records, .build): report.json
is the records' own, report.html is rendered from the same objects, `verify`'s report is the
same builder fed with fewer records, and no record holds a wall-clock time."""

from __future__ import annotations

from dataclasses import replace

from printgen.report.build import build_report
from printgen.report.jsonout import dumps
from printgen.report.records import RunRecords
from printgen.report.summary import summarize
from printgen.run.provenance import TIME_KEYS


def _times(obj, path=""):
    """Paths of every key of TIME_KEYS in `obj`."""
    if isinstance(obj, dict):
        return [p for k, v in obj.items()
                for p in ([f"{path}/{k}"] if k in TIME_KEYS else []) + _times(v, f"{path}/{k}")]
    if isinstance(obj, (list, tuple)):
        return [p for i, v in enumerate(obj) for p in _times(v, f"{path}/{i}")]
    return []


def test_report_json_is_the_records_own(made_1_40):
    ctx, out = made_1_40
    rec = {**ctx.records.to_record(), "summary": summarize(ctx.records).to_record(),
           "files": ctx.record["files"]}
    assert dumps(rec) == (out / "report.json").read_text()


def test_records_hold_no_wall_clock_time_the_timings_do(made_1_40):
    ctx, _ = made_1_40
    assert _times(ctx.records.to_record()) == []
    assert set(ctx.timings["gcode"]) == set(ctx.record["gcode"])  # each part's G-code time
    assert ctx.timings["verification"]["bands"]["seconds"] > 0
    assert ctx.timings["timings_s"]["total"] > 0


def test_report_html_is_rendered_from_the_records(made_simple_drag):
    ctx, out, _ = made_simple_drag
    rep, summary = build_report(ctx.records)
    assert rep.html() == (out / "report.html").read_text()
    assert summary.to_record() == ctx.record["summary"]


def test_verify_is_the_same_builder_with_fewer_records(made_simple_drag):
    """verify's run: the design and the check (no plan, parts or provenance); its report.json
    keeps the band and the lab beside "verification", with the same numbers as make's."""
    ctx, _, _ = made_simple_drag
    check = ctx.records.check
    run = RunRecords("verify", ctx.design, steps={"verification": replace(
        check, nested=False, counterexample=False, solver_work=None)})
    made, rec = ctx.record["verification"], run.to_record()
    assert set(rec) == {"design", "verification", "bands", "lab"}
    assert _times(rec) == []  # the band's wall time is the run's timings', not report.json's
    assert dumps(rec["bands"]) == dumps(made["bands"]) and dumps(rec["lab"]) == dumps(made["lab"])
    assert dumps(rec["verification"]) == dumps(
        {k: v for k, v in made.items() if k not in ("bands", "lab", "solver_work")})
    rep, summary = build_report(run)
    html = "\n".join(rep.blocks)
    assert "Pre-print verification" in html and "Uncertainty band" in html
    assert "Provenance" not in html and "Similitude targets" not in html
    assert summary.verdict == made["verdict"] and summary.parts[0]["stiffness_error"] is None
