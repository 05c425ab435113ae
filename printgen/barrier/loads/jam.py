"""A barrier partly clogged by woody debris: a porous log jam of porosity n, thickness L (in
the flow direction) and log diameter D resting against the net, the whole flow seeping
through the jam and then the net (the paper's log test: flowing water and logs instead of the
film give smaller elongations, because water seeps through the logs; barrier-physics.md,
section 4; Lambert et al. 2023, doi:10.1061/JHEND8.HYENG-13070).

At upstream depth h_u = r h_B the discharge per unit width q that passes solves
    h_u - h_m = L i(U),   U = q / ((h_u + h_m) / 2)            (through the jam)
    h_m - h_d = 0.5 U_n^2 k / g,   U_n = q / h_m,  k = l d / A*  (through the net: its drag)
    h_d = (q^2 / (g Fr_t^2))^(1/3)                                (tailwater at Froude Fr_t)
with Ergun's law for the head gradient of a packed bed (Ergun 1952, Chem. Eng. Prog. 48(2),
89), i = 150 nu (1-n)^2 U / (g n^3 D_p^2) + 1.75 (1-n) U^2 / (g n^3 D_p), for logs the
surface-volume diameter of a long cylinder D_p = 1.5 D. The net carries the jam's head
difference, rho g [(h_u - z)+ - (h_m - z)+] A* (the logs press it on: the momentum balance of
a channel-spanning log jam, whose drag is the head difference across it; Schalko, Follett and
Nepf 2023, Water Resour. Res., doi:10.1029/2023WR034689, and the work it builds on), plus the
drag 0.5 rho U_n^2 l d of the water through its strands below h_m. Porosity 0: nothing seeps
(q = 0), the load is the hydrostatic case's; porosity towards 1: the jam vanishes, the load
tends to drag only (the barrier in free flow).

The load levels are the flume's discharge steps (the paper's log test at 1:40: 2 to 8 L/s):
each step's upstream depth on the printed model; a step the jam holds above the overflow
(h/h_B = 1.1) is read at the overflow, where the seepage alone is modelled. Jam sizes are
given at the prototype's scale and scaled by Froude (lengths / lambda) on the model. Ergun's
data reach a modified Reynolds number U D_p / (nu (1 - n)) of about 4200 (recorded per level
as `jam_reynolds`); above it only the quadratic (Forchheimer, turbulent) term matters, and
that term is Reynolds-free, so the law is extrapolated in its turbulent form, the same at
both scales.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from printgen import solver
from printgen.barrier.loads import (
    FLOW,
    OVERFLOW,
    LoadCase,
    LoadsAt,
    Param,
    SceneView,
    Site,
    hydrostatic,
)
from printgen.barrier.loads.drag import strand_drag, strand_per_node
from printgen.units import L_PER_S, NU_WATER, RHO_WATER, G

DISCHARGES_L_PER_S = (2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0)  # the flume's steps (paper, 1:40)
CYLINDER_DP = 1.5  # surface-volume diameter of a long cylinder / its diameter (6 V / S)
NEWTON_STEPS = 30  # the net's head loss: Newton steps on a convex cubic (converges in < 10)
BEHIND = tuple(-x for x in FLOW)  # the water between jam and net pushes upstream
ROOT_TOL = 1e-12  # m (depth) and m^2/s (discharge per width): far below any flume reading
PARAMS = (Param("porosity", 0.6, 0.0, 0.99, "(void fraction)", "jam porosity"),
          Param("thickness_m", 4.0, 0.01, 50.0, "m at the prototype's scale",
                "jam thickness in the flow direction"),
          Param("log_diameter_m", 0.4, 0.005, 3.0, "m at the prototype's scale",
                "log diameter"),
          Param("tailwater_froude", 1.0, 0.2, 2.0, "", "tailwater Froude number"))


def ergun_gradient(u: float, porosity: float, log_d: float) -> float:
    """Head lost per metre of jam (-) at superficial velocity u (m/s): Ergun's law."""
    n, dp = porosity, CYLINDER_DP * log_d
    lam = 150.0 * NU_WATER * (1 - n) ** 2 * u / (n**3 * dp**2)
    return (lam + 1.75 * (1 - n) * u * u / (n**3 * dp)) / G


def net_factor(s: SceneView) -> float:
    """l / A* (1/m): strand length per unit net area; times d, the strands' frontal area
    per unit net area."""
    return strand_per_node(s) / s.area_per_node


def behind_net(q: float, k: float, froude: float) -> tuple[float, float]:
    """(h_m, h_d): depth between jam and net and the tailwater for discharge q per width."""
    if q <= 0:
        return 0.0, 0.0
    hd = (q * q / (G * froude**2)) ** (1 / 3)
    c = 0.5 * q * q * k / G  # h_m^2 (h_m - h_d) = c
    h = hd + c ** (1 / 3)  # right of the root: Newton then descends monotonically
    for _ in range(NEWTON_STEPS):
        step = (h**3 - hd * h * h - c) / (3 * h * h - 2 * hd * h)
        h -= step
        if abs(step) < ROOT_TOL:
            break
    return h, hd


