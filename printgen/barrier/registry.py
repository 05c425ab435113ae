"""The registries of `patterns` and `loads`: every module of the package that defines the
package's entry (`PATTERN` or `CASE`) is one entry, named by its `name` (which is the
module's name: tests/test_barrier.py checks it). A package's `FAMILIES` names its modules
that build entries from parameters instead of defining one (the curved strands' pattern,
made from a layout and a wave): they are not entries."""

from __future__ import annotations

import importlib
import pkgutil
from types import ModuleType
from typing import Any


def names(package: ModuleType) -> list[str]:
    """The entries' names without importing them: each module is named as its entry."""
    families = set(getattr(package, "FAMILIES", ()))
    return sorted(info.name for info in pkgutil.iter_modules(package.__path__)
                  if info.name not in families)


def entries(package: ModuleType, attribute: str) -> dict[str, Any]:
    """name -> the `attribute` of every module of `package`, sorted by name."""
    found = {}
    for name in names(package):
        module = importlib.import_module(f"{package.__name__}.{name}")
        entry = getattr(module, attribute, None)
        if entry is not None:
            found[entry.name] = entry
    return dict(sorted(found.items()))
