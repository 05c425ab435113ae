"""The wave stage of `printgen design`: nets printed with waved strands
(`printgen.barrier.patterns.curved`), searched by the solver on the quantities the flume reads.

What is scored. The paper's flume test reads three sensor wires (barrier-physics.md, section 4:
mid-height elongation at h/h_B = 0.5, 0.8 and 1.0, the cables' at 1.0). A trial net is scored by
its model's readings there against the prototype's (`VERDICT_POINTS`, model / prototype - 1),
its worst point first: the law of the blocked net alone does not say how the barrier shares its
load between the net across (to the walls) and up (to the border cables), nor what the sensors'
pull does at low load, and both decide these readings. The model is swept with the sensors the
prototype file states (`[flume] sensor_force_n`, else the paper's 1 N), as the verification
sweeps it; the prototype is the search's one sweep.

Mechanics the search follows (each a lever, searched, not set):
- the wave softens the net at low load (its strands unbend before they stretch), where the
  sensors' pull holds a straight net back (the mid-height at h/h_B = 0.5);
- a diamond's strands all follow one wave, but its mesh sets how the strand law maps across and
  up: the net strain up reaches a strand as sin^2 of the chord's angle, across as cos^2, so a
  wave straightens across long before up and leaves the net softer up than across. A softer net
  up carries less of the water to the border cables, whose elongation is their tension over
  E A: the top cable reads low. A steeper mesh (larger diagonal up) raises the share up;
- the top sensor's wire runs along the top cable and shares the equilibrium of its sag: its
  pull takes part of the cable's tension, so the cable stretches less than the prototype's,
  by about the pull over the cable's E A (a shallow cable's e (e + F / EA)^2 = e0^3); only
  weaker sensors lift that part (the prototype file's `[flume] sensor_force_n`);
- the material and section set the straightened stiffness the wave softens.

Search, every sweep on the coarse net (`WAVE_COARSEN` times the design's meshes, strands as many
times stiffer: the same membrane stiffness, the waved strands' own curve) at WAVE_LEVEL_STEP:
1. nets: per material, the best-ranked printable net of the screen whose small-strain stiffness
   across is at least the target (a wave only softens at small strain), and the chosen net;
   a net whose softest printable wave is still STIFF_LIMIT x the target across is left out
   (a membrane's strains go as its stiffness^(-2/3): 2 x stiffer reads 37 % low at least;
   the nets' softest waves' strand curves are solved on the runner's workers);
2. on each net, its straight strands and the printable waves by half-wave count in rising
   amplitude, a count's scan stopped once the mid-height at h/h_B = 1 reads more than
   POINT_TOLERANCE high (more amplitude only softens) or the sweep fails;
3. for the best waved trial of each of the MESH_TRIALS best materials: the same section and
   wave (and one amplitude step either side) on every diagonal up of the search space (the
   share up), straight strands too;
4. the FULL_TRIALS best trials and the best straight net are swept on the design's own net at
   the search's levels, with their deformation mismatch (the verification's RMS over every
   level and quantity); among the waved nets that read every point within POINT_TOLERANCE or
   whose mismatch is no higher than the search's chosen straight net's (a wave that mends the
   flume's points only in part must not cost the whole loading), the best is kept when its
   worst point is better than the best straight net's.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from printgen.barrier.patterns import get_pattern
from printgen.barrier.patterns.curved import (
    CurvedStrands,
    check_wave_mm,
    membrane_law,
)
from printgen.errors import GeometryError
from printgen.inputs.materials import load_material
from printgen.scaling.record import Design, NetDesign, Wave
from printgen.scaling.section import net_membrane_law
from printgen.search.space import MESH_DIGITS, SearchSpace, half_cell_counts
from printgen.solver import Law
from printgen.units import MM

WAVE_STEP_MM = 0.25  # amplitude grid: a quarter of a typical 0.4-0.6 mm bead
MAX_HALF_WAVES = 3  # more half-waves bend tighter than a bead allows on these meshes
# The flume's readings (sensor, h / h_B) the paper reports for its 1:40 model (reference,
# section 4: mid-height at 0.5, 0.8 and 1.0, the top cable at 1.0) and the bottom cable beside.
VERDICT_POINTS = (("strain_mid", 0.5), ("strain_mid", 0.8), ("strain_mid", 1.0),
                  ("strain_top", 1.0), ("strain_bottom", 1.0))
POINT_TOLERANCE = 0.20  # a reading within +-20 % of the prototype's counts as matched
WAVE_COARSEN = 2  # screening net: meshes twice coarser (about 7 x faster; on the realistic
# barrier its readings move by up to ~0.1 at h/h_B = 0.5, where the elongations are smallest:
# it ranks, the sweeps on the design's own net decide)
WAVE_LEVEL_STEP = 0.1  # screening sweep's level step: 0.5, 0.8 and 1.0 are levels of it
STIFF_LIMIT = 2.0  # softest printable wave's small-strain stiffness over the target: beyond,
# the readings are at least 2^(-2/3) - 1 = -37 % off (strains ~ stiffness^(-2/3))
MESH_TRIALS = 2  # materials whose best waved trial is tried on every diagonal up
FULL_TRIALS = 5  # best trials swept on the design's own net (some a coarse sweep passes
# fail there: the sensor wires fold over a soft net's shorter segments)
SMALL_STRAIN = 1e-6  # strand strain the straight law's small-strain tangent is read at (its
# first segment; at zero a tension-only law has no tangent)
# The stage's solver work for the run's time estimate, in sweeps of the design's own net: its
# own-net sweeps (the chosen and best straight nets, FULL_TRIALS), and its screening sweeps at
# about a seventh of one each (measured on the realistic barrier at 1:40: about 120 of them).
WAVES_VERIFIED = FULL_TRIALS + 2 + 120 // 7


def point_key(metric: str, level: float) -> str:
    return f"{metric}@{level:g}"


POINT_KEYS = tuple(point_key(m, lv) for m, lv in VERDICT_POINTS)
POINT_LABELS = {"strain_mid": "mid-height", "strain_top": "top cable",
                "strain_bottom": "bottom cable"}


def point_errors(model_levels: np.ndarray, model: dict[str, np.ndarray],
                 proto_levels: np.ndarray, proto: dict[str, np.ndarray]) -> dict[str, float]:
    """model / prototype - 1 at each of VERDICT_POINTS (each barrier's values interpolated
    linearly between its levels; NaN where a barrier did not reach the level)."""
    out = {}
    for metric, level in VERDICT_POINTS:
        vals = []
        for lv, v in ((model_levels, model[metric]), (proto_levels, proto[metric])):
            lv = np.asarray(lv, float)
            vals.append(float(np.interp(level, lv, v)) if lv.size and lv[-1] >= level - 1e-9
                        else math.nan)
        out[point_key(metric, level)] = vals[0] / vals[1] - 1 if vals[1] else math.nan
    return out


def screen_levels() -> np.ndarray:
    """The screening sweep's levels: 0 to the highest point in WAVE_LEVEL_STEP."""
    top = max(level for _, level in VERDICT_POINTS)
    return np.round(np.linspace(0.0, top, round(top / WAVE_LEVEL_STEP) + 1), 10)


