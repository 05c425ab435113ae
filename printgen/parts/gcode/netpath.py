"""Direct toolpath of the net (mm, mm/s), one layer per pass, for any pattern whose strands
are straight lines of two families (the diamond's diagonals, the square's strands up and
across; `printgen.barrier.patterns`).

Each layer: the border first, then every strand of one family as one straight
extrusion from border to border through the crossings, then the other family; the family
order alternates from layer to layer ("crossed passes"). The strands laid second in a layer
cross beads already there: over each crossing their flow is `crossing_flow_factor` (1 = full
bead, the crossing gets a double deposit; 0 = the crossing holds one bead, as the mesh).

With an `Attachment` (loops on the edge nodes, eyelets on the corners,
`printgen.parts.geometry.attach`) the border beads detour around every hole on their own
side of the edge (together they make each loop's ring), the corner eyelets get their extra
full rings first, and each strand ends at its loop's hole; over the ring it overlaps, a
strand lays the same reduced flow as over a crossing (and over the border frame band
it crosses beyond the ring). A strand of several beads side by side lays them there and
back; each bead is trimmed, and reduced over the crossings, the ring and the frame, where
that bead itself meets them (an offset bead meets a crossing strand o cot(theta) off the
centre line's crossing point, and its end corner nearer the centre line meets the hole
first). Between strands the nozzle travels
along the inner border bead (over printed material, so the writer does not retract there).

A net with a wave (`NetDesign.wave`) lays each bead along its strand's waved centre line
(`printgen.parts.geometry.wave`), offset along the wave's normal, as a fine polyline of G1
moves within the wave's chord tolerance; the same spans as above, each at the tangents where
it lies (a crossing strand's tangent at the junction, the strand's end tangent at a hole),
measured along the chord. Polylines, not G2/G3 arcs: a sinusoid is no arc (arcs would need a
biarc fit, with its own tolerance), firmware may lack arc support or split arcs into its own
segments, and every reader of the G-code here (the read-back, the shared checker) reads
straight moves.
"""

from __future__ import annotations

import itertools
from collections.abc import Callable

import numpy as np

from printgen.barrier.graph import NetGraph
from printgen.errors import ProfileError
from printgen.inputs.materials import Material
from printgen.inputs.printers import Printer, PrintStyle
from printgen.parts.gcode.toolpath import (
    BORDER,
    COMB,
    EYELET,
    STRAND_MINUS,
    STRAND_PLUS,
    Builder,
    Toolpath,
    VolumeBudget,
    border_bead,
    check_part,
    circle,
    speeds,
)
from printgen.parts.geometry.attach import CORNER_EXTRA_RINGS, Attachment, Hole, holes
from printgen.parts.geometry.lattice import crossing_direction, crossing_sin, end_sin
from printgen.parts.geometry.wave import (
    WavedStrand,
    check_inside,
    crossing_tangent,
    node_tangents,
    strand_colours,
    waved_areas,
    waved_strand,
)
from printgen.scaling.record import NetDesign, Section, check_net_wave

EXIT_TOL_MM = 1e-4  # a waved bead's reduced flow ends where its line leaves the border, to
# 0.1 um: a bead 0.6 mm wide then misplaces 6e-5 mm^2 per end (the mesh's own round-off)


