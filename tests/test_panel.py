"""The virtual panel test (issue 25): the blocked, infinite panel against the analytic diamond
formula, the strand-law derivation against the panel laws it was derived from, and the free
short-diagonal panel of a pin-jointed net reported as a mechanism."""

from __future__ import annotations

import numpy as np
import pytest

from printgen.barrier.patterns.diamond import lockup_strain
from printgen.barrier.patterns.diamond import strand_law as strand_law_from_membrane
from printgen.scene.panel import PanelTest, analytic_blocked, derive_law, law_strains, simulate
from printgen.solver import Law

MM = 1e-3
ANALYTIC_TOL = 0.01  # issue 25: a blocked, infinite panel matches the formula within 1 %
DERIVED_TOL = 0.05  # issue 25: a derived law reproduces its panel law within 5 %
SMALL = 0.002  # strain where the finite-strain formula equals the linear one to < 0.5 %
MECHANISM = 0.5  # the hold carries more than half the clamp force: no strand stiffness
CLAMP_HOLD = 0.3  # the 23 mm clamps stiffen a 2-mesh-long free panel: derived slope within 30 %
POINTS = 5  # strains per derivation (checked between them too): a cheap test


def test_blocked_infinite_panel_matches_the_diamond_formula():
    law = Law((0.05,), (150.0, 40.0))  # strand law (N per unit strain), knee at 5 %
    for along, across in ((9.4, 20.6), (20.6, 9.4)):
        t = PanelTest(along * MM, across * MM, 12 * along * MM, 12 * across * MM, "blocked")
        eps = np.array([SMALL, 0.05, 0.15, 0.3])
        sim = simulate(law, t, eps).force_per_width
        np.testing.assert_allclose(sim, analytic_blocked(law, t, eps), rtol=ANALYTIC_TOL)
        sin = (along / 2) / np.hypot(along / 2, across / 2)
        linear = 2 * law.slopes[0] * sin**3 / (across * MM) * SMALL  # the diamond formula
        assert sim[0] == pytest.approx(linear, rel=ANALYTIC_TOL)


def test_prototype_panel_law_is_reproduced_by_its_derived_strand_law():
    """The prototype's 1.33 m panel along the water-drop's long axis, transverse blocked."""
    t = PanelTest(0.63, 0.35, 1.33, 1.33, "blocked")
    knees, slopes = (0.2,), (250e3 * 1.33, 1500e3 * 1.33)
    d = derive_law(knees, slopes, t, law_strains(knees, POINTS))
    assert d.error < DERIVED_TOL


@pytest.mark.slow
def test_printed_panel_along_the_long_diagonal_is_derived_within_tolerance():
    """The TPE net's free 43 x 23 mm panel loaded along its 20.6 mm diagonal: the clamps hold
    two meshes' length, so the derived law's low-strain slope stays near the formula's."""
    t = PanelTest(20.6 * MM, 9.4 * MM, 43 * MM, 23 * MM, "free")
    knees, slopes = (0.4,), (30e3 * 0.043, 6e3 * 0.043)
    d = derive_law(knees, slopes, t, law_strains(knees, POINTS))
    assert d.error < DERIVED_TOL
    formula = strand_law_from_membrane(knees, slopes, t.mesh_along, t.mesh_across)
    assert d.law.slopes[0] == pytest.approx(formula.slopes[0], rel=CLAMP_HOLD)


def test_free_short_diagonal_panel_is_a_mechanism():
    """Along the 9.4 mm diagonal the 23 mm clamps hold one mesh across: a pin-jointed net
    closes its meshes at no force until lock-up (141 % strain); what the test reads is the
    hold that picks one state of the mechanism, not the strands."""
    t = PanelTest(9.4 * MM, 20.6 * MM, 43 * MM, 23 * MM, "free")
    law = strand_law_from_membrane((0.4,), (30e3 * 0.043, 6e3 * 0.043), t.mesh_along,
                                   t.mesh_across)
    c = simulate(law, t, np.array([0.05, 0.1]))
    assert c.hold_share > MECHANISM
    assert lockup_strain(9.4, 20.6) == pytest.approx(1.41, abs=0.01)
    assert lockup_strain(20.6, 9.4) == pytest.approx(0.099, abs=0.001)
