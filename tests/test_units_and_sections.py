"""Unit conversions and the equivalent-section arithmetic."""

from __future__ import annotations

import math

import numpy as np
import pytest

from printgen.barrier.patterns.diamond import diamond_factor
from printgen.barrier.patterns.square import square_factor
from printgen.inputs.laws import piecewise_linear
from printgen.scaling.record import Section
from printgen.scaling.section import area_m2, equal_area_diameter
from printgen.units import GPA, MM, m_to_mm, mm_to_m, split_unit_key

EXACT = 1e-12  # closed-form arithmetic, round-off only


@pytest.mark.parametrize("key, name, factor, unit", [
    ("tensile_modulus_gpa", "tensile_modulus", GPA, "GPa"),
    ("kappa_kn_per_m_per_m", "kappa", 1e3, "kN/m/m"),
    ("velocity_m_per_s", "velocity", 1.0, "m/s"),
    ("max_volumetric_flow_mm3_per_s", "max_volumetric_flow", 1e-9, "mm^3/s"),
    ("width_m", "width", 1.0, "m"),
    ("strand_diameter_mm", "strand_diameter", MM, "mm"),
    ("froude_min", "froude_min", 1.0, ""),
])
def test_unit_suffixes(key, name, factor, unit):
    assert split_unit_key(key) == (name, factor, unit)


def test_mm_round_trip():
    x = np.array([0.33, 0.1, 1e-4])
    np.testing.assert_allclose(mm_to_m(m_to_mm(x)), x, rtol=EXACT)
    assert m_to_mm(0.0206) == pytest.approx(20.6, rel=EXACT)


def test_section_of_the_reference_cable():
    """PETG cable of the reference: 2 beads of 0.45 mm x 2 layers of 0.30 mm = 0.9 x 0.6 mm."""
    s = Section(0.45, 2, (0.30, 0.30))
    assert (s.width_mm, s.thickness_mm, s.passes) == (0.9, 0.6, 4)
    assert area_m2(s) == pytest.approx(0.54e-6, rel=EXACT)
    assert equal_area_diameter(s) == pytest.approx(math.sqrt(4 * 0.54e-6 / math.pi), rel=EXACT)


def test_equivalent_section_keeps_ea():
    """A_print = A_target E_target / E_polymer (barrier-physics.md, section 2)."""
    ea_target = 100e9 * math.pi / 4 * 0.024**2 / 40**3
    a_print = ea_target / 1.30e9
    assert 1.30e9 * a_print == pytest.approx(ea_target, rel=EXACT)
    # the 0.9 x 0.6 mm layout is within 1 % of that area
    assert area_m2(Section(0.45, 2, (0.3, 0.3))) / a_print - 1 == pytest.approx(-0.0067, abs=5e-4)


def test_diamond_factor_limits():
    # strands along the load (theta = 90 deg) -> 2 / a_across; square mesh diamond -> 1/(sqrt2 a)
    assert diamond_factor(1.0, 1e-9) == pytest.approx(2 / 1e-9, rel=1e-6)
    assert diamond_factor(0.2, 0.2) == pytest.approx(2 * (1 / math.sqrt(2)) ** 3 / 0.2, rel=EXACT)
    assert square_factor(0.2) == 5.0


def test_piecewise_linear_is_tension_only_and_continuous():
    knees, slopes = (0.2,), (250.0, 1500.0)
    eps = np.array([-0.1, 0.0, 0.1, 0.2, 0.3])
    np.testing.assert_allclose(piecewise_linear(eps, knees, slopes),
                               [0, 0, 25.0, 50.0, 50.0 + 150.0], rtol=EXACT)
