"""Reader of tensile-test exports: every CSV variant a tester writes, bad files, fuzzing.

`write_export` (also used by the other calibrate tests) writes channels in one of `VARIANTS`.
"""

from __future__ import annotations

import zipfile
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy.testing import assert_allclose

from printgen.calibrate.numbers import decimal_of, parse_number
from printgen.calibrate.reader import read_export
from printgen.calibrate.specimen import from_metadata, machine_modulus
from printgen.errors import CalibrationError

# Written numbers keep 10 significant digits: relative round-off far below this.
ROUNDTRIP_RTOL = 1e-6
FORCE_ATOL_N = 1e-9  # far below any load cell; tiny forces written in kN may round to zero

# name -> how the file is written. units: where units go ("paren": `Load (N)`, "in": `Kraft in
# kN`, "bracket": `Load [N]`, "suffix": `force_N`, "row": a units row, "rowparen": `(N)` row).
VARIANTS = {
    "comma": {"delim": ",", "dec": ".", "units": "paren", "quote": False, "thousands": False,
              "ext": ".csv", "force_unit": "N", "disp_unit": "mm"},
    "semicolon_decimal_comma": {"delim": ";", "dec": ",", "units": "in", "quote": False,
                                "thousands": False, "ext": ".CSV", "force_unit": "kN",
                                "disp_unit": "mm"},
    "tab_units_row": {"delim": "\t", "dec": ".", "units": "row", "quote": False,
                      "thousands": False, "ext": ".TXT", "force_unit": "N", "disp_unit": "m"},
    "bluehill_quoted": {"delim": ",", "dec": ".", "units": "rowparen", "quote": True,
                        "thousands": True, "ext": ".csv", "force_unit": "N", "disp_unit": "mm"},
    "european_quoted": {"delim": ";", "dec": ",", "units": "bracket", "quote": True,
                        "thousands": True, "ext": ".txt", "force_unit": "N", "disp_unit": "mm"},
}
UNIT_SCALE = {"N": 1.0, "kN": 1e3, "mm": 1e-3, "m": 1.0, "%": 1e-2, "MPa": 1e6, "s": 1.0}
NAMES = {"time": "Time", "force": "Load", "displacement": "Crosshead", "strain": "Strain",
         "stress": "Stress"}
GERMAN = {"time": "Zeit", "force": "Kraft", "displacement": "Weg", "strain": "Dehnung",
          "stress": "Spannung"}


def number(v: float, variant: dict) -> str:
    text = f"{v:,.10g}" if variant["thousands"] else f"{v:.10g}"
    if variant["dec"] == ",":
        text = text.replace(",", "\0").replace(".", ",").replace("\0", ".")
    return f'"{text}"' if variant["quote"] else text


def write_export(path: Path, channels: dict[str, np.ndarray], variant_name: str, *,
                 metadata: list[tuple[str, float, str]] = (), units: dict[str, str] | None = None
                 ) -> Path:
    """Write SI `channels` (role -> values) as a tester of `variant_name` would; return path."""
    v = VARIANTS[variant_name]
    unit = {"time": "s", "force": v["force_unit"], "displacement": v["disp_unit"],
            "strain": "%", "stress": "MPa", **(units or {})}
    roles = list(channels)
    names = GERMAN if v["units"] == "in" else NAMES
    d = v["delim"]
    lines = [d.join([key, number(val, v), u]) for key, val, u in metadata]
    if metadata:
        lines.append("")
    header = {"paren": "{n} ({u})", "in": "{n} in {u}", "bracket": "{n} [{u}]",
              "row": "{n}", "rowparen": "{n}", "suffix": "{n}_{u}"}[v["units"]]
    lines.append(d.join(header.format(n=names[r], u=unit[r]) for r in roles))
    if v["units"] == "row":
        lines.append(d.join(unit[r] for r in roles))
    if v["units"] == "rowparen":
        lines.append(d.join(f"({unit[r]})" for r in roles))
    cols = [np.asarray(channels[r]) / UNIT_SCALE[unit[r]] for r in roles]
    lines += [d.join(number(c[i], v) for c in cols) for i in range(len(cols[0]))]
    out = path.with_suffix(v["ext"])
    out.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return out


def noisy_breaking_exports(folder: Path, stem: str, eps: np.ndarray, force: np.ndarray,
                           length: float, noise: float, n: int = 3, seed: int = 36
                           ) -> list[Path]:
    """`n` Bluehill-like exports of a test of `force` (N) at strains `eps` over gauge
    `length` (m): normal noise of SD `noise` x the largest force, then a drop (the break) a
    fit must leave out."""
    rng = np.random.default_rng(seed)
    tail = np.linspace(0, 1, 20)[1:]
    e = np.concatenate([eps, eps[-1] + 0.002 * tail])
    paths = []
    for i in range(n):
        f = force + noise * force.max() * rng.standard_normal(eps.size)
        f = np.concatenate([f, f[-1] * (1 - 0.9 * tail)])
        ch = {"time": np.arange(e.size) * 0.1, "force": f, "displacement": e * length}
        paths.append(write_export(folder / f"{stem}-{i}", ch, "bluehill_quoted"))
    return paths


def _channels(n: int = 50) -> dict[str, np.ndarray]:
    t = np.linspace(0.0, 10.0, n)
    return {"time": t, "force": 1234.5 * t + 0.25, "displacement": 1e-4 * t}


