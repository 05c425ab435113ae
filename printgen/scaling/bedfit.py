"""Whether the printed net fits a printer's bed, checked before any mesh is built (so that
`select` says it, not `make` after its meshes): the net panel with its border frame and eyelet
margin, against the usable bed of every printer profile, axis-aligned or turned a quarter;
and the smallest scale factor lambda at which it fits the chosen printer (the model's size
goes as 1 / lambda)."""

from __future__ import annotations

import math
from dataclasses import dataclass

from printgen.inputs.printers import Printer, load_printer
from printgen.inputs.profiles import list_profiles
from printgen.scaling.record import Design

EYELET_MARGIN_MM = 4.0  # the net's corner eyelets reach about this far beyond the frame


@dataclass(frozen=True)
class BedFit:
    """size_mm : (w, h) of the net's footprint; fits : printer key -> bool; chosen : the
    design's printer; min_scale : smallest lambda at which the net fits the chosen printer."""

    size_mm: tuple[float, float]
    fits: dict[str, bool]
    chosen: str
    scale: float
    min_scale: float

    @property
    def ok(self) -> bool:
        return self.fits[self.chosen]

    def message(self) -> str:
        """One line: fits, or which printers fit and which lambda fits the chosen one."""
        w, h = self.size_mm
        if self.ok:
            return f"bed: the net ({w:.0f} x {h:.0f} mm) fits {self.chosen}"
        others = [k for k, ok in self.fits.items() if ok]
        fix = (f"printers that fit: {', '.join(others)} (--printer)" if others else
               "no printer profile fits it")
        return (f"bed: the net ({w:.0f} x {h:.0f} mm) does not fit {self.chosen}; {fix}; on "
                f"{self.chosen} it fits from lambda = {math.ceil(self.min_scale * 10) / 10:g} "
                f"(a smaller model; now 1:{self.scale:g})")


def usable_mm(p: Printer) -> tuple[float, float]:
    return p.bed_x_mm - 2 * p.bed_margin_mm, p.bed_y_mm - 2 * p.bed_margin_mm


def need(size: tuple[float, float], p: Printer) -> float:
    """Factor by which `size` must shrink to fit `p` (<= 1: it fits), best of both turns."""
    (w, h), (bx, by) = size, usable_mm(p)
    return min(max(w / bx, h / by), max(w / by, h / bx))


def bed_fit(d: Design) -> BedFit:
    """The net of `d` against every printer profile's usable bed."""
    n = d.net
    pad = 2 * (n.border_width_mm + EYELET_MARGIN_MM)
    size = (n.width_mm + pad, n.height_mm + pad)
    fits = {k: need(size, load_printer(k)) <= 1.0 for k in list_profiles("printers")}
    fits.setdefault(d.printer, need(size, load_printer(d.printer)) <= 1.0)
    return BedFit(size, fits, d.printer, d.scale, d.scale * need(size, load_printer(d.printer)))
