"""Normalised deformation metrics and the prototype-vs-model mismatch."""

from __future__ import annotations

import math

import numpy as np
import pytest

from printgen.verification.compare import (
    METRICS,
    Deformation,
    compare,
    explain,
    headlines,
    row_strain,
)

EXACT = 1e-12  # closed-form geometry, round-off only


def test_row_strain_of_a_pulled_straight_row():
    """A row of span L pulled out of plane by delta at mid-span: sqrt(1 + (2 delta/L)^2) - 1."""
    x0 = np.array([[0.0, 0, 0], [1.0, 0, 0], [2.0, 0, 0]])
    x = x0.copy()
    x[1, 1] = 0.3
    assert row_strain(x0, x) == pytest.approx(math.hypot(1, 0.3) - 1, rel=EXACT)
    assert row_strain(x0, x0) == 0.0


def _deformation(scale: float, levels: np.ndarray) -> Deformation:
    values = {k: scale * levels**2 for k in METRICS}
    return Deformation(levels, values, levels.copy(), levels.copy())


def test_identical_deformations_match():
    lv = np.linspace(0, 1.1, 23)
    mm = compare(_deformation(1.0, lv), _deformation(1.0, lv))
    assert all(m.ok and m.max_rel == 0.0 for m in mm)
    assert explain(mm) == []


def test_a_stiffer_model_fails_with_a_reason():
    lv = np.linspace(0, 1.1, 23)
    mm = compare(_deformation(1.0, lv), _deformation(0.5, lv))
    assert all(not m.ok for m in mm)
    assert mm[0].max_rel == pytest.approx(0.5, rel=EXACT)  # half the prototype's peak, at 1.1
    assert mm[0].worst_level == pytest.approx(1.1)
    assert mm[0].ratio_high == pytest.approx(0.5, rel=EXACT)
    reasons = explain(mm)
    assert "model 0.50x the prototype above h/h_B = 0.8 (too stiff)" in reasons[0]
    assert "lowers too little" in reasons[1]


def test_levels_must_agree():
    with pytest.raises(ValueError):
        compare(_deformation(1, np.linspace(0, 1, 5)), _deformation(1, np.linspace(0, 1.1, 5)))


def test_headline_says_which_way_and_by_how_much():
    lv = np.linspace(0, 1.1, 23)
    stiff = headlines(compare(_deformation(1.0, lv), _deformation(0.5, lv)))
    assert len(stiff) == 1
    assert stiff[0].startswith("model too stiff in 5 of 5 quantities (mid-height deflection / "
                               "width, top-centre lowering / height, bottom cable elongation, ")
    assert ("deforms 50% less than the prototype above h/h_B = 0.8 (off by more than 25% of "
            "the prototype's peak)") in stiff[0]
    soft = headlines(compare(_deformation(1.0, lv), _deformation(1.5, lv)))
    assert soft[0].startswith("model too soft in 5 of 5 quantities") and "50% more" in soft[0]
    close = headlines(compare(_deformation(1.0, lv), _deformation(0.9, lv)))
    assert close[0].startswith("model within 25% of the prototype's peak on all 5 quantities")
    assert "0.90x to 0.90x" in close[0]


def test_one_headline_sentence_per_direction_of_error():
    """A model stiffer in some quantities and softer in others gets two sentences, each naming
    its own quantities: never "too stiff ... too soft" in one line."""
    lv = np.linspace(0, 1.1, 23)
    model = _deformation(0.6, lv)
    model.values["strain_mid"] = 1.5 * lv**2
    model.values["strain_top"] = 1.3 * lv**2
    lines = headlines(compare(_deformation(1.0, lv), model))
    assert len(lines) == 2
    assert lines[0].startswith("model too stiff in 3 of 5 quantities (mid-height deflection / "
                               "width, top-centre lowering / height, bottom cable elongation): "
                               "deforms 40% less")
    assert lines[1].startswith("model too soft in 2 of 5 quantities (top cable elongation, "
                               "elongation at mid-height): deforms 30% to 50% more")
    assert not any("stiff" in x and "soft" in x for x in lines)
