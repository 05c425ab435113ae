"""Scenes of the pre-print check: sensor wires (a constant 1 N along the wire, reading = change
of wire length) and the two lateral mountings in the flume."""

from __future__ import annotations

import math

import numpy as np
import pytest
from conftest import planned
from proto_files import REALISTIC

from printgen import solver
from printgen.errors import InputError
from printgen.inputs.prototype import load_prototype
from printgen.scene import SceneOptions, build_scene
from printgen.scene.scenes import SENSOR_FORCE_N, BarrierScene, Wire
from printgen.scene.solvernet import WIRE_RATE, WIRE_STRAIN, build, wire_law
from printgen.solver.assemble import internal, make_bars, make_cable
from printgen.verification.compare import wire_elongation
from printgen.verification.preprint import sweep

EXACT = 1e-12  # closed-form geometry: round-off only
SOLVED = 1e-6  # relative: solver tolerance (1e-7 of the load) plus the spring's 1e-6 slope
AT_REST = 1e-12  # m per m of width: "does not move" (round-off of a converged solve)
MOVES = 1e-4  # m per m of width: clearly moved (the edges deflect ~1e-2 of the width)
# N: the wire springs' slope (1e-6 x the tension per unit strain) over strain changes < 10
WIRE_SPRING = 10 * WIRE_RATE * SENSOR_FORCE_N


@pytest.fixture(scope="module")
def design():
    return planned(REALISTIC)


def _cable_forces(x: np.ndarray, nodes: np.ndarray, law, rest: float) -> np.ndarray:
    """Forces (n, 3) N the cable exerts on the nodes at positions x (solver's assembly)."""
    bars = make_bars(x, np.zeros((0, 2), int), np.zeros(0), np.zeros(0, int), [law])
    g, _ = internal(bars, [make_cable(x, nodes, rest, law)], np.zeros_like(x), len(x),
                    with_tangent=False)
    return -g  # internal returns the resisting forces


def test_taut_wire_on_a_flat_net_pushes_nothing_out_of_plane(design):
    """The model at rest: every wire pulls along itself only; the anchor node is pulled by the
    sensor force towards the potentiometer, the nodes it runs over feel nothing."""
    _, d = design
    s = build_scene(d)
    net, ex = build(s)
    n = len(s.nodes)
    assert len(net.cables) == len(s.cables)  # the wires are segments, not sliding cables
    laws = [net.laws[k] for k in net.law_index]
    start = 0
    for name, w in s.wires.items():
        seg = ex.wire_elements[start:start + len(w.nodes)]  # anchor .. last node, to the exit
        start += len(w.nodes)
        el = net.elements[seg]
        assert np.array_equal(el[:, 0], w.nodes) and el[-1, 1] >= n, name  # exit outside
        bars = make_bars(net.nodes, el, net.rest_lengths()[seg], np.zeros(len(seg), int),
                         [laws[seg[0]]])
        g, _ = internal(bars, [], np.zeros_like(net.nodes), len(net.nodes), with_tangent=False)
        f = -g  # internal returns the resisting forces
        assert np.abs(f[:, 1]).max() <= EXACT * SENSOR_FORCE_N, name  # no out-of-plane force
        np.testing.assert_allclose(f[w.nodes[0]], [w.force, 0, 0], atol=SOLVED)
        assert np.abs(f[w.nodes[1:]]).max() <= SOLVED * SENSOR_FORCE_N, name
    assert start == len(ex.wire_elements)


def test_wire_segments_pull_like_a_sliding_wire():
    """A wire over two free nodes, each tied by a strand to a point below and pushed out of
    plane and up: the equilibrium of the wire's segments (the net's build) is an equilibrium of
    one frictionless sliding cable of the same constant tension (the same nodal forces)."""
    row = np.array([[0.0, 0, 0], [1.0, 0, 0], [2.0, 0, 0], [3.0, 0, 0]])
    x = np.vstack([row, row[1:3] - [0, 0, 1.0]])  # the strands' anchors below nodes 1 and 2
    fixed = np.array([True, False, False, True, True, True])
    strands = np.array([[4, 1], [5, 2]])
    exit_point = np.array([3.3, 0, 0])
    s = BarrierScene("wire", 1.0, 3.0, 1.0, x, fixed, strands, np.zeros(2, int),
                     [solver.linear(10.0)], {}, {}, 0, 0, 1.0,
                     {"w": Wire(np.arange(4), exit_point, SENSOR_FORCE_N)})
    net, ex = build(s)
    push = np.array([[0, 0.3, 0.5], [0, 0.4, 0.6]])
    r = solver.solve(net, [solver.PointLoads(np.array([1, 2]), push)], strict=True)
    assert np.abs(r.positions[1:3] - x[1:3]).max() > MOVES  # the wire bends
    assert np.abs(r.tensions[ex.wire_elements] - SENSOR_FORCE_N).max() <= WIRE_SPRING
    x0 = net.nodes
    length = float(np.linalg.norm(np.diff(x0[[0, 1, 2, 3, 6]], axis=0), axis=1).sum())
    cable = make_cable(x0, np.array([0, 1, 2, 3, 6]), length / (1 + WIRE_STRAIN),
                       wire_law(SENSOR_FORCE_N))
    bars = make_bars(x0, strands, np.ones(2), np.zeros(2, int), [solver.linear(10.0)])
    g, _ = internal(bars, [cable], r.displacements, len(x0), with_tangent=False)
    np.testing.assert_allclose(g[1:3], push, atol=WIRE_SPRING)


