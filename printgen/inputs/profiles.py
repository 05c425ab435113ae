"""Profile files: TOML under `profiles/<kind>/<name>.toml`, with `inherits`.

A profile may name a parent of the same kind with `inherits = "name"`; tables merge key by key,
the child winning. Lookup order (`search_dirs`): directories in $PRINTGEN_PROFILES
(os.pathsep-separated), then the per-user folder (`user_dir`: platformdirs' config folder, e.g.
~/.config/printgen/profiles on Linux), then the bundled profiles (`bundled_dir`: package data
of an installed printgen, the top-level `profiles/` of a source checkout, which is their source
of truth; setup.py copies it into the wheel). Validation is done by the module that owns the
data (materials.py, printers.py, ...); this module only finds, reads and merges.
"""

from __future__ import annotations

import importlib.resources
import os
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from printgen.errors import ProfileError
from printgen.inputs.schema import load_toml

KINDS = ("materials", "printers", "prints")
MAX_INHERIT_DEPTH = 8  # a longer chain is almost surely a cycle or a mistake
CHECKOUT = Path(__file__).resolve().parents[2]  # the clone's root, when printgen runs from one


def bundled_dir(folder: str = "profiles") -> Path:
    """The data printgen ships (`profiles`, or `examples`): `printgen/<folder>` inside an
    installed wheel (package data), else `<folder>/` at the root of a source checkout (an
    editable install or PYTHONPATH), where it is kept."""
    packaged = importlib.resources.files("printgen") / folder
    if isinstance(packaged, Path) and packaged.is_dir():
        return packaged
    return CHECKOUT / folder


BUNDLED = bundled_dir()


def user_dir() -> Path:
    """The per-user profile folder (same layout as `profiles/`), searched after
    $PRINTGEN_PROFILES and before the bundled profiles."""
    from platformdirs import user_config_path

    return user_config_path("printgen", appauthor=False) / "profiles"


def search_dirs() -> list[Path]:
    """Profile roots, highest priority first."""
    extra = [Path(p) for p in os.environ.get("PRINTGEN_PROFILES", "").split(os.pathsep) if p]
    return [*extra, user_dir(), BUNDLED]


def searched() -> str:
    """Where profiles are looked for, for error messages."""
    env = "" if os.environ.get("PRINTGEN_PROFILES") else " ($PRINTGEN_PROFILES is not set)"
    return f"looked in {', '.join(map(str, search_dirs()))}{env}"


def profile_path(kind: str, name: str) -> Path:
    """Path of profile `name` of `kind` (case-insensitive file stem), first match wins."""
    if kind not in KINDS:
        raise ProfileError(f"unknown profile kind {kind!r}; kinds: {', '.join(KINDS)}")
    stem = name.lower()
    for root in search_dirs():
        p = root / kind / f"{stem}.toml"
        if p.is_file():
            return p
    known = ", ".join(list_profiles(kind)) or f"none ({searched()})"
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
