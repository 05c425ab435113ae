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
from dataclasses import dataclass

import numpy as np

from printgen.barrier.patterns import get_pattern
from printgen.inputs.laws import piecewise_linear
from printgen.inputs.materials import load_material
from printgen.scaling.panel_test import (  # the solve of the test, below the scenes
    HOLD_RATIO,
    MODES,
    PANEL_TOL,
    STRAIN_POINTS,
    STRAIN_STEP,
    PanelCurve,
    PanelTest,
    _graph,
    _solve_all,
    analytic_blocked,
    lattice_size,
    law_strains,
    panel_lockup,
    simulate,
)
from printgen.scaling.record import Design
from printgen.scene.scenes import TESTED_PATTERN, model_net_law, panel_axes
from printgen.solver import Law
from printgen.units import MM

__all__ = ["HOLD_RATIO", "MODES", "PANEL_TOL", "STRAIN_POINTS", "STRAIN_STEP", "PanelCurve",
           "PanelTest", "analytic_blocked", "lattice_size", "law_strains", "panel_lockup",
           "simulate", "derive_law", "design_panel", "DerivedLaw", "DesignPanel",
           "refined_knees", "square_panel_size", "loaded_strands"]

DERIVE_STEPS = 8  # fixed-point passes of the strand-law derivation (each re-solves the test)
DERIVE_TOL = 1e-3  # ... stopped once the slopes move by less than 0.1 % in a pass


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
                 mode: str = "blocked", points: int = STRAIN_POINTS,
                 size: tuple[float, float] | None = None) -> DesignPanel:
    """The simulated panel test of design `d`'s net printed with curved strands (its layout,
    section and material; the wave's `amplitude_mm` and `half_waves` between junctions,
    `printgen.barrier.patterns.curved`), loaded along its `orientation` diagonal, with the
    net law its strand curves give (the blocked, infinite net) to compare with. The panel is
    PRINTED_PANEL long, or longer to hold two meshes (`size`: length, clamp width m, when
    given); its strains reach 1.5 x the knee."""
    from printgen.barrier.patterns.curved import (
        blocked_membrane,
        check_wave,
        membrane_law,
        strand_law,
    )
    from printgen.scene.waved import waved_strands

    n = d.net
    # the material as the verification reads it (the panel-law reading the material can
    # produce), as the waved scene takes it
    straight, how = model_net_law(load_material(n.material), n, None)
    s = waved_strands(n, straight, amplitude_mm, half_waves,
                      f"the design's straight strands' law ({how}) per unit area")
    check_wave(n.pattern, s, n.mesh_x_mm, n.mesh_y_mm, "--wave")
    along, across = panel_axes(n.mesh_x_mm * MM, n.mesh_y_mm * MM, orientation)
    if size is None:
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


# The square test panel, pulled along one strand family with its sides free: the strands along
# the load carry it, each strained as the panel (they lie along the load from the start: no
# mechanism, `panel_lockup` 0), the strands across carry nothing (their ends move alike). So
# the pin-jointed panel has no edge zone; the printed one has two: the outer loaded strands
# (beside the cut side bars, with the stubs of the across strands) and the strands' ends at
# the clamps (clamp slip and the junction row held in the jaws move the crosshead without
# straining the gauge). Its size keeps both small against the whole:
SQUARE_MIN_STRANDS = 8  # loaded strands between the cut side bars: an outer pair off by
# 20 % (a stub, a bead that ends) moves the panel's force 2 x 0.2 / 8 = 5 %
SQUARE_MIN_MESHES = 4  # meshes between the clamps: the row at each clamp edge, held by the
# jaws, is at most 1 / 4 of the gauge's junctions; and at least the paper's printed 43 mm


def square_panel_size(mesh: float) -> tuple[float, float]:
    """(length along the load, clamp width) m of the square test panel of mesh side `mesh`
    m: SQUARE_MIN_MESHES meshes long and SQUARE_MIN_STRANDS + 1 meshes wide (the loaded
    strands between the side bars), at least PRINTED_PANEL."""
    return (max(PRINTED_PANEL[0], SQUARE_MIN_MESHES * mesh),
            max(PRINTED_PANEL[1], (SQUARE_MIN_STRANDS + 1) * mesh))


def loaded_strands(t: PanelTest) -> tuple[int, int]:
    """(loaded strands of the printed square panel once its two side bars are cut, those of
    the simulated panel): nx - 1 and nx + 1 for nx meshes across (the simulation's edge
    columns are strands, `edge_share`). Every loaded strand carries the same force, so the
    printed panel's force is the simulated one times their ratio."""
    nx = round(lattice_size(t)[1] / t.mesh_across)
    return nx - 1, nx + 1
