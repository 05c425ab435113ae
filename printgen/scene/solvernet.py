"""A scene as a solver net (`solver.Net`): its strands and border cables, the sensor wires
that pull, and the hold of unloaded nodes when the scene has one.

Sensor wire: a wire from its anchor node over the row's nodes to the potentiometer (a fixed
node appended after the net's nodes), at constant tension. A frictionless wire at constant
tension pulls every node it bends over exactly as its segments would, each pulling with that
tension on its own; so the wire is built as one tension-only element per segment, each with
a constant-force spring law: the spring is at strain `WIRE_STRAIN` at rest and its slope there
is `WIRE_RATE` x the tension, so the tension stays the sensor's force (within 1e-6 per unit
strain) whatever the segment's length, as long as no segment shortens below its knee (checked:
`wire_slack`). The solver's tangent gets each segment's geometric stiffness T / l; a sliding
cable would add a dense rank-one block over all the wire's nodes (three times the
factorization's work on the simple barrier's model) for a stiffness of 1e-6 x the tension.

Hold ("strands that carry no load stay where they are", `BarrierScene.hold` N/m): each free net
node is tied to two fixed points `HOLD_ARM` x the shortest strand upstream and downstream of
it by tension-only ties at strain 1, tension T = hold x arm / 2: together they pull nothing at
rest and resist a move by `hold` N/m in the wall's plane (2 x hold out of it; hold once the
node has moved more than arm / 2 downstream and the downstream tie is slack). Short ties keep
their constant share of the strain energy small (the solver's line search compares energies);
ties of 5 % to 200 % of the net's size did not converge on the simple barrier's model.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from printgen import solver
from printgen.scene.scenes import BarrierScene

WIRE_STRAIN = 3.0  # the spring's strain at rest (its rest length is a quarter of the segment's)
WIRE_KNEE = 0.5  # below this strain the law is steep: a segment shorter than 3/8 of its length
WIRE_RATE = 1e-6  # slope at rest / tension: a constant-force spring
HOLD_ARM = 1.0  # tie length / shortest strand


@dataclass(frozen=True)
class Extras:
    """What `build` appended after the scene's own items: node, strand and cable counts of
    the scene (the net's items come first), the elements of the pulling sensor wires' segments
    and the hold ties (node, anchor) pairs (the last elements)."""

    n_nodes: int
    n_elements: int
    n_cables: int
    ties: np.ndarray  # (t, 2) int: net node, fixed anchor
    wire_elements: np.ndarray = field(default_factory=lambda: np.zeros(0, int))


def wire_law(force: float) -> solver.Law:
    """Constant-force spring of tension `force` N at strain WIRE_STRAIN (see the module)."""
    flat = WIRE_RATE * force
    steep = (force - flat * (WIRE_STRAIN - WIRE_KNEE)) / WIRE_KNEE
    return solver.piecewise((WIRE_KNEE,), (steep, flat))


def path_length(x: np.ndarray, nodes: np.ndarray, exit_point: np.ndarray) -> float:
    """Length (m) of a wire through positions x[nodes] and on to `exit_point`."""
    p = np.vstack([x[nodes], exit_point[None, :]])
    return float(np.linalg.norm(np.diff(p, axis=0), axis=1).sum())


def build(s: BarrierScene, *, slack: float = 0.0) -> tuple[solver.Net, Extras]:
    """The solver net of scene `s` with relative initial `slack` of strands and cables."""
    nodes, fixed = [s.nodes], [s.fixed]
    elements, law_index = [s.elements], [s.element_law]
    printed = s.nodes if s.rest_nodes is None else s.rest_nodes  # strands' unstressed shape
    lengths = np.linalg.norm(printed[s.elements[:, 1]] - printed[s.elements[:, 0]], axis=1)
    rest = [lengths * (1.0 + slack)]
    laws = list(s.laws)
    cables = [solver.SlidingCable(c, law, None if s.rest_nodes is None else
                                  _polyline(printed[c]) * (1.0 + slack))
              for c, law in s.cables.values()]
    n, first = len(s.nodes), len(s.elements)
    for w in s.wires.values():
        if w.force <= 0:
            continue
        nodes.append(w.exit[None, :])
        fixed.append(np.array([True]))
        seg = np.column_stack([w.nodes, np.append(w.nodes[1:], n)])
        span = np.linalg.norm(np.diff(np.vstack([s.nodes[w.nodes], w.exit]), axis=0), axis=1)
        law = wire_law(w.force)
        if law not in laws:
            laws.append(law)
        elements.append(seg)
        law_index.append(np.full(len(seg), laws.index(law)))
        rest.append(span / (1.0 + WIRE_STRAIN))
        n += 1
    wire_elements = np.arange(first, first + sum(len(e) for e in elements[1:]))
    ties = np.zeros((0, 2), int)
    if s.hold > 0:
        free = np.flatnonzero(~s.fixed)
        arm = HOLD_ARM * float(lengths.min())
        tension = s.hold * arm / 2
        anchors = np.vstack([s.nodes[free] - [0, arm, 0], s.nodes[free] + [0, arm, 0]])
        idx = n + np.arange(2 * len(free))
        ties = np.column_stack([np.tile(free, 2), idx])
        nodes.append(anchors)
        fixed.append(np.ones(len(anchors), bool))
        elements.append(ties)
        law_index.append(np.full(len(ties), len(laws)))
        rest.append(np.full(len(ties), arm / 2))
        laws.append(solver.linear(tension))  # EA = T: strain 1 at rest
    net = solver.Net(np.vstack(nodes), np.concatenate(fixed), np.vstack(elements), laws,
                     element_law=np.concatenate(law_index), rest_length=np.concatenate(rest),
                     slack=slack, cables=cables)
    return net, Extras(len(s.nodes), len(s.elements), len(s.cables), ties, wire_elements)


def _polyline(p: np.ndarray) -> float:
    return float(np.linalg.norm(np.diff(p, axis=0), axis=1).sum())


def wire_slack(strains: np.ndarray, ex: Extras) -> int:
    """How many sensor-wire segments are below the spring's knee (0: every segment pulls with
    the sensor's force, as a wire sliding over the nodes would)."""
    return int(np.sum(strains[ex.wire_elements] <= WIRE_KNEE))


def hold_share(x: np.ndarray, tensions: np.ndarray, ex: Extras, applied: float) -> float:
    """Force the hold ties exert on the net (sum of |resultant| over nodes, N) / `applied` N."""
    if not len(ex.ties) or applied <= 0:
        return 0.0
    t = tensions[len(tensions) - len(ex.ties):]  # the ties come last
    d = x[ex.ties[:, 1]] - x[ex.ties[:, 0]]
    f = (t / np.linalg.norm(d, axis=1))[:, None] * d
    per_node = np.zeros((ex.n_nodes, 3))
    np.add.at(per_node, ex.ties[:, 0], f)
    return float(np.linalg.norm(per_node, axis=1).sum() / applied)
