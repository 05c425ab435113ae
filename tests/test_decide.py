"""The three-valued verdict from the model's and the prototype's bands
(printgen.verification.decide): PASS, FAIL and UNDECIDED on constructed bands, the deciding
variant and the cheapest test it names, the variants the lab's data exclude, the record."""

from __future__ import annotations

import dataclasses
import json

import numpy as np
import pytest

from printgen.report.jsonout import dumps
from printgen.verification.bands import Band
from printgen.verification.compare import METRICS, TOLERANCE
from printgen.verification.decide import decide, excluded_by_data
from printgen.verification.measured import Measurement
from printgen.verification.variants import READING, TESTS, Variant, cheapest_test, settling_tests

LEVELS = np.array([0.0, 0.5, 1.0])
PROTO = {k: np.array([0.0, 0.4, 1.0]) for k in METRICS}  # peak 1: mismatches read directly


def band(nominal: float, variants: dict[str, tuple[float, str, float, str]]) -> Band:
    """A model band whose nominal is `nominal` x the prototype, each variant `factor` x it
    (label -> (factor, question, weight, excluded))."""
    curves = {label: {k: f * c for k, c in PROTO.items()}
              for label, (f, *_rest) in variants.items()}
    info = {label: Variant(label, question=q, weight=w, excluded=x)
            for label, (_, q, w, x) in variants.items()}
    return Band(LEVELS, {k: nominal * c for k, c in PROTO.items()}, curves,
                {k: "" for k in curves}, [], 1, {}, info=info)


def test_a_band_inside_the_tolerance_passes():
    d = decide(PROTO, band(1.0, {"a bit soft": (1.1, "lateral mounting", 0.5, "")}))
    assert d.verdict == "PASS" and d.deciding == [] and d.test == "" and d.sentence() == ""
    assert all(m.worst == pytest.approx(0.1) for m in d.metrics)


def test_a_band_outside_the_tolerance_fails():
    d = decide(PROTO, band(2.0, {"softer": (2.2, "lateral mounting", 0.5, "")}))
    assert d.verdict == "FAIL"
    assert all(m.best == pytest.approx(1.0) for m in d.metrics)  # 2x at the peak: 100 % off


def test_a_band_that_straddles_the_tolerance_is_undecided_and_names_what_decides():
    d = decide(PROTO, band(1.0, {"eyelets": (1.6, "lateral mounting", 0.5, ""),
                                 "normal pressure": (1.05, "pressure direction", 0.5, "")}))
    assert d.verdict == "UNDECIDED"
    assert d.deciding == ["eyelets"]  # the one whose move alone crosses the 25 %
    assert d.questions == ["lateral mounting"]
    assert d.test == TESTS["lateral mounting"]
    text = d.sentence()
    assert "eyelets" in text and TESTS["lateral mounting"] in text
    assert f"{TOLERANCE:.0%} tolerance" in text


def test_an_excluded_variant_does_not_decide():
    d = decide(PROTO, band(1.0, {"squeezed": (1.6, "mounting span", 0.5, "sags visibly")}))
    assert d.verdict == "PASS"


def test_an_input_the_solver_refuses_keeps_the_verdict_from_passing():
    """A weighted variant with no curves (the solver refused it: its sensor wires fold the
    net) turns a PASS of the others into UNDECIDED, decided by that input; a FAIL stays FAIL,
    and a refused variant excluded on its own grounds decides nothing."""
    why = "its sensor wires fold back over their nodes"
    nan = {k: np.full(len(LEVELS), np.nan) for k in METRICS}

    def refusing(nominal: float, excluded: str = "") -> Band:
        b = band(nominal, {"free section": (nominal, "mounting span", 0.5, excluded),
                           "a bit soft": (1.1 * nominal, "lateral mounting", 0.5, "")})
        return dataclasses.replace(b, variants={**b.variants, "free section": nan},
                                   refused={"free section": why})

    d = decide(PROTO, refusing(1.0))
    assert d.verdict == "UNDECIDED" and d.deciding == ["free section"]
    assert d.questions == ["mounting span"] and d.test == TESTS["mounting span"]
    assert why in d.sentence() and d.to_record()["refused_variants"] == {"free section": why}
    assert decide(PROTO, refusing(2.0)).verdict == "FAIL"
    assert decide(PROTO, refusing(1.0, excluded="sags visibly")).verdict == "PASS"
    assert "the solver refused it" in refusing(1.0).excluded["free section"]


def test_the_prototype_band_counts_too():
    proto = Band(LEVELS, PROTO, {"slack": {k: 1.5 * c for k, c in PROTO.items()}}, {"slack": ""},
                 [], 1, {}, info={"slack": Variant("slack", question="prototype initial slack",
                                                   weight=1.0, spread="range")})
    d = decide(PROTO, band(1.0, {}), proto)
    assert d.verdict == "UNDECIDED" and d.deciding == ["slack"]
    assert d.test == TESTS["prototype initial slack"]


