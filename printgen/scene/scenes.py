"""Solver scenes of the pre-print check (barrier-physics.md, section 7): the prototype and the
printed model as tension-only strand nets, mounted as in the flume and measured by the
three extension sensors of the loading test (Lambert et al. 2023, doi:10.1061/JHEND8.HYENG-13070).

Plane of the net: x across the barrier, z up (from the flume bed), y the flow direction. Net strands
are the pattern's graph's strand segments (`printgen.barrier.patterns`: the diamond's diagonals, the
square's strands up and across, whose edge rows are strands of the prototype and the printed border
frame of the model); their force-strain law is the panel law turned into a strand law by the pattern
(`NetPattern.strand_law`). With border cables, the cables slide through the net's edge nodes between
the four corner anchors; the lateral edges are held by the flume's side sheets along their whole
height (`walls`, the default) or only the lateral cables' eyelets are anchored (`eyelets`). Without
border cables the net is anchored on the bed and the banks and its top is free.

Sensor wires (`Wire`; as solver cables in `printgen.scene.solvernet`): a string
potentiometer's wire is anchored at the barrier's left edge node of its row, runs along the
row of nodes (the nodes are the points the wire bends over, frictionless), leaves the right
edge node and runs on, in line with the row at rest, to the potentiometer `SENSOR_EXIT` x width
beyond the right edge. Its spring keeps it taut at the sensor's force (`SENSOR_FORCE_N` unless
the prototype file's [flume] sensor_force_n says otherwise) whatever its length. The reading
is the change of the wire's length from the anchor to the potentiometer; the elongation is
that change over the row's rest length.
The mid-height wire lies at exactly half the net's height, which in general falls between two
node rows (z1 < h/2 < z2). The net between them is represented by linear interpolation in z,
so a wire at h/2 is the two rows' wires weighted (z2 - h/2) / (z2 - z1) and (h/2 - z1) /
(z2 - z1): its reading is the weighted change of their lengths over the weighted rest length,
and its pull is split between them in the same proportions (the consistent nodal forces of a
wire between the rows). As the mesh is refined both rows close in on h/2, so the reading
converges; it is never the top or bottom row's.
On the model the wires pull (the flume test as it is run); on the prototype they only read.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field

import numpy as np

from printgen.barrier.graph import NetGraph
from printgen.barrier.loads import FLOW, LoadCase, get_load
from printgen.barrier.patterns import AS_DRAWN, get_pattern, mesh_text
from printgen.errors import GeometryError
from printgen.inputs.materials import load_material
from printgen.inputs.prototype import LATERAL, Prototype
from printgen.inputs.prototype import SENSOR_FORCE_N as PAPER_SENSOR_N
from printgen.scaling.panel_test import TESTED_PATTERN
from printgen.scaling.reading import (
    ORIENTATIONS,
    PROTOTYPE_ORIENTATION,
    panel_axes,
    panel_reading,
    recorded_orientation,
)
from printgen.scaling.record import Design
from printgen.scaling.section import area_m2, net_membrane_law
from printgen.scene.rows import mid_levels, to_edges
from printgen.solver import Law, linear
from printgen.units import MM, RHO_WATER, G

# wire tension of each string potentiometer (reference, section 4), unless [flume] says
SENSOR_FORCE_N = PAPER_SENSOR_N
MID_UPPER = "mid_upper"  # the mid-height sensor's wire on the row above h/2 (when between rows)
SENSOR_EXIT = 0.1  # the potentiometer stands this fraction of the width beyond the right edge
__all__ = ["FLOW", "ORIENTATIONS", "PROTOTYPE_ORIENTATION", "TESTED_PATTERN",  # re-exported
           "recorded_orientation"]  # FLOW: the flow direction (printgen.barrier.loads)
MOUNTINGS = LATERAL  # lateral mounting in the flume ([flume] lateral), the default first
# Panel-test orientation (ORIENTATIONS): the diagonal of the mesh its panel test loaded, the one
# a panel law is read along. The prototype's is stated by its source (PROTOTYPE_ORIENTATION);
# a printed net's is chosen by physical consistency (`printgen.scaling.reading`).
# Direction of the water's force on a node: along the flow (the reference's section 3), or
# normal to the deformed net (the film lies on the net: `printgen.scene.pressure`).
PRESSURES = ("flow", "normal")
# Stiffness holding each free node where it is when its strands carry no load (N/m), as a
# fraction of rho g A* (the rate at which a node's hydrostatic load grows per metre of head):
# it scales like every stiffness (lambda^-2), so prototype and model get the same share.
HOLD_FRACTION = 1e-3

Assumption = tuple[str, str, str]  # (what, value, source)


@dataclass(frozen=True)
class Wire:
    """A sensor wire: `nodes` (k,) the row it follows, anchor first; `exit` (3,) m the fixed
    point where it enters the potentiometer; `force` N its tension (0: it only reads);
    `weight` its share of its sensor (of the reading and of the sensor's pull: 1 unless the
    sensor lies between two rows, see the module)."""

    nodes: np.ndarray
    exit: np.ndarray
    force: float
    weight: float = 1.0


def sensor_of(key: str) -> str:
    """The sensor ("bottom", "top", "mid") a wire of `BarrierScene.wires` belongs to: its key,
    up to an underscore (MID_UPPER is the mid-height sensor's second wire)."""
    return key.split("_")[0]


def sensor_wires(wires: dict[str, Wire], sensor: str) -> list[Wire]:
    """The wires of `sensor` in `wires` (one, or the two rows a mid-height wire lies between)."""
    return [w for k, w in wires.items() if sensor_of(k) == sensor]


@dataclass(frozen=True)
class BarrierScene:
    """A barrier as arrays for the solver (SI).

    nodes : (n, 3) m; fixed : (n,) bool anchors; elements : (m, 2) int; element_law : (m,) int
    index into `laws`; cables : name -> (node sequence anchor..anchor, law);
    rows : name -> node sequence of the bottom, top and mid-height rows (left to right; "mid"
    the row nearest h/2 among the one or two the mid-height sensor is read from); centre : the
    node nearest the centre of rows["mid"]; top_centre : of the top row;
    wires : the sensor wires by row name (the mid-height sensor's second row: MID_UPPER);
    area_per_node : m^2 (A* = net area / nodes);
    mounting : one of MOUNTINGS; hold : N/m holding each free node at rest (0: none);
    assumptions : (what, value, source) of every modelling choice, for the report.
    """

    name: str
    scale: float
    width: float
    height: float
    nodes: np.ndarray
    fixed: np.ndarray
    elements: np.ndarray
    element_law: np.ndarray
    laws: list[Law]
    cables: dict[str, tuple[np.ndarray, Law]]
    rows: dict[str, np.ndarray]
    centre: int
    top_centre: int
    area_per_node: float
    wires: dict[str, Wire] = field(default_factory=dict)
    mounting: str = MOUNTINGS[0]
    hold: float = 0.0
    assumptions: tuple[Assumption, ...] = ()
    pressure: str = "flow"  # one of PRESSURES: the water's force along the flow or normal
    rest_nodes: np.ndarray | None = None  # (n, 3) m printed geometry when mounted otherwise
    # (node, weight) at the centre of each row the mid-height sensor is read from: the
    # deflection at mid-height is interpolated between them as the reading is (empty: `centre`)
    mid_centres: tuple[tuple[int, float], ...] = ()


def _net_arrays(g: NetGraph, to_m: float
                ) -> tuple[np.ndarray, dict[str, np.ndarray], list[tuple[np.ndarray, float]],
                           tuple[tuple[int, float], ...], int]:
    """3D nodes (m), edge node sequences (corner to corner; "mid": the mid-height row nearest
    h/2), the mid-height sensor's (wire nodes, weight) rows, the (centre node, weight) of each
    of those rows and the top-centre node."""
    xy = g.nodes_mm * to_m
    nodes = np.column_stack([xy[:, 0], np.zeros(len(xy)), xy[:, 1]])
    w, h = xy[:, 0].max(), xy[:, 1].max()
    tol = 1e-9 * max(w, h)

    def edge(mask: np.ndarray, key: np.ndarray) -> np.ndarray:
        idx = np.flatnonzero(mask)
        return idx[np.argsort(key[idx])]

    x, z = nodes[:, 0], nodes[:, 2]
    edges = {"bottom": edge(z < tol, x), "top": edge(z > h - tol, x),
             "left": edge(x < tol, z), "right": edge(x > w - tol, z)}
    bracket = [(edge(np.abs(z - level) < 2 * tol, x), weight)
               for level, weight in mid_levels(x, z, w, h, tol)]
    mids = [(to_edges(row, edges["left"], edges["right"], z), wt) for row, wt in bracket]
    edges["mid"] = max(bracket, key=lambda m: m[1])[0]
    centres = tuple((int(r[np.argmin(np.abs(x[r] - w / 2))]), wt) for r, wt in bracket)
    top_centre = int(edges["top"][np.argmin(np.abs(x[edges["top"]] - w / 2))])
    return nodes, edges, mids, centres, top_centre


def _scene(name: str, scale: float, g: NetGraph, to_m: float, net_law: Law,
           cable_law: Law | None, border_law: Law | None, mounting: str) -> BarrierScene:
    if mounting not in MOUNTINGS:
        raise GeometryError(f"mounting {mounting!r} is not one of {', '.join(MOUNTINGS)}; "
                            "set [flume] lateral in the prototype file")
    nodes, edges, mids, centres, top_centre = _net_arrays(g, to_m)
    centre = max(centres, key=lambda c: c[1])[0]
    diag = g.family != 0
    elements, element_law, laws = g.segments[diag], np.zeros(int(diag.sum()), int), [net_law]
    if border_law is not None:
        elements = np.vstack([elements, g.segments[~diag]])
        element_law = np.concatenate([element_law, np.ones(int((~diag).sum()), int)])
        laws.append(border_law)
    fixed = np.zeros(len(nodes), dtype=bool)
    cables = {}
    if cable_law is not None:  # four corner anchors, cables sliding along the edges
        fixed[[edges["bottom"][0], edges["bottom"][-1], edges["top"][0], edges["top"][-1]]] = True
        if mounting == "walls":  # the side sheets hold the lateral edges along their height
            fixed[np.concatenate([edges["left"], edges["right"]])] = True
        cables = {side: (edges[side], cable_law) for side in ("bottom", "top", "left", "right")}
    elif mounting != "walls":
        raise GeometryError(f"mounting {mounting!r} needs border cables (their eyelets are the "
                            "anchors); a net without border cables is anchored on the bed and "
                            "the banks: set [flume] lateral = \"walls\"")
    else:  # no border cables: anchored on the bed and the banks, top free (simple-free-top)
        fixed[np.concatenate([edges["bottom"], edges["left"], edges["right"]])] = True
    w, h = float(nodes[:, 0].max()), float(nodes[:, 2].max())
    rows = {k: edges[k] for k in ("bottom", "top", "mid")}
    beyond = np.array([SENSOR_EXIT * w, 0.0, 0.0])
    wires = {k: Wire(edges[k], nodes[edges[k][-1]] + beyond, 0.0) for k in ("bottom", "top")}
    for key, (r, weight) in zip(("mid", MID_UPPER), mids, strict=False):
        wires[key] = Wire(r, nodes[r[-1]] + beyond, 0.0, weight)
    area = w * h / len(nodes)
    hold = HOLD_FRACTION * RHO_WATER * G * area if cable_law is None else 0.0
    return BarrierScene(name, scale, w, h, nodes, fixed, elements, element_law, laws, cables,
                        rows, centre, top_centre, area, wires, mounting, hold,
                        mid_centres=centres)


def lateral_mounting(p: Prototype) -> str:
    """The prototype file's `[flume] lateral` (the default when it has no [flume] table)."""
    return p.flume.lateral if p.flume is not None else MOUNTINGS[0]


def prototype_scene(p: Prototype, *, mounting: str | None = None,
                    orientation: str = PROTOTYPE_ORIENTATION,
                    load: str | LoadCase | None = None,
                    sensor_force: float = 0.0) -> BarrierScene:
    """The prototype's nominal scene (callers use `printgen.scene.build_scene`, which applies
    the other options): net with its panel law (read along the mesh diagonal `orientation`) or
    linear strands, sliding border cables, mounted like the model (`mounting`, default the
    file's [flume] lateral); its sensor wires only read (a field barrier carries no sensors)
    unless `sensor_force` N > 0 (the model's sensor force scaled by lambda^3, to tell the
    sensors' disturbance apart); `load`: the load case its assumptions state (default
    hydrostatic)."""
    mounting = mounting or lateral_mounting(p)
    pattern = get_pattern(p.net.pattern)
    g = pattern.graph(p.width / MM, p.height / MM, p.net.mesh_x / MM, p.net.mesh_y / MM)
    if pattern.edge_strands:  # the square's edge rows are strands of the prototype's net
        g = dataclasses.replace(g, family=np.where(g.family == 0, 1, g.family))
    if p.net.panel_law is not None:
        knees, kappas, length = p.net.panel_law
        along, across = panel_axes(p.net.mesh_x, p.net.mesh_y, orientation)
        net_law = pattern.strand_law(knees, tuple(k * length for k in kappas), along, across)
        law_text = ("panel law " + ", ".join(f"{k / 1e3:g}" for k in kappas) + " kN/m/m"
                    + (" (knees " + ", ".join(f"{k:.0%}" for k in knees) + ")" if knees else "")
                    + f" of a panel loaded along the {along / MM:g} mm ({orientation}) "
                    "diagonal, transverse displacement blocked, turned into a strand law"
                    + (" (the diagonal and the test mode the source states: no reading to "
                       "choose)" if orientation == PROTOTYPE_ORIENTATION else ""))
    else:
        net_law = linear(p.net.strand_modulus * math.pi / 4 * p.net.strand_diameter**2)
        law_text = (f"linear strands E = {p.net.strand_modulus / 1e9:g} GPa, "
                    f"d = {p.net.strand_diameter / MM:g} mm")
    cable_law = None
    if p.border is not None:
        cable_law = linear(p.border.modulus * math.pi / 4 * p.border.diameter**2)
    s = _scene(f"{p.name}: prototype", 1.0, g, MM, net_law, cable_law, None, mounting)
    src = f"prototype file {p.path.name}" if p.path else "prototype file"
    drawn = f" (as {AS_DRAWN[p.net.pattern]}s)" if p.net.pattern in AS_DRAWN else ""
    rows = [("net", (f"{p.net.pattern} mesh {p.net.mesh_x / MM:g} x {p.net.mesh_y / MM:g} mm"
                     f"{drawn}, {len(s.nodes)} nodes"), src), ("net strands", law_text, src)]
    if p.border is not None:
        rows.append(("border cables", (f"d = {p.border.diameter / MM:g} mm, E = "
                     f"{p.border.modulus / 1e9:g} GPa, sliding, no pretension"), src))
    return _finish(s, rows, force=sensor_force, load=load, model=False)


def model_scene(d: Design, *, mounting: str = MOUNTINGS[0],
                orientation: str | None = None,
                load: str | LoadCase | None = None,
                sensor_force: float = SENSOR_FORCE_N) -> BarrierScene:
    """The printed model's nominal scene (callers use `printgen.scene.build_scene`, which
    applies the other options): its pattern's net with the material's (measured) law, printed
    border frame, cables of the measured modulus, mounted by `mounting`, and the three sensor
    wires pulling `sensor_force` N along themselves ([flume] sensor_force_n). `orientation`
    ("short", "long"): the mesh diagonal the material's panel test loaded (None: the reading
    its material can produce, `printgen.scaling.reading`); `load`: the load case its
    assumptions state (default hydrostatic)."""
    n = d.net
    pattern = get_pattern(n.pattern)
    g = n.graph()
    mat = load_material(n.material)
    net_law, how = model_net_law(mat, n, orientation)
    e, e_src = frame_modulus(mat, orientation)
    border_ea = e * n.border_width_mm * n.strand.thickness_mm * MM * MM
    cable_law, rows = None, []
    if d.cables:
        c = d.cables[0]
        cm = load_material(c.material)
        ce, ce_src = cm.modulus()
        cable_law = linear(ce * area_m2(c.section))
        rows.append(("border cables", (f"{cm.name}, E = {ce / 1e9:.3g} GPa ({ce_src}), "
                     f"{c.section.width_mm:g} x {c.section.thickness_mm:g} mm, sliding"),
                     f"profile materials/{c.material}"))
    s = _scene(f"printed model 1:{d.scale:g}", d.scale, g, MM, net_law, cable_law,
               linear(border_ea), mounting)
    rows = [("net", (f"{mesh_text(pattern.name, n.mesh_x_mm, n.mesh_y_mm)}, "
             f"{len(s.nodes)} nodes, rigid junctions"), "design"),
            ("net strands", (f"{mat.name}: {how}, strand {n.strand.width_mm:g} x "
             f"{n.strand.thickness_mm:g} mm"), f"profile materials/{n.material}"),
            ("printed border frame", (f"{n.border_width_mm:g} mm wide, E = {e / 1e9:.3g} GPa "
             f"({e_src})" + (", on the edge rows (the prototype's edge strands)"
                             if pattern.edge_strands else "")),
             f"design; profile materials/{n.material}"), *rows]
    reading = panel_reading(mat) if orientation is None else None
    if reading is not None:
        rows.insert(2, ("panel-law reading", reading.why() + ". " + "; ".join(
            c.summary() for c in reading.checks),
            f"profile materials/{n.material} [measured.panel_law] and [datasheet]; printgen "
            "docs: physics, the reading of a panel law"))
    return _finish(s, rows, force=sensor_force, load=load, model=True)


def frame_modulus(mat, orientation: str | None) -> tuple[float, str]:
    """(E Pa, its source) of the printed border frame, a strip of the net's material printed
    as its strands are: the measured printed modulus when the profile has one; else, with a
    panel law, the strand modulus its reading implies (the reading the material can produce,
    or `orientation`): a printed strand's modulus, where the datasheet's is the filament's;
    else the datasheet's."""
    e, source = mat.modulus()
    reading = panel_reading(mat)
    if source == "measured" or reading is None:
        return e, source
    check = reading.check(orientation or reading.orientation)
    return check.modulus, f"implied by the panel law read along its {check.orientation} diagonal"


def model_net_law(mat, n, orientation: str | None) -> tuple[Law, str]:
    """The printed net's strand law and how it was found: a panel law with its tested net is
    read along the tested net's `orientation` diagonal (None: the reading the material can
    produce, `printgen.scaling.reading`): a strand law of the tested strands, rescaled to the
    design's strand section; otherwise the membrane law of the design."""
    law = mat.panel_law
    if law is None or not law.has_geometry:
        knees, slopes, how = net_membrane_law(mat, n.strand, n.mesh_y_mm * MM, n.mesh_x_mm * MM,
                                              n.pattern)
        law_of = get_pattern(n.pattern).strand_law
        return law_of(knees, slopes, n.mesh_y_mm * MM, n.mesh_x_mm * MM), how
    if orientation is None:  # the reading the material can produce
        reading = panel_reading(mat)
        orientation = reading.orientation if reading is not None else recorded_orientation(law)
    along, across = panel_axes(law.mesh_along_load, law.mesh_across_load, orientation)
    tested = get_pattern(TESTED_PATTERN).strand_law(
        law.knee_strains, tuple(k * law.panel_length for k in law.kappas), along, across)
    ratio = area_m2(n.strand) / (law.strand_width * law.strand_thickness)
    return tested.scaled(ratio), (
        f"measured panel law read along the tested net's {along / MM:g} mm ({orientation}) "
        "diagonal")


def with_factors(s: BarrierScene, net: float, frame: float, cable: float) -> BarrierScene:
    """Scene `s` with the force laws of its net's strands, its printed border frame (the
    second law, when it has one) and its border cables multiplied by `net`, `frame`, `cable`."""
    laws = list(s.laws)
    laws[0] = laws[0].scaled(net)
    if len(laws) > 1:  # the printed border frame, of the net's material
        laws[1] = laws[1].scaled(frame)
    cables = {k: (nodes, law.scaled(cable)) for k, (nodes, law) in s.cables.items()}
    return dataclasses.replace(s, laws=laws, cables=cables)


def noted(s: BarrierScene, *rows: Assumption) -> BarrierScene:
    """Scene `s` with assumption `rows` added after its own."""
    return dataclasses.replace(s, assumptions=(*s.assumptions, *rows))


def _finish(s: BarrierScene, rows: list[Assumption], *, force: float,
            load: str | LoadCase | None, model: bool) -> BarrierScene:
    """The scene with its sensor wires pulling `force` N each (0: they only read), and the
    assumptions shared by every scene after the scene's own (`model`: the printed model's)."""
    if not 0 <= force < math.inf:
        raise GeometryError(f"sensor force {force:g} N must be 0 or more; set [flume] "
                            "sensor_force_n in the prototype file")
    wires = {k: dataclasses.replace(w, force=force * w.weight) for k, w in s.wires.items()}
    rows = [*rows, *_common_assumptions(s, force, model, get_load(load))]
    return dataclasses.replace(s, wires=wires, assumptions=tuple(rows))


def _common_assumptions(s: BarrierScene, force: float, model: bool, load: LoadCase
                        ) -> list[Assumption]:
    paper = "Lambert et al. 2023"
    out = []
    if s.cables:
        held = ("lateral edges held by the side sheets along their whole height"
                if s.mounting == "walls" else "lateral cables held only at their eyelets")
        out.append(("mounting", (f"{s.mounting}: {held}; top and bottom cables on the four "
                     "corner anchors"),
                    (f"[flume] lateral (default walls: {paper}, the 1:40 model fixed to the "
                     "flume's side sheets; printgen docs: Pre-print verification, Mounting)")))
    else:
        out.append(("mounting", "anchored on the bed and the banks, top free",
                    ("printgen's scene simple-free-top (printgen docs: Pre-print verification, "
                     "barriers without border cables)")))
    if force > 0:
        wire = f"{force:.4g} N along each wire" + (
            "" if model else " (the model's sensor force x lambda^3: the sensors' share of the "
            "load as on the model)")
    else:
        wire = ("read only (no sensors on a field barrier)" if not model
                else "read only (sensor_force_n = 0)")
    out += [("sensor wires", (f"bottom, top and mid-height rows, {wire}; anchored at the left "
             f"edge node, over the row's nodes, to the potentiometer {SENSOR_EXIT:.0%} of the "
             "width beyond the right edge; reading = change of wire length"),
             (f"[flume] sensor_force_n (default {SENSOR_FORCE_N:g} N: {paper}, three 1 N "
              "extension sensors, Fig. 6a); routing: printgen docs: The flume test as it is run")),
            _mid_assumption(s),
            *load.assumptions,
            ("initial state", "flat, no pretension, no slack; gravity on the net neglected",
             f"{paper}: no pretension in the main cables at installation")]
    if s.hold > 0:
        out.append(("unloaded strands", (f"stay where they are: each free node held at rest by "
                    f"{s.hold:.3g} N/m ({HOLD_FRACTION:g} x rho g A*), a regularisation of the "
                    "dry, slack net above the water (a mechanism otherwise)"),
                    "printgen (printgen docs: barriers without border cables); its force share is "
                    "reported"))
    return out


def _mid_assumption(s: BarrierScene) -> Assumption:
    """The row of the assumptions that says where the mid-height wire is read."""
    mids = sensor_wires(s.wires, "mid")
    heights = [float(np.median(s.nodes[w.nodes, 2])) for w in mids]
    at = f"at h/2 = {s.height / 2 / MM:.4g} mm"
    if len(mids) == 1:
        value = f"{at}: the node row at {heights[0] / MM:.4g} mm"
    else:
        value = (f"{at}, between the node rows at {heights[0] / MM:.4g} and {heights[1] / MM:.4g}"
                 f" mm: their readings and the sensor's pull weighted {mids[0].weight:.3f} and "
                 f"{mids[1].weight:.3f} (linear interpolation of the net in z; the deflection at "
                 "mid-height alike, from the rows' centre nodes)")
    return ("mid-height sensor", value,
            "printgen: a wire at exactly mid-height (Lambert et al. 2023: the barrier "
            "mid-height), read between the rows that bracket it; converges as the mesh is "
            "refined")
