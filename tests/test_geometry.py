"""Meshes of the printed parts: watertight, one body, bounds and volume against the analytic
values (strand lengths x section minus crossing and border overlaps; strip plus eyelets)."""

from __future__ import annotations

import dataclasses

import pytest

from printgen.errors import GeometryError, PrintabilityError
from printgen.gcode.toolpath import cable_volume_budget, net_volume_budget
from printgen.geometry.net import diamond_net
from printgen.geometry.solid import cable_solid, net_solid
from printgen.printers import load_print_style

pytest.importorskip("manifold3d")

VOLUME = 0.01  # issue 5: mesh volume within 1 % of the analytic value
CIRCLE = 5e-4  # eyelets are 128-gons: their area is 0.04 % below the circle's
FLOAT32 = 1e-4  # mm: manifold3d stores vertices in float32


@pytest.fixture(scope="module")
def net_mesh(request):
    from conftest import reference_design_1_40

    d = reference_design_1_40()
    return d.net, net_solid(d.net)


def test_net_is_one_watertight_body(net_mesh):
    _, mesh = net_mesh
    assert mesh.is_watertight and mesh.is_volume
    assert len(mesh.split(only_watertight=False)) == 1


def test_net_bounds(net_mesh):
    net, mesh = net_mesh
    sx, sy = diamond_net(net.width_mm, net.height_mm, net.mesh_x_mm, net.mesh_y_mm).size_mm
    half = net.border_width_mm / 2  # the border frame is centred on the panel edge
    lo, hi = mesh.bounds
    assert lo == pytest.approx([-half, -half, 0.0], abs=FLOAT32)
    assert hi == pytest.approx([sx + half, sy + half, net.strand.thickness_mm], abs=FLOAT32)


def test_net_volume_matches_the_analytic_budget(net_mesh):
    net, mesh = net_mesh
    budget = net_volume_budget(net, load_print_style(net.print_style))
    assert mesh.volume == pytest.approx(budget.solid_mm3, rel=VOLUME)
    # and the overlaps matter: without them the error would exceed the tolerance
    assert abs(budget.nominal_mm3 / mesh.volume - 1) > VOLUME


def test_cable_is_one_watertight_body_with_the_analytic_volume(design_1_40):
    for cable in design_1_40.cables:
        mesh = cable_solid(cable)
        assert mesh.is_watertight and len(mesh.split(only_watertight=False)) == 1
        assert mesh.volume == pytest.approx(cable_volume_budget(cable).solid_mm3,
                                            rel=CIRCLE)
        half = cable.length_mm / 2 + cable.eyelet_outer_mm / 2
        assert mesh.bounds[1] == pytest.approx(
            [half, cable.eyelet_outer_mm / 2, cable.section.thickness_mm], abs=FLOAT32)


@pytest.mark.parametrize("change, message", [
    ({"eyelet_inner_mm": 7.0}, "need 0 < inner < outer"),
    ({"length_mm": 5.0}, "leaves no strip"),
    ({"eyelet_inner_mm": 0.3, "eyelet_outer_mm": 0.8}, "not narrower than the eyelet"),
])
def test_impossible_cables_are_rejected(design_1_40, change, message):
    with pytest.raises(GeometryError, match=message):
        cable_solid(dataclasses.replace(design_1_40.cables[0], **change))


def test_impossible_net_is_rejected(design_1_40):
    with pytest.raises(GeometryError, match="half-meshes"):
        net_solid(dataclasses.replace(design_1_40.net, width_mm=15.0))


def test_part_larger_than_the_bed_is_rejected(design_1_40):
    from printgen.export import place_mesh
    from printgen.printers import load_printer

    mesh = cable_solid(dataclasses.replace(design_1_40.cables[0], length_mm=600.0))
    with pytest.raises(PrintabilityError, match="does not fit .* in any orientation"):
        place_mesh(mesh, load_printer("generic-350"), "cable top")
