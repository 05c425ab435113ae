"""The printed model's scene of a design with waved strands: its strand law is the beam model's
curve of the design's strands (`printgen.scene.waved`), on its own net and on the band's coarser
nets, stated in the scene's assumptions; the model it gives deforms more than the straight one
and stiffens like it once the strands are straight."""

from __future__ import annotations

import dataclasses

import numpy as np
from conftest import reference_design_1_40
from numpy.testing import assert_allclose

from printgen.scaling.record import Wave
from printgen.scene import SceneOptions, build_scene
from printgen.scene.waved import waved_curve
from printgen.solver.strand_curve import STRAIGHT_FRACTION
from printgen.verification.bands import COARSENINGS
from printgen.verification.preprint import SOLVER_TOL, sweep

WAVE = Wave(0.5, 1)  # excess length 0.48 % on the 1:40 net's 11.3 mm chords: below the strand
# strain its strands reach at full load (about 1.4 %), so the model passes the knee
COARSE = COARSENINGS[0]  # the band's first coarser net: the same scene on fewer nodes, fast
LEVELS = np.array([0.5, 0.7, 0.9, 1.0])  # h / h_B where the strands carry load
ROUND_OFF = 1e-12  # one law computed twice through other float operations
NEWTON_REL = 1e-8  # the beam model's equilibrium (1e-10 of EA) on forces of order EA x strain
MODEL_REL = 1e2 * SOLVER_TOL  # two solutions of one net, each to the solver's tolerance
STRAIGHTENED_REL = 1 - STRAIGHT_FRACTION  # the curve counts as straight within this of its top
STIFF_REL = 0.10  # the top load step's deflection, waved vs straight: the straightened strand
# keeps bent layers at its clamped ends (tangent 95 % of the straight strand's for this wave)
# and the waved net stands more deflected


def _design(wave):
    d = reference_design_1_40()
    return dataclasses.replace(d, net=dataclasses.replace(d.net, wave=wave))


def test_a_straight_design_keeps_its_scene():
    a, b = build_scene(_design(None)), build_scene(reference_design_1_40())
    assert a.laws == b.laws and a.assumptions == b.assumptions


def test_the_waved_law_is_the_curve_of_the_designs_strands_and_says_so():
    straight, waved = build_scene(_design(None)), build_scene(_design(WAVE))
    curve = waved_curve(straight.laws[0], _design(WAVE))
    assert waved.laws[0] == curve.law()
    assert waved.laws[1:] == straight.laws[1:]  # the printed border frame stays straight
    what, text, _ = waved.assumptions[-1]
    assert what == "strand wave"
    assert "a = 0.5 mm" in text and "n = 1" in text and "clamped" in text
    # soft while the wave unbends, then the straight strand's slope
    e_low, e_high = 0.1 * curve.strand.excess(), 3 * curve.strand.excess()
    f_w, t_w = waved.laws[0].force_and_tangent(np.array([e_low, e_high]))
    f_s, t_s = straight.laws[0].force_and_tangent(np.array([e_low, e_high]))
    assert t_w[0] < 0.7 * t_s[0] and f_w[1] < f_s[1]
    assert_allclose(t_w[1], t_s[1], rtol=STRAIGHTENED_REL)


def test_coarser_nets_keep_the_designs_curve_k_times_stiffer():
    fine = build_scene(_design(WAVE))
    for k in COARSENINGS:
        coarse = build_scene(_design(WAVE), SceneOptions(coarsen=k))
        # the straight law behind it is rebuilt on the coarse mesh: equal to round-off
        assert_allclose(coarse.laws[0].knees, fine.laws[0].knees, rtol=ROUND_OFF)
        assert_allclose(coarse.laws[0].slopes, np.multiply(fine.laws[0].slopes, k),
                        rtol=ROUND_OFF)


def test_a_zero_amplitude_wave_is_the_straight_net():
    opts = SceneOptions(coarsen=COARSE)
    straight, flat = build_scene(_design(None), opts), build_scene(_design(Wave(0.0, 1)), opts)
    e = np.linspace(1e-4, 0.3, 200)
    assert_allclose(flat.laws[0].force_and_tangent(e)[0], straight.laws[0].force_and_tangent(e)[0],
                    rtol=NEWTON_REL)
    a, b = sweep(straight, LEVELS).deformation, sweep(flat, LEVELS).deformation
    for key, v in a.values.items():
        assert_allclose(b.values[key], v, rtol=MODEL_REL, atol=MODEL_REL * np.abs(v).max(),
                        err_msg=key)


def test_the_waved_model_deforms_more_then_stiffens_like_the_straight_one():
    opts = SceneOptions(coarsen=COARSE)
    a = sweep(build_scene(_design(None), opts), LEVELS).deformation.values["deflection"]
    b = sweep(build_scene(_design(WAVE), opts), LEVELS).deformation.values["deflection"]
    assert np.all(b > a)
    assert_allclose(b[-1] - b[-2], a[-1] - a[-2], rtol=STIFF_REL)