@dataclass(frozen=True)
class WaveTask:
    """One solver task of the stage: a design (its net's wave None: straight) swept on its
    meshes `coarsen` times coarser (1: its own net, at the search's levels)."""

    key: str
    design: Design
    coarsen: int


@dataclass(frozen=True)
class Trial:
    """A swept net (its `wave` None: straight): model / prototype - 1 at each VERDICT_POINTS
    key (empty: the sweep failed, `note` says why), the deformation mismatch (RMS over the
    levels and metrics, NaN on the screening net), the sensor force (N per wire) the model
    carried and the net it was swept on (`coarsen`)."""

    net: NetDesign
    errors: dict[str, float] = field(default_factory=dict)
    mismatch: float = math.nan
    sensor_force_n: float = math.nan
    coarsen: int = 1
    note: str = ""

    @property
    def worst(self) -> float:
        """The largest |model / prototype - 1| over the points (inf: not swept through)."""
        vals = [abs(v) for v in self.errors.values()]
        return max(vals) if vals and all(math.isfinite(v) for v in vals) else math.inf

    @property
    def matched(self) -> bool:
        return self.worst <= POINT_TOLERANCE

    def key(self) -> tuple:
        """Rank: worst point, then RMS of the points, then the net (deterministic)."""
        rms = math.sqrt(sum(v * v for v in self.errors.values()) / len(self.errors)) \
            if math.isfinite(self.worst) else math.inf
        w = self.net.wave
        return (round(self.worst, 9), round(rms, 9), self.net.material,
                self.net.strand.beads_across, len(self.net.strand.layer_heights_mm),
                self.net.mesh_x_mm, self.net.mesh_y_mm,
                (0.0, 0) if w is None else (w.amplitude_mm, w.half_waves))

    def label(self) -> str:
        n, w = self.net, self.net.wave
        wave = "straight" if w is None else f"{w.amplitude_mm:g} mm x {w.half_waves}"
        return (f"{n.material} {n.strand.beads_across}x{len(n.strand.layer_heights_mm)}, "
                f"{n.mesh_x_mm:.4g} x {n.mesh_y_mm:.4g} mm, {wave}")

    def readings(self) -> str:
        if not self.errors:
            return self.note or "not swept"
        return ", ".join(f"{POINT_LABELS[k.split('@')[0]]} {k.split('@')[1]} {v:+.0%}"
                         for k, v in self.errors.items())

    def to_record(self) -> dict:
        w = self.net.wave
        return {"material": self.net.material, "beads_across": self.net.strand.beads_across,
                "layers": len(self.net.strand.layer_heights_mm),
                "mesh_x_mm": self.net.mesh_x_mm, "mesh_y_mm": self.net.mesh_y_mm,
                "wave": None if w is None else dataclasses.asdict(w),
                "errors": self.errors, "worst": self.worst if math.isfinite(self.worst)
                else None, "mismatch": None if math.isnan(self.mismatch) else self.mismatch,
                "coarsen": self.coarsen, "note": self.note}