def slack_band(factor: float, question: str) -> Band:
    """A band with the nominal at the prototype and one 0-1 % slack range variant (labelled
    as its question) moving every curve by `factor`."""
    return Band(LEVELS, PROTO, {question: {k: factor * c for k, c in PROTO.items()}},
                {question: ""}, [], 1, {}, info={question: Variant(
                    question, question=question, weight=1.0, spread="range")})


def test_the_two_nets_slack_is_one_input():
    """Slack that moves both nets alike leaves them alike (geometric similitude hangs the
    model with the prototype's relative slack): PASS, where the same two ranges taken as
    independent inputs straddle the tolerance; the pairing is stated in the record."""
    model, proto = slack_band(1.5, "initial slack"), slack_band(1.5, "prototype initial slack")
    d = decide(PROTO, model, proto)
    assert d.verdict == "PASS" and d.assumptions and "similitude" in d.assumptions[0]
    assert d.to_record()["assumptions"] == d.assumptions
    own = model.info["initial slack"]
    apart = decide(PROTO, dataclasses.replace(model, info={"initial slack": dataclasses.replace(
        own, question="something else")}), proto)
    assert apart.verdict == "UNDECIDED" and not apart.assumptions
    # slack that moves the model more than the prototype still decides
    d = decide(PROTO, slack_band(1.6, "initial slack"), slack_band(1.1, "prototype initial slack"))
    assert d.verdict == "UNDECIDED" and d.deciding == ["initial slack"]
    assert d.test == TESTS["initial slack (both nets)"]


def test_the_cheapest_test_is_the_first_listed():
    assert cheapest_test(["modulus", "lateral mounting"]) == TESTS["lateral mounting"]
    assert settling_tests(["modulus", "cable modulus", "initial slack", "new one"]) == [
        TESTS["initial slack"], TESTS["modulus"], "find out new one"]
    assert cheapest_test(["cable modulus"]) == TESTS["modulus"]
    assert "long diagonal" in TESTS[READING]


def test_variants_the_data_contradict_are_named_with_the_numbers():
    b = band(1.0, {"slack": (3.0, "initial slack", 1.0, ""),
                   "bed": (1.1, "bottom edge", 0.5, "")})
    # the mid-height sensor read below 0.5 % at h/h_B = 0.5 and 2.0 % at 1.0 (a value the
    # nominal, 1 %, misses by more than 25 % of the peak: it excludes nothing)
    m = Measurement("t", np.array([0.5, 1.0]),
                    {"strain_mid": np.array([np.nan, 0.02])},
                    {"strain_mid": "mid_height_elongation_pct"},
                    {"strain_mid": np.array([0.005, np.nan])})
    model = band(0.01, {"slack": (0.03, "initial slack", 1.0, ""),
                        "bed": (0.011, "bottom edge", 0.5, "")})
    out = excluded_by_data(model, m)
    assert list(out) == ["slack"]  # 1.2 % at 0.5 against < 0.5 %; the bed stays
    assert "1.2 % predicted, < 0.5 % measured" in out["slack"]
    assert "h/h_B = 0.5" in out["slack"]
    # a value the nominal agrees with excludes a variant that misses it
    m2 = Measurement("t", np.array([1.0]), {"strain_mid": np.array([0.01])},
                     {"strain_mid": "mid_height_elongation_pct"})
    assert "3 % predicted, 1 % measured" in excluded_by_data(model, m2)["slack"]
    assert excluded_by_data(b, Measurement("t", np.array([1.0]), {}, {})) == {}


def test_the_decision_record_is_json_ready():
    d = decide(PROTO, band(1.0, {"eyelets": (1.6, "lateral mounting", 0.5, "")}))
    rec = json.loads(dumps(d.to_record()))
    assert rec["verdict"] == "UNDECIDED" and rec["cheapest_test"] == d.test
    assert rec["deciding_variants"] == ["eyelets"] and rec["tests"] == [d.test]
    assert {m["metric"] for m in rec["metrics"]} == set(METRICS)
    assert all(m["status"] == "UNDECIDED" for m in rec["metrics"])


def test_the_prototype_band_reads_its_law_otherwise_only_with_a_law():
    from conftest import EXAMPLES

    from printgen.inputs.prototype import load_prototype
    from printgen.verification.variants import prototype_variants

    real = prototype_variants(load_prototype(EXAMPLES / "realistic_barrier.toml"))
    simple = prototype_variants(load_prototype(EXAMPLES / "simple_barrier.toml"))
    assert [v.question for v in real] == ["prototype initial slack",
                                          "prototype panel-test orientation"]
    assert real[1].excluded and real[0].spread == "range"
    assert [v.question for v in simple] == ["prototype initial slack"]


