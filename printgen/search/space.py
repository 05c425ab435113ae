"""The design space of `printgen design`: material x strand section x mesh x border, in the
printed net's pattern (`selection.printed_pattern`: diamond, or square for a square-mesh
prototype).

A candidate is a `NetPoint`, a small frozen record that a sweep task evaluates on its own (so
the results do not depend on where it runs). The mesh is parameterised by whole half-diagonals
across and up the panel (nx, ny): every candidate's diagonals fit the model panel exactly
(mesh_x = 2 W / nx, mesh_y = 2 H / ny), as `barrier.patterns.diamond.diamond_net` builds it.

The bounds default to the printer's pass limits (`selection.MAX_BEADS_ACROSS`, `MAX_LAYERS`) and
to each mesh diagonal within +-`MESH_TOLERANCE` of the scaled prototype's (Pi2 = a / h_B; the
tolerance lives in `printgen.scaling.similitude`, which also warns of a [model] mesh chosen for
another scale with it); the user can set all of them.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from printgen.errors import InputError
from printgen.inputs.materials import Material, load_material, material_names
from printgen.inputs.printers import Printer, PrintStyle, load_print_style, load_printer
from printgen.inputs.prototype import Prototype
from printgen.scaling.selection import (
    DEFAULT_PRINTER,
    MAX_BEADS_ACROSS,
    MAX_LAYERS,
    net_print_name,
    printed_pattern,
)
from printgen.scaling.similitude import MESH_TOLERANCE, ScaledTargets

BORDER_BEADS = (2, 4)  # border frame widths searched, in net beads (even: the frame splits
# around the net's corner loops in the parts stage)
MIN_HALF_CELLS = 4  # fewer half-meshes than this across or up is not a net worth verifying
MESH_DIGITS = 6  # mesh diagonals are rounded to 1e-6 mm in the records
# Nets one search screens at most: screening keeps every net's record (~300 bytes in
# candidates.json), about SCREEN_RATE nets per second on one core; the simple barrier's default
# space at 1:40 holds ~230k, and unbounded mesh ranges reach tens of millions.
MAX_CANDIDATES = 500_000
# nets screened per second on one core, for the estimates (26k measured on the 1:40 grid:
# benchmarks/measurements.md#design-verification)
SCREEN_RATE = 20_000
# The solver stage's load-level step (h / h_B): 1 to 220 levels per sweep of 0 to 1.1.
LEVEL_STEP_RANGE = (0.005, 1.1)


@dataclass(frozen=True)
class NetPoint:
    """One candidate net (mm): what a sweep task gets besides the shared `SearchContext`."""

    index: int
    material: str
    beads_across: int
    layers: int
    half_cells_x: int
    half_cells_y: int
    mesh_x_mm: float
    mesh_y_mm: float
    border_beads: int
    pattern: str = "diamond"  # "square": a square mesh of side mesh_x_mm = mesh_y_mm, with
    # half_cells the doubled whole meshes (mesh = 2 L / half_cells, as the diamond's)

    @property
    def net_key(self) -> tuple:
        """The net without its border: candidates that differ only in the border share it."""
        return (self.material, self.beads_across, self.layers, self.half_cells_x,
                self.half_cells_y)


@dataclass(frozen=True)
class SearchSpace:
    """Bounds of the search (mm): materials, beads across, layers, mesh diagonals, border."""

    materials: tuple[str, ...]
    beads: tuple[int, ...]
    layers: tuple[int, ...]
    mesh_x_mm: tuple[float, float]
    mesh_y_mm: tuple[float, float]
    border_beads: tuple[int, ...] = BORDER_BEADS


@dataclass(frozen=True)
class SearchContext:
    """What every screening task shares (sent to each worker once): the prototype, its
    targets at this scale, the printer, the net print style and the material profiles."""

    prototype: Prototype
    targets: ScaledTargets
    printer: Printer
    style: PrintStyle
    materials: tuple[Material, ...]

    @property
    def width_mm(self) -> float:
        return self.targets["width"] * 1e3

    @property
    def height_mm(self) -> float:
        return self.targets["height"] * 1e3

    def material(self, key: str) -> Material:
        for m in self.materials:
            if m.key == key:
                return m
        raise InputError(f"material {key!r} is not in the search; known: "
                         f"{', '.join(m.key for m in self.materials)}")


def search_context(p: Prototype, t: ScaledTargets, space: SearchSpace, *,
                   printer: str | None = None) -> SearchContext:
    """Load the printer, the prototype's net print style and the space's materials."""
    printer_obj = load_printer(printer or p.model.printer or DEFAULT_PRINTER)
    style = load_print_style(net_print_name(p, printer_obj))
    if style.component != "net":
        raise InputError(f"print style {style.key!r} is for {style.component}s, not nets; "
                         "set [model] net_print to a net style (printgen profiles list)")
    return SearchContext(p, t, printer_obj, style, tuple(load_material(m) for m in space.materials))


def default_space(p: Prototype, t: ScaledTargets, *, materials: tuple[str, ...] | None = None,
                  mesh_x_mm: tuple[float, float] | None = None,
                  mesh_y_mm: tuple[float, float] | None = None,
                  tolerance: float = MESH_TOLERANCE,
                  border_beads: tuple[int, ...] = BORDER_BEADS) -> SearchSpace:
    """The default space, with the user's bounds where given (None: the default)."""
    if not 0 <= tolerance < 1:
        raise InputError(f"mesh tolerance {tolerance:g} must be in [0, 1) (0.25 = +-25 %)")
    ax, ay = t["mesh_x"] * 1e3, t["mesh_y"] * 1e3
    space = SearchSpace(
        materials=material_names(materials, p.model.materials),
        beads=tuple(range(1, MAX_BEADS_ACROSS["net"] + 1)),
        layers=tuple(range(1, MAX_LAYERS["net"] + 1)),
        mesh_x_mm=mesh_x_mm or (ax * (1 - tolerance), ax * (1 + tolerance)),
        mesh_y_mm=mesh_y_mm or (ay * (1 - tolerance), ay * (1 + tolerance)),
        border_beads=tuple(border_beads))
    check_space(space)
    return space


