"""What a calibration says about its set (issue 22, case 3 and the rest): each written value's
own source, specimen orientations mixed in one folder, specimen names in the table, and the mode
of a written profile.

Force-only files are generated in the layout of the joshcarter/tensile_test exports
(`xy-trial-<k>.csv.zip` / `z-trial-<k>.csv.zip`, each holding one `time_ms,force_N` CSV); no
copied data.
"""

from __future__ import annotations

import json
import os
import re
import zipfile
from pathlib import Path

import numpy as np
import pytest
from numpy.testing import assert_allclose
from test_calibrate_windows import _bluehill

from printgen.calibrate.groups import orientation
from printgen.calibrate.pipeline import calibrate
from printgen.calibrate.reader import MetaItem
from printgen.cli import main

AREA_MM2 = 25.0
PEAKS_N = {"xy": (988.6, 1218.0, 1083.5, 1195.7, 1125.1), "z": (640.2, 702.9, 590.4, 655.0,
                                                                  611.7)}
THRESHOLD_N = 50.0  # recording starts when the force passes it
PEAK_ATOL_N = 1e-6  # forces are written with 10 digits
STRENGTH_RTOL = 1e-9  # mean of the written peaks over the area, exact but for round-off


def _trial(folder: Path, axis: str, k: int, peak: float) -> Path:
    """One zipped force-time record: rise from the threshold to the peak, then fracture."""
    t = np.arange(0, 4000, 10)  # ms
    rise = THRESHOLD_N + (peak - THRESHOLD_N) * np.sin(np.pi / 2 * np.minimum(t / 3000, 1))
    force = np.where(t <= 3000, rise, peak * np.exp(-(t - 3000) / 50))
    text = "time_ms,force_N\n" + "".join(f"{a},{f:.10g}\n" for a, f in zip(t, force,
                                                                           strict=True))
    path = folder / f"{axis}-trial-{k}.csv.zip"
    with zipfile.ZipFile(path, "w") as z:
        z.writestr(f"{axis}-trial-{k}.csv", text)
    return path


@pytest.fixture
def force_only(tmp_path):
    d = tmp_path / "Overture PETG Black"
    d.mkdir()
    for axis, peaks in PEAKS_N.items():
        for k, p in enumerate(peaks, 1):
            _trial(d, axis, k, p)
    (d / "summary.txt").write_text("=== Test Summary ===\nAxis: xy\n")
    return d