def seepage(hu: float, k: float, porosity: float, thickness: float, log_d: float,
            froude: float) -> tuple[float, float, float]:
    """(q, h_m, h_d) at upstream depth hu: the discharge per width the jam and net pass."""
    if hu <= 0 or porosity <= 0:
        return 0.0, 0.0, 0.0

    def excess(q: float) -> float:
        hm, _ = behind_net(q, k, froude)
        return hu - hm - thickness * ergun_gradient(2 * q / (hu + hm), porosity, log_d)

    q = _root(excess, 0.0, froude * math.sqrt(G * hu**3))
    return (q, *behind_net(q, k, froude))


def _root(f, low: float, high: float) -> float:
    """The root of `f` in [low, high] to ROOT_TOL (brentq). scipy.optimize is imported here,
    not with the module: every command that takes --load imports each load case for its help
    text, and scipy.optimize alone is about 0.1 s of it."""
    from scipy.optimize import brentq

    return float(brentq(f, low, high, xtol=ROOT_TOL))


def _jam(s: SceneView, site: Site, values: dict[str, float]) -> dict[str, float]:
    """The jam at this barrier's scale (SI), its net factor and its flow width."""
    return {"k": net_factor(s) * site.strand_diameter, "porosity": values["porosity"],
            "thickness": values["thickness_m"] / site.scale,
            "log_d": values["log_diameter_m"] / site.scale, "froude": values["tailwater_froude"]}


def loads(s: SceneView, site: Site, **values: float) -> LoadsAt:
    """The jam's head difference on the free nodes at their current height, and the drag of
    the seepage through the strands below h_m."""
    jam = _jam(s, site, values)
    free = np.flatnonzero(~s.fixed)
    upstream = hydrostatic.loads(s, site)
    drag_at = strand_drag(s, site.strand_diameter)

    def loads_at(r: float) -> list:
        q, hm, _ = seepage(r * s.height, **jam)
        return [*upstream(r),
                solver.Hydrostatic(free, s.area_per_node, hm, BEHIND, rho=RHO_WATER, g=G),
                drag_at(hm / s.height, q / hm if hm > 0 else 0.0)]

    return loads_at


def levels(s: SceneView, site: Site, **values: float) -> np.ndarray:
    """0 and the upstream depth / h_B of each discharge step on this barrier (the flume's
    printed model); steps held above the overflow are read at OVERFLOW."""
    jam = _jam(s, site, values)
    width = site.flow_width or s.width
    top = OVERFLOW * s.height
    out = [0.0]
    q_top = seepage(top, **jam)[0]  # the most the jam passes below the overflow
    for discharge in DISCHARGES_L_PER_S:
        q = discharge * L_PER_S / width
        if q_top < q:
            out.append(OVERFLOW)
            continue
        low = behind_net(q, jam["k"], jam["froude"])[0]  # no jam passes q below this
        hu = _root(lambda h, q=q: seepage(h, **jam)[0] - q, low, top)
        out.append(hu / s.height)
    return np.unique(np.round(out, 10))


def per_level(s: SceneView, site: Site, lv: np.ndarray, **values: float
              ) -> tuple[dict[str, Any], str]:
    """Discharge (L/s through this barrier's flow width), depths and velocities at each level."""
    jam = _jam(s, site, values)
    width = site.flow_width or s.width
    rows = [seepage(float(r) * s.height, **jam) for r in lv]
    q = np.array([x[0] for x in rows])
    hm, hd = np.array([x[1] for x in rows]), np.array([x[2] for x in rows])
    hu = np.asarray(lv, dtype=float) * s.height
    u_net = np.divide(q, hm, out=np.zeros_like(q), where=hm > 0)
    u_jam = np.divide(2 * q, hu + hm, out=np.zeros_like(q), where=hu > 0)
    n = jam["porosity"]
    reynolds = u_jam * CYLINDER_DP * jam["log_d"] / (NU_WATER * (1 - n))  # n <= 0.99
    rec = {"discharge_l_per_s": q * width / L_PER_S, "upstream_depth_m": hu,
           "depth_behind_jam_m": hm, "tailwater_depth_m": hd,
           "jam_head_loss_m": hu - hm, "velocity_through_net_m_per_s": u_net,
           "jam_reynolds": reynolds,
           "flow_width_m": width, "jam_thickness_m": jam["thickness"],
           "log_diameter_m": jam["log_d"], "porosity": jam["porosity"]}
    text = (f"porosity {jam['porosity']:g}, {jam['thickness']:.4g} m thick, logs "
            f"{jam['log_d']:.4g} m; discharge {rec['discharge_l_per_s'][-1]:.4g} L/s at h/h_B = "
            f"{float(lv[-1]):g} over {width:.4g} m")
    return rec, text


CASE = LoadCase(
    "jam", "log jam: seepage through a porous jam and the net (discharge steps)", loads,
    (("loading: jam", ("a porous log jam against the net: its head difference rho g [(h_u - "
      "z)+ - (h_m - z)+] A* at the current node height, plus the drag 0.5 rho U_n^2 l d of the "
      "seepage through the strands below h_m; the seepage by Ergun's law (logs as a packed bed "
      "of diameter 1.5 D), tailwater at the stated Froude number; no overflow modelled; levels "
      "= upstream depths of the flume's discharge steps 2 to 8 L/s on the printed model"),
      ("Lambert et al. 2023: log test (discharge raised stepwise, water seeps through the "
       "logs); Ergun 1952 (Chem. Eng. Prog. 48(2) 89); Schalko, Follett & Nepf 2023 (WRR, "
       "doi:10.1029/2023WR034689): momentum balance of a log jam")),),
    params=PARAMS, levels=levels, per_level=per_level)
