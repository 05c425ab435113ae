"""The advice of a run that does not pass (printgen.verification.advice): a change printgen
verified to pass, whose design file passes again when verified; or a plain statement that none
exists and the constraint that binds. And the design search sweeps the prototype once per scale.

These run the solver (a few model sweeps each): slow.
"""

from __future__ import annotations

import dataclasses
import json

import pytest
from conftest import EXAMPLES

from printgen.inputs.prototype import FlumeSpec
from printgen.report.jsonout import dumps
from printgen.run.make import plan_run
from printgen.run.options import RunOptions
from printgen.run.search import SearchOptions, search_at_scales
from printgen.scaling.design_file import load_design
from printgen.verification import preprint
from printgen.verification.advice import (
    ADVICE_NETS,
    ADVICE_ROUNDS,
    NEXT_DESIGN,
    advise,
    bracketed,
    direction,
    spread,
    weaker_force,
)
from printgen.verification.preprint import verify

SIMPLE = EXAMPLES / "simple_barrier.toml"
REALISTIC = EXAMPLES / "realistic_barrier.toml"


def _quiet_sensors(p, force=0.01):
    """The prototype with sensors pulling `force` N a wire (default: they only read), in a
    flume that runs any test (walls, no free section: as without a [flume] table)."""
    return dataclasses.replace(p, flume=FlumeSpec(width=100.0, max_discharge=1e3,
                                                  free_section=None, froude_min=0.0,
                                                  froude_max=100.0, sensor_force=force))


def test_weaker_force_rounds_down_to_the_two_digits_shown():
    assert weaker_force(0.0318) == pytest.approx(0.031)
    assert weaker_force(0.529) == pytest.approx(0.52)
    assert weaker_force(2.0) == pytest.approx(2.0)


def test_spread_takes_both_ends():
    assert spread(3) == [0, 1, 2]
    assert spread(10, 4) == [0, 3, 6, 9]


def test_bracketing_sweeps_between_the_last_too_stiff_and_the_first_too_soft():
    """Candidates 0..19 ordered softer and softer; 0..9 still too stiff, 11.. too soft, 10
    passes: the first round (0, 6, 13, 19) brackets 6..13, the second finds 10 inside it."""
    from printgen.verification.advice import Tried

    seen: list[int] = []

    def check(idx):
        seen.extend(idx)
        return [Tried(str(i), i == 10, 0.0, "", stiff=("m",) if i < 10 else (),
                      soft=("m",) if i > 10 else ()) for i in idx]

    order, tried = bracketed(20, "stiff", check)
    assert seen[:ADVICE_NETS] == [0, 6, 13, 19]
    assert all(6 < i < 13 for i in seen[ADVICE_NETS:]) and 10 in seen
    assert len(seen) <= ADVICE_NETS * ADVICE_ROUNDS and order == sorted(seen)
    assert any(t.passes for t in tried)


@pytest.mark.slow
def test_a_verified_sensor_change_is_named_and_passes_when_applied(tmp_path):
    """The simple barrier at 1:100: its sensors pull far more than their share; the advice names
    the weaker force, and the prototype file with it passes."""
    ctx = plan_run(SIMPLE, 100)
    p, d = ctx.prototype, ctx.design
    v = verify(p, d)
    assert v.verdict != "PASS" and v.sensors is not None and v.sensors.too_strong
    a = advise(p, d, v.prototype, sensors_too_strong=True, sensor_limit_n=v.sensors.limit_n)
    assert a.found and a.design is None and a.sensor_force_n is not None
    assert a.sensor_force_n <= v.sensors.limit_n
    text = a.next_step(str(SIMPLE), 100, str(tmp_path / "o"))
    assert f"sensor_force_n = {a.sensor_force_n:.2g}" in text
    assert f"printgen make {SIMPLE} -s 100" in text
    assert "add a [flume] table" in text  # the example has none to set the force in
    assert p.flume is None  # the default sensors: the same as a flume table stating them
    assert verify(_quiet_sensors(p, a.sensor_force_n), d).verdict == "PASS"


@pytest.mark.slow
def test_a_verified_net_is_written_as_a_design_file_that_passes(tmp_path):
    """A constructed failure: the simple barrier at 1:100 with quiet sensors (select's TPU-85A
    net then passes) printed in PETG is far too stiff; the advice names a strand it verified
    and that design's file, loaded as make --design loads it, passes the verification again."""
    ctx = plan_run(SIMPLE, 100)
    p, d = _quiet_sensors(ctx.prototype), ctx.design
    stiff = dataclasses.replace(d, net=dataclasses.replace(d.net, material="petg"))
    v = verify(p, stiff)
    assert v.verdict == "FAIL" and direction(v.mismatches) == "stiff"
    a = advise(p, stiff, v.prototype, sensors_too_strong=False, sensor_limit_n=None,
               way="stiff")
    assert a.found, a.reason
    assert a.design is not None and any(t.passes for t in a.tried)
    assert len(a.tried) <= ADVICE_NETS * ADVICE_ROUNDS
    text = a.next_step(str(SIMPLE), 100, str(tmp_path / "o"))
    assert f"--design {tmp_path / 'o'}/{NEXT_DESIGN}" in text and "verified" in text
    assert a.change in text
    path = tmp_path / NEXT_DESIGN
    path.write_text(dumps(a.design.to_dict()))
    again = load_design(path, scale=100, prototype=p)
    assert verify(p, again).verdict == "PASS"


