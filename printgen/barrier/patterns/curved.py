"""Curved-strand nets: a square or diamond layout whose strands follow an in-plane wave between
junctions, so that the net is soft while its strands unbend and stiffens once they are straight
(the prototype's water-drop net does so: barrier-physics.md, section 4, after Lambert et al.
2023, doi:10.1061/JHEND8.HYENG-13070, whose printed nets had straight strands only).

A strand between two junctions a chord L apart follows y = a sin(n pi x / L) (amplitude a,
n half-waves), printed as `beads_across` beads side by side of the bead width, `thickness` of
stacked layers: the strand's in-plane width (beads x bead width) is the dimension that bends.
Its law is the chord force against the chord strain of the large-deflection beam model
(`printgen.solver.strand_curve`), with the material's own stress-strain law (`stress_law`).

The junctions, the graph and the mesh are the layout's: a curved net is the layout's net with
another strand law. Its membrane law (`membrane_law`) is the strand curve carried through the
blocked, infinite net at finite strain (every chord stretched alike and turned toward the load),
which the virtual panel test reproduces; at small strain it is the layout's mapping (strand
strain per net strain, membrane force per strand force, as the layout's `strand_law` states
them). Its bilinear summary: low-strain slope, straightened slope, knee strain.

Printability (`check_wave`), each limit named in its error:
- the wave's smallest centre-line radius 1 / (a k^2), k = n pi / L, less the offset of the
  innermost bead ((W - w) / 2, W the strand width, w the bead width), is at least
  MIN_RADIUS_BEADS bead widths: on a tighter path the bead's inner edge turns on a radius
  below its half-width and the extrusion piles up inside the bend (a rule of thumb, not yet
  checked by a printed coupon);
- the band the wave sweeps, 2 a + W, fits between two parallel strands (their spacing across
  the chord): wider, neighbouring strands' waves overlap and would fuse.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from printgen.barrier.patterns import Law, NetPattern, get_pattern
from printgen.errors import GeometryError
from printgen.inputs.materials import Material
from printgen.solver import linear
from printgen.solver.strand_curve import Strand, StrandCurve, strand_curve
from printgen.units import MM

LAYOUTS = ("square", "diamond")
MIN_RADIUS_BEADS = 1.0  # innermost bead's centre-line radius >= 1 bead width (printable curve)
TOP_STRAIN = 0.3  # chord strain the curve is solved to at least (beyond: its last tangent)
FIRST_POINT = 0.01  # first solved point at 1 % of the excess: the law's first slope (its
# secant from zero) is the initial tangent there (the curve's tangent varies on the excess)
KNEE_POINTS = 16  # solved points up to twice the excess length (the unbending and the knee)
TAIL_POINTS = 8  # ... and from there to the top strain (straightened: nearly straight)


@dataclass(frozen=True)
class CurvedStrands:
    """The strands of a curved net: wave amplitude (mm) and half-waves between junctions,
    bead width (mm), beads side by side, thickness (mm, layers stacked), the material's
    stress law (a `Law` of stress, Pa per unit strain) and where it comes from."""

    amplitude_mm: float
    half_waves: int
    bead_width_mm: float
    beads_across: int
    thickness_mm: float
    stress: Law
    stress_source: str = ""

    @property
    def width_mm(self) -> float:
        """In-plane width of the strand (beads x bead width): the dimension that bends."""
        return self.bead_width_mm * self.beads_across

    def strand(self, chord: float) -> Strand:
        """The beam model's strand of chord `chord` m."""
        return Strand(chord, self.amplitude_mm * MM, self.half_waves, self.width_mm * MM,
                      self.thickness_mm * MM, self.stress)


def chord(layout: str, mesh_along: float, mesh_across: float) -> float:
    """Junction-to-junction chord of a strand along the load (any length unit): the square's
    side, the diamond's half-diagonals' hypotenuse."""
    return math.hypot(*chord_parts(layout, mesh_along, mesh_across))


