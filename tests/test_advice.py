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

from printgen.report.jsonout import dumps
from printgen.run.make import plan_run
from printgen.run.options import RunOptions
from printgen.run.search import SearchOptions, search_at_scales
from printgen.scaling.design_file import load_design
from printgen.verification import preprint
from printgen.verification.advice import NEXT_DESIGN, advise, weaker_force
from printgen.verification.preprint import verify

SIMPLE = EXAMPLES / "simple_barrier.toml"
REALISTIC = EXAMPLES / "realistic_barrier.toml"


def test_weaker_force_rounds_down_to_the_two_digits_shown():
    assert weaker_force(0.0318) == pytest.approx(0.031)
    assert weaker_force(0.529) == pytest.approx(0.52)
    assert weaker_force(2.0) == pytest.approx(2.0)


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
    flume = dataclasses.replace(p.flume, sensor_force=a.sensor_force_n)
    assert verify(dataclasses.replace(p, flume=flume), d).verdict == "PASS"


@pytest.mark.slow
def test_a_verified_net_is_written_as_a_design_file_that_passes(tmp_path):
    """A constructed failure: the simple barrier at 1:40 printed in PETG (select's TPE pick
    passes) is far too stiff; the advice names a net it verified and that net's design file,
    loaded as make --design loads it, passes the verification again."""
    ctx = plan_run(SIMPLE, 40)
    p, d = ctx.prototype, ctx.design
    stiff = dataclasses.replace(d, net=dataclasses.replace(d.net, material="petg"))
    v = verify(p, stiff)
    assert v.verdict == "FAIL"
    a = advise(p, stiff, v.prototype, sensors_too_strong=False, sensor_limit_n=None)
    assert a.found, a.reason
    assert a.design is not None and any(t.passes for t in a.tried)
    text = a.next_step(str(SIMPLE), 40, str(tmp_path / "o"))
    assert f"--design {tmp_path / 'o'}/{NEXT_DESIGN}" in text and "verified" in text
    path = tmp_path / NEXT_DESIGN
    path.write_text(dumps(a.design.to_dict()))
    again = load_design(path, scale=40, prototype=p)
    assert verify(p, again).verdict == "PASS"


@pytest.mark.slow
def test_no_change_states_the_binding_constraint():
    """Only PSU in the prototype's [model] materials: no printable PSU net is anywhere near soft
    enough, and the advice says so with how far the closest is, instead of a change."""
    ctx = plan_run(SIMPLE, 40)
    p, d = ctx.prototype, ctx.design
    p = dataclasses.replace(p, model=dataclasses.replace(p.model, materials=("psu",)))
    stiff = dataclasses.replace(d, net=dataclasses.replace(d.net, material="psu"))
    v = verify(p, stiff)
    assert v.verdict == "FAIL"
    a = advise(p, stiff, v.prototype, sensors_too_strong=False, sensor_limit_n=None)
    assert not a.found and a.design is None
    assert "no profile is soft enough" in a.reason and "x the target membrane stiffness" \
        in a.reason
    assert a.next_step(str(SIMPLE), 40, None).startswith("No change printgen tried passes")
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
    verified = sum(len(r.verified) + 1 for r in run.results)  # and select's pick
    assert len(names) - len(proto) == verified
