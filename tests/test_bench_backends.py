"""`bench solver --backends`: the backend table times the same solve with each linear backend,
lists the ones not installed as skipped, and every backend reaches the same equilibrium."""

from __future__ import annotations

import pytest

from benchmarks.bench_solver import backend_table

SAME = 1e-9  # relative agreement of the centre deflection between backends: each solve stops
# at bench_solver.GOAL_TOL (1e-6 of the force scale), but its last Newton step converges
# quadratically and lands far below that (measured: 12 equal digits from 3.4k to 57k unknowns)


def test_backend_table_rows_agree_and_name_what_is_missing():
    rows = backend_table([0.5], ["lu", "ldl", "cholmod", "no-such-backend"])
    assert [r["backend"] for r in rows] == ["lu", "ldl", "cholmod", "no-such-backend"]
    assert rows[-1]["skipped"] == "no-such-backend not installed"
    timed = [r for r in rows if "skipped" not in r]
    assert timed[0]["backend"] == "lu"  # SuperLU is always there
    for r in timed:
        assert r["converged"] and r["cpu_s"] > 0 and r["unknowns"] == rows[0]["unknowns"]
        assert r["deflection_m"] == pytest.approx(timed[0]["deflection_m"], rel=SAME)
