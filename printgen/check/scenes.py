"""Solver scenes of the realistic barrier (barrier-physics.md, section 7, `realistic-1:40`):
the prototype and the printed model as tension-only strand nets with sliding border cables.

Plane of the net: x across the barrier, z up (from the flume bed), y the flow direction.
Net strands are the diamond graph's diagonal segments; their force-strain law is the panel
law turned into a strand law (`strand_law_from_membrane`). The border cables slide through
the net's edge nodes between the four corner anchors. The model also carries the printed
border frame (family-0 segments) and the three 1 N extension sensors (Lambert et al. 2023),
pulling downstream at mid-span of the bottom and top cables and at the net's centre.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from printgen.design.record import Design
from printgen.design.section import area_m2, diamond_factor, diamond_sin, net_membrane_law
from printgen.inputs.materials import load_material
from printgen.inputs.prototype import Prototype
from printgen.parts.geometry.net import NetGraph, diamond_net
from printgen.units import MM

SENSOR_FORCE_N = 1.0  # retraction force of each cable extension sensor (reference, section 4)
FLOW = np.array([0.0, 1.0, 0.0])  # flow direction: the sensors pull and the water pushes along it

Law = tuple[tuple[float, ...], tuple[float, ...]]  # (strain knees, force slopes N per strain)


@dataclass(frozen=True)
class BarrierScene:
    """A barrier as arrays for the solver (SI).

    nodes : (n, 3) m; fixed : (n,) bool anchors; elements : (m, 2) int; element_law : (m,) int
    index into `laws`; cables : name -> (node sequence anchor..anchor, law);
    rows : name -> node sequence whose elongation is reported (bottom, top, mid);
    sensors : (node, force (3,) N) point loads; area_per_node : m^2 (A* = net area / nodes).
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
    sensors: list[tuple[int, np.ndarray]] = field(default_factory=list)


def strand_law_from_membrane(knees: tuple[float, ...], slopes: tuple[float, ...],
                             mesh_along: float, mesh_across: float) -> Law:
    """Strand force law whose diamond net has the membrane law (knees, slopes N/m).

    Stretching the net by eps along the load strains a strand by eps sin^2(theta), and the
    strands carry N = (2 / a_across) F sin(theta) per unit width; so the strand law has knees
    eps_k sin^2(theta) and slopes N' a_across / (2 sin^3(theta)).
    """
    sin = diamond_sin(mesh_along, mesh_across)
    f = 1.0 / (diamond_factor(mesh_along, mesh_across))
    return tuple(k * sin * sin for k in knees), tuple(s * f for s in slopes)


def _net_arrays(g: NetGraph, to_m: float) -> tuple[np.ndarray, dict[str, np.ndarray], int, int]:
    """3D nodes (m), edge node sequences (corner to corner), centre and top-centre nodes."""
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
    levels = np.unique(np.round(z / tol)) * tol
    mid_z = levels[np.argmin(np.abs(levels - h / 2))]  # the node row nearest mid-height
    mid_row = np.abs(z - mid_z) < 2 * tol
    edges["mid"] = edge(mid_row, x)
    centre = int(edges["mid"][np.argmin(np.abs(x[edges["mid"]] - w / 2))])
    top_centre = int(edges["top"][np.argmin(np.abs(x[edges["top"]] - w / 2))])
    return nodes, edges, centre, top_centre


def _scene(name: str, scale: float, g: NetGraph, to_m: float, net_law: Law,
           cable_law: Law | None, border_law: Law | None) -> BarrierScene:
    nodes, edges, centre, top_centre = _net_arrays(g, to_m)
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
        cables = {side: (edges[side], cable_law) for side in ("bottom", "top", "left", "right")}
    else:  # no border cables: anchored on the bed and the banks, top free (simple-free-top)
        fixed[np.concatenate([edges["bottom"], edges["left"], edges["right"]])] = True
    w, h = float(nodes[:, 0].max()), float(nodes[:, 2].max())
    return BarrierScene(name, scale, w, h, nodes, fixed, elements, element_law, laws, cables,
                        {k: edges[k] for k in ("bottom", "top", "mid")}, centre, top_centre,
                        w * h / len(nodes))


