"""Load cases of the pre-print check: what pushes on the net as the water rises.

Each module here defines `CASE`, a `LoadCase`; `get_load(name)` finds it (a new load case
is one module plus its test). A case reads the barrier's scene (nodes, anchors, strands,
height and tributary area: a `printgen.verification.scenes.BarrierScene`) and its `Site` (the flow
and strands at that barrier's scale), and gives the solver's loads at each relative loading
r = h / h_B.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from printgen.errors import InputError

FLOW = np.array([0.0, 1.0, 0.0])  # flow direction: the water pushes along it
OVERFLOW = 1.1  # last relative loading h / h_B of the loading test (the water overtops)
DEFAULT = "hydrostatic"  # the loading test of the reference (barrier-physics.md, section 4)
Assumption = tuple[str, str, str]  # (what, value, source)
LoadsAt = Callable[[float], list]  # relative loading r -> the solver's loads


@dataclass(frozen=True)
class Site:
    """What a load case reads of one barrier at its own scale (SI): the approach flow's
    velocity (m/s; the model's is its similitude target) and the net strand diameter (m)."""

    velocity: float
    strand_diameter: float


@dataclass(frozen=True)
class LoadCase:
    """A load case: `title` names it in the report; `loads(scene, site)` builds the loads at
    each relative loading; `assumptions` are the rows it adds to the assumptions table."""

    name: str
    title: str
    loads: Callable[[Any, Site], LoadsAt]
    assumptions: tuple[Assumption, ...]


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
    """The load case called `name` (a LoadCase as it is; None: DEFAULT); InputError listing
    the known ones otherwise."""
    if isinstance(name, LoadCase):
        return name
    known = load_cases()
    found = known.get(name or DEFAULT)
    if found is None:
        raise InputError(f"load case {name!r} is not one of {', '.join(known)}; add "
                         "printgen/barrier/loads/<name>.py or use a known one (--load)")
    return found
