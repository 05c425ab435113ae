"""Net patterns: how a mesh of strands turns into a graph, a membrane law and a node count.

Each module here defines `PATTERN`, a `NetPattern`; `get_pattern(name)` finds it (a new
pattern is one module plus its test). Lengths of the graph in mm, of the laws in m.
"""

from __future__ import annotations

import functools
from collections.abc import Callable
from dataclasses import dataclass, field

from printgen.barrier.graph import NetGraph
from printgen.errors import InputError
from printgen.solver import Law  # the one force-strain law type: strain knees, force slopes (N)

# Patterns built from parameters, not entries of the registry: "curved" makes a curved-strand
# net of a layout (square or diamond) and a wave. Not a [net] or [model] pattern choice: a design
# does not record a wave, and meshes and G-code of curved strands are not built.
FAMILIES = ("curved",)

# Prototype patterns drawn as another (the prototype file's [net] pattern), said so in the
# verification's assumptions.
AS_DRAWN = {"water-drop": "diamond"}


@dataclass(frozen=True)
class NetPattern:
    """A net pattern as data: its functions of the mesh (a_along: mesh along the load, i.e.
    up the barrier; a_across: across it).

    graph(width_mm, height_mm, mesh_x_mm, mesh_y_mm) : the NetGraph of a panel about that size
    membrane_factor(a_along, a_across) : 1/m, membrane stiffness (N/m) per strand E*A (N)
    strand_law(knees, slopes N/m, a_along, a_across) : the strand law (knees, N) whose net
      has the membrane law
    strand_force(n, a_along, a_across) : N, the strand tension under a membrane force n N/m
      along the load
    span(length, mesh) : `length` rounded to the lattice of `mesh` (any unit)
    nodes(width, height, mesh_x, mesh_y) : nodes of `graph` (any length unit)
    edge_strands : the border loop's segments are strands of the prototype's net (the
      square's edge rows); False: the border is only the printed frame (the diamond's)
    lockup(a_along, a_across) : the panel strain at which a free pin-jointed panel's strands
      lie along the load (its meshes closed across it: a mechanism below); None: they lie
      along it from the start (the square's strands up)
    mesh_name : what mesh_x and mesh_y measure, as the outputs name it ("mesh side",
      "mesh diagonal")
    check_mesh(mesh_x, mesh_y, where) : GeometryError naming `where` when the pattern cannot
      have that mesh (the square's sides must be equal; mesh_y None: taken as mesh_x)
    panel_test : the virtual panel test (`testpieces`, the panel command) models this pattern
    """

    name: str
    graph: Callable[[float, float, float, float], NetGraph]
    membrane_factor: Callable[[float, float], float]
    strand_law: Callable[[tuple[float, ...], tuple[float, ...], float, float], Law]
    strand_force: Callable[[float, float, float], float]
    span: Callable[[float, float], float]
    nodes: Callable[[float, float, float, float], int]
    edge_strands: bool = False
    lockup: Callable[[float, float], float] | None = None
    # below: no defaults, so that a new pattern states each of them
    mesh_name: str = field(kw_only=True)
    check_mesh: Callable[[float, float | None, str], None] = field(kw_only=True)
    panel_test: bool = field(kw_only=True)


def mesh_text(pattern: str, mesh_x_mm: float, mesh_y_mm: float) -> str:
    """How a printed net is named in every output: "square mesh 5 x 5 mm" (the square's
    sides), "diamond mesh 20.6 x 9.4 mm" (the diamond's diagonals), across x up."""
    return f"{pattern} mesh {mesh_x_mm:g} x {mesh_y_mm:g} mm"


def any_mesh(mesh_x: float, mesh_y: float | None, where: str = "net") -> None:
    """`check_mesh` of a pattern that takes any mesh_x and mesh_y (the diamond's diagonals)."""


def panel_test_patterns() -> tuple[str, ...]:
    """The patterns the virtual panel test models (`NetPattern.panel_test`)."""
    return tuple(name for name, p in patterns().items() if p.panel_test)


def pattern_names() -> tuple[str, ...]:
    """Every pattern's name, then those drawn as another (`AS_DRAWN`), without importing the
    patterns: the prototype file's [net] pattern choices."""
    import printgen.barrier.patterns as package
    from printgen.barrier.registry import names

    return (*names(package), *AS_DRAWN)


def printed_pattern_names() -> tuple[str, ...]:
    """The patterns printgen builds (meshes, toolpaths, scenes), without importing them: the
    choices of [model] pattern."""
    import printgen.barrier.patterns as package
    from printgen.barrier.registry import names

    return tuple(names(package))


def patterns() -> dict[str, NetPattern]:
    """Every pattern, by name (a copy: the registry is read once per process)."""
    return dict(_registry())


@functools.cache
def _registry() -> dict[str, NetPattern]:
    """The registry's scan of this package, once: `get_pattern` runs for every candidate a
    design search screens, and the folder's scan was more than half of its time."""
    import printgen.barrier.patterns as package
    from printgen.barrier.registry import entries

    return entries(package, "PATTERN")


def get_pattern(name: str) -> NetPattern:
    """The pattern called `name` (or the one it is drawn as, `AS_DRAWN`); InputError
    listing the known ones otherwise."""
    known = _registry()
    found = known.get(AS_DRAWN.get(name, name))
    if found is None:
        raise InputError(f"net pattern {name!r} is not one of {', '.join(known)}; add "
                         "printgen/barrier/patterns/<name>.py or use a known one")
    return found
