"""Centre lines of a curved-strand net's strands (mm): each straight strand of the `NetGraph`
waved between its junctions, y = a sin(n pi x / L) on every segment of chord L
(`NetDesign.wave`, `printgen.barrier.patterns.curved`), for the meshes (`solid`) and the
direct toolpath (`printgen.parts.gcode.netpath`).

Phase: at every junction both strands' tangents turn the same way by atan(a k) off their
chords, so the two cross at the straight net's angle (turned the other way they would close
it by 2 atan(a k): at 1.5 mm on the 1:40 diamond mesh, 49 deg to 4 deg, two strands fused
along a millimetre instead of a junction). With n even every segment's wave turns the same
way at both its ends (all signs +); with n odd a segment's ends turn opposite ways, so its
sign is its first node's colour in a two-colouring of the strand graph (neighbouring
junctions opposite), and a strand of equal segments is one smooth sinusoid through its
junctions. The curvature is zero at a junction, so two waved strands meet in the
parallelogram of two straight bands along their tangents.

Curves are fine polylines: a chord of length c on a curve of radius R sags c^2 / (8 R) off
it; the points are spaced so that the sag stays within CHORD_TOL_MM on the tightest bend of
the bead (the wave's smallest radius less the bead's offset from the centre line).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from printgen.barrier.graph import NetGraph
from printgen.errors import GeometryError
from printgen.parts.geometry.lattice import EDGE_TOL_MM
from printgen.scaling.record import NetDesign, Wave, check_net_wave

__all__ = ["CHORD_TOL_MM", "WavedAreas", "WavedStrand", "check_inside", "check_net_wave",
           "crossing_tangent", "node_colours", "node_tangents", "strand_colours", "wave_length",
           "waved_areas", "waved_strand", "waved_strands"]

# A polyline stays within 0.01 mm of the wave: 1/40 of a 0.4 mm nozzle, ten times finer than
# the 0.1 mm the printers place a bead to; the eyelet circles use the same tolerance
# (`printgen.parts.gcode.toolpath.CHORD_TOL_MM`).
CHORD_TOL_MM = 0.01


def wave_length(chord_mm: float, wave: Wave) -> float:
    """Arc length of one waved segment of chord `chord_mm` (closed form: the sinusoid's
    length over n half-waves, 2 L / pi sqrt(1 + m^2) E(m^2 / (1 + m^2)), m = a k)."""
    from scipy.special import ellipe

    m2 = (wave.amplitude_mm * wave.half_waves * math.pi / chord_mm) ** 2
    return float(2 * chord_mm / math.pi * math.sqrt(1 + m2) * ellipe(m2 / (1 + m2)))


@dataclass(frozen=True)
class WavedStrand:
    """One strand's waved centre line. Positions along it are given by t, the distance along
    its straight chord from its first node (mm).

    p0 : (2,) first node; u, nrm : (2,) unit chord direction and its left normal
    t_nodes : (k,) t of its nodes (junctions and ends); wave : the wave
    signs : (k - 1,) +1 / -1, each segment's wave sign (the module docstring's phase)
    """

    p0: np.ndarray
    u: np.ndarray
    nrm: np.ndarray
    t_nodes: np.ndarray
    wave: Wave
    signs: np.ndarray

    @property
    def length(self) -> float:
        return float(self.t_nodes[-1])

    def _local(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """(sign, k, x) of each t's segment (its wave's sign, wave number, local x) and the
        segment index."""
        t = np.asarray(t, float)
        i = np.clip(np.searchsorted(self.t_nodes, t, side="right") - 1, 0, len(self.t_nodes) - 2)
        chord = self.t_nodes[i + 1] - self.t_nodes[i]
        return self.signs[i], self.wave.half_waves * np.pi / chord, t - self.t_nodes[i], i

    def shape(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(y, y') of the wave at t: lateral offset (mm) and its slope along the chord."""
        sign, k, x, _ = self._local(t)
        a = self.wave.amplitude_mm
        return sign * a * np.sin(k * x), sign * a * k * np.cos(k * x)

    def frame(self, t: float) -> tuple[np.ndarray, np.ndarray, float]:
        """(tangent, left normal, cos of the tangent's angle to the chord) at t."""
        slope = float(self.shape(np.array([t]))[1][0])
        c = 1.0 / math.sqrt(1.0 + slope * slope)
        tangent = (self.u + slope * self.nrm) * c
        return tangent, np.array([-tangent[1], tangent[0]]), c

    def points(self, t: np.ndarray, offset_mm: float = 0.0) -> np.ndarray:
        """(k, 2) points of the line `offset_mm` to the left of the centre line at t."""
        y, slope = self.shape(t)
        c = 1.0 / np.sqrt(1.0 + slope * slope)
        normal = (self.nrm[None, :] - slope[:, None] * self.u[None, :]) * c[:, None]
        return (self.p0[None, :] + np.outer(np.asarray(t, float), self.u)
                + np.outer(y, self.nrm) + offset_mm * normal)

    def samples(self, t0: float, t1: float, offset_mm: float = 0.0) -> np.ndarray:
        """t from t0 to t1 (both included, and every node between), spaced so that the
        polyline of the line at `offset_mm` stays within CHORD_TOL_MM of it."""
        chords = np.diff(self.t_nodes)
        a, n = self.wave.amplitude_mm, self.wave.half_waves
        radius = float(np.min(chords)) ** 2 / (a * (n * np.pi) ** 2) - abs(offset_mm)
        if radius <= 0:
            raise GeometryError(f"wave of {a:g} mm amplitude: a bead {abs(offset_mm):g} mm off "
                                "the centre line turns on no radius (check_net_wave)")
        step = math.sqrt(8 * radius * CHORD_TOL_MM)
        # the arc, not the chord, is what the step bounds: divide by the steepest stretch
        step /= math.sqrt(1 + (a * n * np.pi / float(np.min(chords))) ** 2)
        inner = self.t_nodes[(self.t_nodes > t0) & (self.t_nodes < t1)]
        knots = np.concatenate([[t0], inner, [t1]])
        out = [np.array([t0])]
        for lo, hi in zip(knots[:-1], knots[1:], strict=True):
            k = max(1, math.ceil((hi - lo) / step))
            out.append(np.linspace(lo, hi, k + 1)[1:])
        return np.concatenate(out)

    def polyline(self, t0: float, t1: float, offset_mm: float = 0.0) -> np.ndarray:
        """(k, 2) the fine polyline of the line at `offset_mm` from t0 to t1."""
        return self.points(self.samples(t0, t1, offset_mm), offset_mm)


