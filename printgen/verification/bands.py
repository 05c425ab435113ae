"""Uncertainty bands of the pre-print check: the printed model swept for its nominal design
and for each uncertain input it depends on, one at a time, and the min/max envelope of the
normalised deformations at every relative loading.

The variants of the printed model, as data, and their list: `printgen.verification.variants`.

Cheap sweeps: the variants run on the coarsest solver net (the design's mesh times k, k in
`COARSENINGS`, strands k times stiffer: the same membrane stiffness per unit width) whose
nominal curves stay within `REFINE_TOL` of the design's own net (the refinement test, run
with the nominal); a variant's curve is then the nominal curve plus the variant's change on
the coarse net. Every sweep warm-starts each level from the previous one (solver.solve_path),
a variant on the nominal's own net also from the nominal's state at that level (`warm_start`),
and the runs go to worker processes in parallel.

A variant the solver refuses (its sensor wires fold the net, or too few levels converge:
`SolverError`) has no curves: it is recorded with the solver's reason (`Band.refused`) and
carries no weight in the central interval, and the verdict cannot be PASS while such an input
is plausible (`printgen.verification.decide`): under it the test cannot run as designed.
"""

from __future__ import annotations

import dataclasses
import time
from collections.abc import Callable
from concurrent.futures import Future
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from printgen.barrier.loads import LoadCase
from printgen.errors import GeometryError, SolverError
from printgen.executor.local import collect, submit_jobs
from printgen.inputs.prototype import Prototype
from printgen.scaling.record import Design
from printgen.scene.options import SceneOptions, build_scene
from printgen.trace import span
from printgen.verification.central import Contribution, central_interval
from printgen.verification.compare import METRICS
from printgen.verification.preprint import Run, States, from_states, load_keywords, sweep
from printgen.verification.sensors import scene_sensor_force
from printgen.verification.variants import Variant, model_variants, prototype_variants

COARSENINGS = (2, 3)  # mesh multipliers tried in turn for the variant sweeps
REFINE_TOL = 0.01  # a coarser net is used when no nominal curve moves by more than 1 % of its peak


def model_load_kw(p: Prototype, d: Design, load: str | LoadCase | None = None
                  ) -> dict[str, Any]:
    """The model's load keywords for `sweep` under load case `load`, as `verify` loads it."""
    return load_keywords(p, d, load)[1]


def run_variant(d: Design, v: Variant, lv: np.ndarray, coarsen: int = 1,
                load_kw: dict | None = None, start: States | None = None) -> Run:
    """Sweep the model with variant `v` on the design's mesh times `coarsen` (a worker job:
    module-level, picklable); `start`: the nominal's states (`warm_start`)."""
    scene = build_scene(d, dataclasses.replace(v.options, coarsen=coarsen))
    return sweep(scene, lv, slack=v.slack, guesses=from_states(start), **(load_kw or {}))


def warm_start(v: Variant, nominal: Run, coarsen: int = 1) -> States | None:
    """The nominal run's state at each level, one more start for variant `v`'s sweep there
    (`solver.solve_path`: the solver begins from the lowest potential of its starts, so the
    answer is the equilibrium it converges to, within its tolerance, whichever start it took;
    held at rest where the variant's net is held, `solver.solve_path`), on the nominal's own net
    only (the nodes must be the same, node for node), and not for a slack variant: slack
    moves every strand's rest length, and from the taut net's state a slack net can settle in
    another equilibrium (measured on the 1:40 prototype: curves 24 % of their peak apart),
    which the path from rest does not."""
    if coarsen != 1 or v.slack or not nominal.states:
        return None
    return nominal.states


@dataclass(frozen=True)
class Refused:
    """A variant's sweep the solver refused, with its reason (the SolverError's message)."""

    reason: str


def try_variant(d: Design, v: Variant, lv: np.ndarray, coarsen: int = 1,
                load_kw: dict | None = None, start: States | None = None) -> Run | Refused:
    """`run_variant`, with a refusal of the solver returned as `Refused` (a worker job)."""
    try:
        return run_variant(d, v, lv, coarsen, load_kw, start)
    except SolverError as e:
        return Refused(str(e))


def curves(run: Run) -> dict[str, np.ndarray]:
    """The run's normalised deformations, NaN at the levels that did not converge."""
    d = run.deformation
    bad = np.isin(d.levels, list(run.failed))
    return {k: np.where(bad, np.nan, d.values[k]) for k in METRICS}


