"""The curved-strand net (printgen.barrier.patterns.curved): a square or diamond layout whose
strands follow a wave, its membrane law from the strand curves, its printability limits."""

from __future__ import annotations

import math

import numpy as np
import pytest

import printgen.barrier.patterns as patterns_package
from printgen.barrier.patterns import get_pattern, pattern_names, patterns
from printgen.barrier.patterns.curved import (
    MIN_RADIUS_BEADS,
    CurvedStrands,
    blocked_membrane,
    check_wave,
    chord,
    curved_pattern,
    membrane_law,
    spacing,
    strain_ratio,
    strand_curve_of,
    strand_law,
    stress_law,
)
from printgen.barrier.registry import names
from printgen.errors import GeometryError
from printgen.inputs.materials import load_material
from printgen.solver import linear

MM = 1e-3
EXACT = 1e-12  # the same arithmetic two ways: round-off only
E_TPE = 0.24e9  # Pa, TPE's datasheet modulus (barrier-physics.md, section 5)
ALONG, ACROSS = 9.4 * MM, 20.6 * MM  # the 1:40 diamond net's diagonals, loaded along 9.4 mm
STRAIGHTENED = 0.02  # a linear strand's largest tangent is within 2 % of E A L / S (solved to
# 30 % chord strain, seven times the excess: the clamped ends' bent layer is nearly gone)
KNEE_BAND = (0.7, 1.1)  # the knee of the bilinear summary, as a fraction of the excess length:
# below it, because the curve rounds the knee (the strand straightens progressively)


def strands(amplitude=1.5, half_waves=1, bead=0.6, beads=1, stress=None) -> CurvedStrands:
    return CurvedStrands(amplitude, half_waves, bead, beads, 0.95, stress or linear(E_TPE))


def test_curved_is_a_family_not_a_pattern_choice():
    """A curved net is built from a layout and a wave: the registries and the prototype
    file's choices do not list it (a design does not record a wave yet)."""
    assert "curved" in patterns_package.FAMILIES
    assert "curved" not in names(patterns_package)
    assert "curved" not in patterns() and "curved" not in pattern_names()


@pytest.mark.parametrize("layout", ["square", "diamond"])
def test_a_curved_net_is_its_layouts_net_with_the_curve_as_strand_law(layout):
    along, across = (ALONG, ACROSS) if layout == "diamond" else (ALONG, ALONG)
    s = strands(1.0)
    base, pat = get_pattern(layout), curved_pattern(layout, s)
    assert pat.name == f"curved-{layout}"
    g0, g1 = base.graph(100.0, 50.0, across / MM, along / MM), pat.graph(
        100.0, 50.0, across / MM, along / MM)
    np.testing.assert_array_equal(g0.nodes_mm, g1.nodes_mm)
    np.testing.assert_array_equal(g0.segments, g1.segments)
    curve = strand_curve_of(layout, s, along, across)
    assert curve.strand.chord == pytest.approx(chord(layout, along, across), rel=EXACT)
    # the membrane factor is the low-strain (bending) slope per strand E A
    m = membrane_law(layout, s, along, across)
    assert pat.membrane_factor(along, across) * curve.strand.ea == pytest.approx(
        m.low_slope, rel=EXACT)
    # at small strain the layout's strand law of the membrane law is the curve's first slope
    back = pat.strand_law((m.knee,), (m.low_slope, m.straight_slope), along, across)
    assert back.slopes[0] == pytest.approx(curve.initial_slope, rel=EXACT)
    # the membrane law's knots are the blocked net's force at them (one formula, two uses)
    knots = np.array(m.knees)
    force = np.cumsum(np.diff(np.concatenate([[0.0], knots])) * np.array(m.slopes[:-1]))
    np.testing.assert_allclose(blocked_membrane(layout, s, along, across, knots), force,
                               rtol=1e-9)  # cumulated secants: round-off of 24 sums
    if layout == "square":  # the strands along the load strain as the net: the curve itself
        law = strand_law(layout, s, along, across)
        np.testing.assert_allclose(m.knees, law.knees, rtol=EXACT)
        np.testing.assert_allclose(np.array(m.slopes) * across, law.slopes, rtol=EXACT)