def square_graph(width_mm: float, height_mm: float, mesh_mm: float) -> NetGraph:
    """A square-mesh net (strands across and up) as a NetGraph, for square prototypes."""
    nx, ny = round(width_mm / mesh_mm), round(height_mm / mesh_mm)
    ii, jj = np.meshgrid(np.arange(nx + 1), np.arange(ny + 1), indexing="ij")
    nodes = np.column_stack([ii.ravel() * mesh_mm, jj.ravel() * mesh_mm]).astype(float)
    idx = np.arange((nx + 1) * (ny + 1)).reshape(nx + 1, ny + 1)
    segs = np.vstack([np.column_stack([idx[:-1].ravel(), idx[1:].ravel()]),
                      np.column_stack([idx[:, :-1].ravel(), idx[:, 1:].ravel()])])
    ring = np.concatenate([idx[:, 0], idx[-1, 1:], idx[-2::-1, -1], idx[0, -2:0:-1]])
    return NetGraph(nodes, segs, np.ones(len(segs), int), [], ring,
                    (2.0 * mesh_mm, 2.0 * mesh_mm), (2 * nx, 2 * ny))


def prototype_scene(p: Prototype) -> BarrierScene:
    """The prototype: net with its panel law (or linear strands), sliding border cables."""
    if p.net.pattern == "square":
        g = square_graph(p.width / MM, p.height / MM, p.net.mesh_x / MM)
    else:
        g = diamond_net(p.width / MM, p.height / MM, p.net.mesh_x / MM, p.net.mesh_y / MM)
    if p.net.panel_law is not None:
        knees, kappas, length = p.net.panel_law
        net_law = strand_law_from_membrane(knees, tuple(k * length for k in kappas),
                                           p.net.mesh_y, p.net.mesh_x)
    else:
        ea = p.net.strand_modulus * math.pi / 4 * p.net.strand_diameter**2
        net_law = ((), (ea,))
    cable_law = None
    if p.border is not None:
        cable_law = ((), (p.border.modulus * math.pi / 4 * p.border.diameter**2,))
    return _scene(f"{p.name}: prototype", 1.0, g, MM, net_law, cable_law, None)


def model_scene(d: Design) -> BarrierScene:
    """The printed model: diamond net with the material's (measured) law, printed border frame,
    cables of the measured modulus, and the three 1 N sensors."""
    n = d.net
    g = diamond_net(n.width_mm, n.height_mm, n.mesh_x_mm, n.mesh_y_mm)
    mat = load_material(n.material)
    knees, slopes, _ = net_membrane_law(mat, n.strand, n.mesh_y_mm * MM, n.mesh_x_mm * MM)
    net_law = strand_law_from_membrane(knees, slopes, n.mesh_y_mm * MM, n.mesh_x_mm * MM)
    border_ea = mat.modulus()[0] * n.border_width_mm * n.strand.thickness_mm * MM * MM
    cable_law = None
    if d.cables:
        c = d.cables[0]
        cable_law = ((), (load_material(c.material).modulus()[0] * area_m2(c.section),))
    s = _scene(f"printed model 1:{d.scale:g}", d.scale, g, MM, net_law, cable_law,
               ((), (border_ea,)))
    if not d.cables:  # the three sensors belong to the realistic barrier's flume setup
        return s
    sensors = [(_middle(s.rows["bottom"]), SENSOR_FORCE_N * FLOW),
               (_middle(s.rows["top"]), SENSOR_FORCE_N * FLOW), (s.centre, SENSOR_FORCE_N * FLOW)]
    return BarrierScene(**{**s.__dict__, "sensors": sensors})


def _middle(row: np.ndarray) -> int:
    return int(row[len(row) // 2])