@dataclass(frozen=True)
class Band:
    """The printed model's nominal curves and each variant's, on the design's own net.

    levels : (k,) h / h_B; nominal and variants[label] : METRICS key -> (k,), NaN where a
    sweep did not converge; coarsen : mesh multiplier the variants ran on (1: the design's
    net); refinement : multiplier -> largest change of a nominal curve, fraction of its peak.
    """

    levels: np.ndarray
    nominal: dict[str, np.ndarray]
    variants: dict[str, dict[str, np.ndarray]]
    sources: dict[str, str]
    notes: list[str]
    coarsen: int
    refinement: dict[int, float]
    seconds: float = 0.0
    failed: dict[str, list[float]] = field(default_factory=dict)
    mounting: str | None = None  # the nominal run's mounting, kept by every variant
    work: list[dict[str, Any]] = field(default_factory=list)  # Run.work() of every sweep run
    sensor_force: float | None = None  # N per sensor wire of the nominal run, kept by every variant
    info: dict[str, Variant] = field(default_factory=dict)  # label -> its variant (weights)
    data_excluded: dict[str, str] = field(default_factory=dict)  # label -> the data's reason
    refused: dict[str, str] = field(default_factory=dict)  # label -> the solver's reason

    @property
    def excluded(self) -> dict[str, str]:
        """label -> why the variant carries no weight: its own reason (the material, the
        geometry), the solver's refusal (no curves), or the lab's data
        (`printgen.verification.measured.excluded_by_data`)."""
        out = {k: v.excluded for k, v in self.info.items() if v.excluded}
        for k, r in self.refused.items():
            out[k] = "; ".join(x for x in (out.get(k, ""), f"the solver refused it: {r}") if x)
        for k, r in self.data_excluded.items():
            out[k] = "; ".join(x for x in (out.get(k, ""), f"excluded by the data: {r}") if x)
        return out

    def weighted(self) -> list[str]:
        """The labels of the variants that carry weight in the central interval."""
        out = self.excluded
        return [k for k, v in self.info.items() if k in self.variants and k not in out
                and v.weight > 0]

    def central(self, *, from_start: bool = False
                ) -> tuple[dict[str, np.ndarray], dict[str, np.ndarray]]:
        """(lo, hi) of the central interval per metric (`printgen.verification.central`:
        the weighted variants combined, 10 % to 90 %); `from_start` as in `envelope`."""
        def shifted(c: np.ndarray) -> np.ndarray:
            return c - (c[0] if from_start else 0.0)

        lo, hi = {}, {}
        for key in METRICS:
            parts = [Contribution(self.info[k].question or k, shifted(self.variants[k][key]),
                                  self.info[k].weight, self.info[k].spread)
                     for k in self.weighted()]
            lo[key], hi[key] = central_interval(shifted(self.nominal[key]), parts)
        return lo, hi

    def envelope(self, *, from_start: bool = False
                 ) -> tuple[dict[str, np.ndarray], dict[str, np.ndarray]]:
        """(min, max) over the nominal and every variant, per metric; `from_start` counts
        every curve from its value at h / h_B = 0 (what zeroed sensors read)."""
        lo, hi = {}, {}
        for key in METRICS:
            rows = [c[key] - (c[key][0] if from_start else 0.0)
                    for c in [self.nominal, *self.variants.values()]]
            stack = np.vstack(rows)
            lo[key], hi[key] = _nan_reduce(stack, np.nanmin), _nan_reduce(stack, np.nanmax)
        return lo, hi


def _nan_reduce(stack: np.ndarray, fn) -> np.ndarray:
    out = np.full(stack.shape[1], np.nan)
    ok = ~np.all(np.isnan(stack), axis=0)
    out[ok] = fn(stack[:, ok], axis=0)
    return out


def refinement_test(d: Design, nominal: dict[str, np.ndarray], lv: np.ndarray,
                    load_kw: dict | None = None, base: Variant | None = None,
                    work: list[dict[str, Any]] | None = None,
                    ahead: dict[int, Future] | None = None) -> tuple[int, dict[int, float]]:
    """Coarsest mesh multiplier whose nominal sweep stays within REFINE_TOL of `nominal` (the
    design's own net) on every metric, and each tried multiplier's largest change. The
    multipliers are tried from the finest: once one fails, coarser ones are not run. `work`
    gets each sweep's Run.work(). `ahead`: multiplier -> the sweep of `base` on it, started
    before `lv` was known (used when it ran at `lv`, else run again)."""
    best, change = 1, {}
    for k in COARSENINGS:
        if not meshable(d, k):
            break
        run = collect([ahead[k]])[0] if ahead and k in ahead else None
        if run is None or not np.array_equal(run.deformation.levels, lv):
            run = run_variant(d, base or Variant(), lv, k, load_kw)
        if work is not None:
            work.append(run.work())
        change[k] = _largest_change(curves(run), nominal)
        if change[k] >= REFINE_TOL:
            break
        best = k
    return best, change