def test_the_square_and_diamond_mappings():
    """Square: strands along the load strain as the net, one per mesh across; diamond: strand
    strain sin^2(theta) of the net's, chord the half-diagonals' hypotenuse."""
    assert strain_ratio("square", ALONG, ALONG) == pytest.approx(1.0, rel=EXACT)
    sin2 = ALONG**2 / (ALONG**2 + ACROSS**2)
    assert strain_ratio("diamond", ALONG, ACROSS) == pytest.approx(sin2, rel=EXACT)
    assert chord("diamond", ALONG, ACROSS) == pytest.approx(math.hypot(4.7, 10.3) * MM,
                                                            rel=EXACT)
    # parallel diamond strands: the rhombus's area a b / 2 over its side
    assert spacing("diamond", ALONG, ACROSS) == pytest.approx(
        ALONG * ACROSS / 2 / math.hypot(ALONG / 2, ACROSS / 2), rel=EXACT)


@pytest.mark.parametrize("layout", ["square", "diamond"])
def test_the_membrane_law_softens_then_straightens(layout):
    """Low slope: bending-dominated, far below the straight net's; straightened slope: the
    straight net's of a strand as long as the wave's arc; knee near the excess length."""
    along, across = (ALONG, ACROSS) if layout == "diamond" else (ALONG, ALONG)
    s = strands(1.5)
    m = membrane_law(layout, s, along, across)
    straight = get_pattern(layout).membrane_factor(along, across) * s.strand(1.0).ea
    assert m.low_slope < 0.2 * straight
    curve = strand_curve_of(layout, s, along, across)
    assert max(curve.tangents) == pytest.approx(curve.strand.ea / (1 + m.excess),
                                                rel=STRAIGHTENED)
    assert m.straight_slope > 5 * m.low_slope  # the net stiffens as its strands straighten
    curve = strand_curve_of(layout, s, along, across)
    assert KNEE_BAND[0] * m.excess < curve.knee < KNEE_BAND[1] * m.excess


def test_the_stress_law_is_the_tested_nets_read_back():
    """TPE's profile records its tested diamond net: the stress law, times the tested strand's
    area and the diamond's factor, gives back the measured membrane law (kappa x length)."""
    mat = load_material("tpe")
    law, how = stress_law(mat)
    pl = mat.panel_law
    area = pl.strand_width * pl.strand_thickness
    factor = get_pattern("diamond").membrane_factor(pl.mesh_along_load, pl.mesh_across_load)
    np.testing.assert_allclose([v * area * factor for v in law.slopes],
                               [k * pl.panel_length for k in pl.kappas], rtol=EXACT)
    assert "panel law" in how
    petg, how = stress_law(load_material("petg"))
    assert petg.knees == () and "modulus" in how


def test_unprintable_waves_are_refused_naming_the_limit():
    check_wave("diamond", strands(1.5), 20.6, 9.4)  # the realistic net's scale: printable
    with pytest.raises(GeometryError, match=f"printable minimum of {MIN_RADIUS_BEADS:g} bead "
                                            r"width \(0.6 mm\).*amplitude of at most"):
        check_wave("diamond", strands(1.5, half_waves=4), 20.6, 9.4)
    with pytest.raises(GeometryError, match=r"wider than the .* mm between parallel strands"):
        check_wave("diamond", strands(4.2, bead=0.4), 20.6, 9.4)
    with pytest.raises(GeometryError, match="amplitude > 0.*use pattern 'square'"):
        check_wave("square", strands(0.0), 10.0, 10.0)
    with pytest.raises(GeometryError, match="square mesh needs mesh_x = mesh_y"):
        check_wave("square", strands(1.0), 10.0, 12.0)
    with pytest.raises(GeometryError, match="layout 'hexagon' is not one of square, diamond"):
        check_wave("hexagon", strands(1.0), 10.0, 10.0)
    # the pattern's mesh check (m, as the prototype file's) is the wave's check
    with pytest.raises(GeometryError, match="printable minimum"):
        curved_pattern("diamond", strands(1.5, half_waves=4)).check_mesh(20.6 * MM, 9.4 * MM,
                                                                           "[model]")