def net_toolpath(net: NetDesign, printer: Printer, style: PrintStyle, material: Material, *,
                 crossing_flow_factor: float | None = None,
                 attachment: Attachment | None = None) -> Toolpath:
    """Toolpath of the whole net, one layer per pass (see the module docstring)."""
    check_net_wave(net)
    g = net.graph()
    check_inside(net, g)
    hs = [] if attachment is None else holes(net, g, attachment)
    angle, centre = check_part("net", net, printer, style,
                               reach_mm=max((h.outer_r_mm for h in hs), default=0.0))
    f = style.crossing_flow_factor if crossing_flow_factor is None else crossing_flow_factor
    if not 0.0 <= f <= 1.0:
        raise ProfileError(f"crossing_flow_factor {f!r} must lie in 0..1")
    size = np.array(g.size_mm)
    b = Builder(angle, centre, size / 2)
    sec = net.strand
    wb = border_bead(net)[1]
    heights = list(sec.layer_heights_mm)
    layer_speeds = speeds(material, [sec.bead_width_mm, wb], heights)
    travel = printer.travel_speed_mm_per_s
    z = np.cumsum(heights)
    fams = _strands_by_family(g)
    rings = _border_rings(net, g, hs) if hs else _plain_border(net, g)
    by_node = {h.node: h for h in hs}
    line = _line_maker(net, g)
    for k, (h, v) in enumerate(zip(heights, layer_speeds, strict=True)):
        zk = float(round(z[k], 6))
        for ring, kind in rings:
            for p0, p1 in itertools.pairwise(ring):
                b.line(p0, p1, zk, wb, h, v, 1.0, k, kind, travel)
        comb = _Comb(rings[-1][0]) if hs else None
        order = (1, -1) if k % 2 == 0 else (-1, 1)
        for rank, fam in enumerate(order):
            f_cross = f if rank == 1 else 1.0
            kind = STRAND_PLUS if fam == 1 else STRAND_MINUS
            for n, s in enumerate(fams[fam]):
                s = s if n % 2 == 0 else s[::-1]
                ends = (by_node.get(int(s[0])), by_node.get(int(s[-1])))
                beads = _strand_beads(line(s), sec, f_cross, f, ends, net.border_width_mm)
                if comb is not None and b.pos is not None and b.pos[2] == zk:
                    b.travel(comb.route(b.part_xy(), beads[0][0][0][0]), zk, k, travel, COMB)
                for pts, fl in itertools.chain.from_iterable(beads):
                    for p0, p1 in itertools.pairwise(pts):
                        b.line(p0, p1, zk, sec.bead_width_mm, h, v, fl, k, kind, travel)
    return b.toolpath([float(round(x, 6)) for x in z], "net")


def _plain_border(net: NetDesign, g: NetGraph) -> list[tuple[np.ndarray, int]]:
    """Concentric rectangles of the border beads, outermost first."""
    n_loops, wb = border_bead(net)
    sx, sy = g.size_mm
    out = []
    for j in range(n_loops):
        o = (j - (n_loops - 1) / 2) * wb
        out.append((np.array([(-o, -o), (sx + o, -o), (sx + o, sy + o), (-o, sy + o),
                              (-o, -o)]), BORDER))
    return out


def _border_rings(net: NetDesign, g: NetGraph, hs: list[Hole]) -> list[tuple[np.ndarray, int]]:
    """The corner eyelets' extra rings, then each border bead's closed path around the holes
    (outward beads around the outside of every hole, inward beads around the inside),
    outermost first; the last one is the innermost bead, along which the nozzle travels."""
    from shapely import unary_union
    from shapely.geometry import box

    n_loops, wb = border_bead(net)
    sx, sy = g.size_mm
    out = []
    for h in hs:
        if h.corner:
            out += [(circle(h.centre_mm, h.hole_r_mm + wb * (j + 0.5)), EYELET)
                    for j in range(CORNER_EXTRA_RINGS)]
    for j in range(n_loops):
        o = (j - (n_loops - 1) / 2) * wb
        discs = unary_union([_disc(h.centre_mm, h.hole_r_mm + abs(o)
                                   + (CORNER_EXTRA_RINGS * wb if h.corner else 0.0))
                             for h in hs])
        rect = box(o, o, sx - o, sy - o)
        region = rect.union(discs) if o < 0 else rect.difference(discs)
        if region.geom_type != "Polygon":
            raise ProfileError(f"net border bead {j} falls apart around the loops; use a "
                               "larger mesh or smaller loops")
        ring = np.asarray(region.exterior.coords)
        start = int(np.argmin(ring[:-1, 0] + ring[:-1, 1]))  # nearest the lower-left corner
        out.append((np.vstack([ring[start:-1], ring[:start + 1]]), BORDER))
    return out


def _disc(c: np.ndarray, r: float):
    from shapely.geometry import Polygon

    return Polygon(circle(c, r)[:-1])


class _Comb:
    """Travel routes along a closed bead path (over printed material)."""

    def __init__(self, ring: np.ndarray) -> None:
        from shapely.geometry import LineString

        self.line = LineString(ring)
        self.length = float(self.line.length)

    def route(self, p: np.ndarray, q: np.ndarray) -> np.ndarray:
        """(k, 2) points from near p to q: onto the path, along it the shorter way, off it."""
        from shapely.geometry import Point
        from shapely.ops import substring

        d0 = float(self.line.project(Point(p)))
        d1 = float(self.line.project(Point(q)))
        L = self.length
        fwd = (d1 - d0) % L
        if fwd <= L / 2:
            legs = [(d0, d0 + fwd)] if d0 + fwd <= L else [(d0, L), (0.0, d0 + fwd - L)]
        else:
            back = L - fwd
            legs = [(d0, d0 - back)] if d0 - back >= 0 else [(d0, 0.0), (L, d0 - back + L)]
        pts = [np.asarray(substring(self.line, a, c).coords) for a, c in legs]
        return np.vstack([*pts, np.asarray(q, dtype=float)[None, :]])