def spacing(layout: str, mesh_along: float, mesh_across: float) -> float:
    """Distance between two parallel strands, across their chords (any length unit): the
    square's side; the diamond's a b / (2 chord) (a, b its diagonals)."""
    if layout == "square":
        return mesh_across
    return mesh_along * mesh_across / (2 * chord(layout, mesh_along, mesh_across))


def min_radius_mm(s: CurvedStrands, chord_mm: float) -> float:
    """Smallest centre-line radius of curvature of the wave (mm), at its crests."""
    k = s.half_waves * math.pi / chord_mm
    return math.inf if s.amplitude_mm == 0 else 1.0 / (s.amplitude_mm * k * k)


def check_wave(layout: str, s: CurvedStrands, mesh_x_mm: float, mesh_y_mm: float | None,
               where: str = "curved net") -> None:
    """GeometryError naming the limit when the wave cannot be printed on this mesh (mm)."""
    check_wave_mm(layout, s.amplitude_mm, s.half_waves, s.bead_width_mm, s.beads_across,
                  mesh_x_mm, mesh_y_mm, where)


def check_wave_mm(layout: str, amplitude_mm: float, half_waves: int, bead_width_mm: float,
                  beads_across: int, mesh_x_mm: float, mesh_y_mm: float | None,
                  where: str = "curved net") -> None:
    """`check_wave` of the wave's geometry alone (mm; the printed parts check their design's
    wave with it, no material needed): the strands along the load (chord from the mesh
    across `mesh_x_mm` and up `mesh_y_mm`)."""
    if layout not in LAYOUTS:
        raise GeometryError(f"{where}: layout {layout!r} is not one of {', '.join(LAYOUTS)}")
    mesh_y = mesh_x_mm if mesh_y_mm is None else mesh_y_mm
    get_pattern(layout).check_mesh(mesh_x_mm, mesh_y, where)
    if not (half_waves >= 1 and amplitude_mm > 0):
        raise GeometryError(f"{where}: a curved strand needs amplitude > 0 mm and at least one "
                            f"half-wave, got {amplitude_mm:g} mm and {half_waves}; for "
                            f"straight strands use pattern {layout!r}")
    width_mm = bead_width_mm * beads_across
    length = chord(layout, mesh_y, mesh_x_mm)
    k = half_waves * math.pi / length
    radius = 1.0 / (amplitude_mm * k * k)
    inner = radius - (width_mm - bead_width_mm) / 2
    limit = MIN_RADIUS_BEADS * bead_width_mm
    if inner < limit:
        most = 1.0 / (k * k * (limit + (width_mm - bead_width_mm) / 2))
        raise GeometryError(
            f"{where}: the wave's tightest bend ({amplitude_mm:g} mm amplitude, "
            f"{half_waves} half-waves over a {length:.3g} mm chord) puts the innermost bead "
            f"on a {inner:.3g} mm radius, below the printable minimum of {MIN_RADIUS_BEADS:g} "
            f"bead width ({limit:g} mm); use an amplitude of at most {most:.3g} mm, fewer "
            "half-waves or a larger mesh")
    gap = spacing(layout, mesh_y, mesh_x_mm)
    band = 2 * amplitude_mm + width_mm
    if band > gap:
        raise GeometryError(
            f"{where}: the wave sweeps a band of {band:.3g} mm (2 x {amplitude_mm:g} mm "
            f"amplitude + {width_mm:g} mm strand width), wider than the {gap:.3g} mm between "
            f"parallel strands of this mesh: neighbouring strands would fuse; use an amplitude "
            f"of at most {(gap - width_mm) / 2:.3g} mm or a larger mesh")


def curve_strains(excess: float, top: float = TOP_STRAIN) -> np.ndarray:
    """Chord strains the curve is solved at: FIRST_POINT x the excess length, KNEE_POINTS up
    to twice the excess (where the law bends), TAIL_POINTS on to max(top, 3 x excess)."""
    knee = 2.0 * excess
    end = max(top, 1.5 * knee)
    return np.concatenate([[FIRST_POINT * excess], np.linspace(0.0, knee, KNEE_POINTS + 1)[1:],
                           np.linspace(knee, end, TAIL_POINTS + 1)[1:]])


