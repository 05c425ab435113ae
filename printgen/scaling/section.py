"""Printed strand sections and their stiffness: axial E*A of a cable, membrane law of a net.

A section is rectangular: beads side by side x stacked layers (`design.Section`). The net's
membrane law comes from its pattern's geometry (`printgen.barrier.patterns`: for the diamond,
N = 2 E A sin^3(theta) / a_across * eps). A measured panel law of the same material is
rescaled by that geometric factor from the tested net (a diamond net, the panel tests of the
profiles) to the candidate.
"""

from __future__ import annotations

import math

from printgen.barrier.patterns import get_pattern
from printgen.barrier.patterns.diamond import diamond_factor
from printgen.inputs.materials import Material
from printgen.scaling.record import Section
from printgen.units import MM


def area_m2(section: Section) -> float:
    """Section area in m^2 (rectangle of width x total thickness)."""
    return section.area_mm2 * MM * MM


def equal_area_diameter(section: Section) -> float:
    """Diameter (m) of the circle with the section's area: the section's Pi3 length."""
    return math.sqrt(4 * area_m2(section) / math.pi)


def net_membrane_law(material: Material, section: Section, mesh_along: float,
                     mesh_across: float, pattern: str = "diamond"
                     ) -> tuple[tuple[float, ...], tuple[float, ...], str]:
    """(knees, membrane slopes N/m, source) of a net of `section` strands in `pattern`.

    Uses the material's measured panel law rescaled by geometry when it records its tested
    net; otherwise E (measured if any) times the geometric factor, linear.
    """
    net = get_pattern(pattern)
    factor = net.membrane_factor(mesh_along, mesh_across) * area_m2(section)
    law = material.panel_law
    if law is not None and law.has_geometry:
        tested = diamond_factor(law.mesh_along_load, law.mesh_across_load) * (
            law.strand_width * law.strand_thickness)
        slopes = tuple(k * law.panel_length * factor / tested for k in law.kappas)
        return law.knee_strains, slopes, "measured panel law"
    modulus, source = material.modulus()
    return (), (modulus * factor,), f"{source} modulus x {net.name} geometry"
