"""The report of a design with waved strands: the target, straight and waved nets' laws on one
plot (`printgen.scene.waved.wave_laws`, `printgen.report.wave_report`) and the waved net's print
time and mass against the straight one's; `make --design` of a waved design shows both."""

from __future__ import annotations

import dataclasses
import json

import numpy as np
import pytest
from conftest import EXAMPLES, planned, reference_design_1_40
from numpy.testing import assert_allclose

from printgen.barrier.patterns.curved import blocked_force
from printgen.inputs.laws import piecewise_linear
from printgen.inputs.materials import load_material
from printgen.inputs.printers import load_print_style, load_printer
from printgen.parts.gcode.price import wave_price
from printgen.report.html import Report
from printgen.report.wave_report import WaveRecord, wave_section
from printgen.scaling.record import Wave
from printgen.scaling.selection import target_net_law
from printgen.scene.waved import wave_laws

WAVE = Wave(1.5, 1)  # the top of the 1.0-1.5 mm range asked of the 1:40 net
NEWTON_REL = 1e-8  # the beam model's equilibrium (1e-10 of EA) on forces of order EA x strain
ROUND_OFF = 1e-12  # one law built through two orders of float operations
REDUCED_MM = (40.0, 60.0)  # a piece of the 1:40 net for the price: the same strands, quick


def _planned(wave):
    """The realistic prototype at 1:40 and the reference's TPE design (a measured, softening
    panel law against the prototype's stiffening one) with `wave`."""
    p, d = planned(EXAMPLES / "realistic_barrier.toml")
    from printgen.scaling.similitude import scale_targets

    ref = reference_design_1_40()
    return p, scale_targets(p, d.scale), dataclasses.replace(
        ref, net=dataclasses.replace(ref.net, wave=wave))


def test_the_laws_are_the_target_the_straight_and_the_waved_nets():
    p, t, d = _planned(WAVE)
    laws = wave_laws(p, t, d)
    assert_allclose(laws.target, piecewise_linear(laws.strains, *target_net_law(p, t)))
    # a zero-amplitude wave is the straight net, through the same beam model
    flat = wave_laws(p, t, dataclasses.replace(d, net=dataclasses.replace(d.net,
                                                                          wave=Wave(0.0, 1))))
    assert_allclose(flat.curved, flat.straight, rtol=NEWTON_REL)
    assert_allclose(flat.straight, laws.straight)
    # softer than the straight net while the strands unbend; closer to the stiffening target
    assert np.all(laws.curved < laws.straight)
    assert laws.error_rms_log(laws.curved) < laws.error_rms_log(laws.straight)
    rec = laws.to_record()
    assert rec["wave"] == {"amplitude_mm": 1.5, "half_waves": 1}


def test_the_search_and_the_scene_give_the_same_straight_and_waved_laws():
    # the design search screens waves with the law the verification's scene will use
    from printgen.scene import build_scene
    from printgen.search.waves import straight_law

    p, t, d = _planned(WAVE)
    straight = build_scene(dataclasses.replace(d, net=dataclasses.replace(d.net, wave=None)))
    law = straight_law(d.net)
    assert_allclose(law.knees, straight.laws[0].knees, rtol=ROUND_OFF)
    assert_allclose(law.slopes, straight.laws[0].slopes, rtol=ROUND_OFF)
    laws = wave_laws(p, t, d)
    assert_allclose(laws.straight, blocked_force(d.net.pattern, law, d.net.mesh_y_mm * 1e-3,
                                                 d.net.mesh_x_mm * 1e-3, laws.strains),
                    rtol=ROUND_OFF)


def test_the_section_shows_the_plot_and_the_price():
    p, t, d = _planned(WAVE)
    net = dataclasses.replace(d.net, width_mm=REDUCED_MM[0], height_mm=REDUCED_MM[1])
    price = wave_price(net, load_printer(d.printer), load_print_style(net.print_style),
                       load_material(net.material))
    rep = Report("t")
    wave_section(rep, WaveRecord(wave_laws(p, t, d), price))
    rep.draw()
    assert [f.name for f in rep.figures] == ["wave-laws"]
    png = rep.figures[0].png
    assert png.startswith(b"\x89PNG")
    text = rep.html()
    assert "Waved strands: net law and print cost" in text
    assert f"{price.time_ratio:.2f}" in text and f"{price.mass_ratio:.2f}" in text
    assert price.time_ratio > 1 and price.mass_ratio > 1  # a waved strand is longer


@pytest.mark.slow
def test_make_of_a_waved_design_reports_its_wave(tmp_path):
    from printgen.run.make import make
    from printgen.run.options import RunOptions

    p, t, d = _planned(WAVE)
    design = tmp_path / "design.json"
    design.write_text(json.dumps(d.to_dict()))
    out = tmp_path / "out"
    make(EXAMPLES / "realistic_barrier.toml", 40, out,
         options=RunOptions(design_file=str(design)))
    rep = json.loads((out / "report.json").read_text())
    assert rep["wave"]["price"]["time_ratio"] > 1
    assert rep["wave"]["laws"]["wave"] == {"amplitude_mm": 1.5, "half_waves": 1}
    html = (out / "report.html").read_text()
    assert "Waved strands: net law and print cost" in html and "strand wave" in html
    assert any(f.name.endswith("wave-laws.png") for f in (out / "figures").iterdir())