def _strands_by_family(g: NetGraph) -> dict[int, list[np.ndarray]]:
    """Strands of each family sorted across the panel (so consecutive strands are neighbours)."""
    out: dict[int, list[np.ndarray]] = {1: [], -1: []}
    a, bb = g.mesh_mm
    for s in g.strands:
        p0, p1 = g.nodes_mm[s[0]], g.nodes_mm[s[-1]]
        fam = 1 if p1[1] > p0[1] else -1
        out[fam].append(s)
    for fam, lst in out.items():
        # intercept of the line y = fam * (b/a) * x + c: sorting by c orders them across
        lst.sort(key=lambda s, fam=fam: g.nodes_mm[s[0], 1] - fam * bb / a * g.nodes_mm[s[0], 0])
    return out


def _crossing_half_span(sec: Section, g: NetGraph) -> float:
    """Half length of a strand lying over a crossing strand of the same width (mm)."""
    return sec.width_mm / 2 / _sin_crossing(g)


def _sin_crossing(g: NetGraph) -> float:
    return crossing_sin(g)  # sin of the angle between the two families, any pattern


class _Straight:
    """A straight strand's centre line through its nodes `pts`, in t (mm along it from the
    first node); a bead's offset is a vector across it."""

    def __init__(self, pts: np.ndarray, g: NetGraph) -> None:
        self.pts, self.g = pts, g
        d = pts[-1] - pts[0]
        self.d = d
        self.u = d / float(np.hypot(*d))
        self.length = float(np.dot(pts[-1] - pts[0], self.u))

    def offsets(self, sec: Section) -> list[np.ndarray]:
        return _bead_offsets(sec, self.d)

    @staticmethod
    def size(off: np.ndarray) -> float:
        return float(np.hypot(*off))

    def trim(self, h: Hole | None, at_end: bool, sec: Section, off: np.ndarray) -> float:
        """t from the end node to where the bead stops at the hole `h` (`_trim`)."""
        return _trim(h, sec, self.size(off))

    def exit(self, h: Hole, at_end: bool, off: np.ndarray, bw: float) -> float:
        """t from the end node to where the bead leaves the ring and frame (`_border_exit`)."""
        return _border_exit(h, self.g, -self.u if at_end else self.u, off, bw)

    def crossings(self, off: np.ndarray, sec: Section) -> list[tuple[float, float, float, float]]:
        """(t, shift, half span, dt per mm along the bead) of each junction: the offset
        bead meets the crossing strand at t - shift (an offset line meets it o cot(theta)
        off the centre line's crossing point)."""
        half = _crossing_half_span(sec, self.g)
        v = crossing_direction(self.g, self.u)  # the other family's direction (any pattern)
        shift = _cross2(off, v) / _cross2(self.u, v)
        return [(float(np.dot(p - self.pts[0], self.u)), shift, half, 1.0)
                for p in self.pts[1:-1]]

    def piece(self, a: float, c: float, off: np.ndarray) -> np.ndarray:
        p00 = self.pts[0] + off
        return np.array([p00 + self.u * a, p00 + self.u * c])