def meshable(d: Design, k: int) -> bool:
    try:
        build_scene(d, SceneOptions(coarsen=k))
    except GeometryError:
        return False
    return True


def _largest_change(c: dict[str, np.ndarray], ref: dict[str, np.ndarray]) -> float:
    worst = 0.0
    for key in METRICS:
        peak = float(np.nanmax(np.abs(ref[key])))
        if peak > 0:
            diff = np.abs(c[key] - ref[key])
            worst = max(worst, float(np.nanmax(diff)) / peak if np.any(~np.isnan(diff)) else 0)
    return worst


def model_band(d: Design, nominal: Run, *, load_kw: dict | None = None,
               variants: list[Variant] | None = None, notes: list[str] | None = None,
               free_section: float | None = None, ahead: dict[int, Future] | None = None,
               then: Callable[[int], object] | None = None) -> Band:
    """Sweep every variant of design `d` and collect them around the `nominal` run (the
    model's sweep on the design's own net, as `verify` ran it), at the same levels.

    The variants run on the coarsest net that passes the refinement test (`ahead`: its
    sweeps already started, `refinement_test`); there a variant's curve is the nominal plus
    the variant's change on the coarse net. `then` is called with that net's coarsening
    once the variants are started (within printgen.executor.local.shared_pool: to queue more
    jobs behind them, or to work here while they run).
    """
    t0 = time.perf_counter()
    lv = nominal.deformation.levels
    mounting = getattr(nominal.scene, "mounting", None)
    force = scene_sensor_force(nominal.scene)  # every variant's sensors pull as the nominal's
    if variants is None:
        variants, auto_notes = model_variants(d, mounting, free_section)
        notes = [*(notes or []), *auto_notes]
    variants = [dataclasses.replace(v, options=dataclasses.replace(
        v.options, mounting=v.options.mounting or mounting,
        sensor_force=force if v.options.sensor_force is None else v.options.sensor_force))
        for v in variants]
    nominal_variant = Variant(options=SceneOptions(mounting=mounting, sensor_force=force))
    nom = curves(nominal)
    work: list[dict[str, Any]] = []
    with span("band: refinement test"):
        k, change = refinement_test(d, nom, lv, load_kw, nominal_variant, work, ahead)
    # longest first (the worker that takes the last job should not start a long one late)
    order = sorted(range(len(variants)), key=lambda i: -variants[i].effort)
    jobs: list[tuple] = [(try_variant, (d, variants[i], lv, k, load_kw,
                                        warm_start(variants[i], nominal, k)), {})
                         for i in order]
    if k > 1:
        jobs.append((run_variant, (d, nominal_variant, lv, k, load_kw), {}))
    started = submit_jobs(jobs)
    if then is not None:
        then(k)
    done = collect(started)
    extra = done[len(variants):]  # the nominal on the coarse net, when k > 1
    base = curves(extra[0]) if extra else None
    runs = [done[order.index(i)] for i in range(len(variants))]
    # report.json's solver_work rows: the slack variant's first, then the list's order
    recorded = sorted(range(len(variants)), key=lambda i: -variants[i].slack)
    work += [r.work() for r in (runs[i] for i in recorded) if isinstance(r, Run)]
    work += [r.work() for r in extra]
    out, failed, refused = {}, {}, {}
    for v, r in zip(variants, runs, strict=True):
        if isinstance(r, Refused):
            refused[v.label] = r.reason
            out[v.label] = {m: np.full(len(lv), np.nan) for m in METRICS}
            continue
        c = curves(r)
        out[v.label] = c if base is None else {m: nom[m] + c[m] - base[m] for m in METRICS}
        if r.failed:
            failed[v.label] = sorted(r.failed)
    return Band(lv, nom, out, {v.label: v.source for v in variants}, list(notes or []), k,
                change, time.perf_counter() - t0, failed, mounting, work, force,
                {v.label: v for v in variants}, refused=refused)


def run_prototype_variant(p: Prototype, v: Variant, lv: np.ndarray, load_kw: dict | None = None,
                          start: States | None = None) -> Run:
    """Sweep the prototype with variant `v` (a worker job: module-level, picklable); `start`:
    its nominal's states (`warm_start`)."""
    return sweep(build_scene(p, v.options), lv, slack=v.slack, guesses=from_states(start),
                 **(load_kw or {}))