def fake_verification(d):
    """What the summary and the band's record read of a verification, with decision `d`."""
    from types import SimpleNamespace

    deformation = SimpleNamespace(values=PROTO)
    return SimpleNamespace(verdict=d.verdict, headline=d.sentence(), mismatches=[], ok=True,
                           sensors=None, sensors_to_blame=False, runnable=True, flow=None,
                           decision=d, prototype=SimpleNamespace(deformation=deformation),
                           prototype_band=None)


def test_undecided_gets_the_cheapest_test_as_its_next_step(monkeypatch):
    from printgen.report import summary as summary_module
    from printgen.report.records import CheckRecords, RunRecords
    from printgen.report.summary import NEXT_UNDECIDED, summarize, summary_html

    b = band(1.0, {"eyelets": (1.6, "lateral mounting", 0.5, "")})
    v = fake_verification(decide(PROTO, b))
    monkeypatch.setattr(summary_module, "band_verdicts", lambda values, band: [])
    monkeypatch.setattr(summary_module, "chosen_parts", lambda design, plan=None, net=None: [])
    s = summarize(RunRecords("t", None, steps={"verification": CheckRecords(v, b, 40.0)}))
    assert s.verdict == "UNDECIDED" and s.next == NEXT_UNDECIDED.format(test=v.decision.test)
    assert '<span class="undecided">UNDECIDED</span>' in summary_html(s)


def test_the_band_record_has_the_central_interval_weights_and_exclusions():
    from printgen.report.uncertainty import band_record

    b = band(1.0, {"eyelets": (1.6, "lateral mounting", 0.5, ""),
                   "squeezed": (9.0, "mounting span", 0.0, "sags visibly")})
    rec = json.loads(dumps(band_record(fake_verification(decide(PROTO, b)), b)))
    assert rec["central_max"]["strain_mid"][-1] == pytest.approx(1.6)
    assert rec["max"]["strain_mid"][-1] == pytest.approx(9.0)  # the envelope keeps it
    assert "10% to 90%" in rec["central_definition"]
    assert rec["weights"]["squeezed"] == {"question": "mounting span", "weight": 0.0,
                                          "spread": "answer", "weight_source": "",
                                          "excluded": "sags visibly"}
    assert rec["weights"]["eyelets"]["weight"] == 0.5 and rec["prototype"] is None
    assert rec["at"]["1"]["strain_mid"]["central_max"] == pytest.approx(1.6)


def test_the_readings_of_one_panel_law_are_one_question_weighted_evenly():
    from conftest import EXAMPLES

    from printgen.inputs.prototype import load_prototype
    from printgen.scaling.design_file import load_design
    from printgen.verification.preprint import free_section
    from printgen.verification.variants import model_variants

    p = load_prototype(EXAMPLES / "realistic_barrier.toml")
    d = load_design(EXAMPLES / "paper_1_40" / "design.json", scale=40.0, prototype=p)
    variants, _ = model_variants(d, "walls", free_section(p))
    readings = [v for v in variants if v.question == READING and not v.excluded]
    assert readings  # the derived strand law at least (the short diagonal is refused)
    assert all(v.weight == pytest.approx(1 / (len(readings) + 1)) for v in readings)
    refused = [v for v in variants if v.question == READING and v.excluded]
    assert refused and all(v.weight == 0 for v in refused)  # the short diagonal: no weight
    by_q: dict[str, float] = {}
    for v in variants:
        if not v.excluded and v.spread == "answer":
            by_q[v.question] = by_q.get(v.question, 0.0) + v.weight
    assert all(0 < w <= 1 for w in by_q.values())  # every question's answers leave room
    assert all(v.weight_source for v in variants if not v.excluded)  # every weight argued
    squeezed = [v for v in variants if v.question == "mounting span"]
    assert squeezed and all("sag of about" in v.excluded for v in squeezed)


def test_a_net_of_another_pattern_cannot_be_the_tested_panel():
    """The profile's panels were diamond nets: for a square design the 'tested net = the
    design's net' reading is shown with why it carries no weight."""
    from conftest import EXAMPLES

    from printgen.run.make import plan_run
    from printgen.verification.variants import model_variants

    d = plan_run(EXAMPLES / "simple_barrier.toml", 100).design
    assert d.net.pattern == "square" and d.net.material == "tpe"
    variants, _ = model_variants(d)
    tested = [v for v in variants if "tested net" in v.label]
    assert tested and all("cannot be the tested net" in v.excluded for v in tested)
