"""The mid-height sensor wire: a wire at exactly half the net's height, read between the two
node rows that bracket it (linear interpolation in z), never the top or bottom row, and
converging as the mesh is refined; the deflection at mid-height alike."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from conftest import planned
from proto_files import REALISTIC, write_variant

from printgen.barrier.loads import Site, get_load
from printgen.inputs.prototype import load_prototype
from printgen.scene import build_scene
from printgen.scene.readings import flume_units
from printgen.scene.scenes import SENSOR_FORCE_N, sensor_wires
from printgen.verification.compare import sensor_elongation, wire_elongation
from printgen.verification.preprint import sweep

EXACT = 1e-12  # closed-form geometry: round-off only


def _heights(s) -> list[float]:
    return [float(np.median(s.nodes[w.nodes, 2])) for w in sensor_wires(s.wires, "mid")]


def _check_bracket(s) -> None:
    """The mid-height wires lie on rows strictly inside the net, bracketing h/2, weighted by
    linear interpolation in z; the assumptions table says so."""
    mids = sensor_wires(s.wires, "mid")
    z = _heights(s)
    assert 0 < min(z) <= s.height / 2 <= max(z) < s.height
    assert sum(w.weight for w in mids) == pytest.approx(1.0, abs=EXACT)
    assert float(np.dot([w.weight for w in mids], z)) == pytest.approx(s.height / 2, rel=EXACT)
    for w in mids:  # from the left edge to the right edge
        assert s.nodes[w.nodes[0], 0] == pytest.approx(0.0, abs=EXACT * s.width)
        assert s.nodes[w.nodes[-1], 0] == pytest.approx(s.width, rel=EXACT)
    row = dict((a[0], a[1]) for a in s.assumptions)["mid-height sensor"]
    assert f"h/2 = {s.height / 2 * 1e3:.4g} mm" in row


def test_realistic_mid_wire_between_the_rows_that_bracket_mid_height():
    """The 1:40 example's prototype and model: mid-height falls between two rows; the model's
    two wires pull the sensor's 1 N between them, in the reading's proportions."""
    p = load_prototype(REALISTIC)
    ps = build_scene(p)
    _check_bracket(ps)
    assert len(sensor_wires(ps.wires, "mid")) == 2
    assert all(w.force == 0 for w in ps.wires.values())  # the prototype's wires only read
    _, d = planned(REALISTIC)
    ms = build_scene(d)
    _check_bracket(ms)
    mids = sensor_wires(ms.wires, "mid")
    assert sum(w.force for w in mids) == pytest.approx(SENSOR_FORCE_N, rel=EXACT)
    assert [w.force for w in mids] == pytest.approx([w.weight * SENSOR_FORCE_N for w in mids])
    u = flume_units(ms)  # the mm reading's divisor: the weighted rest lengths of the rows
    assert u.row_mm["mid"] == pytest.approx(ms.width * 1e3, rel=0.01)


def test_coarse_mesh_mid_wire_is_never_the_top_row(tmp_path):
    """A coarse legal mesh (diamonds 2.4 x 1.6 m on 13.2 x 4 m: an odd number of half-meshes
    across, so no inner row reaches both edges) had its "mid-height" wire on the top row; now
    it is read between the rows at 1.6 and 2.4 m, each carried to the edges."""
    f = write_variant(tmp_path, {("net", "mesh_x_m"): 2.4, ("net", "mesh_y_m"): 1.6})
    s = build_scene(load_prototype(f))
    _check_bracket(s)
    edges = set(s.rows["top"].tolist()) | set(s.rows["bottom"].tolist())
    for w in sensor_wires(s.wires, "mid"):
        assert not edges & set(w.nodes.tolist())
    assert _heights(s) == pytest.approx([1.6, 2.4])
    centres = [c for c, _ in s.mid_centres]  # the deflection at mid-height: between them
    assert s.nodes[centres, 2] == pytest.approx([1.6, 2.4])
    assert [wt for _, wt in s.mid_centres] == pytest.approx([0.5, 0.5])


def test_one_wire_reads_as_before():
    """A sensor of one wire reads what that wire reads (the interpolation adds nothing)."""
    _, d = planned(REALISTIC)
    s = build_scene(d)
    rng = np.random.default_rng(0)
    x = s.nodes + rng.normal(scale=1e-3 * s.width, size=s.nodes.shape)
    w = s.wires["top"]
    assert sensor_elongation(s.nodes, x, [w]) == pytest.approx(wire_elongation(s.nodes, x, w),
                                                               rel=EXACT)


def _mid_readings(k: int) -> tuple[float, float]:
    """Mid-height elongation and deflection / width of the realistic prototype at h/h_B = 1
    on its mesh / k."""
    p = load_prototype(REALISTIC)
    q = dataclasses.replace(p, net=dataclasses.replace(p.net, mesh_x=p.net.mesh_x / k,
                                                       mesh_y=p.net.mesh_y / k))
    s = build_scene(q)
    r = sweep(s, np.array([0.0, 0.25, 0.5, 0.75, 1.0]), load=get_load(None),
              site=Site(q.velocity, q.net.strand_diameter, q.depth, None))
    assert not r.failed
    v = r.deformation.values
    return float(v["strain_mid"][-1]), float(v["deflection"][-1])


@pytest.mark.slow
def test_mid_height_reading_converges_under_refinement():
    """x1, x2, x3 refinement of the realistic prototype's net (the same panel law per unit
    width): the change of the mid-height reading and of the deflection at mid-height shrinks
    (the nearest row jumped +6 % at x2 and back at x3), and x2 to x3 moves them by under 1 %."""
    readings = [_mid_readings(k) for k in (1, 2, 3)]
    for e in zip(*readings, strict=True):
        d1, d2 = e[1] - e[0], e[2] - e[1]
        assert abs(d2) < abs(d1), e
        assert abs(d2) / e[2] < 0.01, e  # the x3 net's discretisation error, at most