class _Waved:
    """A waved strand's centre line (`WavedStrand`), in t along its chord; a bead's offset
    is a signed distance along the wave's normal."""

    def __init__(self, ws: WavedStrand, nodes: np.ndarray, g: NetGraph,
                 tangents: dict[int, list[np.ndarray]]) -> None:
        self.ws, self.nodes, self.g, self.tangents = ws, nodes, g, tangents
        self.length = ws.length

    @staticmethod
    def offsets(sec: Section) -> list[float]:
        n = sec.beads_across
        return [(j - (n - 1) / 2) * sec.bead_width_mm for j in range(n)]

    @staticmethod
    def size(off: float) -> float:
        return abs(off)

    def trim(self, h: Hole | None, at_end: bool, sec: Section, off: float) -> float:
        """`_trim` along the end tangent (the hole is within a few bead widths of the node,
        where the wave is straight: no curvature at a junction), as t."""
        return _trim(h, sec, abs(off)) * self.ws.frame(self.length if at_end else 0.0)[2]

    def exit(self, h: Hole, at_end: bool, off: float, bw: float) -> float:
        """t from the end node to where the bead's line (in its first segment) last leaves
        the ring's disc or the frame band on the node's edge, to EXIT_TOL_MM: a waved end may
        run along the frame at a slant and turn away from it, which the end tangent alone
        does not see."""
        seg = (self.ws.t_nodes[-2], self.length) if at_end else (0.0, self.ws.t_nodes[1])
        t = self.ws.samples(float(seg[0]), float(seg[1]), off)
        dist = (self.length - t) if at_end else t
        inside = self._inside(h, t, off, bw)
        if not inside.any():
            return 0.0
        j = int(np.flatnonzero(inside)[np.argmax(dist[inside])])
        k = j - 1 if at_end else j + 1  # the next sample away from the node
        if not 0 <= k < len(t):
            return float(dist[j])  # inside to the segment's far end
        lo, hi = float(dist[j]), float(dist[k])
        while hi - lo > EXIT_TOL_MM:  # bisect the crossing between the last inside sample
            mid = (lo + hi) / 2       # and the next one
            at = np.array([self.length - mid if at_end else mid])
            lo, hi = (mid, hi) if self._inside(h, at, off, bw)[0] else (lo, mid)
        return (lo + hi) / 2

    def _inside(self, h: Hole, t: np.ndarray, off: float, bw: float) -> np.ndarray:
        """Whether the bead's line at t lies in the ring's disc or the node's frame band."""
        p = self.ws.points(t, off)
        sx, sy = self.g.size_mm
        x, y = h.centre_mm
        inside = np.hypot(*(p - h.centre_mm).T) <= h.outer_r_mm
        for on_edge, coord, edge in ((np.isclose(x, 0.0), 0, 0.0), (np.isclose(x, sx), 0, sx),
                                     (np.isclose(y, 0.0), 1, 0.0), (np.isclose(y, sy), 1, sy)):
            if on_edge:
                inside |= np.abs(p[:, coord] - edge) <= bw / 2
        return inside

    def crossings(self, off: float, sec: Section) -> list[tuple[float, float, float, float]]:
        out = []
        for node, t in zip(self.nodes[1:-1], self.ws.t_nodes[1:-1], strict=True):
            tangent, normal, c = self.ws.frame(float(t))
            v = crossing_tangent(self.tangents[int(node)], tangent)
            sin = _cross2(tangent, v)
            out.append((float(t), _cross2(off * normal, v) / sin, sec.width_mm / 2 / abs(sin), c))
        return out

    def piece(self, a: float, c: float, off: float) -> np.ndarray:
        return self.ws.polyline(a, c, off)


def _line_maker(net: NetDesign, g: NetGraph) -> Callable[[np.ndarray], _Straight | _Waved]:
    """nodes -> the strand's centre line (`_Straight`, or `_Waved` for a net with a wave)."""
    if net.wave is None:
        return lambda s: _Straight(g.nodes_mm[s], g)
    wave = net.wave
    colour, tangents = strand_colours(g, wave), node_tangents(g, wave)
    return lambda s: _Waved(waved_strand(g, s, wave, colour), s, g, tangents)


def _strand_beads(line, sec: Section, f_cross: float, f_end: float,
                  ends: tuple[Hole | None, Hole | None], bw: float):
    """Pieces (points, flow) of each bead of one strand, beads side by side laid there and
    back (serpentine): `f_cross` where the bead lies over a crossing strand, `f_end` where it
    lies over the border frame or a ring at an end with a hole (it stops at the hole)."""
    out = []
    for j, off in enumerate(line.offsets(sec)):
        pieces = [(line.piece(a, c, off), fl)
                  for a, c, fl in _bead_pieces(line, off, sec, f_cross, f_end, ends, bw)]
        if j % 2:
            pieces = [(pts[::-1], fl) for pts, fl in reversed(pieces)]
        out.append(pieces)
    return out


