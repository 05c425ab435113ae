"""benchmarks/measurements.json, the data behind the tuned constants: its page is generated from
it, and every constant it names has the value it records (a retuned constant updates both)."""

from __future__ import annotations

import importlib
import json
import re

import pytest
from conftest import ROOT

from benchmarks.measurements import PAGE, load, render

ENTRIES = load()


def test_the_page_is_generated_from_the_data():
    assert PAGE.read_text("utf-8") == render(ENTRIES), \
        "benchmarks/measurements.md is out of date: python -m benchmarks.measurements"


def test_ids_are_unique_and_every_entry_has_rows():
    ids = [e["id"] for e in ENTRIES]
    assert len(ids) == len(set(ids))
    assert all(e["rows"] and e["why"] and e["bench"] for e in ENTRIES)


@pytest.mark.parametrize(("name", "recorded"),
                         [(k, v) for e in ENTRIES for k, v in e["constants"].items()])
def test_recorded_constants_are_the_code_s(name, recorded):
    module, attr = name.rsplit(".", 1)
    value = getattr(importlib.import_module(module), attr)
    assert json.loads(json.dumps(value)) == recorded, f"{name} is {value!r} in the code"


def test_comments_point_at_entries_that_exist():
    ids = {e["id"] for e in ENTRIES}
    cited = set()
    for path in [*(ROOT / "printgen").rglob("*.py"), *(ROOT / "solver").rglob("*.py")]:
        text = path.read_text("utf-8")
        cited |= set(re.findall(r"measurements\.md#([a-z0-9-]+)", text))
    assert cited <= ids, f"unknown measurements.md anchors: {sorted(cited - ids)}"
    assert cited, "no constant points at benchmarks/measurements.md"