def check_space(space: SearchSpace) -> None:
    """Raise InputError naming the bad bound."""
    for name, (lo, hi) in (("mesh x", space.mesh_x_mm), ("mesh y", space.mesh_y_mm)):
        if not (math.isfinite(lo) and math.isfinite(hi) and 0 < lo <= hi):
            raise InputError(f"{name} bounds {lo:g}:{hi:g} mm must be positive with low <= high; "
                             "give e.g. --mesh-x-mm 12:20")
    for name, vals in (("beads", space.beads), ("layers", space.layers),
                       ("border beads", space.border_beads)):
        if not vals or min(vals) < 1:
            raise InputError(f"{name} {list(vals)} must be whole numbers >= 1")
    odd = [b for b in space.border_beads if b % 2]
    if odd:
        raise InputError(f"border beads {odd} must be even: the printed border frame splits "
                         "around the net's corner loops; use e.g. --border-beads 2,4")
    if not space.materials:
        raise InputError("no materials to search; name at least one (--materials tpe)")


def half_cell_counts(length_mm: float, bounds_mm: tuple[float, float]) -> list[int]:
    """Whole half-diagonal counts n whose diagonal 2 L / n lies within the bounds."""
    lo = max(math.ceil(2 * length_mm / bounds_mm[1] - 1e-9), MIN_HALF_CELLS)
    hi = math.floor(2 * length_mm / bounds_mm[0] + 1e-9)
    return list(range(lo, hi + 1))


