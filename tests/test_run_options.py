"""One options record (printgen.run.options.RunOptions) for how a run runs: the command line
builds it, the public verbs take it (their keywords are shorthands of its fields) and make's
helper process receives it."""

from __future__ import annotations

import dataclasses
import inspect
import json
from pathlib import Path

import pytest

from printgen.cli import build_parser
from printgen.commands.common import run_options
from printgen.run import api
from printgen.run.options import RunOptions


def parsed(*argv: str):
    args = build_parser(list(argv)).parse_args(list(argv))
    args.argv = ["printgen", *argv]
    return args


def test_record_is_frozen_and_json_ready():
    o = RunOptions(loads=("jam",), design_file=Path("d.json"), command=["printgen", "make"])
    with pytest.raises(dataclasses.FrozenInstanceError):
        o.force = True  # type: ignore[misc]
    rec = o.to_record()
    assert json.loads(json.dumps(rec)) == rec
    assert set(rec) == {f.name for f in dataclasses.fields(RunOptions)}
    assert rec["design_file"] == "d.json" and rec["loads"] == ["jam"]


def test_the_command_line_builds_the_record():
    o = run_options(parsed("make", "p.toml", "-s", "40", "--load", "jam", "--load-param",
                           "porosity=0.4", "--loads", "hydrostatic,jam", "--time-limit", "90",
                           "--force", "--pdf", "--printer", "generic-350"))
    assert o.load.startswith("jam:porosity=0.4") and o.loads == ("hydrostatic", o.load)
    assert (o.time_limit_s, o.force, o.pdf, o.printer, o.step) == (90.0, True, True,
                                                                    "generic-350", False)
    assert o.command == ["printgen", "make", "p.toml", "-s", "40", "--load", "jam",
                         "--load-param", "porosity=0.4", "--loads", "hydrostatic,jam",
                         "--time-limit", "90", "--force", "--pdf", "--printer", "generic-350"]
    s = run_options(parsed("series", "p.toml", "--workers", "2", "--drag"))
    assert (s.load, s.workers, s.serial, s.scheduler) == ("drag", 2, None, None)
    assert run_options(parsed("design", "p.toml", "-s", "40", "--serial")).serial is True


def test_verbs_keywords_are_shorthands_of_the_record():
    base = RunOptions(force=True, workers=2)
    assert api.run_options(base, workers=None, scheduler="tcp://h:1") == dataclasses.replace(
        base, scheduler="tcp://h:1")
    assert api.with_load(RunOptions(), None, True).load == "drag"
    for verb in (api.make, api.verify_design, api.series):
        assert inspect.signature(verb).parameters["options"].annotation in (
            "RunOptions | None", RunOptions | None)
    assert "run" in inspect.signature(api.search_nets).parameters


def test_make_helper_receives_the_record():
    from printgen.run.steps import sweeps_and_advice, verification_sweeps

    assert list(inspect.signature(sweeps_and_advice).parameters) == [
        "prototype", "design", "options"]
    assert list(inspect.signature(verification_sweeps).parameters)[:3] == [
        "prototype", "design", "options"]
