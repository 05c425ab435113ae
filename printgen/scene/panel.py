"""The virtual panel test: a net's panel tensile test simulated with printgen's own solver, as
its source ran it (barrier-physics.md, sections 4 and 5; Lambert et al. 2023,
doi:10.1061/JHEND8.HYENG-13070), and the strand law derived so that the simulated test
reproduces a measured panel law.

Panel: a net of the test's pattern (`barrier.patterns`; the diamond by default) of the net's strands
only (no border frame; the square's edge columns are strands of its net, `edge_strands`, so a square
panel of nx meshes holds nx + 1 strands along the load over the width nx a it is read on), x across
the load, z along it, y out of plane (held: the panel lies flat). The clamp rows are the panel's
bottom and top node rows; the top clamp moves by eps L along z. Two boundary conditions, as the
sources describe them:
- "blocked": every node's transverse (x) displacement blocked (the prototype's 1.33 m panel);
- "free": the nodes between the clamps free in the plane (the printed 43 mm panels).
The reading is the clamp force per clamp width, n = F / w (N/m), against the elongation
dl = eps L; the panel law kappa = n / dl (kN/m/m), or n against eps for the membrane law.

The analytic diamond formula (the diamond pattern's `strand_law`) is the
blocked, infinite panel: every strand stretched alike. `analytic_blocked` gives it at finite
strain too (the strands rotate toward the load), the test the blocked simulation must match.

A pin-jointed, tension-only diamond net with free sides is a mechanism: its meshes close
across the load at no force until the strands lie along it (`NetPattern.lockup`). A free panel's
stiffness below that strain comes only from the clamps' hold on the meshes next to them and,
in a printed net, from its rigid junctions, which the solver does not model. So a strand law
that makes the free simulated test match a measured law at low strain may not exist: the
derivation reports how far it gets (`DerivedLaw.error`) instead of forcing it.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass

import numpy as np

from printgen import solver
from printgen.barrier.patterns import get_pattern
from printgen.errors import SolverError
from printgen.inputs.laws import piecewise_linear
from printgen.inputs.materials import load_material
from printgen.scaling.record import Design
from printgen.scene.scenes import TESTED_PATTERN, model_net_law, panel_axes
from printgen.solver import Law
from printgen.units import MM

MODES = ("blocked", "free")
PANEL_TOL = 1e-9  # out-of-balance force / strand force scale: exact for a 1 % comparison
DERIVE_STEPS = 8  # fixed-point passes of the strand-law derivation (each re-solves the test)
DERIVE_TOL = 1e-3  # ... stopped once the slopes move by less than 0.1 % in a pass
STRAIN_STEP = 0.01  # largest strain step between two solves of the test
STRAIN_POINTS = 12  # panel strains simulated over the law's range
HOLD_RATIO = 1e-4  # free mode: each free node held at rest by this x the strand EA / length
# (a vanishing stiffness that picks one state of the mechanism; its force share is reported)


@dataclass(frozen=True)
class PanelTest:
    """One panel test set-up (SI): mesh diagonals (the square's sides) along and across the
    load (m), panel length along the load and clamp width (m), boundary mode (one of MODES),
    the net's pattern (`printgen.barrier.patterns`)."""

    mesh_along: float
    mesh_across: float
    length: float
    width: float
    mode: str = "free"
    pattern: str = TESTED_PATTERN

    def describe(self) -> str:
        side = ("transverse displacement blocked" if self.mode == "blocked"
                else "free between the clamps")
        return (f"{self.length / MM:g} mm long x {self.width / MM:g} mm clamps, {self.pattern} "
                f"mesh {self.mesh_along / MM:g} mm along the load x {self.mesh_across / MM:g} mm "
                f"across, {side}")


@dataclass(frozen=True)
class PanelCurve:
    """A simulated (or analytic) panel test: strains (k,) along the load, membrane force per
    clamp width n (k,) N/m; hold_share : largest share of the clamp force the mechanism's
    hold carried (free mode; 0 when blocked)."""

    test: PanelTest
    strains: np.ndarray
    force_per_width: np.ndarray
    hold_share: float = 0.0

    @property
    def kappa(self) -> np.ndarray:
        """Secant panel law n / dl (N/m per m), as a tensile test reads it."""
        with np.errstate(divide="ignore", invalid="ignore"):
            return self.force_per_width / (self.strains * lattice_size(self.test)[0])


def _graph(t: PanelTest):
    if t.mode not in MODES:
        raise SolverError(f"panel mode {t.mode!r} is not one of {', '.join(MODES)}")
    pattern = get_pattern(t.pattern)
    g = pattern.graph(t.width / MM, t.length / MM, t.mesh_across / MM, t.mesh_along / MM)
    xz = g.nodes_mm * MM
    nodes = np.column_stack([xz[:, 0], np.zeros(len(xz)), xz[:, 1]])
    elements = g.segments if pattern.edge_strands else g.segments[g.family != 0]
    used = np.unique(elements)  # corner nodes the lattice adds without strands are dropped
    remap = -np.ones(len(nodes), int)
    remap[used] = np.arange(len(used))
    nodes, elements = nodes[used], remap[elements]
    z = nodes[:, 2]
    tol = 1e-9 * t.length
    return nodes, elements, np.flatnonzero(z < tol), np.flatnonzero(z > z.max() - tol)


def lattice_size(t: PanelTest) -> tuple[float, float]:
    """(length, width) m of the simulated panel: the test's rounded to whole half-meshes
    (the lattice keeps its mesh exact); the reading divides by these."""
    g = get_pattern(t.pattern).graph(t.width / MM, t.length / MM, t.mesh_across / MM,
                                     t.mesh_along / MM)
    xz = g.nodes_mm * MM
    return float(xz[:, 1].max()), float(xz[:, 0].max())


def panel_lockup(t: PanelTest) -> float:
    """Panel strain of test `t` at which its strands lie along the load (its pattern's
    `lockup`: the diamond's `lockup_strain`); 0 when they lie along it from the start."""
    lockup = get_pattern(t.pattern).lockup
    return 0.0 if lockup is None else lockup(t.mesh_along, t.mesh_across)


def analytic_blocked(law: Law, t: PanelTest, strains: np.ndarray) -> np.ndarray:
    """Membrane force per width (N/m) of the blocked, infinite diamond panel at `strains`:
    every strand stretched alike, 2 / a_across strands per unit width, each pulling along its
    current direction (finite strain; its small-strain slope is the diamond formula)."""
    hx, hz = t.mesh_across / 2, t.mesh_along / 2
    e = np.asarray(strains, float)
    l0, l1 = math.hypot(hx, hz), np.hypot(hx, hz * (1 + e))
    n = piecewise_linear(l1 / l0 - 1, law.knees, law.slopes)
    return 2.0 / t.mesh_across * n * hz * (1 + e) / l1


def simulate(law: Law, t: PanelTest, strains: np.ndarray) -> PanelCurve:
    """The panel test of a net whose strands follow `law`, solved at each strain in turn
    (each warm-started from the last); SolverError when a strain cannot be reached."""
    _, elements, _, top = _graph(t)
    width = lattice_size(t)[1]
    out, share = [], 0.0
    for positions, tensions, held in _solve_all(law, t, strains):
        force = _clamp_force(positions, tensions, elements, top)
        out.append(force / width)
        if force > 0:
            share = max(share, held / force)
    return PanelCurve(t, np.asarray(strains, float), np.array(out), share)


def _solve_all(law: Law, t: PanelTest, strains: np.ndarray):
    """Yield (positions (n, 3) m, tensions (m,) N, hold force N) of the test at each strain."""
    nodes, elements, bottom, top = _graph(t)
    n, length = len(nodes), lattice_size(t)[0]
    rest = np.linalg.norm(nodes[elements[:, 1]] - nodes[elements[:, 0]], axis=1)
    fixed = np.zeros((n, 3), bool)
    fixed[:, 1] = True  # the panel lies flat
    fixed[np.concatenate([bottom, top])] = True
    if t.mode == "blocked":
        fixed[:, 0] = True
    laws = [law]
    free = np.flatnonzero(~fixed[:, 0])
    arm = float(rest.min())
    hold_k = HOLD_RATIO * float(law.slopes[0]) / arm if t.mode == "free" else 0.0
    if hold_k:  # two ties per free node, out of the plane: in-plane stiffness hold_k
        anchors = np.vstack([nodes[free] - [0, arm, 0], nodes[free] + [0, arm, 0]])
        ties = np.column_stack([np.tile(free, 2), n + np.arange(2 * len(free))])
        nodes = np.vstack([nodes, anchors])
        fixed = np.vstack([fixed, np.ones((len(anchors), 3), bool)])
        elements = np.vstack([elements, ties])
        rest = np.concatenate([rest, np.full(len(ties), arm / 2)])
        laws.append(solver.linear(hold_k * arm / 2))  # tension hold_k arm / 2 at rest
    index = np.concatenate([np.zeros(len(elements) - 2 * len(free) * bool(hold_k), int),
                            np.ones(2 * len(free) * bool(hold_k), int)])
    u = None
    for eps in _substeps(np.asarray(strains, float)):
        moved = nodes.copy()
        moved[top, 2] += eps * length
        net = solver.Net(moved, fixed, elements, laws, element_law=index, rest_length=rest)
        start = None if u is None else np.where(fixed, 0.0, u)
        res = solver.solve(net, [], u0=start, tol=PANEL_TOL)
        if not res.converged:
            raise SolverError(f"panel test ({t.describe()}) at strain {eps:.3g}: {res.reason}")
        u = res.positions - nodes
        held = hold_k * float(np.abs(u[free, 0]).sum())
        if np.any(np.isclose(eps, strains, rtol=0, atol=1e-12)):
            yield res.positions[:n], res.tensions[:len(index) - 2 * len(free) * bool(hold_k)], held


def _substeps(strains: np.ndarray) -> np.ndarray:
    """The requested strains with steps of at most STRAIN_STEP in between (a mechanism's
    path is followed, not jumped)."""
    out, last = [], 0.0
    for e in strains:
        n = max(1, math.ceil((e - last) / STRAIN_STEP - 1e-9))
        out += list(last + (e - last) * np.arange(1, n + 1) / n)
        last = e
    return np.array(out)


def _clamp_force(x: np.ndarray, tensions: np.ndarray, elements: np.ndarray,
                 top: np.ndarray) -> float:
    """Sum of the strand forces' z components on the top clamp's nodes (N)."""
    at_top = np.isin(elements, top)
    d = x[elements[:, 1]] - x[elements[:, 0]]
    unit_z = d[:, 2] / np.linalg.norm(d, axis=1)
    # the clamp holds each strand's top end against its pull: + its z component from below
    sign = np.where(at_top[:, 1], 1.0, np.where(at_top[:, 0], -1.0, 0.0))
    return float(np.sum(sign * tensions * unit_z))


@dataclass(frozen=True)
class DerivedLaw:
    """A strand law whose simulated panel test reproduces a measured panel law.

    law : (knees, slopes N) of the strand; curve : its simulated test at the fitted strains
    and between them; target : the measured membrane force per width at curve.strains (N/m);
    error : largest |simulated - measured| there, fraction of the measured peak; passes :
    fixed-point passes run.
    """

    law: Law
    curve: PanelCurve
    target: np.ndarray
    error: float
    passes: int


def law_strains(knees: tuple[float, ...], points: int = STRAIN_POINTS) -> np.ndarray:
    """Panel strains of a measured law's range: up to 1.5 x its last knee (the law is stated
    'above' the knee, not to a given strain), or 10 % for a linear law."""
    top = 1.5 * max(knees) if knees else 0.1
    return np.linspace(top / points, top, points)


def refined_knees(knees: tuple[float, ...]) -> tuple[float, ...]:
    """The measured law's knees plus one inside each segment (its middle, and 1.25 x the last
    knee): a strand law twice as fine, so that a softening strand can offset the meshes'
    geometric stiffening (the strands turn toward the load) that a test of the same number
    of segments cannot."""
    lo = [0.0, *knees]
    mids = [(a + b) / 2 for a, b in itertools.pairwise(lo)]
    extra = [1.25 * knees[-1]] if knees else []
    return tuple(sorted({*knees, *mids, *extra}))


def derive_law(knees: tuple[float, ...], slopes: tuple[float, ...], t: PanelTest,
               strains: np.ndarray | None = None) -> DerivedLaw:
    """The strand law (on `refined_knees`) whose simulated test `t` gives the membrane
    law n = piecewise(eps; knees, slopes N/m). Starts from the pattern's analytic mapping and
    repeats: solve the test, split the clamp force into each law segment's share at the
    solved strand strains (linear in the slopes at fixed geometry), refit the slopes by
    non-negative least squares and each strand knee as the clamp strands' mean strain at the
    panel knee, until the slopes settle."""
    from scipy.optimize import nnls

    eps = law_strains(knees) if strains is None else np.asarray(strains, float)
    target = piecewise_linear(eps, knees, slopes)
    fine = refined_knees(knees)
    fine_slopes = tuple(slopes[int(np.searchsorted(knees, k, side="right"))]
                        for k in (0.0, *fine))  # the measured slope of each fine segment
    law = get_pattern(t.pattern).strand_law(fine, fine_slopes, t.mesh_along, t.mesh_across)
    passes = 0
    for passes in range(1, DERIVE_STEPS + 1):  # noqa: B007 (the count is returned)
        shares, strand_eps = _segment_shares(law, t, eps)
        new, _ = nnls(shares, target * lattice_size(t)[1])
        new = np.maximum(new, 1e-9 * float(np.max(new)))
        k_new = tuple(float(np.interp(k, eps, strand_eps)) for k in fine)
        moved = float(np.max(np.abs(new / np.asarray(law.slopes) - 1)))
        law = Law(k_new, tuple(float(s) for s in new))
        if moved < DERIVE_TOL:
            break
    check = np.sort(np.concatenate([eps, (eps[1:] + eps[:-1]) / 2]))  # between the fitted too
    curve = simulate(law, t, check)
    target = piecewise_linear(check, knees, slopes)
    err = float(np.max(np.abs(curve.force_per_width - target)) / np.max(np.abs(target)))
    return DerivedLaw(law, curve, target, err, passes)


def _segment_shares(law: Law, t: PanelTest, eps: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(k, segments) clamp force per unit slope of each law segment, and (k,) the mean strain
    of the strands on the top clamp, from the test solved with `law`."""
    nodes, elements, _, top = _graph(t)
    rest = np.linalg.norm(nodes[elements[:, 1]] - nodes[elements[:, 0]], axis=1)
    at_top = np.isin(elements, top)
    on_clamp = at_top.any(axis=1)
    sign = np.where(at_top[:, 1], 1.0, -1.0)[on_clamp]
    lo = np.array([0.0, *law.knees])
    width = np.append(np.diff(lo), np.inf)
    rows, mean_eps = [], []
    for positions, _, _ in _solve_all(law, t, eps):
        d = positions[elements[on_clamp, 1]] - positions[elements[on_clamp, 0]]
        length = np.linalg.norm(d, axis=1)
        e = length / rest[on_clamp] - 1
        phi = np.clip(np.maximum(e, 0)[:, None] - lo, 0.0, width)  # (strands, segments)
        rows.append((sign * d[:, 2] / length) @ phi)
        mean_eps.append(float(e.mean()))
    return np.array(rows), np.array(mean_eps)


PRINTED_PANEL = (43 * MM, 23 * MM)  # the paper's printed panels: length, clamp width (m)


@dataclass(frozen=True)
class DesignPanel:
    """A design's net as a printed test panel: the test set-up, the strand law the barrier
    scene gives its strands, the simulated test and the material's measured panel law at the
    same strains (N/m per unit width, None when the profile has none)."""

    orientation: str
    test: PanelTest
    law: Law
    curve: PanelCurve
    measured: np.ndarray | None
    # curved strands (`curved_panel`): how they are made, and the law the strand curves give
    # the net, read as this panel reads it (N/m at curve.strains)
    strands: str = ""
    expected: np.ndarray | None = None


def design_panel(d: Design, orientation: str, mode: str = "free",
                 points: int = STRAIN_POINTS) -> DesignPanel:
    """The simulated panel test of design `d`'s printed net, loaded along its `orientation`
    diagonal, of the size its material's panel law was tested at (else PRINTED_PANEL)."""
    n = d.net
    mat = load_material(n.material)
    pl = mat.panel_law
    along, across = panel_axes(n.mesh_x_mm * MM, n.mesh_y_mm * MM, orientation)
    size = (pl.panel_length, pl.panel_width or PRINTED_PANEL[1]) if pl else PRINTED_PANEL
    t = PanelTest(along, across, size[0], size[1], mode, n.pattern)
    law = model_net_law(mat, n, orientation if pl is not None and pl.has_geometry else None)[0]
    eps = law_strains(pl.knee_strains if pl else (), points)
    curve = simulate(law, t, eps)
    # the profiles' panel laws were measured on diamond nets (`design.section`): another
    # pattern's panel is not that test, and gets no measured column
    same_net = pl is not None and n.pattern == TESTED_PATTERN
    return DesignPanel(orientation, t, law, curve, pl.force_per_width(eps) if same_net else None)


def curved_panel(d: Design, orientation: str, amplitude_mm: float, half_waves: int,
                 mode: str = "blocked", points: int = STRAIN_POINTS) -> DesignPanel:
    """The simulated panel test of design `d`'s net printed with curved strands (its layout,
    section and material; the wave's `amplitude_mm` and `half_waves` between junctions,
    `printgen.barrier.patterns.curved`), loaded along its `orientation` diagonal, with the
    net law its strand curves give (the blocked, infinite net) to compare with. The panel is
    PRINTED_PANEL long, or longer to hold two meshes; its strains reach 1.5 x the knee."""
    from printgen.barrier.patterns.curved import (
        CurvedStrands,
        blocked_membrane,
        check_wave,
        membrane_law,
        strand_law,
        stress_law,
    )

    n = d.net
    stress, how = stress_law(load_material(n.material))
    s = CurvedStrands(amplitude_mm, half_waves, n.strand.bead_width_mm, n.strand.beads_across,
                      n.strand.thickness_mm, stress, how)
    check_wave(n.pattern, s, n.mesh_x_mm, n.mesh_y_mm, "--wave")
    along, across = panel_axes(n.mesh_x_mm * MM, n.mesh_y_mm * MM, orientation)
    size = (max(PRINTED_PANEL[0], 2 * along), max(PRINTED_PANEL[1], 2 * across))
    t = PanelTest(along, across, size[0], size[1], mode, n.pattern)
    law = strand_law(n.pattern, s, along, across)
    m = membrane_law(n.pattern, s, along, across)
    eps = law_strains((m.knee,), points)
    curve = simulate(law, t, eps)
    # the strand curves' net law is the blocked, infinite net's: the free panel is another test
    expected = (blocked_membrane(n.pattern, s, along, across, eps) * edge_share(t)
                if mode == "blocked" else None)
    text = (f"curved strands: {amplitude_mm:g} mm amplitude, {half_waves} half-wave(s) per "
            f"strand, excess length {m.excess:.2%}, in-plane width {s.width_mm:g} mm bends; "
            f"net law low {m.low_slope:.4g} N/m, straightened {m.straight_slope:.4g} N/m, "
            f"knee {m.knee:.1%}; stress law: {how}")
    return DesignPanel(orientation, t, law, curve, None, text, expected)


def edge_share(t: PanelTest) -> float:
    """Loaded strands of the panel per those of as wide a strip of the infinite net: (nx + 1)
    / nx for a pattern whose edge columns are strands (the square: nx meshes across hold nx + 1
    strands along the load), 1 otherwise (the diamond's strands fill its width evenly)."""
    if not get_pattern(t.pattern).edge_strands:
        return 1.0
    nx = round(lattice_size(t)[1] / t.mesh_across)
    return (nx + 1) / nx