Sweeper = Callable[[list[WaveTask]], list[Trial]]
# (fn, items) -> [fn(None, item) for item in items], in order: the runner's map
Ratios = Callable[[Callable[[Any, Any], float], list[Any]], list[float]]


def printable_waves(n: NetDesign) -> list[Wave]:
    """Every wave of the grid (amplitudes in WAVE_STEP_MM, 1 to MAX_HALF_WAVES half-waves)
    that `check_wave_mm` lets print on net `n`, by half-waves then amplitude."""
    out = []
    s = n.strand
    for k in range(1, MAX_HALF_WAVES + 1):
        a = WAVE_STEP_MM
        while True:
            try:
                check_wave_mm(n.pattern, a, k, s.bead_width_mm, s.beads_across, n.mesh_x_mm,
                              n.mesh_y_mm)
            except GeometryError:
                break
            out.append(Wave(round(a, 6), k))
            a += WAVE_STEP_MM
    return out


def straight_law(n: NetDesign) -> Law:
    """The straight strands' law of net `n` (the material's membrane law up the barrier,
    `net_membrane_law`, turned into its pattern's strand law), N per unit strain."""
    up, across = n.mesh_y_mm * MM, n.mesh_x_mm * MM
    knees, slopes, _ = net_membrane_law(load_material(n.material), n.strand, up, across,
                                        n.pattern)
    return get_pattern(n.pattern).strand_law(knees, slopes, up, across)


def softest_across(n: NetDesign, waves: Sequence[Wave]) -> float:
    """The small-strain membrane stiffness across the barrier (N/m, blocked infinite net) of
    net `n` with the softest of `waves` (the largest amplitude of each half-wave count)."""
    law = straight_law(n).scaled(1.0 / (n.strand.area_mm2 * MM * MM))
    s = n.strand
    top: dict[int, float] = {}
    for w in waves:
        top[w.half_waves] = max(top.get(w.half_waves, 0.0), w.amplitude_mm)
    return min(membrane_law(n.pattern, CurvedStrands(a, k, s.bead_width_mm, s.beads_across,
                                                     s.thickness_mm, law),
                            n.mesh_x_mm * MM, n.mesh_y_mm * MM).low_slope
               for k, a in top.items())


def with_net(d: Design, n: NetDesign) -> Design:
    return dataclasses.replace(d, net=n)


def with_wave(d: Design, w: Wave | None) -> Design:
    """Design `d` with its net's strands waved by `w` (None: straight)."""
    return dataclasses.replace(d, net=dataclasses.replace(d.net, wave=w))


def with_mesh_y(n: NetDesign, ny: int) -> NetDesign:
    """Net `n` with `ny` half-diagonals up its height (its diagonal up 2 H / ny)."""
    return dataclasses.replace(n, mesh_y_mm=round(2 * n.height_mm / ny, MESH_DIGITS))


