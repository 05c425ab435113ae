"""Datasheet flexible-filament profiles: schema, and what the design search makes of them at
1:40 (issue 27: a strand soft enough for the target and strong enough for the overflow)."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from conftest import ROOT

from printgen.errors import InputError
from printgen.inputs import materials as mats
from printgen.inputs.prototype import load_prototype
from printgen.scaling.selection import CALIBRATE_FIRST, MIN_SAFETY_FACTOR
from printgen.scaling.similitude import scale_targets
from printgen.search.choice import SMALL_STRAIN_TOLERANCE
from printgen.search.per_material import first_on_target, per_material, reachable, target_sentence
from printgen.search.screen import screen_batch
from printgen.search.space import default_space, grid, search_context

DATASHEET_PROFILES = ("tpu-85a",)
CLOSEST = 3  # the TPE nets nearest the target that the strength check must be holding off
SECANT_TO_100_PERCENT_PA = 6e6  # CR-3D TPU 85A TDS: stress at 100 % strain 6 MPa / strain 1.0
TDS_STRENGTH_PA = 45e6  # CR-3D TPU 85A TDS: Bruchbelastung 45 MPa (DIN EN ISO 527)


@pytest.mark.parametrize("key", DATASHEET_PROFILES)
def test_datasheet_profile_names_its_document_standard_and_print_source(key):
    m = mats.load_material(key)
    assert m.modulus()[1] == "datasheet" and m.failure_stress()[1] == "datasheet"
    assert "ISO 527" in m.sheet.test_standard or "D638" in m.sheet.test_standard
    assert "Datenblatt" in m.datasheet_source or "data sheet" in m.datasheet_source.lower()
    assert m.print.source  # which print settings are the datasheet's and which printgen's
    assert m.family == "flexible" and m.print.filament_type == "FLEX"
    assert m.print.retract_length_mm <= 1.0  # flexibles: retraction off or short


def test_tpu_85a_values_are_the_datasheets():
    m = mats.load_material("tpu-85a")
    assert m.datasheet_modulus == pytest.approx(SECANT_TO_100_PERCENT_PA)
    assert m.datasheet_failure_stress == pytest.approx(TDS_STRENGTH_PA)
    assert "secant" in m.sheet.modulus_basis
    assert m.sheet.shore_hardness_a == 85.0


@pytest.mark.parametrize("key, value, message", [
    ("shore_hardness_a", 120.0, "shore_hardness_a = 120.0 is out of range"),
    ("elongation_at_break_percent", -5.0, "elongation_at_break_percent = -5.0 is out of range"),
    ("shore_a", 85.0, "unknown key 'shore_a'"),
])
def test_bad_datasheet_key_is_named(key, value, message):
    sheet = {"tensile_modulus_gpa": 0.006, "failure_stress_mpa": 45.0, "source": "x", key: value}
    with pytest.raises(InputError, match=message):
        mats.read_table(sheet, mats.DATASHEET, where="tpu.toml [datasheet]")


@pytest.fixture(scope="module")
def screened_1_40():
    """TPE (the paper's) and TPU 85A (datasheet) strands of 1-2 beads x 1-5 layers at 1:40."""
    p = load_prototype(ROOT / "examples" / "realistic_barrier.toml")
    t = scale_targets(p, 40)
    space = dataclasses.replace(default_space(p, t, materials=("tpe", "tpu-85a")),
                                border_beads=(2,))
    ctx = search_context(p, t, space)
    return screen_batch(ctx, grid(ctx, space))


@pytest.mark.slow
def test_datasheet_tpu_reaches_the_1_40_target_the_papers_tpe_does_not(screened_1_40):
    rows = {r["material"]: r for r in per_material(screened_1_40)}
    assert rows["tpe"]["on_target"] == 0  # the finding: held off by strength
    # the TPE nets closest to the target (across and up: none within SMALL_STRAIN_TOLERANCE)
    # are the ones too thin for the overflow
    tpe = sorted((s for s in screened_1_40 if s.point.material == "tpe"),
                 key=lambda s: abs(s.error_small))
    assert abs(tpe[0].error_small) > SMALL_STRAIN_TOLERANCE
    assert all(any(k == "strength" for k, _ in s.violations) for s in tpe[:CLOSEST])
    hit = first_on_target(screened_1_40)
    assert hit is not None and hit.point.material == "tpu-85a"
    assert abs(hit.error_small) <= SMALL_STRAIN_TOLERANCE
    assert hit.safety_factor >= MIN_SAFETY_FACTOR and hit.datasheet
    assert rows["tpu-85a"]["first_on_target"]["index"] == hit.point.index
    assert any(CALIBRATE_FIRST in line for line in target_sentence(screened_1_40))


def test_reachable_lists_the_scales_with_a_net_on_target():
    recs = [{"scale": 20.0, "per_material": [{"material": "tpu", "on_target": 0}]},
            {"scale": 40.0, "per_material": [{"material": "tpu", "on_target": 3}]},
            {"scale": 60.0, "per_material": [{"material": "tpu", "on_target": 1}]}]
    assert reachable(recs) == [{"material": "tpu", "scales_on_target": [40.0, 60.0],
                                "scale_range": [40.0, 60.0]}]


COUPON_GAUGE_MM = 50.0  # gauge length of a strand-section coupon (extensometer)
CALIBRATE_BACK_RTOL = 0.01  # issue 27: a known modulus calibrates back within 1 %


def test_strand_section_coupon_export_calibrates_back_to_its_modulus(tmp_path, screened_1_40):
    """A tensile export of a coupon with the section of the first on-target TPU 85A strand,
    generated with the datasheet modulus (linear to 2 % strain, then softening), and its
    sidecar: `calibrate` gives that modulus back."""
    from printgen.calibrate.pipeline import calibrate
    from printgen.search.screen import strand_section

    hit = first_on_target(screened_1_40)
    p = load_prototype(ROOT / "examples" / "realistic_barrier.toml")
    t = scale_targets(p, 40)
    ctx = search_context(p, t, default_space(p, t, materials=("tpu-85a",)))
    sec = strand_section(ctx, hit.point)
    area_m2 = sec.width_mm * sec.thickness_mm * 1e-6
    e0 = mats.load_material("tpu-85a").datasheet_modulus
    strain = np.linspace(0.0, 0.05, 251)
    stress = np.where(strain < 0.02, e0 * strain, e0 * (0.02 + 0.5 * (strain - 0.02)))
    for i in range(3):
        lines = ["Time (s),Load (N),Strain (%)"]
        lines += [f"{k * 0.1:.3f},{s * area_m2:.9g},{e * 100:.6f}"
                  for k, (e, s) in enumerate(zip(strain, stress, strict=True))]
        (tmp_path / f"coupon-{i}.csv").write_text("\n".join(lines) + "\n", encoding="utf-8")
    (tmp_path / "specimen.toml").write_text(
        f'kind = "cable"\nwidth_mm = {sec.width_mm:g}\nthickness_mm = {sec.thickness_mm:g}\n'
        f"gauge_length_mm = {COUPON_GAUGE_MM:g}\n", encoding="utf-8")
    cal = calibrate([tmp_path], material="tpu-85a-printed")
    assert cal.modulus.mean == pytest.approx(e0, rel=CALIBRATE_BACK_RTOL)
