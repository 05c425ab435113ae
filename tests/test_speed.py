"""The machine's speed in the run's estimate (printgen.run.speed, printgen.run.budget)."""

from __future__ import annotations

import math

import pytest
from proto_files import REALISTIC

from printgen.errors import InputError
from printgen.run import speed
from printgen.run.budget import Work, check_budget, estimate
from printgen.run.make import plan_run

SCALE = 40.0
SLOW = 1e4  # a machine 10^4 times slower than the reference: every make is over a minute


@pytest.fixture
def fresh_factor(monkeypatch):
    """speed_factor measured (or read) anew in the test, and cached anew after it."""
    speed.speed_factor.cache_clear()
    yield monkeypatch
    speed.speed_factor.cache_clear()


def test_calibration_is_a_measured_cpu_time():
    t = speed.calibration_cpu()
    assert math.isfinite(t) and 0 < t < 100 * speed.REFERENCE_CPU_S  # a real solve, finished


def test_the_estimate_scales_its_times_not_its_work():
    ctx = plan_run(REALISTIC, SCALE)
    one = estimate(ctx.prototype, ctx.design, cores=2, variants=3)
    two = estimate(ctx.prototype, ctx.design, cores=2, variants=3, speed=2.0)
    assert two.seconds == pytest.approx(2 * one.seconds, rel=1e-12)  # linear: a product
    assert two.verification_s == pytest.approx(2 * one.verification_s, rel=1e-12)
    assert two.parts_s == pytest.approx(2 * one.parts_s, rel=1e-12)
    assert two.to_record() == one.to_record()  # the solver work does not depend on the machine
    assert "2 x the reference machine's time" in two.summary()


def test_the_environment_sets_the_factor(fresh_factor):
    fresh_factor.setenv(speed.SPEED_ENV, "2.5")
    assert speed.speed_factor() == 2.5


@pytest.mark.parametrize("value", ["fast", "0", "-1", "nan", "inf"])
def test_a_bad_factor_is_refused_by_name(fresh_factor, value):
    fresh_factor.setenv(speed.SPEED_ENV, value)
    with pytest.raises(InputError, match=f"{speed.SPEED_ENV}={value!r} must be a positive"):
        speed.speed_factor()


def test_a_slow_machine_is_refused_with_its_factor(fresh_factor):
    """check_budget measures (here: reads) the factor: the same run that fits on the reference
    machine is over the default minute on one SLOW times slower, and the message says why."""
    ctx = plan_run(REALISTIC, SCALE)
    assert check_budget(ctx.prototype, ctx.design, limit_s=60, cores=2, work=Work(),
                        speed=1.0).seconds < 60
    fresh_factor.setenv(speed.SPEED_ENV, str(SLOW))
    with pytest.raises(InputError, match="this run is too big") as err:
        check_budget(ctx.prototype, ctx.design, limit_s=60, cores=2, work=Work())
    assert f"{SLOW:.2g} x the reference machine's time" in str(err.value)
