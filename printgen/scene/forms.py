"""Model-form options of the printed model's scene, each argued from the material or
the test, never fitted to the flume curve (Lambert et al. 2023, doi:10.1061/JHEND8.HYENG-13070):

- net law (`NET_LAWS`): "formula" (the nominal) turns the profile's panel law into a strand
  law by the analytic diamond mapping (every strand of an infinite, blocked panel stretched
  alike); "derived" uses the strand law whose simulated panel test, as the source ran it,
  reproduces the panel law (`printgen.scene.panel.derive_law`): free between the clamps,
  or blocked where a free pin-jointed panel is a mechanism over the law's range (the printed
  net's rigid junctions, which the solver does not model, stop its meshes closing at no force;
  blocking is their stiff limit);
- bed (`BEDS`): "free" (the nominal) lets the bottom cable move between its corner anchors;
  "held" keeps the net's bottom row where it is: it rests on the flume bed at the foot of the
  folded film, which must lie on the bed to hold the water back and is pressed onto it by the
  full head; contact and friction hold the bottom edge (with the net squeezed into the free
  section, its slack bottom cable can only lie on the bed);
- sensor routing (`ROUTINGS`): beyond the barrier's right edge node the wire runs "in-line"
  to its potentiometer (the nominal, docs/physics.md: The flume test as it is run) or turns
  "downstream" to a potentiometer standing behind the barrier, out of the water (the paper
  does not say where they stood). Where the rows' end nodes are held (walls mounting) the
  exit segment is fixed at both ends: the routing changes neither the net nor the reading, and
  no variant is run.
"""

from __future__ import annotations

import dataclasses
from functools import lru_cache

import numpy as np

from printgen.barrier.patterns import get_pattern
from printgen.inputs.materials import load_material
from printgen.scaling.reading import panel_reading
from printgen.scaling.record import Design
from printgen.scaling.section import area_m2
from printgen.scene.panel import PanelTest, derive_law, law_strains, simulate
from printgen.scene.scenes import (
    TESTED_PATTERN,
    BarrierScene,
    model_net_law,
    panel_axes,
    recorded_orientation,
)
from printgen.solver import Law
from printgen.units import MM

NET_LAWS = ("formula", "derived")
BEDS = ("free", "held")
ROUTINGS = ("in-line", "downstream")
DERIVE_POINTS = 5  # strains the derivation fits (checked between them too): TPE long, free,
# within 3.6 % of its panel law (12 points: 6.7 %, the same CPU time)
SLACK_SLOPE = 1e-4  # slope of a slack segment / the law's first slope (keeps it solvable)
MECHANISM = 0.5  # a free panel whose solver hold carries over half the clamp force is a mechanism


@lru_cache(maxsize=16)
def _derived(knees: tuple[float, ...], slopes: tuple[float, ...], along: float, across: float,
             length: float, width: float) -> tuple[Law, str, float]:
    """(strand law, test mode, derivation error) of a panel law n(eps) = piecewise(knees,
    slopes N/m) tested on a `length` x `width` panel loaded along the `along` diagonal."""
    free = PanelTest(along, across, length, width, "free", TESTED_PATTERN)
    formula = get_pattern(TESTED_PATTERN).strand_law(knees, slopes, along, across)
    probe = simulate(formula, free, law_strains(knees)[:2])
    t = free if probe.hold_share <= MECHANISM else dataclasses.replace(free, mode="blocked")
    d = derive_law(knees, slopes, t, law_strains(knees, DERIVE_POINTS))
    return d.law, t.mode, d.error


def derived_net_law(mat, n, orientation: str | None) -> tuple[Law, str]:
    """The design's strand law derived from the virtual panel test of `mat`'s panel law, read
    along `orientation` (None: the reading it can produce, `printgen.scaling.reading`),
    rescaled from the tested strand section to the design's; and how it was found.
    GeometryError-free: a material without a panel law of recorded geometry keeps the formula
    (`model_net_law`)."""
    law = mat.panel_law
    if law is None or not law.has_geometry:
        return model_net_law(mat, n, orientation)
    if orientation is None:  # the reading the material can produce
        reading = panel_reading(mat)
        orientation = reading.orientation if reading is not None else recorded_orientation(law)
    along, across = panel_axes(law.mesh_along_load, law.mesh_across_load, orientation)
    width = law.panel_width or law.panel_length
    strand, mode, err = _derived(tuple(law.knee_strains),
                                 tuple(k * law.panel_length for k in law.kappas),
                                 along, across, law.panel_length, width)
    ratio = area_m2(n.strand) / (law.strand_width * law.strand_thickness)
    how = (f"strand law derived from the virtual panel test ({law.panel_length / MM:g} mm "
           f"panel, {width / MM:g} mm clamps, {mode}, along the {along / MM:g} mm "
           f"({orientation}) diagonal; reproduces the panel law within {err:.1%})")
    return strand.scaled(ratio), how


def with_derived_law(s: BarrierScene, d: Design, orientation: str | None) -> BarrierScene:
    """Scene `s` of design `d` with its net's strand law from the virtual panel test
    (`derived_net_law`), its "net strands" assumption saying so."""
    laws = list(s.laws)
    laws[0], how = derived_net_law(load_material(d.net.material), d.net, orientation)
    rows = tuple((w, f"{d.net.material}: {how}" if w == "net strands" else val, src)
                 for w, val, src in s.assumptions)
    return dataclasses.replace(s, laws=laws, assumptions=rows)


def held_on_bed(s: BarrierScene) -> BarrierScene:
    """Scene `s` with its bottom row's nodes held in place by the bed (see the module)."""
    fixed = s.fixed.copy()
    fixed[s.rows["bottom"]] = True
    note = ("bed", ("the net's bottom row rests on the flume bed, held there by contact and "
                    "friction under the film's foot (the bottom cable cannot move)"),
            ("printgen (the film seals on the bed; Lambert et al. 2023: folded film "
             "larger than the barrier)"))
    return dataclasses.replace(s, fixed=fixed, assumptions=(*s.assumptions, note))


def routed(s: BarrierScene, routing: str) -> BarrierScene:
    """Scene `s` with its sensor wires leaving the right edge node by `routing` (ROUTINGS)."""
    if routing == ROUTINGS[0]:
        return s
    reach = {k: float(np.linalg.norm(w.exit - s.nodes[w.nodes[-1]])) for k, w in s.wires.items()}
    wires = {k: dataclasses.replace(w, exit=s.nodes[w.nodes[-1]] + np.array([0, reach[k], 0]))
             for k, w in s.wires.items()}
    note = ("sensor routing", ("beyond the right edge node each wire turns downstream to a "
                               "potentiometer behind the barrier"),
            "printgen (the paper does not state where the potentiometers stood)")
    return dataclasses.replace(s, wires=wires, assumptions=(*s.assumptions, note))


def slackened(law: Law, slack: float) -> Law:
    """The law with a nearly flat first segment of `slack` strain (SLACK_SLOPE of its slope)."""
    if slack <= 0:
        return law
    return Law((slack, *(k + slack for k in law.knees)),
               (SLACK_SLOPE * law.slopes[0], *law.slopes))


def slack_laws(s: BarrierScene, net: float, cable: float) -> BarrierScene:
    """Scene `s` with every strand law `slackened` by `net` and every cable law by `cable`
    (relative slack as a law's first, nearly flat segment)."""
    laws = [slackened(law, net) for law in s.laws]
    cables = {k: (nodes, slackened(law, cable)) for k, (nodes, law) in s.cables.items()}
    return dataclasses.replace(s, laws=laws, cables=cables)
