"""Write variants of the bundled prototype files for bad-input and fuzz tests."""

from __future__ import annotations

import copy
import tomllib
from pathlib import Path
from typing import Any

import tomli_w

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
REALISTIC = EXAMPLES / "realistic_barrier.toml"
SIMPLE = EXAMPLES / "simple_barrier.toml"


def prototype_dict(path: Path = REALISTIC) -> dict[str, Any]:
    return tomllib.loads(path.read_text())


def write_variant(tmp: Path, edit: dict[tuple[str, ...], Any], base: Path = REALISTIC,
                  name: str = "variant.toml") -> Path:
    """Copy `base` with `edit` applied: {(table, ..., key): value}; value None deletes."""
    data = copy.deepcopy(prototype_dict(base))
    for keys, value in edit.items():
        node = data
        for k in keys[:-1]:
            node = node.setdefault(k, {})
        if value is None:
            node.pop(keys[-1], None)
        else:
            node[keys[-1]] = value
    out = tmp / name
    out.write_bytes(tomli_w.dumps(data).encode())
    return out
