"""The virtual panel test's solve: a net panel of a tested pattern clamped at two node rows and
stretched along the load, free between the clamps or with its transverse displacement blocked, as
its source ran it (barrier-physics.md, sections 4 and 5; Lambert et al. 2023,
doi:10.1061/JHEND8.HYENG-13070). The test and its set-up are described in `printgen.scene.panel`,
which derives strand laws from it; it lives here, below the scenes, because the reading of a
measured panel law (`printgen.scaling.reading`) is checked against it before a design uses it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from printgen import solver
from printgen.barrier.patterns import get_pattern
from printgen.errors import SolverError
from printgen.inputs.laws import piecewise_linear
from printgen.solver import Law
from printgen.units import MM

TESTED_PATTERN = "diamond"  # the pattern of the nets the material profiles' panel laws tested
MODES = ("blocked", "free")
PANEL_TOL = 1e-9  # out-of-balance force / strand force scale: exact for a 1 % comparison
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


def law_strains(knees: tuple[float, ...], points: int = STRAIN_POINTS) -> np.ndarray:
    """Panel strains of a measured law's range: up to 1.5 x its last knee (the law is stated
    'above' the knee, not to a given strain), or 10 % for a linear law."""
    top = 1.5 * max(knees) if knees else 0.1
    return np.linspace(top / points, top, points)