def grid(ctx: SearchContext, space: SearchSpace) -> list[NetPoint]:
    """Every candidate of the space, in a fixed order (material, section, mesh, border)."""
    nxs = half_cell_counts(ctx.width_mm, space.mesh_x_mm)
    nys = half_cell_counts(ctx.height_mm, space.mesh_y_mm)
    if not nxs or not nys:
        which = "x" if not nxs else "y"
        length = ctx.width_mm if which == "x" else ctx.height_mm
        bounds = space.mesh_x_mm if which == "x" else space.mesh_y_mm
        raise InputError(f"mesh {which} bounds {bounds} mm hold no whole number (>= "
                         f"{MIN_HALF_CELLS}) of half-meshes across the {length:.4g} mm panel; "
                         "widen the bounds")
    check_size(space, len(nxs), len(nys))
    pattern = printed_pattern(ctx.prototype)
    meshes = (_square_meshes(ctx, nxs) if pattern == "square" else
              [(nx, ny, round(2 * ctx.width_mm / nx, MESH_DIGITS),
                round(2 * ctx.height_mm / ny, MESH_DIGITS)) for nx in nxs for ny in nys])
    out: list[NetPoint] = []
    for mat in space.materials:
        for beads in space.beads:
            for layers in space.layers:
                for nx, ny, mx, my in meshes:
                    for border in space.border_beads:
                        out.append(NetPoint(len(out), mat, beads, layers, nx, ny, mx, my,
                                            border, pattern))
    return out


def _square_meshes(ctx: SearchContext, nxs: list[int]) -> list[tuple[int, int, float, float]]:
    """(half cells across, up, side, side) of the square meshes whose side fits the panel's
    width in whole meshes (an even half-cell count) within the bounds across; up, the
    height rounded to whole meshes as `square_graph` builds it (its bounds do not apply: the
    mesh is one side both ways)."""
    out = []
    for nx in nxs:
        if nx % 2:
            continue
        side = round(2 * ctx.width_mm / nx, MESH_DIGITS)
        ny = 2 * round(ctx.height_mm / side)
        if ny >= MIN_HALF_CELLS:
            out.append((nx, ny, side, side))
    return out


def space_factors(space: SearchSpace, n_across: int, n_up: int) -> tuple[int, ...]:
    """How many materials, beads, layers, meshes across and up (`n_across`, `n_up`: the
    targets' scale's) and borders the space combines: its size is their product."""
    return (len(space.materials), len(space.beads), len(space.layers), n_across, n_up,
            len(space.border_beads))


def check_size(space: SearchSpace, n_across: int, n_up: int) -> None:
    """InputError before any work when the space holds more than MAX_CANDIDATES nets: each
    screened net is kept (its record, candidates.json), so time and memory grow with it."""
    factors = space_factors(space, n_across, n_up)
    n = math.prod(factors)
    if n > MAX_CANDIDATES:
        raise InputError(
            f"the search space holds {n:,} nets (materials x beads x layers x meshes across x "
            f"meshes up x borders = {' x '.join(map(str, factors))}), over the "
            f"{MAX_CANDIDATES:,} one search screens (about {MAX_CANDIDATES // SCREEN_RATE} s "
            "and a few hundred MB); narrow --mesh-x-mm / --mesh-y-mm (or --mesh-tolerance), "
            "--materials or --border-beads")


def check_level_step(step: float | None) -> None:
    """InputError unless the solver stage's load-level step lies in LEVEL_STEP_RANGE."""
    lo, hi = LEVEL_STEP_RANGE
    if step is not None and not (math.isfinite(step) and lo <= step <= hi):
        raise InputError(f"--level-step {step:g} is outside {lo:g} to {hi:g} (h / h_B per "
                         f"level: {1.1 / lo:.0f} to {1.1 / hi:.0f} levels per sweep); the "
                         "verification's own step is 0.05")


def space_record(space: SearchSpace, n_points: int) -> dict:
    """JSON-ready record of the bounds and the grid size."""
    return {"materials": list(space.materials), "beads_across": list(space.beads),
            "layers": list(space.layers), "mesh_x_mm": list(space.mesh_x_mm),
            "mesh_y_mm": list(space.mesh_y_mm), "border_beads": list(space.border_beads),
            "candidates": n_points}
