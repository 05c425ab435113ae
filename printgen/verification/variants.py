"""The variants of the printed model that make the uncertainty band: one list, here.

A variant is data: a label, its source (the argument for it, shown in the report), the scene
options it changes (`printgen.scene.SceneOptions`: mounting, orientation, pressure, net law,
bed, routing, span, law factors), the initial slack of its solver net and its `effort` (the
sweeps known to take longest start first; it changes no number). The band and the report
keep the order `model_variants` gives. A new variant is one entry below plus its test.

Each variant also answers one `question` (the uncertain input it moves: the variants of one
question are exclusive answers, never combined with each other) with a `weight` and its
argument (`weight_source`, shown in the report): the probability that this answer is the truth
(`spread` "answer"; the nominal answer keeps the rest), or, for a range (`spread` "range"), the
variant is the range's end and the input is uniform between the nominal and it. A variant with
a non-empty `excluded` (the reason) stays in the envelope but carries no weight: the central
interval (`printgen.verification.central`) leaves it out. `TESTS` maps each question to the
cheapest lab test that settles it (the UNDECIDED verdict names it).

Variants of design `d` (`model_variants`):
- measured modulus +- SD of each material whose profile records an SD (`sd_gpa`); the net's
  strands follow it only when their law comes from the modulus (a panel law has no SD), the
  printed border frame always does; the cables follow their material's SD;
- the panel law's geometry assumption: the law's tested net (strand and mesh recorded in the
  profile, an assumption when the source does not give it) against the alternative that the
  tested panel had the design's own strands and mesh (the law used without rescaling);
- the printed border frame at its filament's datasheet modulus, when the nominal takes the
  strand modulus the panel law's reading implies;
- the panel law read along each mesh diagonal but the nominal reading (the one the material
  can produce, `printgen.scaling.reading`), with why it fails a check when it does (`excluded`);
- the mounting in the flume, each of the scene's `MOUNTINGS` but the nominal;
- initial slack of the printed net, 0 to `SLACK_MAX` (0 is the nominal);
- the model-form options (`printgen.scene.forms`, `printgen.scene.mount`): the water's force
  normal to the deformed net, the sensor wires turning downstream (where it matters), the
  virtual panel test's strand law, the bottom row held on the bed, and the net mounted in a
  free section narrower than its printed width, alone and with its bottom on the bed.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field

from printgen.barrier.patterns import get_pattern
from printgen.inputs.materials import Material, load_material
from printgen.inputs.prototype import Prototype
from printgen.scaling.reading import chosen_orientation, panel_axes, panel_reading, tested_net
from printgen.scaling.record import Design
from printgen.scaling.section import area_m2
from printgen.scene.options import SceneOptions, build_scene
from printgen.scene.scenes import (
    MOUNTINGS,
    ORIENTATIONS,
    PROTOTYPE_ORIENTATION,
    TESTED_PATTERN,
    frame_modulus,
    recorded_orientation,
)
from printgen.units import MM

SLACK_MAX = 0.01  # initial slack of the printed net, upper end of the range (0-1 %)
SAME = 1e-9  # relative change below which an alternative equals the nominal (not run)
# a net hung with more slack than this sags visibly at rest (the multi-parameter fit's bound on
# the slack it may fit, printgen.verification.fit): a mounting that builds in more is not how a
# lab installs a barrier whose elongation it measures
VISIBLE_SLACK = 0.03
EVEN = "not stated by the source: every answer equally likely"
# the panel law's tested net, its diagonal and the strand law behind it are readings of one
# measured law: exclusive answers of one question (never combined: two softer readings of the
# same test would make a net softer than either), each weighted evenly with the nominal reading
READING = "panel-law reading"
# effort ranks: the sweeps measured longest run first (the net squeezed into a narrower free
# section with its bottom free hangs folded, most strands slack: its lowest loaded level
# finds no equilibrium from any sub-step, so it spends every iteration the path allows and
# is the band's longest sweep by far; initial slack is a mechanism until its strands
# tighten; then the mounting span on the bed, another mounting, the derived law, the normal
# pressure; the rest are quick)
FOLDED, SLOWEST, SLOWER, SLOW, MEDIUM, QUICKER = 6, 5, 4, 3, 2, 1


@dataclass(frozen=True)
class Variant:
    """One uncertain input of the printed model moved from its nominal value: `label`,
    `source` (why, for the report), the scene `options` it changes, the relative initial
    `slack` of every strand and cable of its solver net, its `effort` rank (higher: started
    earlier); `excluded`: why it is a reading the material cannot produce ("" when it can),
    kept to be shown apart, never as a central value."""

    label: str = "nominal"
    source: str = ""
    options: SceneOptions = field(default_factory=SceneOptions)
    slack: float = 0.0
    effort: int = 0
    question: str = ""
    weight: float = 0.0
    weight_source: str = ""
    spread: str = "answer"  # "answer": `weight` is its probability; "range": uniform to it
    excluded: str = ""  # why it carries no weight (contradicted by the material or the data)


# The cheapest lab test that settles each question, cheapest first (a statement of how the
# test is installed costs nothing; a measurement at the flume little; printed test pieces or
# coupons a print and a tensile test).
TESTS = {
    "lateral mounting": "state how the net is held at the side sheets (along their whole "
                        "height or only at the eyelets) as [flume] lateral",
    "bottom edge": "state how the net's bottom is held (the bottom cable free between its "
                   "anchors, or pressed on the bed by the film's foot)",
    "mounting span": "state how the net's extra width is held in the flume's free section",
    "sensor routing": "state where the potentiometers sit (in line with the rows or "
                      "downstream of the barrier)",
    "initial slack": "measure the net's sag when mounted, before the water arrives",
    "initial slack (both nets)": "state the prototype's initial slack (its as-built sag) and "
                                 "hang the model with the same relative sag",
    "prototype initial slack": "state the prototype's initial slack (its as-built sag)",
    "pressure direction": "photograph the film on the net at full head (does it lie on the "
                          "deformed net?)",
    READING: "print `printgen testpieces` and load the panel along its long diagonal (and its "
             "short one), then compare with `printgen panel`: which reading of the panel law "
             "the printed net follows",
    "modulus": "tensile-test coupons of the printed material and run `printgen calibrate` "
               "(it writes the modulus and its SD)",
}


def settling_tests(questions: list[str]) -> list[str]:
    """The tests of `TESTS` that settle `questions`, cheapest first (one per test; a question
    not listed: "find out" it, last)."""
    def test(q: str) -> str:
        return TESTS.get(q, TESTS["modulus"] if q.endswith("modulus") else f"find out {q}")

    order = list(TESTS.values())
    found = dict.fromkeys(test(q) for q in questions)
    return sorted(found, key=lambda t: order.index(t) if t in order else len(order))


def cheapest_test(questions: list[str]) -> str:
    """The cheapest test of `TESTS` that settles one of `questions` ("" for none)."""
    found = settling_tests(questions)
    return found[0] if found else ""


def model_variants(d: Design, mounting: str | None = None, free_section: float | None = None
                   ) -> tuple[list[Variant], list[str]]:
    """The variants of design `d` to sweep, in the report's order, and one note per
    uncertainty left out and why; `mounting` is the nominal run's (the other mountings become
    variants); `free_section` m: the flume's free section, when narrower than the net (a
    mounting-span variant)."""
    notes: list[str] = []
    out = _modulus_variants(d, notes)
    if d.cables:
        out += _cable_variants(d, notes)
    panel = load_material(d.net.material).panel_law
    if panel is not None and panel.has_geometry:
        out += _panel_geometry_variant(d, notes)
        out += _orientation_variants(d)
        out += _frame_variant(d)
    opts = MOUNTINGS if d.cables else ()  # no border cables: bed and banks only
    nominal = mounting or (opts[0] if opts else None)
    out += [Variant(f"mounting: {m}", f"flume mounting option (nominal: {nominal})",
                    SceneOptions(mounting=m), effort=SLOW, question="lateral mounting",
                    weight=1 / len(opts), weight_source="reference section 4: held along "
                    "the side sheets' height or only at the eyelets, both plausible; " + EVEN)
            for m in opts if m != nominal]
    if not opts:
        notes.append("mounting: the model scene has one mounting only; no mounting variant")
    out.append(Variant(f"initial slack {SLACK_MAX:.0%}", "printed net hung with 0 to 1 % "
                       "slack (printgen; printgen docs: Uncertainty band)", slack=SLACK_MAX,
                       effort=SLOWEST, question="initial slack", weight=1.0, spread="range",
                       weight_source=SLACK_RANGE))
    out += _model_form_variants(d, free_section, notes, nominal)
    return _shared_evenly(out, READING), notes


def _shared_evenly(variants: list[Variant], question: str) -> list[Variant]:
    """`variants` with the answers of `question` weighted evenly with its nominal answer
    (each 1 / (answers + 1); an excluded answer is no answer), their argument saying so."""
    n = sum(v.question == question and not v.excluded for v in variants)
    return [dataclasses.replace(v, weight=1 / (n + 1), weight_source=f"{v.weight_source}: "
                                f"one of {n + 1} readings of the law (the nominal's and {n} "
                                "variants), weighted evenly")
            if v.question == question and not v.excluded else v for v in variants]


SLACK_RANGE = ("uniform from 0 to 1 %: no value is preferred within the range (its effect "
               "taken linear in the slack)")


def _modulus_sd(mat: Material, part: str, notes: list[str]) -> tuple[float, float] | None:
    """(E, SD) Pa of `mat`'s measured modulus, or None with a note saying why it is left out
    (`part`: "net" or "cables", as the note names it)."""
    e, source = mat.modulus()
    sd = mat.measured_modulus.sd if source == "measured" and mat.measured_modulus else None
    if not sd:
        notes.append(f"{mat.name} ({part}): no SD of the {source} modulus in its profile; "
                     "modulus spread not included (printgen calibrate writes sd_gpa)")
        return None
    return e, sd


def _modulus_variants(d: Design, notes: list[str]) -> list[Variant]:
    net = load_material(d.net.material)
    found = _modulus_sd(net, "net", notes)
    if found is None:
        return []
    e, sd = found
    panel = net.panel_law
    law_from_modulus = panel is None or not panel.has_geometry
    out = []
    for sign, word in ((-1, "-"), (1, "+")):
        k = 1 + sign * sd / e
        out.append(Variant(f"{net.name} modulus {word}1 SD",
                           f"{net.name} profile: E = {e / 1e9:.3g} +- {sd / 1e9:.2g} GPa "
                           "(measured)",
                           SceneOptions(net_factor=k if law_from_modulus else 1.0,
                                        frame_factor=k), question="modulus", weight=0.5,
                           weight_source=SD_PAIR))
    return out


SD_PAIR = ("+-1 SD with weight 1/2 each: the two-point spread with the measured mean and SD "
           "(an input's effect taken linear within 1 SD)")


def _cable_variants(d: Design, notes: list[str]) -> list[Variant]:
    mat = load_material(d.cables[0].material)
    found = _modulus_sd(mat, "cables", notes)
    if found is None:
        return []
    e, sd = found
    return [Variant(f"{mat.name} cable modulus {word}1 SD",
                    f"{mat.name} profile: E = {e / 1e9:.3g} +- {sd / 1e9:.2g} GPa",
                    SceneOptions(cable_factor=1 + sign * sd / e), question="cable modulus",
                    weight=0.5, weight_source=SD_PAIR)
            for sign, word in ((-1, "-"), (1, "+"))]


def _panel_geometry_variant(d: Design, notes: list[str]) -> list[Variant]:
    """The panel law used without the rescaling from its (assumed) tested net to the design's."""
    mat = load_material(d.net.material)
    law, n = mat.panel_law, d.net
    if law is None:
        return []
    w, t, a, b = tested_net(law)
    # the panel loaded along the diagonal of the nominal reading, of either net
    o = chosen_orientation(mat) or recorded_orientation(law)
    tested = get_pattern(TESTED_PATTERN).membrane_factor(*panel_axes(a, b, o)) * (w * t)
    design = get_pattern(n.pattern).membrane_factor(
        *panel_axes(n.mesh_x_mm * MM, n.mesh_y_mm * MM, o)) * area_m2(n.strand)
    ratio = tested / design
    if abs(ratio - 1) < SAME:
        notes.append(f"{mat.name} panel law: the design's net is the tested net the profile "
                     "assumes, so the geometry assumption does not change the law")
        return []
    # the profile's panels were TESTED_PATTERN nets: a net of another pattern cannot be one
    other = (f"the profile's panels were {TESTED_PATTERN} nets and the design's is "
             f"{n.pattern}: it cannot be the tested net" if n.pattern != TESTED_PATTERN else "")
    return [Variant(f"{mat.name} panel law: tested net = the design's net",
                    f"{mat.name} profile [measured.panel_law] conditions",
                    SceneOptions(net_factor=ratio), question=READING,
                    weight_source="the profile's tested net is an assumption where its "
                    "source does not give it", excluded=other)]


