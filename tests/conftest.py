"""Shared fixtures: paths, and the slicer requirement (CI fails instead of skipping)."""

from __future__ import annotations

import os
import shutil
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
SHARED = ROOT.parent / "shared"
EXAMPLES = ROOT / "examples"


def require_tool(name: str) -> str:
    """Return the path of a slicer executable; skip locally, fail under CI, when it is missing."""
    path = shutil.which(name)
    if path:
        return path
    msg = f"{name} not installed (bash scripts/setup.sh --with-slicers installs it)"
    if os.environ.get("PRINTGEN_REQUIRE_SLICERS") or os.environ.get("CI"):
        pytest.fail(msg)
    pytest.skip(msg)


def require_shared(rel: str) -> Path:
    """Return a path under ../shared; skip locally, fail under CI, when it is missing."""
    path = SHARED / rel
    if path.exists():
        return path
    msg = f"{path} not found (the shared/ folder sits beside the clone)"
    if os.environ.get("PRINTGEN_REQUIRE_SLICERS") or os.environ.get("CI"):
        pytest.fail(msg)
    pytest.skip(msg)