@dataclass(frozen=True)
class WaveChoice:
    """The wave stage's outcome: the screening trials (coarse net, best first), the full-net
    trials, the chosen straight net's and the best straight net's full-net trials, the kept
    trial (None: no waved net beats the best straight one), the nets left out and why."""

    trials: tuple[Trial, ...]
    full: tuple[Trial, ...]
    chosen_straight: Trial
    best_straight: Trial
    kept: Trial | None
    left_out: tuple[str, ...] = ()

    def design(self, d: Design) -> Design:
        """Design `d` with the kept net (its mesh and wave), or `d` itself."""
        return d if self.kept is None else with_net(d, self.kept.net)

    def sentence(self) -> str:
        if not self.trials:
            return "waved strands: no printable wave on the nets tried"
        force = self.best_straight.sensor_force_n
        head = (f"waved strands: {len(self.trials)} nets swept on a {WAVE_COARSEN} x coarser "
                f"net and {len(self.full)} on their own, scored by the flume's readings "
                f"(sensors pulling {force:.3g} N each: sensor_force_n of the prototype file's "
                "flume table, else the paper's) against the prototype's; best straight net "
                f"{self.best_straight.label()}: {self.best_straight.readings()}")
        if self.kept is None:
            return (f"{head}; no waved net reads closer, within +-{POINT_TOLERANCE:.0%} or with "
                    "a deformation mismatch no higher than the chosen straight net's "
                    f"({self.chosen_straight.mismatch:.3f}): the straight strands are kept")
        within = "all within" if self.kept.matched else "not all within"
        return (f"{head}; printed with {self.kept.label()}: {self.kept.readings()} "
                f"({within} +-{POINT_TOLERANCE:.0%})")

    def to_record(self) -> dict:
        return {"points": [{"sensor": m, "level": lv} for m, lv in VERDICT_POINTS],
                "tolerance": POINT_TOLERANCE, "screen_coarsen": WAVE_COARSEN,
                "screen_level_step": WAVE_LEVEL_STEP,
                "trials": [t.to_record() for t in self.trials],
                "full_net": [t.to_record() for t in self.full],
                "chosen_straight": self.chosen_straight.to_record(),
                "best_straight": self.best_straight.to_record(),
                "kept": None if self.kept is None else self.kept.to_record(),
                "left_out": list(self.left_out)}


def wave_nets(chosen: Design, candidates: Iterable[tuple[Design, float]],
              ratios: Ratios | None = None) -> tuple[list[NetDesign], list[str]]:
    """The nets the stage waves (see the module, step 1): `candidates` are the screen's
    printable nets, best-ranked first, each with its small-strain stiffness across over the
    target's, less 1 (the screen's); returns the nets and the sentences of those left out.
    `ratios` maps `softest_ratio` over the nets tried (each solves its waves' strand curves:
    the runner's workers; None: here, in turn)."""
    tried, seen = [], {chosen.net.material}
    for d, error_across in candidates:
        n = d.net
        if n.material in seen or error_across < 0:  # a wave only softens the net
            continue
        if not printable_waves(n):
            continue
        seen.add(n.material)
        tried.append((n, error_across))
    if ratios is None:
        soft = [softest_ratio(None, item) for item in tried]
    else:
        soft = ratios(softest_ratio, tried)
    nets, out = [chosen.net], []
    for (n, _), ratio in zip(tried, soft, strict=True):
        if ratio > STIFF_LIMIT:
            out.append(f"{n.material}: its softest printable wave is still {ratio:.3g} x the "
                       f"target stiffness across (limit {STIFF_LIMIT:g})")
            continue
        nets.append(n)
    return nets, out


def softest_ratio(_: Any, item: tuple[NetDesign, float]) -> float:
    """The small-strain stiffness across of net `item[0]` with its softest printable wave over
    the target's (`item[1]`: the straight net's over the target's, less 1). A worker job:
    module-level, pure."""
    n, error_across = item
    return softest_across(n, printable_waves(n)) / membrane_across(n) * (1 + error_across)


def membrane_across(n: NetDesign) -> float:
    """The straight net's small-strain membrane stiffness across the barrier (N/m)."""
    law = straight_law(n)
    pat = get_pattern(n.pattern)
    return pat.membrane_factor(n.mesh_x_mm * MM, n.mesh_y_mm * MM) * \
        law.force_and_tangent(np.array([SMALL_STRAIN]))[1][0]