@lru_cache(maxsize=256)
def _curve(s: CurvedStrands, length: float) -> StrandCurve:
    strand = s.strand(length)
    return strand_curve(strand, curve_strains(strand.excess()))


def strand_curve_of(layout: str, s: CurvedStrands, mesh_along: float,
                    mesh_across: float) -> StrandCurve:
    """The solved curve of the strands along the load of this mesh (m)."""
    return _curve(s, chord(layout, mesh_along, mesh_across))


def strand_law(layout: str, s: CurvedStrands, mesh_along: float, mesh_across: float) -> Law:
    """The strand law the net solver gives the curved strands: the curve, piecewise linear."""
    return strand_curve_of(layout, s, mesh_along, mesh_across).law()


@dataclass(frozen=True)
class MembraneLaw:
    """A curved net's membrane law along the load, transverse strain blocked (the blocked,
    infinite panel, at finite strain: `blocked_membrane`): knees (net strain) and slopes
    (N/m) through the net strains at which the strands reach the curve's solved points, its
    bilinear summary (the low-strain slope, the net's tangent where the strands count as
    straightened, `StrandCurve.straightened`, and the knee strain where their lines meet) and
    the strands' excess path length S / L - 1 (a strand strain)."""

    knees: tuple[float, ...]
    slopes: tuple[float, ...]
    low_slope: float
    straight_slope: float
    knee: float
    excess: float


def chord_parts(layout: str, mesh_along: float, mesh_across: float) -> tuple[float, float]:
    """(along the load, across it) components of a loaded strand's chord (any length unit)."""
    if layout == "square":
        return mesh_along, 0.0
    return mesh_along / 2, mesh_across / 2


def _per_width(layout: str, mesh_along: float, mesh_across: float) -> float:
    """Loaded strands per unit width (1/m): the layout's membrane factor (its small-strain
    slope per strand E A) is that count times sin^3 of the chord's angle to the cross
    direction."""
    up, side = chord_parts(layout, mesh_along, mesh_across)
    return get_pattern(layout).membrane_factor(mesh_along, mesh_across) / \
        (up / math.hypot(up, side)) ** 3


def blocked_membrane(layout: str, s: CurvedStrands, mesh_along: float, mesh_across: float,
                     strains: np.ndarray) -> np.ndarray:
    """Membrane force per width (N/m) of the blocked, infinite curved net at panel `strains`
    along the load, at finite strain: every chord stretched alike by the affine stretch (its
    along-load part times 1 + eps, its across part held), each strand pulling along its
    chord with the curve's force at its chord strain."""
    return blocked_force(layout, strand_law(layout, s, mesh_along, mesh_across), mesh_along,
                         mesh_across, strains)


def blocked_force(layout: str, law: Law, mesh_along: float, mesh_across: float,
                  strains: np.ndarray) -> np.ndarray:
    """`blocked_membrane` of a net whose strands pull with `law` (N per unit chord strain):
    straight or curved, the same affine stretch."""
    up, side = chord_parts(layout, mesh_along, mesh_across)
    l0 = math.hypot(up, side)
    e = np.asarray(strains, float)
    l1 = np.hypot(side, up * (1 + e))
    force = law.force_and_tangent(l1 / l0 - 1)[0]
    return _per_width(layout, mesh_along, mesh_across) * force * up * (1 + e) / l1


def strain_ratio(layout: str, mesh_along: float, mesh_across: float) -> float:
    """Strand strain per net strain along the load at small strain (1 for the square,
    sin^2 for the diamond): the layout's strand law of a unit knee."""
    return get_pattern(layout).strand_law((1.0,), (1.0, 1.0), mesh_along, mesh_across).knees[0]