def prototype_jobs(p: Prototype, nominal: Run, load_kw: dict | None = None) -> list[tuple]:
    """(run_prototype_variant, args, kwargs) of every prototype variant, at the levels and
    with the mounting of its `nominal` run."""
    mounting = getattr(nominal.scene, "mounting", None)
    lv = nominal.deformation.levels
    return [(run_prototype_variant, (p, dataclasses.replace(v, options=dataclasses.replace(
        v.options, mounting=mounting)), lv, load_kw, warm_start(v, nominal)), {})
        for v in prototype_variants(p)]


def prototype_band(p: Prototype, nominal: Run, runs: list[Run]) -> Band:
    """The prototype's band: its `nominal` run and the `runs` of `prototype_jobs` (same
    order), on its own net."""
    variants = prototype_variants(p)
    out = {v.label: curves(r) for v, r in zip(variants, runs, strict=True)}
    failed = {v.label: sorted(r.failed) for v, r in zip(variants, runs, strict=True)
              if r.failed}
    return Band(nominal.deformation.levels, curves(nominal), out,
                {v.label: v.source for v in variants}, [], 1, {}, 0.0, failed,
                getattr(nominal.scene, "mounting", None), [r.work() for r in runs], None,
                {v.label: v for v in variants})


SIGNIFICANT = 0.1  # levels where the prototype is below 10 % of its peak carry no verdict
INSIDE = 1e-9  # relative round-off allowed at a band edge


@dataclass(frozen=True)
class BandVerdict:
    """Where the prototype's curve lies against the model band, for one metric.

    kind : "inside", "stiffer", "softer", "partly inside" or "crossing"; least, most :
    smallest and largest relative gap (fraction) where the prototype is outside the band.
    """

    metric: str
    kind: str
    least: float
    most: float
    inside_levels: int
    levels: int
    text: str


def band_verdict(metric: str, proto: np.ndarray, lo: np.ndarray, hi: np.ndarray
                 ) -> BandVerdict:
    """Compare the prototype's curve with the model band [lo, hi] at every level where the
    prototype reaches SIGNIFICANT of its peak. The model is "stiffer" where it deforms less
    than the prototype even in its softest variant; "stiffer by at least X %": its softest
    variant deforms at least X % less than the prototype at every such level ("softer by at
    least X %": its stiffest variant deforms at least X % more)."""
    p = np.asarray(proto, float)
    keep = ~np.isnan(p) & ~np.isnan(lo) & ~np.isnan(hi)
    peak = float(np.abs(p[keep]).max()) if keep.any() else 0.0
    keep &= np.abs(p) >= SIGNIFICANT * peak
    if peak == 0.0 or not keep.any():
        return BandVerdict(metric, "inside", 0.0, 0.0, 0, 0, "no deformation to compare")
    s = np.sign(p[keep])  # compare magnitudes: a negative curve flips the band
    pp, a, b = s * p[keep], s * lo[keep], s * hi[keep]
    low, high = np.minimum(a, b), np.maximum(a, b)
    tol = INSIDE * peak
    stiffer, softer = high < pp - tol, low > pp + tol
    gap_stiff = np.minimum(1 - high[stiffer] / pp[stiffer], 1.0)  # the model deforms less
    gap_soft = low[softer] / pp[softer] - 1  # the model deforms more
    n, inside = int(keep.sum()), int((~stiffer & ~softer).sum())
    if inside == n:
        kind, least, most = "inside", 0.0, 0.0
        text = "prototype inside the model band"
    elif stiffer.any() and softer.any():
        kind, least, most = "crossing", float(gap_stiff.max()), float(gap_soft.max())
        text = (f"the prototype crosses the model band: model stiffer by up to {least:.0%} "
                f"at some levels, softer by up to {most:.0%} at others")
    else:
        gaps, word = (gap_stiff, "stiffer") if stiffer.any() else (gap_soft, "softer")
        least, most = float(gaps.min()), float(gaps.max())
        if inside == 0:
            kind, text = word, f"model {word} by at least {least:.0%} (up to {most:.0%})"
        else:
            kind = "partly inside"
            text = (f"prototype inside the model band at {inside} of {n} levels; model "
                    f"{word} by up to {most:.0%} at the others")
    return BandVerdict(metric, kind, least, most, inside, n, text)


def band_verdicts(proto: dict[str, np.ndarray], band: Band, *, from_start: bool = False
                  ) -> list[BandVerdict]:
    """One verdict per metric: the prototype's curves (at the band's levels) vs the band."""
    lo, hi = band.envelope(from_start=from_start)
    out = []
    for key in METRICS:
        p = proto[key] - (proto[key][0] if from_start else 0.0)
        out.append(band_verdict(key, p, lo[key], hi[key]))
    return out
