"""The variants of the printed model that make the uncertainty band: one list, here.

A variant is data: a label, its source (the argument for it, shown in the report), the scene
options it changes (`printgen.scene.SceneOptions`: mounting, orientation, pressure, net law,
bed, routing, span, law factors), the initial slack of its solver net and its `effort` (the
sweeps known to take longest start first; it changes no number). The band and the report
keep the order `model_variants` gives. A new variant is one entry below plus its test.

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

from dataclasses import dataclass, field

from printgen.barrier.patterns import get_pattern
from printgen.inputs.materials import Material, load_material
from printgen.scaling.reading import chosen_orientation, panel_axes, panel_reading, tested_net
from printgen.scaling.record import Design
from printgen.scaling.section import area_m2
from printgen.scene.options import SceneOptions, build_scene
from printgen.scene.scenes import (
    MOUNTINGS,
    TESTED_PATTERN,
    frame_modulus,
    recorded_orientation,
)
from printgen.units import MM

SLACK_MAX = 0.01  # initial slack of the printed net, upper end of the range (0-1 %)
SAME = 1e-9  # relative change below which an alternative equals the nominal (not run)
# effort ranks: the sweeps measured longest run first (initial slack is a mechanism until
# its strands tighten; then the mounting span, another mounting, the derived law, the
# normal pressure; the rest are quick)
SLOWEST, SLOWER, SLOW, MEDIUM, QUICKER = 5, 4, 3, 2, 1


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
    excluded: str = ""  # why the variant contradicts the material or the test ("": it does not)


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
                    SceneOptions(mounting=m), effort=SLOW) for m in opts if m != nominal]
    if not opts:
        notes.append("mounting: the model scene has one mounting only; no mounting variant")
    out.append(Variant(f"initial slack {SLACK_MAX:.0%}", "printed net hung with 0 to 1 % "
                       "slack (printgen; printgen docs: Uncertainty band)", slack=SLACK_MAX,
                       effort=SLOWEST))
    out += _model_form_variants(d, free_section, notes, nominal)
    return out, notes


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
                                        frame_factor=k)))
    return out


def _cable_variants(d: Design, notes: list[str]) -> list[Variant]:
    mat = load_material(d.cables[0].material)
    found = _modulus_sd(mat, "cables", notes)
    if found is None:
        return []
    e, sd = found
    return [Variant(f"{mat.name} cable modulus {word}1 SD",
                    f"{mat.name} profile: E = {e / 1e9:.3g} +- {sd / 1e9:.2g} GPa",
                    SceneOptions(cable_factor=1 + sign * sd / e))
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
    return [Variant(f"{mat.name} panel law: tested net = the design's net",
                    f"{mat.name} profile [measured.panel_law] conditions",
                    SceneOptions(net_factor=ratio))]


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
                           excluded=f"a reading the material cannot produce: {why}"
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
                    SceneOptions(frame_factor=mat.datasheet_modulus / e))]


def _model_form_variants(d: Design, free_section: float | None, notes: list[str],
                         mounting: str | None) -> list[Variant]:
    """The water's force normal to the deformed net, the sensor routing where it matters, the
    virtual panel test's strand law, the bottom row held on the bed, and the net mounted in a
    free section narrower than its printed width, alone and with its slack bottom cable on
    the bed."""
    out = [Variant("pressure normal to the deformed net", "the folded film presses normal to "
                   "the net (nominal: along the flow, reference section 3)",
                   SceneOptions(pressure="normal"), effort=QUICKER)]
    out += _routing_variants(d, mounting, notes) if d.cables else []
    law = load_material(d.net.material).panel_law
    if law is not None and law.has_geometry:
        out.append(Variant("strand law from the virtual panel test", "printgen panel: the "
                           "strand law whose simulated panel test reproduces the profile's "
                           "(nominal: diamond formula)", SceneOptions(net_law="derived"),
                           effort=MEDIUM))
    if d.cables:
        out.append(Variant("bottom row held on the bed", "the film's foot seals on the bed "
                           "under the full head (nominal: the bottom cable free between its "
                           "anchors)", SceneOptions(bed="held")))
    width = d.net.width_mm * MM
    if d.cables and free_section is not None and free_section < width * (1 - SAME):
        fs = f"{free_section * 1e3:g} mm free section"
        src = (f"net printed {width * 1e3:.4g} mm wide, side sheets {free_section * 1e3:g} mm "
               "apart; how the excess is held is not stated (reference section 4)")
        out += [Variant(f"mounted in the {fs}", src, SceneOptions(span=free_section),
                        effort=SLOWER),
                Variant(f"mounted in the {fs}, bottom on the bed",
                        src + "; its slack bottom cable lies on the bed",
                        SceneOptions(span=free_section, bed="held"), effort=SLOWER)]
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
                    SceneOptions(routing="downstream"))]
