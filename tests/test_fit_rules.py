"""Fits that never mislead, on constructed cases: a profile only from a fit that improves every
measured column with every parameter inside its bounds; a bound's breach scored against the
bound; a part that carries nothing said as that; the mismatch profiled along each parameter
(flat = not determined); the fit's sweeps counted by the run's estimate and refused up front
by --time-limit."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from conftest import EXAMPLES, coarse_design_1_40
from proto_files import REALISTIC

from printgen.cli import main
from printgen.errors import InputError
from printgen.inputs.prototype import load_prototype
from printgen.run.budget import FitPlan, Work, check_budget, estimate
from printgen.run.verify import fit_plan
from printgen.scaling.design_file import load_design
from printgen.verification import fit as fit_mod
from printgen.verification.fit import (
    BOUNDS,
    IDLE,
    PROFILE_POINTS,
    Identifiability,
    MultiFit,
    Params,
    Trial,
    Trials,
    all_choices,
    explained,
    planned_sweeps,
    residuals,
)
from printgen.verification.measured import (
    Fit,
    Measurement,
    Mismatch,
    mismatch,
    not_improved,
    objective,
)

ROUND = 1e-12  # arithmetic round-off of the scored misses
LEVELS = np.array([0.5, 0.8, 1.0])


def paper_like() -> Measurement:
    """The paper test's shape: an onset bound '< 0.5 %' at 0.5, then 5 % and 10.5 %."""
    return Measurement("constructed", LEVELS, {"strain_mid": np.array([np.nan, 0.05, 0.105])},
                       {"strain_mid": "mid"},
                       {"strain_mid": np.array([0.005, np.nan, np.nan])})


def mm(col: str, rel: float, points: int = 2, bounds: int = 0) -> Mismatch:
    return Mismatch(col, col, rel, rel, points, 0, bounds)


def test_a_bound_breach_is_scored_against_the_bound_not_the_peak():
    """1.7 % where the test read '< 0.5 %': a 3.4 x breach misses by 240 % of the bound, not by
    the 11 % of the column's 10.5 % peak it once weighed."""
    m = paper_like()
    pred = {"strain_mid": np.array([0.017, 0.05, 0.105])}
    (one,) = mismatch(m, pred)
    assert one.rms_rel == pytest.approx(math.sqrt((0.012 / 0.005) ** 2 / 3), rel=ROUND)
    assert one.bounds == 1 and one.values == 2
    # the fit's residuals are the same scoring: their sum of squares is the objective
    assert float(np.sum(residuals(m, pred) ** 2)) == pytest.approx(objective(m, pred),
                                                                   rel=ROUND)
    within = {"strain_mid": np.array([0.004, 0.05, 0.105])}
    assert mismatch(m, within)[0].rms_rel == 0.0  # a bound counts by its excess only


def test_a_fit_must_improve_every_measured_column():
    before = [mm("bottom", 0.30, 1, 1), mm("mid", 0.472), mm("top", 0.555)]
    better = [mm("bottom", 0.10, 1, 1), mm("mid", 0.20), mm("top", 0.30)]
    assert not_improved(before, better) == []
    same_top = [mm("bottom", 0.10, 1, 1), mm("mid", 0.20), mm("top", 0.555)]
    assert not_improved(before, same_top) == [("top", 0.555, 0.555)]
    worse_bound = [mm("bottom", 0.40, 1, 1), mm("mid", 0.20), mm("top", 0.30)]
    assert not_improved(before, worse_bound) == [("bottom", 0.30, 0.40)]
    met_bound = [mm("bottom", 0.0, 1, 1), mm("mid", 0.2), mm("top", 0.3)]
    assert not_improved([mm("bottom", 0.0, 1, 1), *before[1:]], met_bound) == []


def test_the_one_factor_fit_writes_a_profile_only_when_it_improves_everything_inside_range():
    before = [mm("mid", 0.47), mm("top", 0.55)]
    assert Fit("stiffness", 1.6, before, [mm("mid", 0.2), mm("top", 0.3)], {}, 9,
               False).writes_profile
    assert not Fit("stiffness", 1.6, before, [mm("mid", 0.2), mm("top", 0.55)], {}, 9,
                   False).writes_profile
    assert not Fit("stiffness", 5.0, before, [mm("mid", 0.2), mm("top", 0.3)], {}, 9,
                   True).writes_profile