def _orientation_variants(d: Design) -> list[Variant]:
    """The panel law read along each mesh diagonal but the nominal reading (the one the
    material can produce, `printgen.scaling.reading`; the paper does not say which diagonal
    its printed panels were loaded along); a reading that fails a check carries why."""
    reading = panel_reading(load_material(d.net.material))
    if reading is None:
        return []
    out = []
    for c in reading.checks:
        if c.orientation == reading.orientation:
            continue
        why = "; ".join(c.reasons())
        out.append(Variant(f"panel test along the {c.orientation} diagonal",
                           f"panel-test orientation not stated (nominal: {reading.orientation}"
                           f", chosen by consistency; profile records {reading.recorded}); "
                           + c.summary(), SceneOptions(orientation=c.orientation),
                           question=READING, weight_source="the source does not state the "
                           "diagonal", excluded=f"a reading the material cannot produce: {why}"
                           if why else ""))
    return out


def _frame_variant(d: Design) -> list[Variant]:
    """The printed border frame at the filament's datasheet modulus instead of the strand
    modulus the panel law's reading implies (the nominal, `scene.scenes.frame_modulus`)."""
    mat = load_material(d.net.material)
    e, source = frame_modulus(mat, None)
    if source in ("measured", "datasheet") or abs(mat.datasheet_modulus / e - 1) < SAME:
        return []
    return [Variant(f"{mat.name} border frame at the datasheet modulus",
                    f"{mat.name} datasheet E = {mat.datasheet_modulus / 1e9:.3g} GPa, the "
                    f"filament's (nominal: {e / 1e6:.3g} MPa, the printed strands' from the "
                    "panel law's reading)",
                    SceneOptions(frame_factor=mat.datasheet_modulus / e),
                    question="border frame modulus",
                    excluded="the frame is printed from the same filament as the strands, whose "
                    f"modulus the panel law's consistent reading gives ({e / 1e6:.3g} MPa); the "
                    "datasheet's is a generic value that reading contradicts")]


