"""benchmarks/bench_table.py, the speed table in one JSON: its rows merge into
measurements.json's entry by (row, label), and the recorded entry holds the table's columns."""

from __future__ import annotations

import copy

from benchmarks.bench_table import ENTRY, ROWS, _estimate, merged
from benchmarks.measurements import load

MACHINE = {"cores": 2, "cpu": "test CPU", "solver_backends": ["ldl", "lu"], "python": "3.11"}


def _data(rows):
    return {"measurements": [{"id": "other", "rows": [{"x": 1}]},
                             {"id": ENTRY, "rows": rows, "conditions": {}}]}


def test_rows_merge_by_row_and_label():
    old = [{"row": "series", "label": "a", "measured": 20.0},
           {"row": "series", "label": "b", "measured": 9.0},
           {"row": "make", "label": "b", "measured": 16.0}]
    report = {"machine": MACHINE, "rows": [
        {"row": "series", "label": "b", "measured": 4.0, "runs": [1, 2]},
        {"row": "design", "label": "b", "measured": 11.0}]}
    data = _data(copy.deepcopy(old))
    out = merged(data, report)
    entry = out["measurements"][1]
    assert [(r["row"], r["label"], r["measured"]) for r in entry["rows"]] == [
        ("series", "a", 20.0), ("make", "b", 16.0), ("series", "b", 4.0), ("design", "b", 11.0)]
    assert all("runs" not in r for r in entry["rows"])  # the per-run detail stays in the JSON
    assert entry["conditions"]["machine"] == "2-core test CPU"
    assert out["measurements"][0] == {"id": "other", "rows": [{"x": 1}]}


def test_estimate_within_x2():
    assert _estimate(10.0, 6.0)["estimate_within_x2"]
    assert not _estimate(10.0, 4.0)["estimate_within_x2"]  # x2.5 over
    assert not _estimate(2.0, 4.5)["estimate_within_x2"]  # x2.25 under


def test_the_recorded_table_has_the_columns():
    entry = next(e for e in load() if e["id"] == ENTRY)
    assert entry["rows"]
    for r in entry["rows"]:
        assert {"row", "command", "measured", "unit", "goal", "goal_met", "load_average",
                "label"} <= set(r), r
    assert set(ROWS) == {"make", "fit", "design", "series", "solver"}
