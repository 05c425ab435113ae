"""Printed strand sections and their stiffness: axial E*A of a cable, membrane law of a net.

A section is rectangular: beads side by side x stacked layers (`design.Section`). The net's
membrane law comes from its diamond geometry: under a stretch eps along the load (transverse
strain blocked, as in the panel test) a strand at angle theta to the cross direction strains
eps sin^2(theta); with 2 / a_across strands per unit width, the force per unit width is
N = 2 E A sin^3(theta) / a_across * eps. A measured panel law of the same material is rescaled
by that geometric factor from the tested net to the candidate.
"""

from __future__ import annotations

import math

from printgen.design.record import Section
from printgen.inputs.materials import Material

MM = 1e-3


def area_m2(section: Section) -> float:
    """Section area in m^2 (rectangle of width x total thickness)."""
    return section.area_mm2 * MM * MM


def equal_area_diameter(section: Section) -> float:
    """Diameter (m) of the circle with the section's area: the section's Pi3 length."""
    return math.sqrt(4 * area_m2(section) / math.pi)


def diamond_sin(mesh_along: float, mesh_across: float) -> float:
    """sin(theta) of a diamond strand, theta its angle to the cross direction."""
    return (mesh_along / 2) / math.hypot(mesh_along / 2, mesh_across / 2)


def diamond_factor(mesh_along: float, mesh_across: float) -> float:
    """2 sin^3(theta) / a_across (1/m) of a diamond net loaded along `mesh_along`."""
    sin = diamond_sin(mesh_along, mesh_across)
    return 2 * sin**3 / mesh_across


def square_factor(mesh_across: float) -> float:
    """1 / a_across (1/m): a square net's strands along the load, one per mesh."""
    return 1.0 / mesh_across


def net_membrane_law(material: Material, section: Section, mesh_along: float,
                     mesh_across: float) -> tuple[tuple[float, ...], tuple[float, ...], str]:
    """(knees, membrane slopes N/m, source) of a diamond net of `section` strands.

    Uses the material's measured panel law rescaled by geometry when it records its tested
    net; otherwise E (measured if any) times the geometric factor, linear.
    """
    factor = diamond_factor(mesh_along, mesh_across) * area_m2(section)
    law = material.panel_law
    if law is not None and law.has_geometry:
        tested = diamond_factor(law.mesh_along_load, law.mesh_across_load) * (
            law.strand_width * law.strand_thickness)
        slopes = tuple(k * law.panel_length * factor / tested for k in law.kappas)
        return law.knee_strains, slopes, "measured panel law"
    modulus, source = material.modulus()
    return (), (modulus * factor,), f"{source} modulus x diamond geometry"