def _bead_pieces(line, off, sec: Section, f_cross: float, f_end: float,
                 ends: tuple[Hole | None, Hole | None], bw: float):
    """Spans (t0, t1, flow) of the bead at offset `off` from the strand's centre line, in t
    (mm along the strand's chord from its first node); see `_strand_beads`."""
    start, end = ends
    length = line.length
    spans = []
    if f_cross < 1.0:
        spans += [(t - c * shift - c * half, t - c * shift + c * half, f_cross)
                  for t, shift, half, c in line.crossings(off, sec)]
    t0 = line.trim(start, False, sec, off)
    t1 = length - line.trim(end, True, sec, off)
    if start is not None:
        spans.append((t0, line.exit(start, False, off, bw), f_end))
    if end is not None:
        spans.append((length - line.exit(end, True, off, bw), t1, f_end))
    cuts = sorted({t0, t1, *(min(max(c, t0), t1) for lo, hi, _ in spans for c in (lo, hi))})
    out: list[tuple[float, float, float]] = []
    for a, c in itertools.pairwise(cuts):
        mid = (a + c) / 2
        fl = min([fl for lo, hi, fl in spans if lo <= mid <= hi], default=1.0)
        if out and out[-1][2] == fl:
            out[-1] = (out[-1][0], c, fl)
        else:
            out.append((a, c, fl))
    return out


def _cross2(a: np.ndarray, b: np.ndarray) -> float:
    return float(a[0] * b[1] - a[1] * b[0])


def _border_exit(h: Hole, g: NetGraph, u: np.ndarray, off: np.ndarray, bw: float) -> float:
    """Distance from the hole's node along u (into the net) at which the bead centre line at
    lateral offset `off` leaves the border's material there: the ring's disc or the frame
    band `bw` wide on the edge, whichever reaches further (mm)."""
    o = float(np.hypot(*off))
    exits = [float(np.sqrt(max(h.outer_r_mm ** 2 - o ** 2, 0.0)))]
    sx, sy = g.size_mm
    x, y = h.centre_mm
    for on_edge, n_in in ((np.isclose(x, 0.0), (1, 0)), (np.isclose(x, sx), (-1, 0)),
                          (np.isclose(y, 0.0), (0, 1)), (np.isclose(y, sy), (0, -1))):
        into = float(np.dot(u, n_in))
        if on_edge and into > 0:
            exits.append((bw / 2 - float(np.dot(off, n_in))) / into)
    return max(exits)


def _trim(h: Hole | None, sec: Section, o: float = 0.0) -> float:
    """Distance from a strand's end node to where the end corners of its bead at lateral
    offset `o` (mm) meet the hole, the corner nearer the centre line binding (mm)."""
    if h is None:
        return 0.0
    hw = sec.bead_width_mm / 2
    near = min(abs(o - hw), abs(o + hw))
    return float(np.sqrt(max(h.hole_r_mm ** 2 - near ** 2, 0.0)))


def _bead_offsets(sec: Section, d: np.ndarray) -> list[np.ndarray]:
    """Perpendicular offsets of the beads side by side in a strand of direction d."""
    n = sec.beads_across
    perp = np.array([-d[1], d[0]]) / np.hypot(*d)
    return [perp * (j - (n - 1) / 2) * sec.bead_width_mm for j in range(n)]


def net_volume_budget(net: NetDesign, style: PrintStyle, *,
                      crossing_flow_factor: float | None = None) -> VolumeBudget:
    """Designed volumes of the net (analytic, rectangular sections)."""
    f = style.crossing_flow_factor if crossing_flow_factor is None else crossing_flow_factor
    g = net.graph()
    sec = net.strand
    t = sec.thickness_mm
    w = sec.width_mm
    size = np.array(g.size_mm)
    border = 2 * (size[0] + size[1]) * net.border_width_mm
    if net.wave is not None:  # the same terms along the waved centre lines
        wa = waved_areas(net, g)
        return VolumeBudget((wa.strands + border) * t, wa.crossings * t, wa.ends * t, f,
                            wa.crossing_count)
    strand_len = sum(float(np.hypot(*(g.nodes_mm[s[-1]] - g.nodes_mm[s[0]]))) for s in g.strands)
    n_cross = sum(len(s) - 2 for s in g.strands) // 2
    nominal = (strand_len * w + border) * t
    crossing = n_cross * w * w / _sin_crossing(g) * t
    # strand ends inside the frame, each at its angle to the border edge it meets
    junction = float(np.sum(net.border_width_mm / 2 / end_sin(g))) * w * t
    return VolumeBudget(nominal, crossing, junction, f, n_cross)

