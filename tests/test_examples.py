"""Every example's run() (each asserts its own headline numbers)."""

from __future__ import annotations

import importlib.util

import pytest
from conftest import EXAMPLES

SCRIPTS = sorted(p for p in EXAMPLES.glob("*.py"))


@pytest.mark.slow  # each example runs its whole pipeline
@pytest.mark.parametrize("path", SCRIPTS, ids=[p.stem for p in SCRIPTS])
def test_example_runs(path):
    spec = importlib.util.spec_from_file_location(path.stem, path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    assert module.run() is not None


def test_there_are_examples():
    assert {p.stem for p in SCRIPTS} >= {"scale_series", "realistic_1_40"}
