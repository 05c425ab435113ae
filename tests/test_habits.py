"""The development habits the CI holds (CONTRIBUTING.md): ruff's rule set, mypy pinned with an
error budget for printgen/ that docs/development.md states, the `slow` marker registered."""

from __future__ import annotations

import importlib.util
import re
import tomllib

import pytest
from conftest import ROOT

PYPROJECT = tomllib.loads((ROOT / "pyproject.toml").read_text("utf-8"))


def _budget_module():
    path = ROOT / "scripts" / "mypy_budget.py"
    spec = importlib.util.spec_from_file_location("mypy_budget", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_readme_states_the_mypy_budget():
    budget = _budget_module().read_budget()
    text = (ROOT / "docs" / "development.md").read_text("utf-8")
    note = text.split("Typing:", 1)[1].split("\n\n", 1)[0]
    assert f"`scripts/mypy_budget.txt`, {budget} errors" in note, \
        f"docs/development.md's Typing note does not state the budget of {budget} errors"


@pytest.mark.parametrize(("output", "count"), [
    ("a.py:1: error: x  [misc]\nFound 107 errors in 30 files (checked 150 source files)\n", 107),
    ("a.py:1: error: x  [misc]\nFound 1 error in 1 file (checked 3 source files)\n", 1),
    ("Success: no issues found in 13 source files\n", 0),
])
def test_the_budget_script_reads_mypy_s_count(output, count):
    assert _budget_module().count_errors(output) == count


def test_mypy_is_pinned_in_the_test_extra():
    test = PYPROJECT["project"]["optional-dependencies"]["test"]
    assert [d for d in test if re.fullmatch(r"mypy==[\d.]+", d)], "mypy is not pinned"


def test_ruff_selects_the_wider_rules():
    selected = set(PYPROJECT["tool"]["ruff"]["lint"]["select"])
    assert {"E", "F", "W", "B", "UP", "SIM", "I"} <= selected


def test_the_slow_marker_is_registered():
    markers = PYPROJECT["tool"]["pytest"]["ini_options"]["markers"]
    assert any(m.startswith("slow:") for m in markers)
