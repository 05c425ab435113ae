"""Normalised deformations of a barrier along a load path, and prototype-vs-model mismatch
(barrier-physics.md, section 6: deformation normalised by each barrier's own dimensions,
compared over the whole loading range, not at one point)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from printgen.scene.scenes import BarrierScene, Wire, sensor_wires
from printgen.scene.solvernet import path_length

# Normalised quantities compared between prototype and model, with their labels.
METRICS = {
    "deflection": "mid-height deflection / width",
    "lowering": "top-centre lowering / height",
    "strain_bottom": "bottom cable elongation (sensor wire, strain)",
    "strain_top": "top cable elongation (sensor wire, strain)",
    "strain_mid": "elongation at mid-height (sensor wire, strain)",
}
TOLERANCE = 0.25  # max mismatch / prototype peak allowed: the paper's model matched to ~25 %
UPPER_RANGE = 0.8  # relative loading above which a mismatch is reported as "at high loading"


@dataclass(frozen=True)
class Deformation:
    """Normalised deformations at each relative loading (levels: (k,) h / h_B)."""

    levels: np.ndarray
    values: dict[str, np.ndarray]  # METRICS key -> (k,)
    max_strand_tension: np.ndarray  # (k,) N
    max_cable_tension: np.ndarray  # (k,) N

    def only(self, keep: np.ndarray) -> Deformation:
        """The deformations at the levels `keep` (a (k,) boolean mask) selects."""
        return Deformation(self.levels[keep], {k: v[keep] for k, v in self.values.items()},
                           self.max_strand_tension[keep], self.max_cable_tension[keep])


def row_strain(x0: np.ndarray, x: np.ndarray) -> float:
    """Elongation of the polyline through a row of nodes: length / initial length - 1."""
    def length(p: np.ndarray) -> float:
        return float(np.linalg.norm(np.diff(p, axis=0), axis=1).sum())
    return length(x) / length(x0) - 1.0


def wire_elongation(x0: np.ndarray, x: np.ndarray, wire: Wire) -> float:
    """What a sensor reads, as a strain: the change of its wire's length (anchor, over the
    row's nodes, to the potentiometer) over the row's rest length."""
    rest = path_length(x0, wire.nodes, wire.exit)
    row = rest - float(np.linalg.norm(wire.exit - x0[wire.nodes[-1]]))
    return (path_length(x, wire.nodes, wire.exit) - rest) / row


def sensor_elongation(x0: np.ndarray, x: np.ndarray, wires: list[Wire]) -> float:
    """What a sensor read from one or two rows' wires reads, as a strain: the wires' changes
    of length weighted by their `weight` (linear interpolation in z between the rows), over
    their rest lengths along the rows weighted alike (one wire: `wire_elongation`)."""
    change = rows = 0.0
    for w in wires:
        rest = path_length(x0, w.nodes, w.exit)
        change += w.weight * (path_length(x, w.nodes, w.exit) - rest)
        rows += w.weight * (rest - float(np.linalg.norm(w.exit - x0[w.nodes[-1]])))
    return change / rows


def mid_deflection(scene: BarrierScene, x0: np.ndarray, x: np.ndarray) -> float:
    """Deflection at mid-height in the flow direction / width: the centre nodes of the rows
    that bracket h/2, linearly interpolated in z as the mid-height sensor is (else `centre`)."""
    centres = scene.mid_centres or ((scene.centre, 1.0),)
    return sum(wt * float(x[c, 1] - x0[c, 1]) for c, wt in centres) / scene.width


def deformation(scene: BarrierScene, levels: np.ndarray, positions: list[np.ndarray],
                strand_tension: list[np.ndarray], cable_tension: list[np.ndarray]) -> Deformation:
    """Normalised deformation of `scene` for each solved state (positions (n, 3) m)."""
    x0 = scene.nodes
    vals: dict[str, list[float]] = {k: [] for k in METRICS}
    for x in positions:
        vals["deflection"].append(mid_deflection(scene, x0, x))
        vals["lowering"].append(-(x[scene.top_centre, 2] - x0[scene.top_centre, 2]) / scene.height)
        for row in ("bottom", "top", "mid"):
            vals[f"strain_{row}"].append(
                sensor_elongation(x0, x, sensor_wires(scene.wires, row)))
    return Deformation(np.asarray(levels, float), {k: np.array(v) for k, v in vals.items()},
                       np.array([t.max() if t.size else 0.0 for t in strand_tension]),
                       np.array([t.max() if t.size else 0.0 for t in cable_tension]))


@dataclass(frozen=True)
class Mismatch:
    """Model vs prototype for one metric, relative to the prototype's peak value."""

    metric: str
    max_rel: float
    rms_rel: float
    worst_level: float
    ratio_high: float  # model / prototype, mean over relative loading >= UPPER_RANGE
    ok: bool


