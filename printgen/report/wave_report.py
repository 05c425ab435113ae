"""The report's section of a design whose net has waved strands: the target net law, the
straight net's and the waved net's on one plot (`printgen.scene.waved.WaveLaws`), and the
print time and mass of the waved net against the straight one (`WavePrice`)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from printgen.parts.gcode.price import WavePrice
from printgen.report.html import Drawing, Report
from printgen.report.plots import _png, _pyplot
from printgen.scene.waved import WaveLaws


@dataclass(frozen=True)
class WaveRecord:
    """A waved design's laws and its net's price against the straight net's."""

    laws: WaveLaws
    price: WavePrice

    def to_record(self) -> dict[str, Any]:
        return {"laws": self.laws.to_record(), "price": self.price.to_record()}


def wave_law_figure(laws: WaveLaws, title: str) -> bytes:
    """Net force per width (N/m) against net strain (%): target, straight and waved nets."""
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(7, 4.4), constrained_layout=True)
    e = laws.strains * 100
    ax.plot(e, laws.target, "k-", lw=2, label="target (prototype's panel law, scaled)")
    ax.plot(e, laws.straight, "C0--", label=f"straight strands (RMS log error "
            f"{laws.error_rms_log(laws.straight):.2f})")
    w = laws.wave
    ax.plot(e, laws.curved, "C3-", label=(f"waved strands, {w.amplitude_mm:g} mm x "
                                          f"{w.half_waves} half-wave(s) (RMS log error "
                                          f"{laws.error_rms_log(laws.curved):.2f})"))
    ax.set_xlabel("net strain along the mesh_y diagonal (%)")
    ax.set_ylabel("net force per width (N/m)")
    ax.set_title(title, fontsize=10)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    return _png(fig)


def wave_section(rep: Report, w: WaveRecord) -> None:
    """The waved net's laws (figure and summary) and its print time and mass."""
    from printgen.parts.gcode.estimate import NOT_COUNTED, duration

    laws, price = w.laws, w.price
    rep.heading("Waved strands: net law and print cost")
    rep.paragraph(
        f"Each strand of the net follows an in-plane wave of {laws.wave.amplitude_mm:g} mm "
        f"amplitude, {laws.wave.half_waves} half-wave(s) between junctions (excess length "
        f"{laws.excess:.2%}). Its law, from the beam model of one strand with both ends clamped, "
        f"starts at {laws.initial_slope:.4g} N per unit strain and reaches "
        f"{laws.straight_slope:.4g} once straight (knee at {laws.knee:.1%} strand strain); the "
        "verification's model net uses it (the scene's assumptions: strand wave). The laws "
        "below are those of the blocked, infinite net stretched along its mesh_y diagonal, the "
        "RMS log error against the target taken over the strains shown.")
    rep.figure(Drawing(wave_law_figure, (laws, "Net law: target, straight and waved strands")),
               "Net force per width against strain: the target (the prototype's panel law "
               "scaled to the model), the design's net with straight strands and with its "
               "waved strands.", "wave-laws")
    rows = [[name, duration(est.seconds), f"{est.filament_mm / 1e3:.3f}", f"{est.mass_g:.2f}",
             str(moves)]
            for name, est, moves in (("waved net", price.curved, price.curved_moves),
                                     ("straight net", price.straight, price.straight_moves))]
    rows.append(["waved / straight", f"{price.time_ratio:.2f}",
                 f"{price.curved.filament_mm / price.straight.filament_mm:.2f}",
                 f"{price.mass_ratio:.2f}", f"{price.curved_moves / price.straight_moves:.2f}"])
    rep.table([f"net (print time: {NOT_COUNTED})", "print time", "filament (m)", "mass (g)",
               "moves"], rows)
