"""Profile files: TOML under `profiles/<kind>/<name>.toml`, with `inherits`.

A profile may name a parent of the same kind with `inherits = "name"`; tables merge key by key,
the child winning. Lookup order: directories in $PRINTGEN_PROFILES (os.pathsep-separated),
then the bundled `profiles/` of this checkout. Validation is done by the module that owns the
data (materials.py, printers.py, ...); this module only finds, reads and merges.
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from printgen.errors import ProfileError
from printgen.inputs.schema import load_toml

KINDS = ("materials", "printers", "prints")
BUNDLED = Path(__file__).resolve().parents[2] / "profiles"
MAX_INHERIT_DEPTH = 8  # a longer chain is almost surely a cycle or a mistake


def search_dirs() -> list[Path]:
    """Profile roots, highest priority first."""
    extra = [Path(p) for p in os.environ.get("PRINTGEN_PROFILES", "").split(os.pathsep) if p]
    return [*extra, BUNDLED]


def user_folder_hint(kind: str, file_name: str) -> str:
    """Where a user puts a profile of their own: the first folder of $PRINTGEN_PROFILES, or
    one to create and name there (never the installation's bundled profiles/)."""
    extra = [p for p in os.environ.get("PRINTGEN_PROFILES", "").split(os.pathsep) if p]
    if extra:
        return f"copy it to {Path(extra[0]) / kind / file_name} ($PRINTGEN_PROFILES)"
    return (f"copy it to a profile folder of your own, e.g. ~/printgen-profiles/{kind}/"
            f"{file_name}, and set PRINTGEN_PROFILES=~/printgen-profiles")


def profile_path(kind: str, name: str) -> Path:
    """Path of profile `name` of `kind` (case-insensitive file stem), first match wins."""
    if kind not in KINDS:
        raise ProfileError(f"unknown profile kind {kind!r}; kinds: {', '.join(KINDS)}")
    stem = name.lower()
    for root in search_dirs():
        p = root / kind / f"{stem}.toml"
        if p.is_file():
            return p
    known = ", ".join(list_profiles(kind)) or "none"
    raise ProfileError(
        f"no {kind[:-1]} profile named {name!r}; known: {known}; "
        f"add profiles/{kind}/{stem}.toml or set PRINTGEN_PROFILES to a folder holding {kind}/"
    )


def list_profiles(kind: str) -> list[str]:
    """Names (file stems) of every profile of `kind`, deduplicated, sorted."""
    names = {p.stem for root in search_dirs() for p in (root / kind).glob("*.toml")}
    return sorted(names)


def load_raw(kind: str, name: str) -> tuple[dict[str, Any], list[Path]]:
    """Read profile `name` with its `inherits` chain merged; return (data, files read)."""
    chain: list[Path] = []
    data: dict[str, Any] = {}
    current: str | None = name
    while current is not None:
        path = profile_path(kind, current)
        if path in chain or len(chain) >= MAX_INHERIT_DEPTH:
            raise ProfileError(
                f"{path}: inherits chain {' -> '.join(p.stem for p in chain)} -> {path.stem} "
                f"loops or is deeper than {MAX_INHERIT_DEPTH}; fix the 'inherits' keys"
            )
        chain.append(path)
        layer = load_toml(path)
        parent = layer.pop("inherits", None)
        if parent is not None and not isinstance(parent, str):
            raise ProfileError(f"{path}: inherits = {parent!r} must be a profile name string")
        data = merge(layer, data)
        current = parent
    return data, chain


def merge(parent: Mapping[str, Any], child: Mapping[str, Any]) -> dict[str, Any]:
    """Deep-merge two tables; values in `child` win, sub-tables merge recursively."""
    out = dict(parent)
    for key, value in child.items():
        if isinstance(value, Mapping) and isinstance(out.get(key), Mapping):
            out[key] = merge(out[key], value)
        else:
            out[key] = value
    return out