def compare(proto: Deformation, model: Deformation, *, tolerance: float = TOLERANCE
            ) -> list[Mismatch]:
    """Mismatch of every metric over the whole loading range."""
    if not np.allclose(proto.levels, model.levels):
        raise ValueError("prototype and model were solved at different relative loadings")
    out = []
    for key in METRICS:
        p, m = proto.values[key], model.values[key]
        peak = float(np.abs(p).max())
        if peak == 0.0:
            continue
        diff = np.abs(m - p) / peak
        high = proto.levels >= UPPER_RANGE - 1e-12
        with np.errstate(divide="ignore", invalid="ignore"):
            ratio = float(np.nanmean(m[high] / p[high])) if high.any() else float("nan")
        out.append(Mismatch(key, float(diff.max()), float(np.sqrt(np.mean(diff**2))),
                            float(proto.levels[int(diff.argmax())]), ratio,
                            bool(diff.max() <= tolerance)))
    return out


def explain(mismatches: list[Mismatch]) -> list[str]:
    """One sentence per failing metric: how far off, where, and which way."""
    out = []
    for mm in mismatches:
        if mm.ok:
            continue
        way = "too stiff" if mm.metric != "lowering" and mm.ratio_high < 1 else "too soft"
        if mm.metric == "lowering":
            way = "lowers too little" if mm.ratio_high < 1 else "lowers too much"
        out.append(f"{METRICS[mm.metric]}: model {mm.ratio_high:.2f}x the prototype above "
                   f"h/h_B = {UPPER_RANGE:g} ({way}); worst mismatch {mm.max_rel:.0%} of the "
                   f"prototype peak at h/h_B = {mm.worst_level:.2f}")
    return out


def increments(d: Deformation) -> Deformation:
    """The deformation counted from the first level (h / h_B = 0): what extension sensors
    zeroed before the water arrives read."""
    return Deformation(d.levels, {k: v - v[0] for k, v in d.values.items()},
                       d.max_strand_tension, d.max_cable_tension)


def headlines(mismatches: list[Mismatch], *, tolerance: float = TOLERANCE) -> list[str]:
    """The verdict's sentences: one when the model matches, else one per direction of error,
    each naming its quantities and by how much they are off (model / prototype above h/h_B =
    UPPER_RANGE; every quantity is a deformation, so less is stiffer). A model off both ways
    gets two sentences, never one that says "too stiff" and "too soft" at once."""
    known = [m for m in mismatches if np.isfinite(m.ratio_high)]
    bad = [m for m in known if not m.ok]
    if not known:
        return ["no deformation to compare"]
    if not bad:
        lo, hi = min(m.ratio_high for m in known), max(m.ratio_high for m in known)
        return [f"model within {tolerance:.0%} of the prototype's peak on all {len(mismatches)} "
                f"quantities; it deforms {lo:.2f}x to {hi:.2f}x the prototype above h/h_B = "
                f"{UPPER_RANGE:g}"]
    out = []
    for way, less, group in (("stiff", True, [m for m in bad if m.ratio_high < 1]),
                             ("soft", False, [m for m in bad if m.ratio_high >= 1])):
        if not group:
            continue
        offs = [abs(m.ratio_high - 1) for m in group]
        least, most = f"{min(offs):.0%}", f"{max(offs):.0%}"
        by = least if least == most else f"{least} to {most}"
        names = ", ".join(METRICS[m.metric].split(" (")[0] for m in group)
        out.append(f"model too {way} in {len(group)} of {len(mismatches)} quantities ({names}): "
                   f"deforms {by} {'less' if less else 'more'} than the prototype above h/h_B = "
                   f"{UPPER_RANGE:g} (off by more than {tolerance:.0%} of the prototype's peak)")
    return out