def membrane_law(layout: str, s: CurvedStrands, mesh_along: float,
                 mesh_across: float) -> MembraneLaw:
    """The membrane law of the curved net along `mesh_along` (m): `blocked_membrane` at the
    net strains of the curve's solved points, with its tangents there (the strand's tangent
    and the chord's turn toward the load, both exact for the affine stretch)."""
    curve = strand_curve_of(layout, s, mesh_along, mesh_across)
    up, side = chord_parts(layout, mesh_along, mesh_across)
    l0 = math.hypot(up, side)
    l1 = l0 * (1 + curve.strains)
    u = np.sqrt(l1**2 - side**2)  # along-load part of the stretched chord
    net = u / up - 1
    per = _per_width(layout, mesh_along, mesh_across)
    force = per * curve.forces * u / l1
    # d/d eps of per F(e) u / l1: de/d eps = up u / (l0 l1), d(u / l1)/d eps = up side^2 / l1^3
    tangent = per * (curve.tangents * up * u * u / (l0 * l1 * l1)
                     + curve.forces * up * side**2 / l1**3)
    low = per * curve.initial_slope * (up / l0) ** 3
    i = curve.straightened
    intercept = net[i] - force[i] / tangent[i]
    secants = np.diff(np.concatenate([[0.0], force])) / np.diff(np.concatenate([[0.0], net]))
    return MembraneLaw(tuple(float(k) for k in net[:-1]), tuple(float(v) for v in secants),
                       float(low), float(tangent[i]), float(intercept / (1 - low / tangent[i])),
                       curve.strand.excess())


def stress_law(mat: Material) -> tuple[Law, str]:
    """The material's stress-strain law (Pa per unit strain) and where it comes from: its
    measured panel law read back to the tested net's strands along the diagonal its profile
    records (the tested net is a straight diamond net, as for the straight nets' laws) and
    divided by their area, when the profile records that net; else linear at its modulus
    (measured preferred). The verification and `printgen panel --wave` read the material as
    the scene does instead (`printgen.scene.scenes.model_net_law`: the reading the material
    can produce)."""
    pl = mat.panel_law
    if pl is not None and pl.has_geometry:
        width, thickness = pl.strand_width, pl.strand_thickness
        along, across = pl.mesh_along_load, pl.mesh_across_load
        assert width and thickness and along and across  # has_geometry: all given
        tested = get_pattern("diamond").strand_law(
            pl.knee_strains, tuple(k * pl.panel_length for k in pl.kappas), along, across)
        return tested.scaled(1.0 / (width * thickness)), (
            f"{mat.name}: measured panel law of its straight diamond net read back to the "
            "strands and divided by their area (compression taken as tension)")
    modulus, source = mat.modulus()
    return linear(modulus), f"{mat.name}: {source} modulus {modulus / 1e9:.3g} GPa, linear"


def curved_pattern(layout: str, s: CurvedStrands) -> NetPattern:
    """The layout's pattern with curved strands `s`: its graph, span, node count, mesh and
    membrane-to-strand mapping; membrane_factor the low-strain (bending-dominated) membrane
    slope per strand E A; check_mesh refuses a wave it cannot print (`check_wave`)."""
    if layout not in LAYOUTS:
        raise GeometryError(f"curved net: layout {layout!r} is not one of {', '.join(LAYOUTS)}")
    base = get_pattern(layout)

    def factor(mesh_along: float, mesh_across: float) -> float:
        curve = strand_curve_of(layout, s, mesh_along, mesh_across)
        return base.membrane_factor(mesh_along, mesh_across) * curve.initial_slope / \
            curve.strand.ea

    def check(mesh_x: float, mesh_y: float | None, where: str = "net") -> None:
        check_wave(layout, s, mesh_x / MM, None if mesh_y is None else mesh_y / MM, where)

    return NetPattern(f"curved-{layout}", base.graph, factor, base.strand_law, base.strand_force,
                      base.span, base.nodes, edge_strands=base.edge_strands, lockup=base.lockup,
                      mesh_name=base.mesh_name, check_mesh=check, panel_test=base.panel_test)
