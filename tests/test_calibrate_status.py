"""Tester status columns decided per column from the data (issue 22, case 1).

A home-built Arduino tester writes `time_s;steps;displacement_mm;force_raw;force_N;accel_x;
accel_y;accel_z;endstop;step_loss`, with `endstop = 1` on every row: its end-stop input is
active-low with a pull-up, so 1 means "not triggered". A column constant through the test is a
state, not an event; a column that changes marks the rows that differ from its start. The files
here are generated from a known law in that layout (no copied data).
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from numpy.testing import assert_allclose

from printgen.calibrate.pipeline import calibrate
from printgen.calibrate.reader import read_export
from printgen.calibrate.sample import FitOptions
from printgen.calibrate.status import decide
from printgen.cli import main
from printgen.errors import CalibrationError

HEADER = ("time_s;steps;displacement_mm;force_raw;force_N;accel_x;accel_y;accel_z;endstop;"
          "step_loss")
WIDTH_MM, THICK_MM, GRIP_MM = 4.0, 2.0, 50.0
AREA = WIDTH_MM * THICK_MM * 1e-6  # m^2
E = 2.0e9  # Pa, a printed PETG cable
SCATTER = (0.98, 1.0, 1.02)  # n = 3
STRAIN_STEP = 2e-5  # per row: 100 rows in the ISO window
YIELD_STRAIN, END_STRAIN = 0.012, 0.03
COUNTS_PER_N = 376.5  # force_raw: HX711 counts
STEPS_PER_MM = 400  # stepper steps per mm of crosshead travel
NOISE_N = 0.02  # force noise (seeded)
TRIGGER_ROWS = 6  # the end stop reads 0 on the last rows of the third test
RECOVERY_RTOL = 0.005  # the calibrate module's recovery requirement for known laws


def _arduino(path: Path, e_pa: float, seed: int, *, trigger: bool = False,
             step_loss: np.ndarray | None = None) -> Path:
    """One export of the Arduino tester: linear to yield, then 5 % of E, to END_STRAIN."""
    rng = np.random.default_rng(seed)
    strain = np.arange(0.0, END_STRAIN, STRAIN_STEP)
    force = AREA * e_pa * (np.minimum(strain, YIELD_STRAIN)
                           + 0.05 * np.maximum(strain - YIELD_STRAIN, 0.0))
    force = force + NOISE_N * rng.standard_normal(force.size)
    endstop = np.ones(force.size, int)
    if trigger:
        endstop[-TRIGGER_ROWS:] = 0  # the crosshead reaches the end stop: the input goes low
    loss = np.zeros(force.size, int) if step_loss is None else step_loss
    accel = 0.01 * rng.standard_normal((force.size, 3)) + [0.0, 0.0, 1.0]
    rows = [HEADER] + [
        f"{0.05 * i:.2f};{round(e * GRIP_MM * STEPS_PER_MM)};{e * GRIP_MM:.5f};"
        f"{round(f * COUNTS_PER_N)};{f:.3f};{a[0]:.3f};{a[1]:.3f};{a[2]:.3f};{s};{k}"
        for i, (e, f, a, s, k) in enumerate(zip(strain, force, accel, endstop, loss,
                                                strict=True))]
    path.write_text("\n".join(rows) + "\n", encoding="utf-8")
    return path


@pytest.fixture
def arduino(tmp_path):
    """Three tests; the third ends on the end stop."""
    d = tmp_path / "arduino"
    d.mkdir()
    for i, f in enumerate(SCATTER):
        _arduino(d / f"run{i + 1}.csv", E * f, seed=i, trigger=i == 2)
    (d / "specimen.toml").write_text(f"width_mm = {WIDTH_MM}\nthickness_mm = {THICK_MM}\n"
                                     f"grip_distance_mm = {GRIP_MM}\n")
    return d


def test_constant_end_stop_is_a_state_and_a_real_trigger_is_marked(arduino):
    cal = calibrate([arduino], material="ard")
    assert len(cal.samples) == 3
    marked = [s for s in cal.samples if s.flags]
    assert [Path(s.path).name for s in marked] == ["run3.csv"]
    n_rows = int(np.ceil(END_STRAIN / STRAIN_STEP))
    first = n_rows - TRIGGER_ROWS + 2  # the header is line 1
    at = (n_rows - TRIGGER_ROWS) * STRAIN_STEP * 100  # % strain
    note = f"endstop set at line {first}, {at:.3g} % strain ({TRIGGER_ROWS} rows; active-low, "
    assert marked[0].flags == (note + "0 = set)",)
    assert cal.excluded == (marked[0].path,)
    assert_allclose(cal.modulus.mean, E * (SCATTER[0] + SCATTER[1]) / 2, rtol=RECOVERY_RTOL)
    # The convention assumed, in the warnings: once per kind of column, with its files.
    assert ("status column 'endstop': 1 on every row, a state, not an event: read as "
            "active-low (1 = not set), no sample marked; if that is wrong, say --flag "
            "endstop=active-high (run1.csv, run2.csv)") in cal.warnings
    assert ("status column 'endstop': 1 at the start of the test, 0 during it: read as "
            "active-low (0 = set); if that is wrong, say --flag endstop=active-high "
            "(run3.csv)") in cal.warnings
    assert not any("step_loss" in w for w in cal.warnings)  # 0 throughout: the usual idle
    # ...and in each sample's record.
    assert cal.samples[0].status == {
        "endstop": {"convention": "active-low", "decided_by": "data", "constant": True,
                    "rows_set": 0},
        "step_loss": {"convention": "active-high", "decided_by": "data", "constant": True,
                      "rows_set": 0}}
    assert cal.samples[2].status["endstop"] == {"convention": "active-low", "decided_by": "data",
                                                "constant": False, "rows_set": TRIGGER_ROWS}


def test_user_says_the_convention(arduino, capsys):
    args = ["calibrate", str(arduino), "--material", "ard"]
    # active-high: every row of run1/run2 is "set", and run3 too: nothing left.
    assert main([*args, "--flag", "endstop=active-high"]) == 2
    assert "all 3 samples carry tester flags" in capsys.readouterr().err
    # active-low, as the data says; said by the user, so no note, and the JSON says who.
    assert main([*args, "--flag", "ENDSTOP=active-low", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert [s["excluded"] for s in out["samples"]] == [False, False, True]
    assert out["samples"][0]["status_columns"]["endstop"]["decided_by"] == "user"
    assert out["samples"][2]["flags"][0].endswith("0 = set, as asked)")
    assert not any("status column 'endstop'" in w for w in out["warnings"])
    # ignore: the column is not a status column at all; run3 is kept.
    assert main([*args, "--flag", "endstop=ignore", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["excluded"] == [] and out["modulus_GPa"]["n"] == 3
    assert "status column 'endstop': ignored (as asked) (all 3 files)" in out["warnings"]
    # Bad names and conventions: one line naming the value and the choices, exit 2.
    assert main([*args, "--flag", "endstopp=active-low"]) == 2
    err = capsys.readouterr().err
    assert "--flag endstopp: no status column of that name" in err
    assert "status columns: 'endstop', 'step_loss'" in err
    assert main([*args, "--flag", "endstop=low"]) == 2
    assert ("status column 'endstop': convention 'low' (--flag or a sidecar [flags] table); "
            "expected one of active-high, active-low, ignore") in capsys.readouterr().err
    assert main([*args, "--flag", "endstop"]) == 2
    assert "expected NAME=VALUE, e.g. endstop=active-low" in capsys.readouterr().err


def test_sidecar_flags_table_and_an_active_high_event(tmp_path):
    loss = np.zeros(int(np.ceil(END_STRAIN / STRAIN_STEP)), int)
    loss[900:903] = 1  # three rows of step loss at 1.8 % strain
    p = _arduino(tmp_path / "loss.csv", E, seed=5, step_loss=loss)
    spec = {"width": WIDTH_MM * 1e-3, "thickness": THICK_MM * 1e-3,
            "grip_distance": GRIP_MM * 1e-3}
    keep = FitOptions(keep_flagged=True)  # one file: keep it flagged to look at it
    cal = calibrate([p], material="x", specimen=spec, options=keep)
    # Raised from 0 during the test: an active-high event, said the usual way.
    assert cal.samples[0].flags == ("step_loss set at line 902, 1.8 % strain (3 rows)",)
    assert not any("step_loss" in w and "status column" in w for w in cal.warnings)
    (tmp_path / "loss.toml").write_text("[flags]\nstep_loss = 'ignore'\n")
    assert calibrate([p], material="x", specimen=spec).samples[0].flags == ()
    # The option wins over the sidecar.
    again = calibrate([p], material="x", specimen=spec, options=keep,
                      flags={"step_loss": "active-high"})
    assert again.samples[0].flags[0].startswith("step_loss set at line 902")
    (tmp_path / "loss.toml").write_text("[flags]\nstep_loss = 1\n")
    with pytest.raises(CalibrationError, match=r"status column 'step_loss': convention '1' "
                       r"\(--flag or a sidecar \[flags\] table\); expected one of active-high"):
        calibrate([p], material="x", specimen=spec)


def test_decide_per_column():
    ones, zeros = np.ones(6), np.zeros(6)
    falls, rises = np.array([1, 1, 1, 1, 0, 0.0]), np.array([0, 0, 1, 0, 0, 0.0])
    cols, notes = decide({"End stop": ones, "Overload": zeros, "limit": falls, "Slip": rises,
                          "cycle": ones}, {}, "f.csv")
    by = {c.name: c for c in cols}
    assert "cycle" not in by  # constant, and not named as a flag: a constant, not a status
    assert [(c.convention, c.constant, int(c.on.sum())) for c in by.values()] == [
        ("active-low", True, 0), ("active-high", True, 0), ("active-low", False, 2),
        ("active-high", False, 1)]
    assert len(notes) == 2 and notes[0].startswith("status column 'End stop': 1 on every row")
    assert notes[1].startswith("status column 'limit': 1 at the start of the test, 0 during")
    # Told by the user: the level they say, on every row (constant or not).
    cols, notes = decide({"End stop": ones}, {"end stop": "active-high"}, "f.csv")
    assert int(cols[0].on.sum()) == 6 and cols[0].decided_by == "user" and notes == ()
    # A cycle column the user names is read as they say.
    cols, _ = decide({"cycle": ones}, {"cycle": "active-low"}, "f.csv")
    assert cols[0].on.sum() == 0
    with pytest.raises(CalibrationError, match=r"f\.csv: --flag force: no status column"):
        decide({"End stop": ones}, {"force": "active-low"}, "f.csv")


def test_true_false_status_words_read_like_numbers(tmp_path):
    p = tmp_path / "words.csv"
    p.write_text("Time [s];Force [N];Crosshead [mm];Limit switch\n"
                 + "".join(f"{i};{2.0 * i};{0.01 * i};{'true' if i < 48 else 'false'}\n"
                           for i in range(50)))
    rec = read_export(p)
    assert rec.status[0].convention == "active-low"
    assert int(rec.flags["Limit switch"].sum()) == 2
