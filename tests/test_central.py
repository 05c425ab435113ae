"""The band's central interval: the weighted one-at-a-time variants combined as independent
contributions, 10 % to 90 % (printgen.verification.central), on synthetic curves whose
quantiles are known; excluded variants leave it but stay in the envelope."""

from __future__ import annotations

import math

import numpy as np
import pytest
from numpy.testing import assert_allclose

from printgen.verification.bands import Band
from printgen.verification.central import (
    POINTS_MAX,
    RANGE_POINTS,
    Contribution,
    central_interval,
    quantile,
)
from printgen.verification.compare import METRICS
from printgen.verification.variants import Variant

EXACT = 1e-12  # the quantiles of a discrete distribution are its own atoms: round-off only


def one(x: float) -> np.ndarray:
    return np.array([x])


def interval(nominal: float, parts: list[Contribution]) -> tuple[float, float]:
    lo, hi = central_interval(one(nominal), parts)
    return float(lo[0]), float(hi[0])


def test_weighted_quantile_is_the_inverse_distribution_function():
    v, w = np.array([3.0, 1.0, 2.0]), np.array([0.2, 0.5, 0.3])
    assert quantile(v, w, 0.1) == 1.0
    assert quantile(v, w, 0.5) == 1.0  # the cumulative weight reaches 0.5 at 1.0
    assert quantile(v, w, 0.6) == 2.0
    assert quantile(v, w, 0.9) == 3.0


def test_an_answer_weighted_below_ten_percent_leaves_the_interval():
    assert interval(1.0, [Contribution("q", one(2.0), 0.3)]) == pytest.approx((1.0, 2.0),
                                                                              abs=EXACT)
    assert interval(1.0, [Contribution("q", one(2.0), 0.05)]) == pytest.approx((1.0, 1.0),
                                                                               abs=EXACT)


def test_independent_questions_combine_as_ratios():
    # two questions, each halving or doubling the reading with weight 1/2: the four
    # combinations 1/2, 1, 1, 2 with weight 1/4 each
    parts = [Contribution("a", one(2.0), 0.5), Contribution("b", one(0.5), 0.5)]
    assert interval(1.0, parts) == pytest.approx((0.5, 2.0), abs=EXACT)


def test_answers_of_one_question_are_never_combined():
    # exclusive answers x2 and x4: never x8 (as two independent questions would give)
    same = [Contribution("q", one(2.0), 0.5), Contribution("q", one(4.0), 0.5)]
    apart = [Contribution("a", one(2.0), 0.5), Contribution("b", one(4.0), 0.5)]
    assert interval(1.0, same) == pytest.approx((1.0, 4.0), abs=EXACT)  # holds the nominal
    assert interval(1.0, apart)[1] == pytest.approx(8.0, abs=EXACT)


def test_a_range_is_uniform_from_the_nominal_to_its_end():
    lo, hi = interval(1.0, [Contribution("slack", one(math.e), 1.0, "range")])
    mid = [(j + 0.5) / RANGE_POINTS for j in range(RANGE_POINTS)]  # log-ratios, 1/5 each
    assert (lo, hi) == pytest.approx((1.0, math.exp(mid[-1])), abs=EXACT)  # q10 is mid[0]:
    # widened to the nominal
    lo, hi = central_interval(one(1.0), [Contribution("s", one(math.e), 1.0, "range")],
                              (0.1, 0.5))
    assert hi[0] == pytest.approx(math.exp(mid[2]), abs=EXACT)


def test_a_reading_that_changes_sign_combines_as_differences():
    # nominal 1, an answer at -1 with weight 1/2: differences {-2, 0}, so q10 = -1
    assert interval(1.0, [Contribution("q", one(-1.0), 0.5)]) == pytest.approx((-1.0, 1.0),
                                                                               abs=EXACT)


def test_many_questions_merge_without_moving_the_quantiles():
    # 14 questions, each x e or x 1/e with weight 1/2 (an SD pair): the log-reading is
    # 2 B - 14 with B ~ Binomial(14, 1/2), whose 10 % and 90 % quantiles are 5 and 9, so
    # -4 and 4; 2^14 combinations pass POINTS_MAX and are merged on the way
    n = 14
    assert 2**n > POINTS_MAX
    parts = [Contribution(f"q{i}", one(x), 0.5) for i in range(n) for x in (math.e, 1 / math.e)]
    lo, hi = interval(1.0, parts)
    assert (math.log(lo), math.log(hi)) == pytest.approx((-4.0, 4.0), abs=1e-9)


def test_weights_of_one_question_above_one_are_refused():
    with pytest.raises(ValueError, match="add to"):
        interval(1.0, [Contribution("q", one(2.0), 0.7), Contribution("q", one(3.0), 0.7)])


def synthetic_band(excluded: str = "", data: dict[str, str] | None = None) -> Band:
    lv = np.array([0.0, 0.5, 1.0])
    nominal = {k: np.array([0.0, 1.0, 2.0]) for k in METRICS}
    curves = {"soft": {k: 2 * c for k, c in nominal.items()},
              "far": {k: 10 * c for k, c in nominal.items()}}
    info = {"soft": Variant("soft", question="a", weight=0.5),
            "far": Variant("far", question="b", weight=0.5, excluded=excluded)}
    return Band(lv, nominal, curves, {k: "" for k in curves}, [], 1, {}, info=info,
                data_excluded=data or {})


def test_an_excluded_variant_leaves_the_central_interval_but_stays_in_the_envelope():
    b = synthetic_band()
    assert b.central()[1]["strain_mid"][2] == pytest.approx(40.0)  # x2 and x10 combine
    for cut in (synthetic_band("the material says no"),
                synthetic_band(data={"far": "bound passed by 9 %"})):
        lo, hi = cut.central()
        assert_allclose(hi["strain_mid"], [0.0, 2.0, 4.0], atol=EXACT)
        assert_allclose(lo["strain_mid"], [0.0, 1.0, 2.0], atol=EXACT)
        assert cut.envelope()[1]["strain_mid"][2] == 20.0  # still in the envelope
        assert cut.weighted() == ["soft"]
    assert synthetic_band(data={"far": "x"}).excluded == {"far": "excluded by the data: x"}


def test_near_zero_the_effects_combine_as_differences():
    # at the first level the nominal is 1 % of its peak: two variants reading 100x it would
    # combine to 10 000x as ratios; as differences they give 1 + 99 + 99
    nominal = np.array([0.01, 1.0])
    parts = [Contribution(q, np.array([1.0, 1.0]), 0.5) for q in ("a", "b")]
    lo, hi = central_interval(nominal, parts, (0.1, 1.0))
    assert hi[0] == pytest.approx(1.99, abs=EXACT)