def test_beads_side_by_side_widen_the_bend_limit():
    """Two beads: the inner one runs (W - w) / 2 inside the centre line, on a tighter bend."""
    check_wave("square", strands(1.5, half_waves=4, bead=0.4, beads=1), 12.0, 12.0)
    with pytest.raises(GeometryError, match="innermost bead"):
        check_wave("square", strands(1.5, half_waves=4, bead=0.4, beads=3), 12.0, 12.0)


def test_the_largest_printable_amplitude_it_names_is_printable():
    """The amplitude the radius error names puts the innermost bead on the limit exactly."""
    with pytest.raises(GeometryError, match="at most") as err:
        check_wave("diamond", strands(1.5, half_waves=4), 20.6, 9.4)
    most = float(str(err.value).split("at most ")[1].split(" mm")[0])
    check_wave("diamond", strands(most * (1 - 1e-3), half_waves=4), 20.6, 9.4)


PANEL_REL = 0.02  # the brief's bound: the blocked virtual panel reproduces the net law built
# from the strand curves within 2 % (the same equilibrium: agreement to the solver's 1e-9)


@pytest.mark.parametrize("layout, along, across", [("diamond", ALONG, ACROSS),
                                                   ("diamond", ACROSS, ALONG),
                                                   ("square", 10 * MM, 10 * MM)])
def test_blocked_virtual_panel_reproduces_the_net_law_of_the_strand_curves(layout, along,
                                                                           across):
    """The virtual panel test (scene.panel, transverse displacement blocked) of a curved net
    whose strands carry the beam model's curve gives the membrane law built from that curve
    for the infinite net (`blocked_membrane`; a square panel reads (nx + 1) / nx of it, its
    edge strands), up to 1.5 x the knee; its initial slope is the bilinear summary's."""
    from printgen.scene.panel import PanelTest, edge_share, law_strains, simulate

    s = strands(1.5, stress=stress_law(load_material("tpe"))[0])
    m = membrane_law(layout, s, along, across)
    t = PanelTest(along, across, 8 * along, 8 * across, "blocked", layout)
    eps = law_strains((m.knee,), 8)
    sim = simulate(strand_law(layout, s, along, across), t, eps).force_per_width
    want = blocked_membrane(layout, s, along, across, eps) * edge_share(t)
    np.testing.assert_allclose(sim, want, rtol=PANEL_REL)
    small = np.array([1e-4])
    first = simulate(strand_law(layout, s, along, across), t, small).force_per_width[0]
    assert first / small[0] / edge_share(t) == pytest.approx(m.low_slope, rel=PANEL_REL)


def test_panel_command_tests_a_curved_net(capsys):
    """`printgen panel --wave`: the design's net with curved strands, blocked, beside the
    strand curves' law; an unprintable wave exits 2 naming the limit, no traceback."""
    import json

    from conftest import ROOT

    from printgen.cli import main

    design = ROOT / "examples" / "paper_1_40" / "design.json"
    assert main(["panel", str(design), "--mode", "blocked", "--orientation", "short",
                 "--wave", "1.5", "--json"]) == 0
    (row,) = json.loads(capsys.readouterr().out)
    assert "1.5 mm amplitude" in row["strands"]
    np.testing.assert_allclose(row["force_per_width_n_per_m"], row["strand_curves_n_per_m"],
                               rtol=PANEL_REL)
    assert main(["panel", str(design), "--wave", "1.5", "--half-waves", "4"]) == 2
    err = capsys.readouterr().err
    assert "Traceback" not in err and "printable minimum of 1 bead width" in err
    assert main(["panel", str(design), "--half-waves", "2"]) == 2
    assert "needs --wave" in capsys.readouterr().err
