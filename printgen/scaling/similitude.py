"""Similitude targets of the model at scale 1/lambda (Lambert et al. 2023, section 2 of the
printgen reference): Froude scaling in the same fluid, with stiffness scaled too.

Every quantity q of the model is q_prototype * lambda**exponent; the exponents are those of the
reference's scaling table. The model flow and the flume's limits: `printgen.scaling.flow`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

from printgen.barrier.patterns import get_pattern
from printgen.errors import InputError
from printgen.inputs.prototype import Prototype
from printgen.outputs.display import Shown, Summary
from printgen.scaling.flow import (  # noqa: F401 (RE_TURBULENT: also read from here)
    RE_TURBULENT,
    FlowCheck,
    flow_check,
)
from printgen.units import MM, G

SCALE_MAX = 100.0  # largest lambda of the reference's scale series (1, 10, 30, 50, 100)


@dataclass(frozen=True)
class TargetRow:
    """One quantity of the scaling table: prototype and model values in `unit` (SI)."""

    key: str
    label: str
    unit: str
    exponent: float
    prototype: float
    model: float


@dataclass(frozen=True, repr=False)
class ScaledTargets(Shown):
    """Targets of the model at 1/scale; `rows` keyed by `TargetRow.key` in `values`."""

    scale: float
    rows: tuple[TargetRow, ...]
    pi_prototype: dict[str, float]
    pi_model: dict[str, float]
    flow: FlowCheck
    values: dict[str, float] = field(repr=False)
    prototype: str = ""  # the prototype's name
    mesh_warnings: tuple[str, ...] = ()  # a [model] mesh chosen for another scale

    def __getitem__(self, key: str) -> float:
        return self.values[key]

    @property
    def warnings(self) -> tuple[str, ...]:
        """Every warning of the targets: the model flow's (the flume's limits among them),
        then the printed mesh's."""
        return self.flow.warnings + self.mesh_warnings

    def summary(self) -> Summary:
        """Each target (model value, prototype value), the model flow and the warnings."""
        f = self.flow
        rows = [(r.label, f"{r.model:.4g} {r.unit} (prototype {r.prototype:.4g})")
                for r in self.rows]
        rows.append(("model flow", f"v = {f.velocity:.3g} m/s, Froude {f.froude:.2f}, "
                                   f"Reynolds {f.reynolds:.3g}"))
        rows += [("warning", w) for w in self.warnings]
        return Summary(f"ScaledTargets: {self.prototype or 'prototype'} at 1:{self.scale:g}",
                       tuple(rows))

    def to_record(self) -> dict:
        """JSON-ready record of the targets (stable keys)."""
        return {
            "prototype": self.prototype,
            "scale": self.scale,
            "targets": {r.key: {"label": r.label, "unit": r.unit, "exponent": r.exponent,
                                "prototype": r.prototype, "model": r.model} for r in self.rows},
            "pi_groups": {"prototype": self.pi_prototype, "model": self.pi_model},
            "flow": self.flow,
            "warnings": list(self.warnings),
        }


# A [model] mesh whose size is off the prototype's mesh scaled to this lambda by more than this is
# warned: the range printgen design searches each diagonal in (printgen.search.space).
MESH_TOLERANCE = 0.25
FORCE_EXPONENT = -3  # a force scales as lambda^-3 (Froude similitude, same fluid density)


def to_prototype(value: Any, exponent: float, scale: float) -> Any:
    """A model quantity (a number or an array) of lambda exponent `exponent` at the
    prototype's scale: value x lambda^-exponent (e.g. a force x lambda^3)."""
    return value * scale ** -exponent


def check_scale(scale: float) -> float:
    """Return scale as float; raise InputError unless it is finite and in [1, SCALE_MAX]."""
    if isinstance(scale, bool) or not isinstance(scale, (int, float)) or not math.isfinite(scale):
        raise InputError(f"scale = {scale!r} is not a finite number; give lambda >= 1, e.g. 40")
    if scale < 1:
        raise InputError(f"scale = {scale:g} is below 1; lambda is prototype / model "
                         "(1:40 -> --scale 40), so it must be >= 1")
    if scale > SCALE_MAX:
        raise InputError(f"scale = {scale:g} exceeds {SCALE_MAX:g}: the similitude is established "
                         f"from lambda = 1 to {SCALE_MAX:g} (Lambert et al. 2023's scale series), "
                         "and beyond it a barrier's strands (16 mm / lambda) are far thinner than "
                         "a printed bead (about 0.4 mm) and the model flow is laminar; use a "
                         f"scale of at most {SCALE_MAX:g}")
    return float(scale)


