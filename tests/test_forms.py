"""Model-form options of the printed model's scene (issue 25, printgen.scene.forms): the
strand law derived from the virtual panel test, and the net's bottom row held on the bed."""

from __future__ import annotations

import numpy as np
import pytest
from proto_files import EXAMPLES

from printgen.inputs.materials import load_material
from printgen.scaling.design_file import load_design
from printgen.scene import SceneOptions, build_scene
from printgen.scene.forms import DERIVE_POINTS, derived_net_law
from printgen.scene.panel import PanelTest, law_strains, simulate
from printgen.verification.bands import curves
from printgen.verification.preprint import sweep
from printgen.verification.variants import model_variants

PAPER = EXAMPLES / "paper_1_40" / "design.json"
MM = 1e-3
DERIVED_TOL = 0.05  # issue 25: a derived law reproduces its panel law within 5 % over its range
STILL = 1e-12  # relative wire change of a row whose nodes are all held (round-off only)
LEVELS = np.array([0.0, 0.5])


@pytest.mark.slow
def test_derived_law_reproduces_the_tpe_panel_law_along_the_long_diagonal():
    d = load_design(PAPER)
    mat = load_material("tpe")
    law, how = derived_net_law(mat, d.net, "long")
    pl = mat.panel_law
    t = PanelTest(20.6 * MM, 9.4 * MM, pl.panel_length, pl.panel_width, "free")
    fitted = law_strains(pl.knee_strains, DERIVE_POINTS)
    eps = np.sort(np.concatenate([fitted, (fitted[1:] + fitted[:-1]) / 2]))  # and between
    sim = simulate(law, t, eps).force_per_width  # the design's strands are the tested ones
    target = pl.force_per_width(eps)
    assert np.max(np.abs(sim - target)) / np.max(target) < DERIVED_TOL
    assert "free" in how and "20.6 mm (long)" in how


def test_derived_law_along_the_short_diagonal_uses_the_blocked_test():
    """A free pin-jointed panel along the 9.4 mm diagonal is a mechanism (issue 25, panel.py):
    the derivation falls back to the blocked test and says so."""
    d = load_design(PAPER)
    _, how = derived_net_law(load_material("tpe"), d.net, "short")
    assert "blocked" in how and "9.4 mm (short)" in how


def test_bed_holds_the_bottom_row_and_its_wire_reads_nothing():
    d = load_design(PAPER)
    s = build_scene(d, SceneOptions(bed="held"))
    assert s.fixed[s.rows["bottom"]].all()
    assert any(a[0] == "bed" for a in s.assumptions)
    c = curves(sweep(s, LEVELS))
    assert abs(c["strain_bottom"][-1]) < STILL
    assert c["strain_mid"][-1] > 0  # the rest of the net still deforms


def test_model_form_variants_of_the_paper_design():
    d = load_design(PAPER)
    labels = {v.label: v for v in model_variants(d, "walls", 0.3)[0]}
    assert labels["strand law from the virtual panel test"].options.net_law == "derived"
    assert labels["bottom row held on the bed"].options.bed == "held"
    both = labels["mounted in the 300 mm free section, bottom on the bed"].options
    assert both.span == pytest.approx(0.3) and both.bed == "held"


def test_sensor_routing_is_a_variant_only_where_the_wire_ends_move():
    d = load_design(PAPER)
    walls, notes = model_variants(d, "walls", None)
    assert not [v for v in walls if v.options.routing != "in-line"]
    assert any("sensor routing" in n and "no routing variant" in n for n in notes)
    eyelets = [v for v in model_variants(d, "eyelets", None)[0]
               if v.options.routing == "downstream"]
    assert len(eyelets) == 1
    s = build_scene(d, SceneOptions(mounting="eyelets", routing="downstream"))
    for w in s.wires.values():
        step = w.exit - s.nodes[w.nodes[-1]]
        assert step[1] > 0 and step[0] == 0 and step[2] == 0  # downstream, out of the plane