def _model_form_variants(d: Design, free_section: float | None, notes: list[str],
                         mounting: str | None) -> list[Variant]:
    """The water's force normal to the deformed net, the sensor routing where it matters, the
    virtual panel test's strand law, the bottom row held on the bed, and the net mounted in a
    free section narrower than its printed width, alone and with its slack bottom cable on
    the bed."""
    out = [Variant("pressure normal to the deformed net", "the folded film presses normal to "
                   "the net (nominal: along the flow, reference section 3)",
                   SceneOptions(pressure="normal"), effort=QUICKER,
                   question="pressure direction", weight=0.5,
                   weight_source="two models of the film's force, neither measured: "
                   "weighted evenly")]
    out += _routing_variants(d, mounting, notes) if d.cables else []
    law = load_material(d.net.material).panel_law
    if law is not None and law.has_geometry:
        out.append(Variant("strand law from the virtual panel test", "printgen panel: the "
                           "strand law whose simulated panel test reproduces the profile's "
                           "(nominal: diamond formula)", SceneOptions(net_law="derived"),
                           effort=MEDIUM, question=READING,
                           weight_source="two models of the strands behind the same law"))
    if d.cables:
        out.append(Variant("bottom row held on the bed", "the film's foot seals on the bed "
                           "under the full head (nominal: the bottom cable free between its "
                           "anchors)", SceneOptions(bed="held"), question="bottom edge",
                           weight=0.5, weight_source=EVEN))
    width = d.net.width_mm * MM
    if d.cables and free_section is not None and free_section < width * (1 - SAME):
        fs = f"{free_section * 1e3:g} mm free section"
        src = (f"net printed {width * 1e3:.4g} mm wide, side sheets {free_section * 1e3:g} mm "
               "apart; how the excess is held is not stated (reference section 4)")
        why = squeezed_slack(width, free_section, d.net.height_mm * MM)
        out += [Variant(f"mounted in the {fs}", src, SceneOptions(span=free_section),
                        effort=FOLDED, question="mounting span", excluded=why),
                Variant(f"mounted in the {fs}, bottom on the bed",
                        src + "; its slack bottom cable lies on the bed",
                        SceneOptions(span=free_section, bed="held"), effort=SLOWER,
                        question="mounting span", excluded=why)]
    else:
        notes.append("mounting span: no free section narrower than the net given "
                     "([flume] free_section_m); no span variant")
    return out