def prototype_quantities(p: Prototype) -> list[tuple[str, str, str, float, float]]:
    """(key, label, unit, exponent, prototype value) of every scaled quantity."""
    rho = p.density
    mesh = get_pattern(p.net.pattern).mesh_name  # what mesh_x_m is
    q = [
        ("width", "barrier width w_B", "m", -1, p.width),
        ("height", "barrier height h_B", "m", -1, p.height),
        ("mesh_x", f"{mesh} across a_x", "m", -1, p.net.mesh_x),
        ("mesh_y", f"{mesh} up a_y", "m", -1, p.net.mesh_y),
        ("strand_d", "net strand diameter d", "m", -1, p.net.strand_diameter),
        ("strand_area", "net strand section A", "m^2", -2, math.pi / 4 * p.net.strand_diameter**2),
        ("depth", "flow depth h", "m", -1, p.depth),
        ("velocity", "flow velocity v_f", "m/s", -0.5, p.velocity),
        ("time", "time", "s", -0.5, 1.0),
        ("hydrostatic_force", "hydrostatic resultant at h = h_B", "N", -3,
         0.5 * rho * G * p.height**2 * p.width),
        ("drag_per_length", "drag per strand length", "N/m", -2,
         0.5 * rho * p.velocity**2 * p.net.strand_diameter),
        ("strain", "strain", "-", 0, 1.0),
    ]
    if p.net.strand_modulus is not None:
        ea = p.net.strand_modulus * math.pi / 4 * p.net.strand_diameter**2
        q += [("strand_modulus", "net strand modulus E", "Pa", -1, p.net.strand_modulus),
              ("strand_ea", "net strand axial stiffness E*A", "N", -3, ea)]
    if p.net.panel_law is not None:
        _knees, kappas, length = p.net.panel_law
        q.append(("panel_length", "net panel test length L_p", "m", -1, length))
        for i, k in enumerate(kappas):
            q.append((f"kappa_{i}", f"net panel stiffness kappa, segment {i + 1}", "N/m/m", -1, k))
            q.append((f"membrane_{i}", f"membrane stiffness kappa*L_p, segment {i + 1}", "N/m",
                      -2, k * length))
    if p.border is not None:
        area = math.pi / 4 * p.border.diameter**2
        q += [("cable_d", "border cable diameter", "m", -1, p.border.diameter),
              ("cable_area", "border cable section A", "m^2", -2, area),
              ("cable_modulus", "border cable modulus E", "Pa", -1, p.border.modulus),
              ("cable_ea", "border cable axial stiffness E*A", "N", -3, p.border.modulus * area)]
    return q


def scale_targets(p: Prototype, scale: float) -> ScaledTargets:
    """Model targets at 1/scale, the five Pi groups of both, and the model flow check."""
    lam = check_scale(scale)
    rows = tuple(TargetRow(k, label, unit, e, v, v * lam**e if e else v)
                 for k, label, unit, e, v in prototype_quantities(p))
    values = {r.key: r.model for r in rows}
    proto = {r.key: r.prototype for r in rows}
    return ScaledTargets(lam, rows, pi_groups(proto, p), pi_groups(values, p),
                         flow_check(p, values, lam, scale_max=SCALE_MAX), values, p.name,
                         mesh_reuse(p, values, lam))


def mesh_reuse(p: Prototype, v: dict[str, float], lam: float) -> tuple[str, ...]:
    """The warning of a [model] mesh chosen for another scale (none without one or within
    MESH_TOLERANCE). It compares the mesh's size, the geometric mean of its two diagonals'
    factors over the prototype's mesh scaled to 1/lam: another scale changes both by the same
    factor, while a lab may reshape the mesh on purpose (the paper's 1:40 diamond, 20.6 x 9.4 mm,
    is 1.31x the scaled prototype's across and 1.07x up: 1.18x in size)."""
    m = p.model
    if m.mesh_x_mm is None or m.mesh_y_mm is None:
        return ()
    fx, fy = m.mesh_x_mm * MM / v["mesh_x"], m.mesh_y_mm * MM / v["mesh_y"]
    size = math.sqrt(fx * fy)
    if abs(size - 1) <= MESH_TOLERANCE:
        return ()
    sx, sy = v["mesh_x"] / MM, v["mesh_y"] / MM
    return (f"[model] mesh {m.mesh_x_mm:g} x {m.mesh_y_mm:g} mm is {size:.2f}x the prototype's "
            f"mesh scaled to 1:{lam:g} ({sx:.3g} x {sy:.3g} mm; {fx:.2f}x across, {fy:.2f}x up: "
            f"Pi2 = a / h_B {fx - 1:+.0%} off), beyond the +-{MESH_TOLERANCE:.0%} printgen "
            f"design searches in; its size fits 1:{lam / size:.0f}, so it was chosen for another "
            "scale. Drop [model] mesh_x_mm and mesh_y_mm to print the prototype's mesh scaled "
            f"({sx:.3g} x {sy:.3g} mm), or give a mesh chosen for 1:{lam:g}",)


def pi_groups(v: dict[str, float], p: Prototype) -> dict[str, float]:
    """Pi1..Pi5 of one scale. Pi5 uses the net strand modulus, else the border cable's."""
    modulus = v.get("strand_modulus", v.get("cable_modulus", math.nan))
    return {
        "pi1_width_over_height": v["width"] / v["height"],
        "pi2_mesh_over_height": v["mesh_x"] / v["height"],
        "pi3_strand_d_over_height": v["strand_d"] / v["height"],
        "pi4_froude": v["velocity"] / math.sqrt(G * v["height"]),
        "pi5_modulus_over_dynamic_pressure": modulus / (p.density * v["velocity"] ** 2),
    }