def node_colours(g: NetGraph) -> np.ndarray:
    """(n,) +1 / -1 per node, neighbours along a strand opposite (the strand graphs of the
    square and diamond are bipartite); GeometryError for a graph that is not."""
    colour = np.zeros(len(g.nodes_mm))
    links: dict[int, list[int]] = {}
    for s in g.strands:
        for a, b in zip(s[:-1], s[1:], strict=True):
            links.setdefault(int(a), []).append(int(b))
            links.setdefault(int(b), []).append(int(a))
    for root in links:
        if colour[root]:
            continue
        colour[root], todo = 1.0, [root]
        while todo:
            node = todo.pop()
            for other in links[node]:
                if not colour[other]:
                    colour[other] = -colour[node]
                    todo.append(other)
                elif colour[other] == colour[node]:
                    raise GeometryError("a waved net needs junctions that two-colour (an odd "
                                        "ring of strands); use a square or diamond net")
    return colour


def waved_strand(g: NetGraph, nodes: np.ndarray, wave: Wave,
                 colour: np.ndarray | None) -> WavedStrand:
    """The waved centre line through the graph's `nodes` (a strand, either way along it;
    `colour`: `node_colours(g)` for an odd number of half-waves, else None)."""
    pts = g.nodes_mm[nodes]
    d = pts[-1] - pts[0]
    u = d / float(np.hypot(*d))
    signs = np.ones(len(nodes) - 1) if colour is None else colour[nodes[:-1]]
    return WavedStrand(pts[0].astype(float), u, np.array([-u[1], u[0]]), (pts - pts[0]) @ u,
                       wave, signs)


def strand_colours(g: NetGraph, wave: Wave) -> np.ndarray | None:
    """The node colours the wave's phase needs (`node_colours`; None for even n)."""
    return node_colours(g) if wave.half_waves % 2 else None


def waved_strands(g: NetGraph, wave: Wave) -> list[WavedStrand]:
    """The waved centre line of each of the graph's strands (first node to last)."""
    colour = strand_colours(g, wave)
    return [waved_strand(g, s, wave, colour) for s in g.strands]


