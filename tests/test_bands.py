"""Uncertainty bands of the printed model: the variants, the envelope, the refinement test and
the verdict's wording (issue 10)."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from conftest import coarse_design_1_40, reference_design_1_40

from printgen.scaling.record import Section
from printgen.scene import SceneOptions, build_scene
from printgen.scene.scenes import MOUNTINGS
from printgen.verification import bands
from printgen.verification import variants as variants_module
from printgen.verification.bands import band_verdict, model_band, refinement_test, run_variant
from printgen.verification.compare import METRICS
from printgen.verification.preprint import sweep
from printgen.verification.variants import Variant, model_variants

COARSE = 3  # the 1:40 net with a 3x coarser mesh (50 nodes): fast sweeps
LEVELS = np.round(np.arange(0.0, 1.11, 0.1), 10)  # 0.1 steps keep the sweeps short
ROUND = 1e-12  # round-off allowed between a curve and the band's edge
LEVELS_V = np.linspace(0.0, 1.1, 12)
SOFT = 0.005  # a net 200x softer than the 1:40 design's: its 1 N sensor wires fold it



@pytest.mark.slow
def test_band_contains_the_nominal_and_every_variant():
    d = coarse_design_1_40(COARSE)
    nominal = run_variant(d, Variant(), LEVELS)
    variants = [Variant("softer net", options=SceneOptions(net_factor=0.7, frame_factor=0.7)),
                Variant("stiffer cables", options=SceneOptions(cable_factor=1.3))]
    b = model_band(d, nominal, variants=variants, notes=["a note"])
    assert b.notes == ["a note"] and set(b.variants) == {v.label for v in variants}
    for from_start in (False, True):
        lo, hi = b.envelope(from_start=from_start)
        for key in METRICS:
            curves = [b.nominal[key], *(c[key] for c in b.variants.values())]
            for c in curves:
                c = c - (c[0] if from_start else 0.0)
                assert np.all(lo[key] <= c + ROUND) and np.all(c <= hi[key] + ROUND)
    lo, hi = b.envelope()
    assert np.max(hi["deflection"] - lo["deflection"]) > 0  # the variants move the curve


def test_a_variant_the_solver_refuses_is_recorded_not_fatal():
    """A variant whose net is so soft that the sensor wires fold it (the solver's
    SolverError) gets no curves and the solver's reason; the band and the other variants
    stand (make and verify go on to a verdict that names it)."""
    d = coarse_design_1_40(COARSE)
    nominal = run_variant(d, Variant(), LEVELS)
    folding = Variant("soft net", options=SceneOptions(net_factor=SOFT, frame_factor=SOFT))
    b = model_band(d, nominal, variants=[folding, Variant("stiffer cables", options=SceneOptions(
        cable_factor=1.3))])
    assert set(b.refused) == {"soft net"} and "folds back" in b.refused["soft net"]
    assert all(np.all(np.isnan(c)) for c in b.variants["soft net"].values())
    assert not np.any(np.isnan(b.variants["stiffer cables"]["deflection"]))
    assert "soft net" not in b.weighted() and "refused" in b.excluded["soft net"]


def test_refinement_test_keeps_the_design_net_when_coarsening_changes_the_answer(monkeypatch):
    d = coarse_design_1_40(COARSE)
    nominal = bands.curves(run_variant(d, Variant(), LEVELS))
    k, change = refinement_test(d, nominal, LEVELS)
    assert list(change) == [2]  # a failing x2 stops the test: x3 is not run
    assert change[2] >= bands.REFINE_TOL and k == 1
    monkeypatch.setattr(bands, "REFINE_TOL", 10.0)  # any change accepted: the coarsest wins
    k, change = refinement_test(d, nominal, LEVELS)
    assert k == max(change) == max(bands.COARSENINGS)


def test_coarse_variant_scene_keeps_membrane_stiffness():
    d = coarse_design_1_40(COARSE)
    fine, coarse = build_scene(d), build_scene(d, SceneOptions(coarsen=2))
    assert len(coarse.nodes) < len(fine.nodes)
    assert coarse.laws[0].slopes[0] == pytest.approx(2 * fine.laws[0].slopes[0], rel=ROUND)
    assert coarse.laws[1] == fine.laws[1]  # the border frame is not meshed: same law


def test_variants_of_the_1_40_design_say_what_is_left_out():
    variants, notes = model_variants(reference_design_1_40())
    assert [v.slack for v in variants if v.slack] == [variants_module.SLACK_MAX]
    text = " ".join(notes)
    assert "TPE (net): no SD" in text and "PETG (cables): no SD" in text
    assert "tested net the profile assumes" in text
    others = MOUNTINGS[1:]  # every mounting but the nominal is a variant
    assert [v.options.mounting for v in variants if v.options.mounting] == list(others)
    variants, _ = model_variants(reference_design_1_40(), mounting=others[-1])
    assert all(v.options.mounting != others[-1] for v in variants)


def test_modulus_sd_and_panel_geometry_variants(tmp_path, monkeypatch):
    (tmp_path / "materials").mkdir()
    (tmp_path / "materials" / "petg-sd.toml").write_text(
        'inherits = "petg"\n[measured.tensile_modulus]\nvalue_gpa = 1.30\nsd_gpa = 0.13\n')
    monkeypatch.setenv("PRINTGEN_PROFILES", str(tmp_path))
    d = reference_design_1_40()
    d = dataclasses.replace(
        d, cables=tuple(dataclasses.replace(c, material="petg-sd") for c in d.cables),
        net=dataclasses.replace(d.net, strand=Section(0.6, 1, (0.35, 0.30))))
    variants = {v.label: v for v in model_variants(d)[0]}
    factors = [v.options.cable_factor for v in variants.values()]
    assert sorted(f for f in factors if f != 1) == \
        pytest.approx([0.9, 1.1], rel=ROUND)
    geometry = [v for label, v in variants.items() if "panel law" in label]
    assert len(geometry) == 1  # the tested net's strands were 0.95 mm thick, these 0.65 mm
    assert geometry[0].options.net_factor == pytest.approx(0.95 / 0.65, rel=1e-9)


VERDICTS = {  # model band (lo, hi) as multiples of the prototype curve -> (kind, text)
    "inside": ((0.9, 1.1), "inside", "prototype inside the model band"),
    "stiffer": ((0.5, 0.8), "stiffer", "model stiffer by at least 20% (up to 20%)"),
    "softer": ((1.3, 1.6), "softer", "model softer by at least 30% (up to 30%)"),
}


@pytest.mark.parametrize("case", sorted(VERDICTS))
def test_band_verdict_wording(case):
    (a, b), kind, text = VERDICTS[case]
    p = LEVELS_V**2
    v = band_verdict("deflection", p, a * p, b * p)
    assert v.kind == kind and v.text == text


def test_band_verdict_partly_inside_crossing_and_sign():
    p = LEVELS_V**2
    half = LEVELS_V > 0.55
    v = band_verdict("deflection", p, np.where(half, 0.5, 0.9) * p, np.where(half, 0.8, 1.1) * p)
    assert v.kind == "partly inside" and "model stiffer by up to 20% at the others" in v.text
    v = band_verdict("deflection", p, np.where(half, 0.5, 1.2) * p, np.where(half, 0.8, 1.5) * p)
    assert v.kind == "crossing"
    neg = band_verdict("lowering", -p, -0.8 * p, -0.5 * p)  # a negative curve: magnitudes
    assert neg.kind == "stiffer" and neg.least == pytest.approx(0.2, rel=1e-9)


STATE_TOL = 1e-6  # curves from a warm start within the solver's tolerance: of each peak


def test_a_variant_started_from_the_nominal_state_reaches_the_same_curves():
    """The bottom row held on the bed: the same nodes as the nominal, held at more of them.
    Started also from the nominal's state at each level (held at rest at its own supports,
    `solver.solve_path`), its curves are those of its path from rest, within the solver's
    tolerance; a slack variant and a coarser net get no start (`warm_start`)."""
    d = coarse_design_1_40(COARSE)
    base = SceneOptions(mounting=MOUNTINGS[0])
    nominal = sweep(build_scene(d, base), LEVELS, keep_states=True)
    bed = Variant("bed", options=dataclasses.replace(base, bed="held"))
    start = bands.warm_start(bed, nominal)
    assert start is nominal.states and len(start) == len(LEVELS)
    cold, warm = (run_variant(d, bed, LEVELS, 1, None, s) for s in (None, start))
    for key in METRICS:
        peak = max(float(np.nanmax(np.abs(cold.deformation.values[key]))), 1e-12)
        np.testing.assert_allclose(warm.deformation.values[key],
                                   cold.deformation.values[key], atol=STATE_TOL * peak)
    assert bands.warm_start(dataclasses.replace(bed, slack=0.01), nominal) is None
    assert bands.warm_start(bed, nominal, coarsen=2) is None
