"""design.json: a `Design` as a file (`Design.to_dict()`), written by `printgen design` and
`printgen make`, read back by `printgen make --design FILE`.

Unknown or missing keys are errors naming the allowed keys; lengths must be positive.
"""

from __future__ import annotations

import dataclasses
import json
import math
from pathlib import Path
from typing import Any

from printgen.design.record import CableDesign, Design, NetDesign, Section
from printgen.errors import InputError
from printgen.inputs.profiles import profile_name
from printgen.outputs.files import read_input_text

DESIGN_LIMIT_BYTES = 16 << 20  # a design.json is ~2 kB, a report.json holding one < 1 MB


def _fields(cls: type, data: Any, where: str) -> dict[str, Any]:
    """`data` as keyword arguments of the dataclass `cls`, or InputError."""
    if not isinstance(data, dict):
        raise InputError(f"{where}: expected a table of {cls.__name__} fields, got "
                         f"{type(data).__name__}")
    names = [f.name for f in dataclasses.fields(cls)]
    unknown, missing = sorted(set(data) - set(names)), [n for n in names if n not in data]
    if unknown or missing:
        raise InputError(f"{where}: unknown keys {unknown} / missing keys {missing}; allowed: "
                         f"{', '.join(names)} (write it with printgen design or make)")
    return dict(data)


def _positive(value: Any, where: str) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or \
            not math.isfinite(value) or value <= 0:
        raise InputError(f"{where} = {value!r} must be a positive number (mm)")
    return float(value)


def _section(data: Any, where: str) -> Section:
    kw = _fields(Section, data, where)
    beads = kw["beads_across"]
    if isinstance(beads, bool) or not isinstance(beads, int) or beads < 1:
        raise InputError(f"{where}.beads_across = {beads!r} must be a whole number >= 1")
    layers = kw["layer_heights_mm"]
    if not isinstance(layers, list) or not layers:
        raise InputError(f"{where}.layer_heights_mm = {layers!r} must be a list of heights (mm)")
    return Section(_positive(kw["bead_width_mm"], f"{where}.bead_width_mm"), beads,
                   tuple(_positive(h, f"{where}.layer_heights_mm") for h in layers))


def design_from_dict(data: Any, where: str = "design") -> Design:
    """Rebuild a Design from `Design.to_dict()` output."""
    kw = _fields(Design, data, where)
    net = _fields(NetDesign, kw["net"], f"{where}.net")
    for key in ("width_mm", "height_mm", "mesh_x_mm", "mesh_y_mm", "border_width_mm"):
        net[key] = _positive(net[key], f"{where}.net.{key}")
    net["strand"] = _section(net["strand"], f"{where}.net.strand")
    for key in ("material", "print_style"):
        net[key] = profile_name(net[key], f"{where}.net.{key}")
    if not isinstance(kw["cables"], list):
        raise InputError(f"{where}.cables must be a list of cables")
    cables = []
    for i, c in enumerate(kw["cables"]):
        ckw = _fields(CableDesign, c, f"{where}.cables[{i}]")
        ckw["section"] = _section(ckw["section"], f"{where}.cables[{i}].section")
        for key in ("material", "print_style"):
            ckw[key] = profile_name(ckw[key], f"{where}.cables[{i}].{key}")
        ckw["name"] = profile_name(ckw["name"], f"{where}.cables[{i}].name", what="cable")
        for key in ("length_mm", "eyelet_inner_mm", "eyelet_outer_mm"):
            ckw[key] = _positive(ckw[key], f"{where}.cables[{i}].{key}")
        cables.append(CableDesign(**ckw))
    return Design(scale=_positive(kw["scale"], f"{where}.scale"), printer=profile_name(kw["printer"], f"{where}.printer"),
                  net=NetDesign(**net), cables=tuple(cables))


def load_design(path: str | Path, *, scale: float | None = None) -> Design:
    """Read a design.json file (or the report.json holding one); with `scale`, it must be a
    design at that scale."""
    p = Path(path)
    text = read_input_text(p, "design file", limit=DESIGN_LIMIT_BYTES)
    try:
        data = json.loads(text)
    except (json.JSONDecodeError, RecursionError) as exc:
        raise InputError(f"design file {p} cannot be read as JSON: {exc}") from exc
    if isinstance(data, dict) and "design" in data and "net" not in data:
        data = data["design"]  # a report.json holds the design under "design"
    d = design_from_dict(data, where=str(p))
    if scale is not None and abs(d.scale - scale) > 1e-9 * scale:
        raise InputError(f"design file {p} is a 1:{d.scale:g} design, not 1:{scale:g}; pass "
                         f"--scale {d.scale:g} or search at 1:{scale:g} (printgen design)")
    return d