def test_strength_only_never_shows_an_inherited_modulus_as_measured(force_only, tmp_path,
                                                                       capsys):
    out = tmp_path / "profiles"
    xy = sorted(map(str, force_only.glob("xy-*")))
    args = ["calibrate", *xy, "--material", "petg-josh", "--area-mm2", str(AREA_MM2),
            "--strength-only", "--inherits", "petg", "--out", str(out), "--json"]
    assert main(args) == 0
    written = json.loads(capsys.readouterr().out)["written"]
    assert_allclose(written["modulus_gpa"], 1.30)  # petg's own measured modulus, inherited
    assert written["modulus_source"].startswith("inherited from petg: Lambert et al. 2023")
    assert written["modulus_source"].endswith("not measured by this calibration "
                                              "(--strength-only)")
    assert written["failure_stress_source"] == "measured: this calibration (5 files)"
    assert_allclose(written["failure_stress_mpa"], np.mean(PEAKS_N["xy"]) / AREA_MM2,
                    rtol=STRENGTH_RTOL)
    # A modulus measured earlier into the same profile stays the profile's own, and says so.
    strain = np.arange(0.0, 0.02, 2e-5)
    coupons = [_bluehill(tmp_path / f"coupon_{i}.csv", strain, 2.0e9 * strain, None, seed=i)
               for i in range(2)]
    assert main(["calibrate", *map(str, coupons), "--material", "petg-josh", "--out", str(out),
                 "--date", "2026-11-30", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["written"]["modulus_source"] == (
        "measured: this calibration (2 files)")
    assert main([*args[:-5], "--out", str(out), "--json"]) == 0  # update, no --inherits
    written = json.loads(capsys.readouterr().out)["written"]
    assert written["modulus_source"].startswith("earlier in this profile: printgen calibrate: "
                                                "tensile tests (2 files), 2026-11-30")
    assert written["modulus_source"].endswith("not measured by this calibration "
                                              "(--strength-only)")


def test_mixed_orientations_grouped_warned_and_not_saved(force_only, tmp_path, capsys):
    cal = calibrate([force_only], material="petg", specimen={"area": AREA_MM2 * 1e-6},
                    strength_only=True)
    assert [(g.label, len(g.files)) for g in cal.groups] == [("xy", 5), ("z", 5)]
    for g in cal.groups:
        assert_allclose(g.strength.mean, np.mean(PEAKS_N[g.label]) / AREA_MM2 * 1e6,
                        rtol=STRENGTH_RTOL)
    mixed = [w for w in cal.warnings if w.startswith("the files mix specimen orientations")]
    assert len(mixed) == 1
    xy, z = (np.mean(PEAKS_N[a]) / AREA_MM2 for a in ("xy", "z"))
    assert f"xy: 5 files, strength {xy:.4g} ± " in mixed[0]
    assert f"z: 5 files, strength {z:.4g} ± " in mixed[0]
    assert "calibrate one orientation at a time" in mixed[0]
    # JSON gives each group; saving a mixed set is refused, and nothing is written.
    args = ["calibrate", str(force_only), "--material", "petg-mix", "--area-mm2",
            str(AREA_MM2), "--strength-only"]
    assert main([*args, "--json"]) == 0
    groups = json.loads(capsys.readouterr().out)["orientations"]
    assert sorted(groups) == ["xy", "z"] and groups["z"]["strength_MPa"]["n"] == 5
    out = tmp_path / "prof"
    assert main([*args, "--inherits", "petg", "--out", str(out)]) == 2
    assert "mix specimen orientations (xy: 5 files, z: 5 files)" in capsys.readouterr().err
    assert not (out / "materials" / "petg-mix.toml").exists()
    # One orientation alone: no groups, no warning.
    one = calibrate(sorted(force_only.glob("z-*")), material="petg",
                    specimen={"area": AREA_MM2 * 1e-6}, strength_only=True)
    assert one.groups == () and not any("orientation" in w for w in one.warnings)


def test_orientation_from_metadata_or_name():
    meta = (MetaItem("Build orientation", "Upright", None, None, 3),)
    assert orientation("/lab/coupon_7.csv", meta) == "upright"
    assert orientation("/lab/PLA_z_3.csv", ()) == "z"
    assert orientation("/lab/coupon-90deg-2.CSV", ()) == "90deg"
    assert orientation("/d/xy-trial-1.csv.zip:xy-trial-1.csv", ()) == "xy"
    assert orientation("/lab/Specimen_RawData_10.csv", ()) is None
    assert orientation("/lab/petg_3.csv", ()) is None


def test_table_shows_whole_specimen_names(tmp_path, capsys):
    strain = np.arange(0.0, 0.02, 2e-5)
    files = [_bluehill(tmp_path / f"Specimen_RawData_{i}.csv", strain, 2.0e9 * strain, 2.0e9,
                       seed=i) for i in range(1, 11)]
    assert main(["calibrate", *map(str, files), "--material", "petg"]) == 0
    text = capsys.readouterr().out
    rows = [ln for ln in text.splitlines() if "Specimen_RawData_" in ln and "│" in ln]
    assert sorted(re.search(r"Specimen_RawData_\d+\.csv", r).group() for r in rows) == sorted(
        f.name for f in files)
    assert "…" not in text  # no name or number cut short


@pytest.mark.parametrize("umask, mode", [(0o022, 0o644), (0o027, 0o640), (0o002, 0o664)])
def test_profile_written_with_the_umask_mode(tmp_path, force_only, umask, mode):
    cal = calibrate(sorted(force_only.glob("xy-*")), material="petg-josh",
                    specimen={"area": AREA_MM2 * 1e-6}, strength_only=True)
    from printgen.calibrate.profile_writer import write_profile

    old = os.umask(umask)
    try:
        path, _ = write_profile(cal, name="petg-josh", out=tmp_path / "p", inherits="petg")
        assert path.stat().st_mode & 0o777 == mode
        path.chmod(0o600)  # a lab's own choice for an existing profile is kept
        write_profile(cal, name="petg-josh", out=tmp_path / "p")
        assert path.stat().st_mode & 0o777 == 0o600
    finally:
        os.umask(old)
