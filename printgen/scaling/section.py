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
from printgen.inputs.materials import Material
from printgen.scaling.panel_test import TESTED_PATTERN
from printgen.scaling.reading import (
    chosen_orientation,
    panel_axes,
    recorded_orientation,
    tested_net,
)
from printgen.scaling.record import Section
from printgen.units import MM


def area_m2(section: Section) -> float:
    """Section area in m^2 (rectangle of width x total thickness)."""
    return section.area_mm2 * MM * MM


def equal_area_diameter(section: Section) -> float:
    """Diameter (m) of the circle with the section's area: the section's Pi3 length."""
    return math.sqrt(4 * area_m2(section) / math.pi)


def net_membrane_law(material: Material, section: Section, mesh_along: float,
                     mesh_across: float, pattern: str = "diamond", orientation: str | None = None
                     ) -> tuple[tuple[float, ...], tuple[float, ...], str]:
    """(knees, membrane slopes N/m) of a net of `section` strands in `pattern` loaded along
    `mesh_along`, and its source.

    Uses the material's measured panel law when it records its tested net: read along the
    tested net's `orientation` diagonal (None: the reading the material can produce,
    `printgen.scaling.reading`), turned into the tested strands' law and that into the
    candidate's membrane law by its pattern's geometry, rescaled by strand section; otherwise
    E (measured if any) times the geometric factor, linear.
    """
    net = get_pattern(pattern)
    law = material.panel_law
    if law is not None and law.has_geometry:
        w, t, a, b = tested_net(law)
        along, across = panel_axes(a, b, orientation or chosen_orientation(material)
                                   or recorded_orientation(law))
        knees, slopes = membrane_law_between(
            law.knee_strains, tuple(k * law.panel_length for k in law.kappas),
            (TESTED_PATTERN, along, across), (pattern, mesh_along, mesh_across))
        ratio = area_m2(section) / (w * t)
        return knees, tuple(s * ratio for s in slopes), "measured panel law"
    factor = net.membrane_factor(mesh_along, mesh_across) * area_m2(section)
    modulus, source = material.modulus()
    return (), (modulus * factor,), f"{source} modulus x {net.name} geometry"


def membrane_law_between(knees: tuple[float, ...], slopes: tuple[float, ...],
                         tested: tuple[str, float, float], net: tuple[str, float, float]
                         ) -> tuple[tuple[float, ...], tuple[float, ...]]:
    """(knees, slopes N/m) of the membrane law of a net of the same strands as a tested net
    whose membrane law is (knees, slopes N/m); each net as (pattern, mesh along the load,
    mesh across it, m). The tested law gives the strand law (its pattern's `strand_law`), and
    the strand law the net's: panel knees over its strain ratio (strand strain per unit panel
    strain), slopes times its `membrane_factor`."""
    strand = get_pattern(tested[0]).strand_law(knees, slopes, tested[1], tested[2])
    to = get_pattern(net[0])
    per_strain = to.strand_law((1.0,), (1.0, 1.0), net[1], net[2]).knees[0]
    factor = to.membrane_factor(net[1], net[2])
    return (tuple(k / per_strain for k in strand.knees),
            tuple(s * factor for s in strand.slopes))