def test_the_multi_fit_explains_only_inside_its_bounds_improving_every_column():
    before = [mm("mid", 0.47), mm("top", 0.55)]
    close = [mm("mid", 0.05), mm("top", 0.08)]
    inside = Params(net_factor=0.5, net_slack=0.01, cable_slack=0.01)
    assert explained(before, close, inside)
    assert not explained(before, close, Params(net_factor=0.5, cable_slack=0.03))
    assert not explained([mm("mid", 0.47), mm("top", 0.08)], close, inside)
    assert not explained(before, [mm("mid", 0.05), mm("top", 0.2)], inside)


def _multi(params: Params, after: list, *, idle: tuple[str, ...] = (),
           profiles: dict | None = None) -> MultiFit:
    before = [mm("mid", 0.47), mm("top", 0.55)]
    ident = Identifiability(np.ones(3), np.eye(3), dict.fromkeys(BOUNDS, 1.0))
    return MultiFit(params, before, after, {}, {}, ident, 10, explained(before, after, params),
                    fit_mod.at_bounds(params), idle, profiles or {})


def test_idle_cables_are_said_as_carrying_nothing_not_as_a_value_at_a_bound():
    slack = Params(net_factor=0.5, cable_slack=BOUNDS["cable_slack"][1])
    fit = _multi(slack, [mm("mid", 0.05), mm("top", 0.08)], idle=("cable_slack",))
    text = fit.sentence()
    assert IDLE["cable_slack"] in text and "cable_slack at the end" not in text
    assert "NOT explained" in text and "no profile is written" in text
    assert fit.to_record()["idle"] == {"cable_slack": IDLE["cable_slack"]}
    # the same set with cables that pull: a value at its bound, said as that
    pulled = _multi(slack, [mm("mid", 0.05), mm("top", 0.08)]).sentence()
    assert "cable_slack at the end of its range" in pulled


def test_idle_is_read_from_the_cables_tension():
    nominal = Trial({}, 8.5)
    assert fit_mod._idle(Trial({}, 1e-3), nominal)
    assert not fit_mod._idle(Trial({}, 1.0), nominal)


class Analytic(Trials):
    """Trials of a closed-form 'net': mid-height strain 5 % x net_factor^-1 + 0 x the slacks
    (the slacks change nothing: flat), no sweep run."""

    def __init__(self, m: Measurement):
        super().__init__(None, m, np.array([0.0, *m.levels]), None)

    def many(self, ps, coarsen=1):
        self.count[coarsen] = self.count.get(coarsen, 0) + len(ps)
        return [Trial({"strain_mid": 0.05 / p.net_factor * self.m.levels}, 1.0) for p in ps]


def test_the_profiles_say_which_parameters_the_data_determine():
    m = Measurement("analytic", LEVELS, {"strain_mid": 0.05 / 0.8 * LEVELS},
                    {"strain_mid": "mid"})
    runs = Analytic(m)
    best = Params(net_factor=0.8)
    ident, profiles = fit_mod._determination(runs, best, [0, 1, 2], 1)
    assert set(profiles) == set(BOUNDS)
    assert profiles["net_factor"].determined
    assert not profiles["net_slack"].determined and not profiles["cable_slack"].determined
    lo, hi = profiles["net_factor"].allowed
    assert lo <= 0.8 <= hi and (lo, hi) != (BOUNDS["net_factor"][0], BOUNDS["net_factor"][1])
    assert len(profiles["net_slack"].values) == PROFILE_POINTS
    assert ident.sensitivity["net_slack"] == 0.0
    fit = _multi(best, [mm("mid", 0.0), mm("top", 0.0)], profiles=profiles)
    assert fit.flat() == ["net_slack", "cable_slack"]
    assert "not determined by the data (flat mismatch along): net_slack, cable_slack" in (
        fit.sentence())
    assert fit.to_record()["not_determined"] == ["net_slack", "cable_slack"]


def test_the_screen_steps_every_choice_towards_its_best():
    """Two Gauss-Newton steps from the nominal bring the analytic net's factor to the one that
    made the data (0.8), within the finite difference's error."""
    m = Measurement("analytic", LEVELS, {"strain_mid": 0.05 / 0.8 * LEVELS},
                    {"strain_mid": "mid"})
    runs = Analytic(m)
    best = fit_mod._screen(runs, [Params(), Params(bed="held")], [0], 2)
    assert {c[3] for c in best} == {"free", "held"}
    for p, obj in best.values():
        assert p.net_factor == pytest.approx(0.8, rel=0.02)  # 2 %: two linearised steps
        assert obj < 1e-3
    n = len(best)
    assert runs.count[2] == n * (fit_mod.SCREEN_STEPS * 2 + 1)  # each step: point + 1 probe


