"""`printgen profiles list|show NAME`: the materials, printers and print styles available."""

from __future__ import annotations

import argparse
from collections.abc import Callable
from typing import Any

from printgen.commands.common import add_json_arg, console, emit_json, table
from printgen.errors import ProfileError
from printgen.inputs.materials import load_material
from printgen.inputs.printers import load_print_style, load_printer
from printgen.inputs.profiles import (
    KINDS,
    list_profiles,
    load_raw,
    profile_name,
    profile_path,
    searched,
)
from printgen.report.jsonout import jsonable

LOADERS: dict[str, Callable[[str], Any]] = {
    "materials": load_material, "printers": load_printer, "prints": load_print_style}


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("profiles", help="list or show material, printer and print profiles")
    verbs = p.add_subparsers(dest="verb", metavar="VERB")
    verbs.required = True
    ls = verbs.add_parser("list", help="list profiles")
    ls.add_argument("--kind", choices=KINDS, help="only this kind")
    add_json_arg(ls)
    ls.set_defaults(func=run_list)
    show = verbs.add_parser("show", help="show one profile, validated, in the units of its file")
    show.add_argument("name")
    show.add_argument("--kind", choices=KINDS, help="kind, when a name exists in several")
    add_json_arg(show)
    show.set_defaults(func=run_show)


def run_list(args: argparse.Namespace) -> int:
    kinds = [args.kind] if args.kind else list(KINDS)
    found = {k: list_profiles(k) for k in kinds}
    if missing := [k for k, names in found.items() if not names]:
        raise ProfileError(f"no {', '.join(missing)} profiles found; {searched()}; reinstall "
                           "printgen, or set PRINTGEN_PROFILES to a folder holding "
                           f"{missing[0]}/NAME.toml")
    if args.json:
        emit_json({k: [{"name": n, "path": profile_path(k, n)} for n in names]
                   for k, names in found.items()})
        return 0
    rows = [[k, n, _summary(k, n)] for k, names in found.items() for n in names]
    console().print(table("profiles", ["kind", "name", "summary"], rows))
    return 0


def _summary(kind: str, name: str) -> str:
    obj = LOADERS[kind](name)
    if kind == "materials":
        e, src = obj.modulus()
        law = ", panel law (measured)" if obj.panel_law else ""
        return f"{obj.name}: E = {e / 1e9:.3g} GPa ({src}){law}"
    if kind == "printers":
        return (f"{obj.name}: nozzle {obj.nozzle_diameter_mm:g} mm, bed "
                f"{obj.bed_x_mm:g} x {obj.bed_y_mm:g} mm")
    return f"{obj.name}: {obj.component}, bead {obj.bead_width_mm:g} mm"


def run_show(args: argparse.Namespace) -> int:
    profile_name(args.name, "profiles show")
    kinds = [args.kind] if args.kind else [k for k in KINDS
                                           if args.name.lower() in list_profiles(k)]
    if not kinds:
        known = "; ".join(f"{k}: {', '.join(list_profiles(k))}" for k in KINDS)
        raise ProfileError(f"no profile named {args.name!r}; known: {known}")
    if len(kinds) > 1:
        raise ProfileError(f"{args.name!r} exists as {' and '.join(kinds)}; add --kind")
    kind = kinds[0]
    data = jsonable(LOADERS[kind](args.name))  # validated (an invalid profile fails here)
    if args.json:
        emit_json({"kind": kind, "profile": data})
        return 0
    raw, chain = load_raw(kind, args.name)  # as written, inherited keys merged in
    rows = [[k, _text(v)] for k, v in _flatten(raw) if k != "inherits"]
    via = f"; inherits {', '.join(p.stem for p in chain[1:])}" if len(chain) > 1 else ""
    console().print(table(f"{kind[:-1]} {args.name} ({profile_path(kind, args.name)}{via})",
                          ["key (its unit in the name)", "value (as in the file)"], rows))
    return 0


def _text(v: object) -> str:
    if isinstance(v, float):
        return f"{v:g}"
    if isinstance(v, list):
        return "[" + ", ".join(_text(x) for x in v) + "]"
    return str(v)


def _flatten(d: dict, prefix: str = "") -> list[tuple[str, object]]:
    out: list[tuple[str, object]] = []
    for k, v in d.items():
        if isinstance(v, dict):
            out += _flatten(v, f"{prefix}{k}.")
        else:
            out.append((f"{prefix}{k}", v))
    return out