def test_wire_keeps_its_force_and_bends_as_a_string():
    """A wire over one free node pushed out of plane by P: 2 T sin(theta) = P with T = 1 N,
    so the node moves (L/2) tan(asin(P / 2T)); the tension stays 1 N."""
    span, push = 1.0, 0.5
    x = np.array([[0, 0, 0], [span / 2, 0, 0], [span, 0, 0], [1.2 * span, 0, 0.0]])
    net = solver.Net(x, np.array([True, False, True, True]), np.zeros((0, 2), int),
                     [solver.linear(1.0)], cables=[solver.SlidingCable(
                         np.arange(4), wire_law(SENSOR_FORCE_N),
                         rest_length=1.2 * span / (1 + WIRE_STRAIN))])
    r = solver.solve(net, [solver.PointLoads(np.array([1]), np.array([[0, push, 0]]))],
                     strict=True)
    theta = math.asin(push / (2 * SENSOR_FORCE_N))
    assert r.positions[1, 1] == pytest.approx(span / 2 * math.tan(theta), rel=SOLVED)
    assert r.cable_tensions[0] == pytest.approx(SENSOR_FORCE_N, rel=SOLVED)


def test_reading_is_the_change_of_wire_length():
    """Row of span L over three nodes, potentiometer 0.1 L beyond: the middle node pushed out
    of plane by delta lengthens the wire by 2 sqrt((L/2)^2 + delta^2) - L; the anchor pulled
    towards the potentiometer by e shortens it by e."""
    span, delta, e = 2.0, 0.3, 0.05
    x0 = np.array([[0.0, 0, 0], [span / 2, 0, 0], [span, 0, 0]])
    wire = Wire(np.arange(3), np.array([1.1 * span, 0, 0]), SENSOR_FORCE_N)
    x = x0.copy()
    x[1, 1] = delta
    expected = (2 * math.hypot(span / 2, delta) - span) / span
    assert wire_elongation(x0, x, wire) == pytest.approx(expected, rel=EXACT)
    x[0, 0] = e
    moved = (math.hypot(span / 2 - e, delta) + math.hypot(span / 2, delta) - span) / span
    assert wire_elongation(x0, x, wire) == pytest.approx(moved, rel=EXACT)
    assert wire_elongation(x0, x0, wire) == 0.0


def _lateral(s) -> np.ndarray:
    x = s.nodes[:, 0]
    return np.flatnonzero((x < 1e-9 * s.width) | (x > s.width * (1 - 1e-9)))


LEVELS = np.array([0.0, 0.5, 1.0])  # enough to load the edges


@pytest.mark.slow
@pytest.mark.parametrize("mounting", ["walls", "eyelets"])
def test_mountings_hold_or_free_the_lateral_edges(design, mounting):
    """walls: the side sheets hold the lateral edge nodes (they do not move); eyelets: only the
    corners are anchored and the lateral edges deflect with the net."""
    p, d = design
    options = SceneOptions(mounting=mounting)
    for s in (build_scene(p, options), build_scene(d, options)):
        run = sweep(s, LEVELS)
        assert not run.failed
        edge = _lateral(s)
        moved = np.abs(run.shapes[1.0][edge] - s.nodes[edge]).max() / s.width
        if mounting == "walls":
            assert s.fixed[edge].all() and moved <= AT_REST
        else:
            assert s.fixed[edge].sum() == 4 and moved > MOVES
        assert abs(run.deformation.values["deflection"][0]) < 0.01  # issue 10: < 1 % at rest


def test_lateral_option_is_read_and_checked(tmp_path):
    text = REALISTIC.read_text()
    assert load_prototype(REALISTIC).flume.lateral == "walls"
    eyelets = tmp_path / "eyelets.toml"
    eyelets.write_text(text.replace('lateral = "walls"', 'lateral = "eyelets"'))
    assert load_prototype(eyelets).flume.lateral == "eyelets"
    bad = tmp_path / "bad.toml"
    bad.write_text(text.replace('lateral = "walls"', 'lateral = "glued"'))
    with pytest.raises(InputError, match="lateral = 'glued' is not one of: walls, eyelets"):
        load_prototype(bad)
    no_border = tmp_path / "no_border.toml"
    start, end = text.index("[border]"), text.index("[flow]")
    no_border.write_text(text[:start] + text[end:].replace('lateral = "walls"',
                                                         'lateral = "eyelets"'))
    with pytest.raises(InputError, match=r"no \[border\] cables; set lateral = \"walls\""):
        load_prototype(no_border)
