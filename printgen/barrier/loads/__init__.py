"""Load cases of the pre-print check: what pushes on the net as the water rises.

Each module here defines `CASE`, a `LoadCase`; `get_load(name)` finds it (a new load case
is one module plus its test). A case reads the barrier's scene through `SceneView` (nodes,
anchors, strands, size and tributary area: `printgen.scene.BarrierScene` is one) and its
`Site` (the flow
and strands at that barrier's scale), and gives the solver's loads at each relative loading
r = h / h_B (the upstream water depth over the barrier's height).

A case may take parameters (`Param`: default and range, given on the command line as
`--load-param KEY=VALUE`); its spec string is then "name:key=value,key=value" (`spec`,
what travels through `make` and its helper processes), and `get_load(spec)` checks each
value against its range. A case may also give its own load levels (`levels`: the jam's
discharge steps) and what it used at each level (`per_level`: velocities, discharges) for
report.json and the assumptions table.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from typing import Any, Protocol

import numpy as np

from printgen.errors import InputError

FLOW = np.array([0.0, 1.0, 0.0])  # flow direction: the water pushes along it
OVERFLOW = 1.1  # last relative loading h / h_B of the loading test (the water overtops)
DEFAULT = "hydrostatic"  # the loading test of the reference (barrier-physics.md, section 4)
Assumption = tuple[str, str, str]  # (what, value, source)
LoadsAt = Callable[[float], list]  # relative loading r -> the solver's loads


class SceneView(Protocol):
    """What a load case reads of a barrier's solver scene (SI): nodes (n, 3) m at rest,
    fixed (n,) bool anchors, elements (m, 2) int the net's strands, width and height m,
    area_per_node m^2 (A*, the tributary area of a node)."""

    @property
    def nodes(self) -> np.ndarray: ...
    @property
    def fixed(self) -> np.ndarray: ...
    @property
    def elements(self) -> np.ndarray: ...
    @property
    def width(self) -> float: ...
    @property
    def height(self) -> float: ...
    @property
    def area_per_node(self) -> float: ...


@dataclass(frozen=True)
class Site:
    """What a load case reads of one barrier at its own scale (SI): the approach flow's
    velocity (m/s; the model's is its similitude target), the net strand diameter (m), the
    flow depth at which that velocity is given (m; None: the barrier's height), the width
    of the flow section the barrier spans (m; None: the barrier's width) and the scale ratio
    lambda of this barrier (1: the prototype; model lengths are the prototype's / lambda)."""

    velocity: float
    strand_diameter: float
    depth: float | None = None
    flow_width: float | None = None
    scale: float = 1.0


@dataclass(frozen=True)
class Param:
    """A load case's parameter: its default and allowed range [low, high] in `unit`."""

    name: str
    default: float
    low: float
    high: float
    unit: str
    help: str


@dataclass(frozen=True)
class LoadCase:
    """A load case: `title` names it in the report; `loads(scene, site, **values)` builds the
    loads at each relative loading; `assumptions` are the rows it adds to the assumptions
    table. `params` declares its parameters and `values` holds the ones in use (`get_load`
    fills them); `levels(scene, site, **values)`, when given, is the case's own load levels
    (relative loading, increasing, from 0); `per_level(scene, site, levels, **values)` what
    the case used at each level (name -> per-level values, JSON-ready) and a one-line text."""

    name: str
    title: str
    loads: Callable[..., LoadsAt]
    assumptions: tuple[Assumption, ...]
    params: tuple[Param, ...] = ()
    values: tuple[tuple[str, float], ...] = ()
    levels: Callable[..., np.ndarray] | None = None
    per_level: Callable[..., tuple[dict[str, Any], str]] | None = None

    @property
    def spec(self) -> str:
        """The case as a string get_load reads back: its name, then its parameters."""
        if not self.values:
            return self.name
        return f"{self.name}:" + ",".join(f"{k}={v:g}" for k, v in self.values)

    def loads_for(self, scene: SceneView, site: Site) -> LoadsAt:
        """The loads at each relative loading, with this case's parameter values."""
        return self.loads(scene, site, **dict(self.values))

    def levels_for(self, scene: SceneView, site: Site) -> np.ndarray | None:
        """The case's own load levels (None: the sweep's usual ones)."""
        return None if self.levels is None else self.levels(scene, site, **dict(self.values))

    def describe(self, scene: SceneView, site: Site, levels: np.ndarray
                 ) -> tuple[dict[str, Any], str]:
        """What the case used at each of `levels`, and a one-line text of it."""
        if self.per_level is None:
            return {}, ""
        return self.per_level(scene, site, levels, **dict(self.values))


def case_names() -> list[str]:
    """The load cases' names (for the command line), without importing them."""
    import printgen.barrier.loads as package
    from printgen.barrier.registry import names

    return names(package)


def load_cases() -> dict[str, LoadCase]:
    """Every load case, by name."""
    import printgen.barrier.loads as package
    from printgen.barrier.registry import entries

    return entries(package, "CASE")


def get_load(name: str | LoadCase | None = None) -> LoadCase:
    """The load case of spec `name` ("case" or "case:key=value,..."; a LoadCase as it is;
    None: DEFAULT) with every parameter's value (the default unless given) checked against
    its range; InputError listing the known cases or naming the bad value otherwise."""
    if isinstance(name, LoadCase):
        return name
    base, _, given = (name or DEFAULT).partition(":")
    known = load_cases()
    found = known.get(base)
    if found is None:
        raise InputError(f"load case {base!r} is not one of {', '.join(known)}; add "
                         "printgen/barrier/loads/<name>.py or use a known one (--load)")
    values = parse_values(found, given)
    return dataclasses.replace(found, values=values) if values else found


def distinct_specs(loads: Iterable[str | LoadCase]) -> list[str]:
    """The full specs of `loads` (`make --loads`), once each, in their order."""
    return list(dict.fromkeys(get_load(x).spec for x in loads))


def parse_values(case: LoadCase, given: str) -> tuple[tuple[str, float], ...]:
    """(key, value) of each of `case`'s parameters: `given` ("key=value,...") over the
    defaults, each checked against its range."""
    params = {p.name: p for p in case.params}
    values = {p.name: p.default for p in case.params}
    for item in filter(None, (x.strip() for x in given.split(","))):
        key, eq, text = item.partition("=")
        key = key.strip()
        if key not in params:
            have = ", ".join(params) or "none"
            raise InputError(f"load case {case.name!r} has no parameter {key!r} (its "
                             f"parameters: {have}); use --load-param KEY=VALUE with one of them")
        try:
            values[key] = float(text) if eq else math.nan
        except ValueError:
            values[key] = math.nan
        p = params[key]
        if not p.low <= values[key] <= p.high:
            raise InputError(f"--load-param {key}={text.strip()}: {case.name}'s {p.help} must be "
                             f"a number from {p.low:g} to {p.high:g} {p.unit}; give one in range")
    return tuple(values.items())


def with_params(spec: str, params: list[str] | tuple[str, ...]) -> str:
    """`spec` with KEY=VALUE items `params` added (those of `--load-param`), checked."""
    if not params:
        return get_load(spec).spec
    base, _, given = spec.partition(":")
    return get_load(f"{base}:{','.join([*filter(None, [given]), *params])}").spec

