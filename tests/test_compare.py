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
    headline,
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
    stiff = headline(compare(_deformation(1.0, lv), _deformation(0.5, lv)))
    assert stiff.startswith("model too stiff: deforms 50% to 50% less than the prototype")
    assert "; 5 of 5 quantities fail (off by more than 25% of the prototype's peak)" in stiff
    soft = headline(compare(_deformation(1.0, lv), _deformation(1.5, lv)))
    assert soft.startswith("model too soft: deforms 50% to 50% more")
    close = headline(compare(_deformation(1.0, lv), _deformation(0.9, lv)))
    assert close.startswith("model within 25% of the prototype's peak on all 5 quantities")
    assert "0.90x to 0.90x" in close