def check_inside(net: NetDesign, g: NetGraph) -> None:
    """GeometryError when a waved strand's band leaves the net: past the outer edge of the
    border frame (centred on the panel edge, `border_width_mm` wide) - near an edge the wave
    may swing a strand toward it."""
    if net.wave is None:
        return
    reach = (net.border_width_mm - net.strand.width_mm) / 2  # band edge within the frame
    sx, sy = g.size_mm
    worst = 0.0
    for ws in waved_strands(g, net.wave):
        p = ws.polyline(0.0, ws.length)
        worst = max(worst, float(np.max(-p[:, 0])), float(np.max(p[:, 0] - sx)),
                    float(np.max(-p[:, 1])), float(np.max(p[:, 1] - sy)))
    if worst > reach + CHORD_TOL_MM:
        raise GeometryError(
            f"net wave: a strand's wave ({net.wave.amplitude_mm:g} mm amplitude) swings its "
            f"centre line {worst:.3g} mm past the panel edge, beyond the {reach:.3g} mm the "
            f"{net.border_width_mm:g} mm border frame holds its {net.strand.width_mm:g} mm "
            "band in; use a smaller amplitude or a wider border")


def node_tangents(g: NetGraph, wave: Wave) -> dict[int, list[np.ndarray]]:
    """Unit tangent of every waved strand through each node (node -> one per strand)."""
    out: dict[int, list[np.ndarray]] = {}
    for s, ws in zip(g.strands, waved_strands(g, wave), strict=True):
        for node, t in zip(s, ws.t_nodes, strict=True):
            out.setdefault(int(node), []).append(ws.frame(float(t))[0])
    return out


def crossing_tangent(tangents: list[np.ndarray], tangent: np.ndarray) -> np.ndarray:
    """Of the tangents at a node, the one crossing `tangent` most steeply (the other
    strand's); `tangent` itself when none crosses it."""
    cross = [abs(float(v[0] * tangent[1] - v[1] * tangent[0])) for v in tangents]
    i = int(np.argmax(cross))
    return tangents[i] if cross[i] > 1e-12 else tangent


@dataclass(frozen=True)
class WavedAreas:
    """Plan-area terms of a waved net's strands (mm^2): every centre line's arc length x the
    strand width, the overlap of the crossings (w^2 / sin of the angle between the tangents
    at each junction) and of the strand ends with the border frame (w x the centre line's
    arc from its end node to where it leaves the frame, bw / 2 deep: near the edge a waved
    end turns, so the straight net's w bw / 2 / sin(phi) would take its end tangent for the
    whole way)."""

    strands: float
    crossings: float
    ends: float
    crossing_count: int


def _arc_in_frame(ws: WavedStrand, from_end: bool, inward: np.ndarray, depth_mm: float) -> float:
    """Arc length (mm) of the centre line from its first (or last) node until it is
    `depth_mm` from that node along the edge's inward normal `inward` (its first segment at
    most), on the fine polyline."""
    lo, hi = (ws.t_nodes[-2], ws.length) if from_end else (0.0, ws.t_nodes[1])
    p = ws.polyline(float(lo), float(hi))
    if from_end:
        p = p[::-1]
    depth = (p - p[0]) @ inward
    seg = np.hypot(*np.diff(p, axis=0).T)
    out = np.flatnonzero(depth >= depth_mm)
    if not len(out):
        return float(seg.sum())
    j = int(out[0])  # crosses between points j - 1 and j
    f = (depth_mm - depth[j - 1]) / (depth[j] - depth[j - 1])
    return float(seg[:j - 1].sum() + f * seg[j - 1])


def waved_areas(net: NetDesign, g: NetGraph) -> WavedAreas:
    """The `WavedAreas` of `net` (its wave must be set)."""
    assert net.wave is not None
    w, bw = net.strand.width_mm, net.border_width_mm
    tangents = node_tangents(g, net.wave)
    length = crossings = ends = 0.0
    count = 0
    sx, sy = g.size_mm
    for s, ws in zip(g.strands, waved_strands(g, net.wave), strict=True):
        length += sum(wave_length(float(c), net.wave) for c in np.diff(ws.t_nodes))
        for node in s[1:-1]:
            t = tangents[int(node)]
            crossings += w * w / abs(float(t[0][0] * t[1][1] - t[0][1] * t[1][0])) / 2
            count += 1
        for node, from_end in ((s[0], False), (s[-1], True)):
            x, y = g.nodes_mm[node]
            inward = (np.array([0.0, 1.0]) if abs(y) < EDGE_TOL_MM else
                      np.array([0.0, -1.0]) if abs(y - sy) < EDGE_TOL_MM else
                      np.array([1.0, 0.0]) if abs(x) < EDGE_TOL_MM else np.array([-1.0, 0.0]))
            ends += w * _arc_in_frame(ws, from_end, inward, bw / 2)
    return WavedAreas(length * w, crossings, ends, count // 2)
