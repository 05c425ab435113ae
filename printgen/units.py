"""Unit constants and conversions. SI inside (m, N, Pa, s); mm only at the geometry boundary.

Data-file keys end with their unit (`tensile_modulus_gpa`, `height_m`); `UNIT_SCALE` maps a
suffix to the factor that converts it to SI, and `split_unit_key` strips it.
"""

from __future__ import annotations

import numpy as np

MM = 1e-3  # m per mm
KN = 1e3  # N per kN
MPA = 1e6  # Pa per MPa
GPA = 1e9  # Pa per GPa
KN_PER_M_PER_M = 1e3  # (N/m)/m per (kN/m)/m
L_PER_S = 1e-3  # m^3/s per L/s
G = 9.81  # m/s^2, standard gravity used throughout
RHO_WATER = 1000.0  # kg/m^3
NU_WATER = 1.0e-6  # m^2/s, kinematic viscosity of water (reference, section 2)

# Key suffix -> (factor to SI, unit label). Longest suffixes first so `_kn_per_m_per_m` wins.
UNIT_SCALE: dict[str, tuple[float, str]] = {
    "_kn_per_m_per_m": (KN_PER_M_PER_M, "kN/m/m"),
    "_mm3_per_s": (1e-9, "mm^3/s"),
    "_g_per_cm3": (1e3, "g/cm^3"),
    "_m_per_s": (1.0, "m/s"),
    "_mm_per_s": (MM, "mm/s"),
    "_l_per_s": (L_PER_S, "L/s"),
    "_percent": (1e-2, "%"),
    "_gpa": (GPA, "GPa"),
    "_mpa": (MPA, "MPa"),
    "_kn": (KN, "kN"),
    "_mm": (MM, "mm"),
    "_m": (1.0, "m"),
    "_n": (1.0, "N"),
    "_deg_c": (1.0, "degC"),
    "_s": (1.0, "s"),
}


def split_unit_key(key: str) -> tuple[str, float, str]:
    """Split a unit-suffixed key into (name, factor to SI, unit label).

    Keys without a known suffix are dimensionless: (key, 1.0, "").
    """
    for suffix, (factor, label) in UNIT_SCALE.items():
        if key.endswith(suffix) and len(key) > len(suffix):
            return key[: -len(suffix)], factor, label
    return key, 1.0, ""


def m_to_mm(x: float | np.ndarray) -> float | np.ndarray:
    """The one m -> mm conversion at the geometry boundary."""
    return np.asarray(x) / MM if isinstance(x, np.ndarray) else x / MM


def mm_to_m(x: float | np.ndarray) -> float | np.ndarray:
    """mm -> m (reading geometry back into SI)."""
    return np.asarray(x) * MM if isinstance(x, np.ndarray) else x * MM