@pytest.mark.slow
def test_no_change_states_the_binding_constraint(tmp_path):
    """A small diamond barrier whose [model] materials are PSU only, printed in PSU: far too
    stiff, and no printable PSU net is soft enough; the advice says so, naming the softest net
    it checked, instead of a change."""
    toml = SIMPLE.read_text().replace('pattern = "square"', 'pattern = "diamond"')
    for a, b in (("width_m = 12.0", "width_m = 6.0"), ("height_m = 4.0", "height_m = 2.0"),
                 ("mesh_x_m = 0.2", "mesh_x_m = 0.4"), ("mesh_y_m = 0.2", "mesh_y_m = 0.4")):
        toml = toml.replace(a, b)
    path = tmp_path / "small-diamond.toml"
    path.write_text(toml + '\n[model]\nmaterials = ["psu"]\n')
    ctx = plan_run(path, 20)
    p, d = _quiet_sensors(ctx.prototype), ctx.design
    assert d.net.material == "psu" and d.net.pattern == "diamond"
    v = verify(p, d)
    assert v.verdict == "FAIL" and direction(v.mismatches) == "stiff"
    a = advise(p, d, v.prototype, sensors_too_strong=False, sensor_limit_n=None, way="stiff")
    assert not a.found and a.design is None
    assert "no printable net is soft enough" in a.reason and "is still too stiff" in a.reason
    assert "PSU" in a.reason
    assert a.next_step(str(path), 20, None).startswith("No change printgen tried passes")
    assert json.loads(dumps(a.to_record()))["found"] is False


@pytest.mark.slow
def test_the_design_search_sweeps_the_prototype_once_per_scale(monkeypatch):
    """Every candidate is compared with one prototype sweep (it does not depend on the net)."""
    names: list[str] = []
    real = preprint.sweep

    def counted(scene, lv, **kw):
        names.append(scene.name)
        return real(scene, lv, **kw)

    monkeypatch.setattr(preprint, "sweep", counted)
    small = SearchOptions(objective="deformation", materials=("tpe",), mesh_x_mm=(26.0, 30.0),
                          mesh_y_mm=(12.5, 14.5), border_beads=(2, 4), verify_nets=1,
                          level_step=0.55)
    run = search_at_scales(REALISTIC, [40.0, 50.0], options=small, run=RunOptions(serial=True))
    proto = [n for n in names if "prototype" in n]
    assert len(proto) == 2  # one per scale
    # and select's pick, and the wave stage's sweeps (coarse trials, then on the own net)
    verified = sum(len(r.verified) + 1 + (len(r.wave.trials) + len(r.wave.full) if r.wave else 0)
                   for r in run.results)
    assert len(names) - len(proto) == verified


@pytest.mark.slow
def test_make_writes_the_verified_design_and_it_passes_when_made(tmp_path):
    """The whole loop through make: the simple barrier at 1:100 with quiet sensors, printed in
    PETG (a design file), fails; make's "Next" names the net it verified, writes it as
    next-design.json (listed in the manifest), and make with that file passes."""
    from printgen.run.make import make, verify_step

    proto = tmp_path / "simple.toml"
    proto.write_text(SIMPLE.read_text() + (
        "\n[flume]\nwidth_m = 10.0\nmax_discharge_l_per_s = 100000.0\nfroude_min = 0.01\n"
        "froude_max = 10.0\nsensor_force_n = 0.01\n"))
    d = plan_run(proto, 100).design
    stiff = tmp_path / "petg.json"
    stiff.write_text(dumps(dataclasses.replace(
        d, net=dataclasses.replace(d.net, material="petg")).to_dict()))
    only = [("verification", verify_step)]
    out = tmp_path / "o"
    ctx = make(proto, 100, out, steps=only, options=RunOptions(design_file=str(stiff)))
    summary = ctx.record["summary"]
    assert summary["verdict"] == "FAIL"
    assert NEXT_DESIGN in json.loads((out / "manifest.json").read_text())["files"]
    assert f"--design OUT/{NEXT_DESIGN}" in summary["next"]  # OUT: "this output folder"
    assert ctx.record["advice"]["found"] is True
    again = make(proto, 100, tmp_path / "o2", steps=only,
                 options=RunOptions(design_file=str(out / NEXT_DESIGN)))
    # the advice checks the nominal inputs: they pass; the band may leave the verdict open
    assert again.record["verification"]["ok"] is True
    assert again.record["summary"]["verdict"] in ("PASS", "UNDECIDED")
    assert "advice" not in again.record


def test_the_designs_own_states_start_only_the_changes_on_its_own_net():
    """Another strand on the same mesh has the design's nodes, node for node: the design's
    states start its sweep; another mesh, or a coarser net, does not."""
    from conftest import reference_design_1_40

    from printgen.scaling.record import Section
    from printgen.verification.advice import same_net

    d = reference_design_1_40()
    strand = dataclasses.replace(d, net=dataclasses.replace(
        d.net, material="tpu-85a", strand=Section(0.6, 2, (0.35,))))
    mesh = dataclasses.replace(d, net=dataclasses.replace(d.net, mesh_x_mm=17.37))
    assert same_net(d, strand, 1) and same_net(d, d, 1)
    assert not same_net(d, mesh, 1) and not same_net(d, strand, 2)
