"""design.json: a `Design` as a file (`Design.to_dict()`), written by `printgen design` and
`printgen make`, read back by `printgen make --design FILE`.

Unknown or missing keys are errors naming the allowed keys; every value is type- and
range-checked with the schema of the prototype files (`printgen.inputs.schema`).
"""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path
from typing import Any

from printgen.barrier.patterns import get_pattern
from printgen.errors import GeometryError, InputError
from printgen.inputs.profiles import profile_name
from printgen.inputs.prototype import MIN_MODEL_MESH_MM, Prototype
from printgen.inputs.schema import Field, check_value, parse_data, positive, shown
from printgen.outputs.files import read_input_text
from printgen.scaling.record import (
    CABLE_SIDES,
    CableDesign,
    Design,
    NetDesign,
    Section,
    Wave,
    check_net_wave,
)

DESIGN_LIMIT_BYTES = 16 << 20  # a design.json is ~2 kB, a report.json holding one < 1 MB

# Every number of a design, with its plausible range (mm unless named): the same checks as
# a prototype file's (printgen.inputs.schema), so a 5000-digit scale, a list for a number or
# a 1e300 mm net is one InputError, never a failure deep in the geometry.
MM_MAX = 1e4  # 10 m: longer than any flume model's part
# Names (printer, material, print_style) are checked by profiles.profile_name: a name, never
# a path; a cable's name must also be the side it borders.
DESIGN = {"scale": Field("scale", float, lo=1.0, hi=100.0, si=False)}
NET = {"width_mm": positive("width_mm", MM_MAX, 1.0, si=False),
       "height_mm": positive("height_mm", MM_MAX, 1.0, si=False),
       "mesh_x_mm": positive("mesh_x_mm", 1000.0, MIN_MODEL_MESH_MM, si=False),
       "mesh_y_mm": positive("mesh_y_mm", 1000.0, MIN_MODEL_MESH_MM, si=False),
       "border_width_mm": positive("border_width_mm", 100.0, 0.05, si=False)}
SECTION = {"bead_width_mm": positive("bead_width_mm", 10.0, 0.05, si=False),
           "beads_across": Field("beads_across", int, lo=1, hi=1000),
           "layer_heights_mm": Field("layer_heights_mm", list, items=float, max_items=1000)}
WAVE = {"amplitude_mm": positive("amplitude_mm", 100.0, 0.01, si=False),
        "half_waves": Field("half_waves", int, lo=1, hi=100)}
LAYER = positive("layer_heights_mm", 5.0, 0.01, si=False)
CABLE_NAME = Field("name", str, choices=CABLE_SIDES)
CABLE = {"length_mm": positive("length_mm", MM_MAX, 1.0, si=False),
         "eyelet_inner_mm": positive("eyelet_inner_mm", 1000.0, 0.05, si=False),
         "eyelet_outer_mm": positive("eyelet_outer_mm", 1000.0, 0.05, si=False)}


def _fields(cls: type, data: Any, where: str, checks: dict[str, Field]) -> dict[str, Any]:
    """`data` as keyword arguments of the dataclass `cls`, each value of `checks` checked
    (floats as float), or InputError (a field with a default may be missing: files written
    before it existed)."""
    if not isinstance(data, dict):
        raise InputError(f"{where}: expected a table of {cls.__name__} fields, got "
                         f"{type(data).__name__}")
    names = [f.name for f in dataclasses.fields(cls)]
    optional = {f.name for f in dataclasses.fields(cls) if f.default is not dataclasses.MISSING}
    unknown = sorted(set(data) - set(names))
    missing = [n for n in names if n not in data and n not in optional]
    if unknown or missing:
        raise InputError(f"{where}: unknown keys {[shown(k) for k in unknown]} / missing keys "
                         f"{missing}; allowed: {', '.join(names)} (write it with printgen "
                         "design or make)")
    out = dict(data)
    for key, f in checks.items():
        value = check_value(out[key], f, where=where)
        out[key] = float(value) if f.kind is float else value
    return out


def _section(data: Any, where: str) -> Section:
    kw = _fields(Section, data, where, SECTION)
    layers = kw["layer_heights_mm"]
    if not layers:
        raise InputError(f"{where}: layer_heights_mm = [] must list the layer heights (mm)")
    return Section(kw["bead_width_mm"], kw["beads_across"],
                   tuple(float(check_value(h, LAYER, where=where)) for h in layers))