@pytest.mark.parametrize("variant", sorted(VARIANTS))
def test_every_variant_reads_back_in_si(tmp_path, variant):
    ch = _channels()
    meta = [("Width", 10.5, "mm"), ("Thickness", 2.0, "mm"), ("Modulus", 178383.19763, "MPa")]
    rec = read_export(write_export(tmp_path / "spec", ch, variant, metadata=meta))
    for role, values in ch.items():
        assert_allclose(rec.channels[role], values, rtol=ROUNDTRIP_RTOL, atol=1e-9)
    assert rec.delimiter == VARIANTS[variant]["delim"]
    assert rec.decimal == VARIANTS[variant]["dec"]
    dims = from_metadata(rec.metadata, rec.path)
    assert_allclose([dims["width"], dims["thickness"]], [10.5e-3, 2.0e-3], rtol=ROUNDTRIP_RTOL)
    assert_allclose(machine_modulus(rec.metadata), 178383.19763e6, rtol=ROUNDTRIP_RTOL)


def test_unit_suffix_header_zip_and_footer(tmp_path):
    """Header units as `force_N`, a zip holding one CSV, a footer after the table."""
    text = "time_ms,force_kN\n10,0.5\n20,0.75\n30,1.0\nEnd of test\nOperator: X\n"
    with zipfile.ZipFile(tmp_path / "trial.csv.zip", "w") as z:
        z.writestr("trial.csv", text)
    rec = read_export(tmp_path / "trial.csv.zip")
    assert_allclose(rec.channels["force"], [500.0, 750.0, 1000.0], rtol=ROUNDTRIP_RTOL)
    assert_allclose(rec.channels["time"], [0.01, 0.02, 0.03], rtol=ROUNDTRIP_RTOL)


def test_a_quote_left_open_ends_with_its_line(tmp_path):
    """Every line is read on its own: an open quote in a metadata line does not swallow the
    table under it (the reader's one-pass split falls back to line by line)."""
    p = tmp_path / "x.csv"
    p.write_text('Operator: "A. Smith\ntime_s,force_N\n1,10\n2,20\n3,30\n')
    rec = read_export(p)
    assert_allclose(rec.channels["force"], [10.0, 20.0, 30.0], rtol=ROUNDTRIP_RTOL)
    assert rec.first_data_line == 3


def test_columns_chosen_by_option_and_unit_override(tmp_path):
    p = tmp_path / "x.csv"
    p.write_text("a,b,c\n1,2,3\n4,5,6\n7,8,9\n")
    with pytest.raises(CalibrationError, match="no force or stress column"):
        read_export(p)
    rec = read_export(p, columns={"force": "b", "displacement": "3"}, units={"force": "kN"})
    assert_allclose(rec.channels["force"], [2e3, 5e3, 8e3], rtol=ROUNDTRIP_RTOL)
    assert_allclose(rec.channels["displacement"], [3e-3, 6e-3, 9e-3], rtol=ROUNDTRIP_RTOL)


@pytest.mark.parametrize("body, match", [
    ("Load (N);Extension (mm)\n1,0;2,0\n2,0;3,0\n3,0;abc\n4,0;5,0\n",
     r"x\.csv:4: column 'Extension \(mm\)' holds 'abc'; expected a number with decimal ','"),
    ("Load (N),Extension (mm)\n1,2\n3,4\n5\n7,8\n", r"x\.csv:4: expected 2 values separated by"),
    ("Load (furlong),Extension (mm)\n1,2\n3,4\n", r"unit 'furlong' is not a force unit"),
    ("just a note\nanother note\n", r"no table found"),
    ("Load (N),Extension (mm)\n1,2\n3," + "4" * 140_000 + "\n5,6\n",
     r"x\.csv, line 3: 140,002 characters, more than the 65,536"),
])
def test_bad_files_name_file_line_and_expectation(tmp_path, body, match):
    p = tmp_path / "x.csv"
    p.write_text(body)
    with pytest.raises(CalibrationError, match=match):
        read_export(p)


@settings(max_examples=200, deadline=None)
@given(v=st.floats(min_value=-1e7, max_value=1e7, allow_nan=False),
       variant=st.sampled_from(sorted(VARIANTS)))
def test_numbers_roundtrip_in_every_style(v, variant):
    text = number(v, VARIANTS[variant])
    assert_allclose(parse_number(text, VARIANTS[variant]["dec"]), v, rtol=ROUNDTRIP_RTOL)


@settings(max_examples=100, deadline=None)
@given(values=st.lists(st.floats(min_value=0.0, max_value=1e5, allow_nan=False), min_size=3,
                       max_size=30),
       variant=st.sampled_from(sorted(VARIANTS)))
def test_fuzzed_tables_read_back(tmp_path_factory, values, variant):
    path = tmp_path_factory.mktemp("fuzz") / "f"
    force = np.array(values)
    ch = {"force": force, "displacement": np.arange(force.size) * 1e-4}
    rec = read_export(write_export(path, ch, variant, metadata=[("Width", 3.25, "mm")]),
                      decimal=VARIANTS[variant]["dec"])
    assert_allclose(rec.channels["force"], force, rtol=ROUNDTRIP_RTOL, atol=FORCE_ATOL_N)


def test_decimal_vote():
    assert decimal_of(["0,5", "12,25", "1.234,5"]) == ","
    assert decimal_of(["2,554.70532", "0.00319"]) == "."


def test_plot_labels_show_control_characters_as_escapes():
    """A file name may hold control characters (an escape, a tab): the plot's legend shows
    them escaped, never raw."""
    from printgen.calibrate.plot import printable

    assert printable("coupon\x1b[31m\t1.csv") == "coupon\\x1b[31m\\x091.csv"
    assert printable("coupon 1 é.csv") == "coupon 1 é.csv"  # printable text unchanged
