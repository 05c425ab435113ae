"""Model-form options of the printed model's scene, each argued from the material or
the test, never fitted to the flume curve (Lambert et al. 2023, doi:10.1061/JHEND8.HYENG-13070):

- net law (`NET_LAWS`): "formula" (the nominal) turns the profile's panel law into a strand
  law by the analytic diamond mapping (every strand of an infinite, blocked panel stretched
  alike); "derived" uses the strand law whose simulated panel test, as the source ran it,
  reproduces the panel law (`printgen.verification.panel.derive_law`): free between the clamps,
  or blocked where a free pin-jointed panel is a mechanism over the law's range (the printed
  net's rigid junctions, which the solver does not model, stop its meshes closing at no force;
  blocking is their stiff limit);
- bed (`BEDS`): "free" (the nominal) lets the bottom cable move between its corner anchors;
  "held" keeps the net's bottom row where it is: it rests on the flume bed at the foot of the
  folded film, which must lie on the bed to hold the water back and is pressed onto it by the
  full head; contact and friction hold the bottom edge (with the net squeezed into the free
  section, its slack bottom cable can only lie on the bed);
- sensor routing (`ROUTINGS`): beyond the barrier's right edge node the wire runs "in-line"
  to its potentiometer (the nominal, README: The flume test as it is run) or turns
  "downstream" to a potentiometer standing behind the barrier, out of the water (the paper
  does not say where they stood). Where the rows' end nodes are held (walls mounting) the
  exit segment is fixed at both ends: the routing changes neither the net nor the reading, and
  no variant is run.
"""

from __future__ import annotations

import dataclasses
from functools import lru_cache
from typing import TYPE_CHECKING

import numpy as np

from printgen.design.record import Design
from printgen.inputs.materials import load_material
from printgen.units import MM
from printgen.verification.scenes import BarrierScene, Law, panel_axes, recorded_orientation

if TYPE_CHECKING:
    from printgen.verification.bands import Variant

NET_LAWS = ("formula", "derived")
BEDS = ("free", "held")
ROUTINGS = ("in-line", "downstream")
DERIVE_POINTS = 5  # strains the derivation fits (checked between them too): TPE long, free,
# within 3.6 % of its panel law (12 points: 6.7 %, the same CPU time)
MECHANISM = 0.5  # a free panel whose solver hold carries over half the clamp force is a mechanism


@lru_cache(maxsize=16)
def _derived(knees: tuple[float, ...], slopes: tuple[float, ...], along: float, across: float,
             length: float, width: float) -> tuple[Law, str, float]:
    """(strand law, test mode, derivation error) of a panel law n(eps) = piecewise(knees,
    slopes N/m) tested on a `length` x `width` panel loaded along the `along` diagonal."""
    from printgen.verification.panel import PanelTest, derive_law, law_strains, simulate
    from printgen.verification.scenes import strand_law_from_membrane

    free = PanelTest(along, across, length, width, "free")
    probe = simulate(strand_law_from_membrane(knees, slopes, along, across), free,
                     law_strains(knees)[:2])
    t = free if probe.hold_share <= MECHANISM else dataclasses.replace(free, mode="blocked")
    d = derive_law(knees, slopes, t, law_strains(knees, DERIVE_POINTS))
    return d.law, t.mode, d.error


def derived_net_law(mat, n, orientation: str | None) -> tuple[Law, str]:
    """The design's strand law derived from the virtual panel test of `mat`'s panel law, read
    along `orientation` (None: the diagonal its profile records), rescaled from the tested
    strand section to the design's; and how it was found. GeometryError-free: a material
    without a panel law of recorded geometry keeps the formula (`model_net_law`)."""
    from printgen.design.section import area_m2
    from printgen.verification.scenes import model_net_law

    law = mat.panel_law
    if law is None or not law.has_geometry:
        return model_net_law(mat, n, orientation)
    if orientation is None:
        orientation = recorded_orientation(law)
    along, across = panel_axes(law.mesh_along_load, law.mesh_across_load, orientation)
    width = law.panel_width or law.panel_length
    strand, mode, err = _derived(tuple(law.knee_strains),
                                 tuple(k * law.panel_length for k in law.kappas),
                                 along, across, law.panel_length, width)
    ratio = area_m2(n.strand) / (law.strand_width * law.strand_thickness)
    how = (f"strand law derived from the virtual panel test ({law.panel_length / MM:g} mm "
           f"panel, {width / MM:g} mm clamps, {mode}, along the {along / MM:g} mm "
           f"({orientation}) diagonal; reproduces the panel law within {err:.1%})")
    return (strand[0], tuple(s * ratio for s in strand[1])), how


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


def _routing_variants(d: Design, mounting: str | None, notes: list[str]) -> list[Variant]:
    from printgen.verification.bands import Variant, variant_scene

    s = variant_scene(d, Variant(mounting=mounting))
    if all(s.fixed[w.nodes[-1]] for w in s.wires.values()):
        notes.append(f"sensor routing: the rows' end nodes are held ({s.mounting} mounting), "
                     "so the wire beyond them changes neither the net nor the reading; no "
                     "routing variant")
        return []
    return [Variant("sensor wires turn downstream at the edge", routing="downstream",
                    source="potentiometers' position not stated (nominal: in line)")]


def model_form_variants(d: Design, free_section: float | None, notes: list[str],
                        mounting: str | None = None) -> list[Variant]:
    """The water's force normal to the deformed net, the virtual panel test's strand
    law and the bottom row held on the bed (printgen.verification.forms), and the net mounted
    in a free section narrower than its printed width (printgen.verification.mount), alone and
    with its slack bottom cable on the bed; the sensor routing where it matters."""
    from printgen.verification.bands import SAME, Variant

    out = [Variant("pressure normal to the deformed net", pressure="normal",
                   source="the folded film presses normal to the net (nominal: along the "
                          "flow, reference section 3)")]
    out += _routing_variants(d, mounting, notes) if d.cables else []
    law = load_material(d.net.material).panel_law
    if law is not None and law.has_geometry:
        out.append(Variant("strand law from the virtual panel test", net_law="derived",
                           source="printgen panel: the strand law whose simulated panel test "
                                  "reproduces the profile's (nominal: diamond formula)"))
    if d.cables:
        out.append(Variant("bottom row held on the bed", bed="held", source=(
            "the film's foot seals on the bed under the full head (nominal: the bottom "
            "cable free between its anchors)")))
    width = d.net.width_mm * MM
    if d.cables and free_section is not None and free_section < width * (1 - SAME):
        fs = f"{free_section * 1e3:g} mm free section"
        src = (f"net printed {width * 1e3:.4g} mm wide, side sheets {free_section * 1e3:g} mm "
               "apart; how the excess is held is not stated (reference section 4)")
        out += [Variant(f"mounted in the {fs}", span=free_section, source=src),
                Variant(f"mounted in the {fs}, bottom on the bed", span=free_section,
                        bed="held", source=src + "; its slack bottom cable lies on the bed")]
    else:
        notes.append("mounting span: no free section narrower than the net given "
                     "([flume] free_section_m); no span variant")
    return out
