"""Profile files: TOML under `profiles/<kind>/<name>.toml`, with `inherits`.

A profile may name a parent of the same kind with `inherits = "name"`; tables merge key by key,
the child winning. Lookup order (`search_dirs`): directories in $PRINTGEN_PROFILES
(os.pathsep-separated), then the per-user folder (`user_dir`: platformdirs' config folder, e.g.
~/.config/printgen/profiles on Linux), then the bundled profiles (`bundled_dir`: package data
of an installed printgen, the top-level `profiles/` of a source checkout, which is their source
of truth; setup.py copies it into the wheel). Validation is done by the module that owns the
data (materials.py, printers.py, ...); this module only finds, reads and merges.

A profile name is a name, never a path: ASCII letters, digits, '-', '_' and '.', not starting
with '.', at most 64 characters (`profile_name`). Every place a profile is named (a
prototype's [model], `inherits`, design.json, --printer, --materials, `profiles show`,
`calibrate --material`) goes through it, so no name can reach a file outside the profile
folders, and no name can make a path when printgen writes `<name>.toml` or `<name>.png`.
"""

from __future__ import annotations

import importlib.resources
import os
import re
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


NAME_MAX = 64  # characters in a profile name
NAME = re.compile(rf"[A-Za-z0-9][A-Za-z0-9._-]{{0,{NAME_MAX - 1}}}")


def profile_name(name: object, where: str = "profile name", *, what: str = "profile") -> str:
    """`name` when it is a plain name (of a profile, or of a part: it becomes a file name),
    else ProfileError naming it and the rule."""
    if isinstance(name, str) and NAME.fullmatch(name):
        return name
    shown = repr(name) if isinstance(name, str) else f"{name!r} ({type(name).__name__})"
    hint = ("a profile is named, never given as a path (put the file in profiles/<kind>/ or a "
            "$PRINTGEN_PROFILES folder)" if what == "profile" else "it becomes a file name")
    raise ProfileError(
        f"{where}: {shown[:80]} is not a {what} name: use ASCII letters, digits, '-', '_' and "
        f"'.', not starting with '.', at most {NAME_MAX} characters; {hint}")


def search_dirs() -> list[Path]:
    """Profile roots, highest priority first."""
    extra = [Path(p) for p in os.environ.get("PRINTGEN_PROFILES", "").split(os.pathsep) if p]
    return [*extra, user_dir(), BUNDLED]


def searched() -> str:
    """Where profiles are looked for, for error messages."""
    env = "" if os.environ.get("PRINTGEN_PROFILES") else " ($PRINTGEN_PROFILES is not set)"
    return f"looked in {', '.join(map(str, search_dirs()))}{env}"


def user_folder_hint(kind: str, file_name: str) -> str:
    """Where a user puts a profile of their own: the first folder of $PRINTGEN_PROFILES, else
    the per-user folder (never the installation's bundled profiles/)."""
    extra = [p for p in os.environ.get("PRINTGEN_PROFILES", "").split(os.pathsep) if p]
    if extra:
        return f"copy it to {Path(extra[0]) / kind / file_name} ($PRINTGEN_PROFILES)"
    return f"copy it to {user_dir() / kind / file_name} (your per-user profile folder)"


def profile_path(kind: str, name: str) -> Path:
    """Path of profile `name` of `kind` (case-insensitive file stem), first match wins."""
    if kind not in KINDS:
        raise ProfileError(f"unknown profile kind {kind!r}; kinds: {', '.join(KINDS)}")
    stem = profile_name(name, f"{kind[:-1]} profile").lower()
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
    """Names (file stems) of every profile of `kind`, deduplicated, sorted; a file whose stem
    is not a profile name (`profile_name`) is left out."""
    names = {p.stem for root in search_dirs() for p in (root / kind).glob("*.toml")}
    return sorted(n for n in names if NAME.fullmatch(n))


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
        if parent is not None:
            parent = profile_name(parent, f"{path}: inherits")
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