def wave_stage(chosen: Design, candidates: Iterable[tuple[Design, float]],
               space: SearchSpace, sweep: Sweeper, ratios: Ratios | None = None) -> WaveChoice:
    """The stage (see the module): `chosen` the search's straight net, `candidates` the
    screen's printable nets best-ranked first with their stiffness across over the target's
    less 1, `space` its bounds, `sweep` the solver (tasks -> trials, in order), `ratios` where
    step 1's strand curves are solved (`wave_nets`)."""
    nets, left_out = wave_nets(chosen, candidates, ratios)
    base = chosen

    def run(items: list[NetDesign], coarsen: int = WAVE_COARSEN) -> list[Trial]:
        tasks = [WaveTask(str(i), with_net(base, n), coarsen) for i, n in enumerate(items)]
        return sweep(tasks) if tasks else []

    trials: dict[NetDesign, Trial] = {}

    def add(items: list[NetDesign]) -> list[Trial]:
        new = [n for n in dict.fromkeys(items) if n not in trials]
        for n, r in zip(new, run(new), strict=True):
            trials[n] = r
        return [trials[n] for n in items]

    # step 2: straight strands, then each half-wave count's amplitudes in rising order
    add([dataclasses.replace(n, wave=None) for n in nets])
    lanes = {(n, k): [w for w in printable_waves(n) if w.half_waves == k]
             for n in nets for k in range(1, MAX_HALF_WAVES + 1)}
    lanes = {key: ws for key, ws in lanes.items() if ws}
    step = 0
    while lanes:
        batch = {key: dataclasses.replace(key[0], wave=ws[step]) for key, ws in lanes.items()}
        done = dict(zip(batch, add(list(batch.values())), strict=True))
        step += 1
        lanes = {key: ws for key, ws in lanes.items()
                 if step < len(ws) and not _overshot(done[key])}
    # step 3: the best trials' section and wave on every diagonal up
    heights = half_cell_counts(chosen.net.height_mm, space.mesh_y_mm)
    for best in best_per_material(trials.values())[:MESH_TRIALS]:
        w = best.net.wave
        assert w is not None
        steps = [Wave(round(w.amplitude_mm + d * WAVE_STEP_MM, 6), w.half_waves)
                 for d in (-1, 0, 1) if w.amplitude_mm + d * WAVE_STEP_MM > 0]
        items = []
        for ny in heights:
            n = with_mesh_y(best.net, ny)
            fits = set(printable_waves(n))
            items += [dataclasses.replace(n, wave=None)] + \
                [dataclasses.replace(n, wave=s) for s in steps if s in fits]
        add(items)
    ranked = sorted(trials.values(), key=Trial.key)
    # step 4: the design's own net
    straight = min((r for r in ranked if r.net.wave is None), key=Trial.key)
    picks = [r.net for r in ranked if r.net.wave is not None][:FULL_TRIALS]
    own = [chosen.net, straight.net, *picks]
    unique = list(dict.fromkeys(own))
    full = dict(zip(unique, run(unique, 1), strict=True))
    best_straight = min((full[chosen.net], full[straight.net]), key=Trial.key)
    limit = full[chosen.net].mismatch
    waved = sorted((full[n] for n in picks if full[n].matched or not full[n].mismatch > limit),
                   key=Trial.key)
    kept = waved[0] if waved and waved[0].key() < best_straight.key() else None
    return WaveChoice(tuple(ranked), tuple(sorted(full.values(), key=Trial.key)),
                      full[chosen.net], best_straight, kept, tuple(left_out))


def best_per_material(trials: Iterable[Trial]) -> list[Trial]:
    """The best waved trial of each material, best first."""
    best: dict[str, Trial] = {}
    for r in sorted((r for r in trials if r.net.wave is not None), key=Trial.key):
        best.setdefault(r.net.material, r)
    return sorted(best.values(), key=Trial.key)


def _overshot(r: Trial) -> bool:
    """True when a lane's scan can stop: the sweep failed, or the mid-height at h/h_B = 1
    reads more than POINT_TOLERANCE high (a larger amplitude only softens the net)."""
    mid = r.errors.get(point_key("strain_mid", 1.0), math.nan)
    return not r.errors or not math.isfinite(mid) or mid > POINT_TOLERANCE