def design_from_dict(data: Any, where: str = "design") -> Design:
    """Rebuild a Design from `Design.to_dict()` output."""
    kw = _fields(Design, data, where, DESIGN)
    net = _fields(NetDesign, kw["net"], f"{where}.net", NET)
    net["strand"] = _section(net["strand"], f"{where}.net.strand")
    for key in ("material", "print_style"):
        net[key] = profile_name(net[key], f"{where}.net.{key}")
    if "pattern" in net:
        net["pattern"] = get_pattern(str(net["pattern"])).name
    if net.get("wave") is not None:  # absent or null: straight strands
        net["wave"] = Wave(**_fields(Wave, net["wave"], f"{where}.net.wave", WAVE))
    if not isinstance(kw["cables"], list):
        raise InputError(f"{where}.cables must be a list of cables")
    cables: list[CableDesign] = []
    for i, c in enumerate(kw["cables"]):
        ckw = _fields(CableDesign, c, f"{where}.cables[{i}]", CABLE)
        name = profile_name(ckw["name"], f"{where}.cables[{i}].name", what="cable")
        ckw["name"] = check_value(name, CABLE_NAME, where=f"{where}.cables[{i}]")
        if any(ckw["name"] == other.name for other in cables):
            raise InputError(f"{where}.cables[{i}]: a second {ckw['name']!r} cable; a net has "
                             f"one cable per side ({', '.join(CABLE_SIDES)})")
        ckw["section"] = _section(ckw["section"], f"{where}.cables[{i}].section")
        for key in ("material", "print_style"):
            ckw[key] = profile_name(ckw[key], f"{where}.cables[{i}].{key}")
        cables.append(CableDesign(**ckw))
    design = Design(scale=kw["scale"], printer=profile_name(kw["printer"], f"{where}.printer"),
                    net=NetDesign(**net), cables=tuple(cables))
    _check_wave(design.net, f"{where}.net")
    return design


def _check_wave(net: NetDesign, where: str) -> None:
    """InputError when the net's wave cannot be printed on its mesh: the curved pattern's
    limits (`printgen.scaling.record.check_net_wave`), the limit named."""
    try:
        check_net_wave(net, where)
    except GeometryError as exc:
        raise InputError(str(exc)) from exc


def load_design(path: str | Path, *, scale: float | None = None,
                prototype: Prototype | None = None) -> Design:
    """Read a design.json file (or the report.json holding one); with `scale`, it must be a
    design at that scale; with `prototype`, a design of that barrier (`check_design_of`)."""
    p = Path(path)
    text = read_input_text(p, "design file", limit=DESIGN_LIMIT_BYTES)
    data = parse_data(text, f"design file {p}", "JSON", json.loads)
    if isinstance(data, dict) and "design" in data and "net" not in data:
        data = data["design"]  # a report.json holds the design under "design"
    d = design_from_dict(data, where=str(p))
    if scale is not None and abs(d.scale - scale) > 1e-9 * scale:
        raise InputError(f"design file {p} is a 1:{d.scale:g} design, not 1:{scale:g}; pass "
                         f"--scale {d.scale:g} or search at 1:{scale:g} (printgen design)")
    if prototype is not None:
        check_design_of(d, prototype, where=f"design file {p}")
    return d


def check_design_of(d: Design, p: Prototype, *, where: str) -> None:
    """InputError unless `d` can be a design of the barrier `p` at its scale: border cables
    exactly when the prototype has a [border], and the net's width and height the barrier's
    over the scale, within one mesh (a design rounds them to its pattern's whole meshes)."""
    fix = (f"make a design for {p.name} (printgen make or printgen design with its prototype "
           "file), or pass the prototype the design was made for")
    if bool(d.cables) != (p.border is not None):
        has = f"{len(d.cables)} border cables" if d.cables else "no border cables"
        need = "has a [border] table" if p.border is not None else "has no [border] table"
        raise InputError(f"{where} has {has}, but the prototype {p.name!r} {need}: it is the "
                         f"design of another barrier; {fix}")
    for what, size, target, mesh in (("width", d.net.width_mm, p.width, d.net.mesh_x_mm),
                                      ("height", d.net.height_mm, p.height, d.net.mesh_y_mm)):
        model = target / d.scale * 1e3
        if abs(size - model) > mesh + 1e-6 * model:
            raise InputError(f"{where}: the net's {what} {size:g} mm is not the barrier's "
                             f"{target:g} m at 1:{d.scale:g} ({model:g} mm, within one mesh "
                             f"of {mesh:g} mm): it is the design of another barrier; {fix}")