def test_the_estimate_counts_the_fit_s_sweeps_and_refuses_up_front():
    p = load_prototype(REALISTIC)
    d = load_design(EXAMPLES / "paper_1_40" / "design.json", scale=40, prototype=p)
    m = Measurement("paper", LEVELS, {"strain_mid": np.array([np.nan, 0.05, 0.105])},
                    {"strain_mid": "mid"})
    plan = fit_plan(d, m, "multi", 0.3)
    planned = planned_sweeps(len(all_choices(0.3)))
    assert plan.sweeps == planned["coarse"] + planned["fine"] and plan.levels == 4
    work = Work(parts=False, fit=True, model_follows=False, fit_plan=plan)
    est = estimate(p, d, cores=2, work=work, variants=8)
    assert sum(s.name.startswith("fit") for s in est.sweeps) == plan.sweeps
    one = fit_plan(d, m, "stiffness", 0.3)
    cheaper = estimate(p, d, cores=2, variants=8,
                       work=Work(parts=False, fit=True, model_follows=False, fit_plan=one))
    assert cheaper.seconds < est.seconds
    limit = (est.seconds + cheaper.seconds) / 2  # the multi fit passes it, the one factor not
    with pytest.raises(InputError) as e:
        check_budget(p, d, limit_s=limit, cores=2, work=work, speed=1.0)
    text = str(e.value)
    assert f"the measured test's fit: {plan.sweeps} sweeps" in text and "--fit stiffness" in text
    assert check_budget(p, d, limit_s=limit, cores=2, speed=1.0,
                        work=Work(parts=False, fit=True, model_follows=False, fit_plan=one))


def test_a_plan_without_a_screen_counts_fine_sweeps_only():
    assert planned_sweeps(1, 2)["coarse"] == 0
    assert FitPlan(((2, 3), (1, 4)), 4).sweeps == 7


PAPER_ARGS = ["verify", str(REALISTIC), "--scale", "40",
              "--design", str(EXAMPLES / "paper_1_40" / "design.json"),
              "--measured", str(EXAMPLES / "paper_1_40" / "measured.csv")]
TIGHT_LIMIT_S = 5.0  # far below the multi fit's estimate on any machine (hundreds of sweeps)


@pytest.mark.slow
def test_time_limit_refuses_the_multi_fit_before_any_solve(tmp_path, capsys):
    out = tmp_path / "o"
    assert main([*PAPER_ARGS, "--fit", "multi", "--out", str(out), "--time-limit",
                 f"{TIGHT_LIMIT_S:g}"]) == 2
    err = " ".join(capsys.readouterr().err.split())
    assert "the measured test's fit:" in err and "--fit stiffness" in err
    assert "--time-limit" in err and not out.exists()


@pytest.mark.slow
def test_the_multi_fit_of_the_papers_test_says_what_the_data_determine(tmp_path):
    """The whole command: no profile written, a profile of the mismatch along every
    parameter in report.json, no more sweeps than the estimate counted."""
    out = tmp_path / "o"
    assert main([*PAPER_ARGS, "--fit", "multi", "--out", str(out), "--time-limit",
                 "3600"]) in (0, 1, 3)
    assert not list(out.glob("*-fitted.toml"))
    measured = json.loads((out / "report.json").read_text())["measured"]
    fit = measured["fit"]
    assert set(fit["profiles"]) == set(BOUNDS) and "bound itself" in measured["scoring"]
    assert not fit["explains"] and "no profile is written" in fit["sentence"]
    timings = json.loads((out / "timings.json").read_text())["timings_s"]
    assert fit["evaluations"] <= timings["estimate_fit_sweeps"]
    assert "Scoring:" in (out / "report.html").read_text()


PATH_AGREE = 1e-6  # strain: the solver's tolerance, far below any reading (1e-4 is 0.01 %)


@pytest.mark.slow
def test_sweeping_only_the_measured_levels_gives_the_fine_path_s_curves():
    """The fit sweeps h/h_B = 0 and the measured levels only: an elastic net's state does not
    depend on the path, and a long step is reached by sub-steps; at the ends of the ranges
    (softest net, largest slacks, free section, both beds) the curves are the 0.1-step path's."""
    d = coarse_design_1_40(2)
    m = paper_like()
    fine = np.union1d(np.round(np.arange(0.0, 1.0 + 1e-9, 0.1), 10), m.levels)
    for p in (Params(net_factor=0.25, net_slack=0.03, cable_slack=0.03, span=0.3),
              Params(net_factor=4.0, cable_slack=0.03, bed="held", orientation="long")):
        short = fit_mod.trial(d, p, m, fit_mod.fit_levels(m)).curves["strain_mid"]
        full = fit_mod.trial(d, p, m, fine).curves["strain_mid"]
        assert not np.isnan(short).any()
        np.testing.assert_allclose(short, full, atol=PATH_AGREE)