def _routing_variants(d: Design, mounting: str | None, notes: list[str]) -> list[Variant]:
    s = build_scene(d, SceneOptions(mounting=mounting))
    if all(s.fixed[w.nodes[-1]] for w in s.wires.values()):
        notes.append(f"sensor routing: the rows' end nodes are held ({s.mounting} mounting), "
                     "so the wire beyond them changes neither the net nor the reading; no "
                     "routing variant")
        return []
    return [Variant("sensor wires turn downstream at the edge",
                    "potentiometers' position not stated (nominal: in line)",
                    SceneOptions(routing="downstream"), question="sensor routing",
                    weight=0.5, weight_source=EVEN)]


def squeezed_slack(width: float, span: float, height: float) -> str:
    """Why a net `width` m wide mounted with its printed lengths over `span` m carries no
    weight (empty when its built-in slack is below VISIBLE_SLACK): the slack and the sag it
    hangs in at rest (a slack strand of span L and excess e sags L sqrt(3 e / 8), the
    parabola's length), against the barrier's `height` m."""
    excess = width / span - 1
    if excess <= VISIBLE_SLACK:
        return ""
    sag = span * math.sqrt(3 * excess / 8)
    return (f"its printed lengths over the {span * 1e3:g} mm span build in {excess:.1%} slack "
            f"across, a sag of about {sag * 1e3:.0f} mm ({sag / height:.0%} of the barrier's "
            f"height) at rest, beyond the {VISIBLE_SLACK:.0%} at which a net sags visibly: "
            "not how a lab mounts a barrier whose elongation it measures (the extra width "
            "lies on the side sheets: the nominal)")


def prototype_variants(p: Prototype) -> list[Variant]:
    """The variants of the prototype's net: its initial slack (0 to `SLACK_MAX`, as the
    printed net's) and, when it has a panel law, the law read along the other diagonal
    (shown, no weight: the reference states the diagonal its panel was loaded along)."""
    out = [Variant(f"prototype initial slack {SLACK_MAX:.0%}", "prototype net hung with 0 to "
                   "1 % slack (printgen; no as-built sag stated)", slack=SLACK_MAX,
                   effort=SLOWEST, question="prototype initial slack", weight=1.0,
                   spread="range", weight_source=SLACK_RANGE)]
    out += [Variant(f"prototype panel law along the {o} diagonal", "the other reading of the "
                    f"prototype's panel law (nominal: {PROTOTYPE_ORIENTATION})",
                    SceneOptions(orientation=o), question="prototype panel-test orientation",
                    excluded="stated by the reference (section 4): the prototype's 1.33 m "
                    "panel was loaded along the water-drop's long axis")
            for o in ORIENTATIONS if o != PROTOTYPE_ORIENTATION and p.net.panel_law is not None]
    return out
