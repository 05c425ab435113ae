"""The model flow at scale 1/lambda and whether the prototype file's flume can run it.

Reynolds number: Re = v R_h / nu with the hydraulic radius of the approach section
R_h = w h / (w + 2 h) (the standard open-channel definition; the paper's v w_B h / nu is not
dimensionless). The flow fills the flume's width w (the barrier's own width without a [flume]
table), so its discharge is Q = v h w.

The flume's limits (discharge, width, Froude range) bind the verdict (`FlumeLimit`): a test
the flume cannot run is not a pass. Each names what would clear it. Under Froude similitude in
a flume of fixed width, Q = v_p h_p w lambda^-1.5 and the model's width is w_B / lambda, so a
larger lambda clears both; the Froude number is the same at every scale, so no lambda clears it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from printgen.inputs.prototype import FlumeSpec, Prototype
from printgen.units import L_PER_S, MM, NU_WATER, G

RE_TURBULENT = 2500.0  # model flow must stay turbulent (reference, section 2)


@dataclass(frozen=True)
class FlumeLimit:
    """One limit of the flume the scaled test goes past: `key` ("discharge", "width",
    "froude"), the model's value and the flume's limit it passes (m^3/s, m or -), `factor`
    (how far past: model / limit, or limit / model for the Froude number's lower bound), and
    `min_scale`: the smallest lambda that clears it (None: no scale does)."""

    key: str
    model: float
    limit: float
    factor: float
    min_scale: float | None
    text: str


@dataclass(frozen=True)
class FlowCheck:
    """The model flow: Froude and Reynolds numbers, discharge, warnings (every one, the
    flume's limits' included); `limits`: those of the flume the test goes past, `fix`: what
    clears them all ("" when none binds)."""

    velocity: float  # m/s
    depth: float  # m
    channel_width: float  # m
    hydraulic_radius: float  # m
    froude: float
    reynolds: float
    discharge: float  # m^3/s over the channel width
    warnings: tuple[str, ...]
    limits: tuple[FlumeLimit, ...] = ()
    fix: str = ""


def flow_numbers(v_proto: float, depth_proto: float, width: float, lam: float
                 ) -> tuple[float, float, float, float, float, float]:
    """(velocity m/s, depth m, hydraulic radius m, Froude, Reynolds, discharge m^3/s) of the
    model flow at 1/lam in a channel `width` (m) wide."""
    u, h = v_proto / math.sqrt(lam), depth_proto / lam
    r_h = width * h / (width + 2 * h)
    return u, h, r_h, u / math.sqrt(G * h), u * r_h / NU_WATER, u * h * width


def flow_check(p: Prototype, v: dict[str, float], lam: float, *, scale_max: float
               ) -> FlowCheck:
    """Froude, Reynolds (hydraulic radius) and flume fit of the model flow (`v`: the model's
    targets; `scale_max`: the largest lambda a fix may propose)."""
    width = p.flume.width if p.flume else v["width"]
    h, u = v["depth"], v["velocity"]
    r_h = width * h / (width + 2 * h)
    froude, reynolds = u / math.sqrt(G * h), u * r_h / NU_WATER
    discharge = u * h * width
    warn = []
    if reynolds < RE_TURBULENT:
        warn.append(f"model flow Re = {reynolds:.0f} is below {RE_TURBULENT:.0f}: not turbulent; "
                    "use a smaller scale (lambda) or a faster, deeper flow")
    limits = () if p.flume is None else flume_limits(p, p.flume, v, lam, froude, discharge)
    warn += [lim.text for lim in limits]
    fix = flume_fix(p, p.flume, lam, limits, scale_max) if p.flume and limits else ""
    return FlowCheck(u, h, width, r_h, froude, reynolds, discharge, tuple(warn), limits, fix)


def flume_limits(p: Prototype, f: FlumeSpec, v: dict[str, float], lam: float, froude: float,
                 discharge: float) -> tuple[FlumeLimit, ...]:
    """The limits of flume `f` that the model at 1/lam goes past, each with its own fix."""
    out = []
    if discharge > f.max_discharge:
        need = lam * (discharge / f.max_discharge) ** (2 / 3)  # Q ~ lambda^-1.5 at fixed width
        out.append(FlumeLimit(
            "discharge", discharge, f.max_discharge, discharge / f.max_discharge, need,
            f"model discharge {discharge / L_PER_S:.2f} L/s exceeds the flume's "
            f"{f.max_discharge / L_PER_S:.2f} L/s ({discharge / f.max_discharge:.2f}x): a "
            f"scale of 1:{need:.3g} or more, or a flume that supplies at least "
            f"{discharge / L_PER_S:.2f} L/s, runs it"))
    if v["width"] > f.width:
        need = p.width / f.width
        out.append(FlumeLimit(
            "width", v["width"], f.width, v["width"] / f.width, need,
            f"model barrier width {v['width'] / MM:.0f} mm exceeds the flume width "
            f"{f.width / MM:.0f} mm ({v['width'] / f.width:.2f}x): a scale of 1:{need:.3g} or "
            "more, or a wider flume, fits it"))
    if not f.froude_min <= froude <= f.froude_max:
        bound = f.froude_max if froude > f.froude_max else f.froude_min
        lo, hi = (x * math.sqrt(G * p.depth) for x in (f.froude_min, f.froude_max))
        out.append(FlumeLimit(
            "froude", froude, bound, max(froude / bound, bound / froude), None,
            f"model Froude {froude:.2f} is outside the flume's range "
            f"{f.froude_min:g}-{f.froude_max:g} ({max(froude / bound, bound / froude):.2f}x "
            f"its {'maximum' if bound == f.froude_max else 'minimum'}): Froude similitude keeps "
            "it at every scale, so no lambda changes it; a flume that runs Froude "
            f"{froude:.2f}, or a prototype flow of {lo:.3g} to {hi:.3g} m/s at its "
            f"{p.depth:g} m depth, does"))
    return tuple(out)


def flume_fix(p: Prototype, f: FlumeSpec, lam: float, limits: tuple[FlumeLimit, ...],
              scale_max: float) -> str:
    """What clears every limit of `limits` at once: the smallest whole lambda (checked: the
    flume's discharge, width and the turbulence of the flow at it) or a larger flume."""
    keys = ", ".join(lim.key for lim in limits)
    flume = [f"a flume that supplies at least {lim.model / L_PER_S:.2f} L/s" for lim in limits
             if lim.key == "discharge"]
    flume += [f"one at least {lim.model / MM:.0f} mm wide" for lim in limits
              if lim.key == "width"]
    flume += [f"one that runs Froude {lim.model:.2f}" for lim in limits if lim.key == "froude"]
    if any(lim.min_scale is None for lim in limits):
        return (f"the flume cannot run the scaled test at any scale ({keys}): Froude similitude "
                f"keeps the Froude number; use {' and '.join(flume)}, or a prototype flow "
                "inside the flume's Froude range")
    need = math.ceil(max(lim.min_scale or lam for lim in limits) - 1e-9)
    larger = f"or, at 1:{lam:g}, {' and '.join(flume)}"
    if need > scale_max:
        return (f"no scale up to 1:{scale_max:g} (the similitude's range) clears the flume's "
                f"{keys} limit (it needs 1:{need}); use {' and '.join(flume)}")
    _, _, _, _, reynolds, q = flow_numbers(p.velocity, p.depth, f.width, need)
    laminar = (f"; at 1:{need} the flow is laminar (Re = {reynolds:.0f} < "
               f"{RE_TURBULENT:.0f}), so only the larger flume keeps it turbulent"
               if reynolds < RE_TURBULENT else "")
    return (f"use a scale of 1:{need} or more (the smallest whole one this flume runs: "
            f"{q / L_PER_S:.2f} L/s of its {f.max_discharge / L_PER_S:.2f} L/s, a model "
            f"{p.width / need / MM:.0f} mm wide in its {f.width / MM:.0f} mm) {larger}"
            f"{laminar}")
