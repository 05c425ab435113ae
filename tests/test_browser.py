"""The HTML report in a real browser (issue 13): headless Chromium renders it, every image
loads, and the page logs no error. The screenshot is kept in `artifacts/` (ignored by git) for
a person to look at; CI keeps it as an artifact. What a lab takes to the flume (issue 23):
the summary box in the first screen, every axis labelled with its unit, no reference to a file
the package lacks, report.pdf with pages and text, and the CSV files holding report.json's
numbers.

Without Chromium the test skips locally and fails under CI (`require_tool`); `scripts/setup.sh
--with-slicers` installs Debian's `chromium` when run as root.
"""

from __future__ import annotations

import csv
import dataclasses
import json
import re
import shutil
import subprocess

import numpy as np
import pytest
from conftest import ROOT, require_tool
from proto_files import REALISTIC

import printgen.run.make as make_mod
from printgen.report import pdf
from printgen.run.options import RunOptions

ARTIFACTS = ROOT / "artifacts"
CHROMIUM_S = 120  # a cold headless start on a loaded machine takes a few seconds
MIN_SCREENSHOT_BYTES = 20_000  # a blank 1200 x 2400 PNG is ~10 kB; the report's is far larger
FLAGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-background-networking",
         "--disable-component-update", "--disable-sync", "--no-first-run",
         "--disable-default-apps", "--hide-scrollbars", "--virtual-time-budget=10000"]
# Injected first in <head>: records page errors (scripts, and resources that fail to load, in
# the capture phase) and console.error calls, then reports every image's state after `load`.
PROBE = """<script>
window.__errors = [];
window.addEventListener("error", function (e) {
  var t = e.target || {};
  window.__errors.push(e.message || ("failed to load " + (t.src || t.href || t.tagName)));
}, true);
var __ce = console.error;
console.error = function () { window.__errors.push([].join.call(arguments, " "));
                              __ce.apply(console, arguments); };
window.addEventListener("load", function () {
  var imgs = [].slice.call(document.images);
  var probe = document.createElement("pre");
  probe.id = "printgen-probe";
  probe.textContent = JSON.stringify({
    images: imgs.length,
    broken: imgs.filter(function (i) { return !(i.complete && i.naturalWidth > 0); })
                .map(function (i) { return i.alt; }),
    errors: window.__errors,
    h1: (document.querySelector("h1") || {}).textContent,
    height: document.body.scrollHeight});
  document.body.appendChild(probe);
});
</script>"""


@pytest.fixture(scope="module")
def made(made_1_40):
    """The session's whole `make` of the 1:40 example: (output folder, the run's context)."""
    ctx, out = made_1_40
    return out, ctx


@pytest.fixture(scope="module")
def printed(made, tmp_path_factory):
    """report.pdf of the 1:40 example: make's PDF step (`report_pdf`, what `make --pdf` runs
    after writing report.html) on a copy of the shared run's folder, with a context of its own
    (the shared one is read only): (the copy, the files the step added)."""
    out, ctx = made
    copy = tmp_path_factory.mktemp("printed") / "out"
    shutil.copytree(out, copy)
    own = dataclasses.replace(ctx, record={}, files=[])
    make_mod.report_pdf(own, copy, None)
    return copy, own.files


@pytest.fixture(scope="module")
def report(made):
    return made[0] / "report.html"


def chromium(exe: str, tmp_path, *args: str) -> subprocess.CompletedProcess:
    profile = tmp_path / "chromium-profile"
    return subprocess.run([exe, *FLAGS, f"--user-data-dir={profile}", "--enable-logging=stderr",
                           "--v=0", *args], check=False, capture_output=True, text=True,
                          timeout=CHROMIUM_S)


def probe_of(run: subprocess.CompletedProcess) -> dict:
    """The probe's JSON from a --dump-dom run."""
    m = re.search(r'<pre id="printgen-probe">(.*?)</pre>', run.stdout, re.DOTALL)
    assert m, f"the page did not finish loading: {run.stderr[-2000:]}"
    return json.loads(m.group(1).replace("&quot;", '"').replace("&amp;", "&"))


@pytest.mark.slow
def test_report_renders_with_every_image_and_no_errors(report, tmp_path):
    exe = require_tool("chromium")
    html = report.read_text()
    probed = tmp_path / "probed.html"
    probed.write_text(html.replace("<head>", "<head>" + PROBE, 1))
    run = chromium(exe, tmp_path, "--dump-dom", probed.as_uri())
    probe = probe_of(run)
    assert probe["images"] == html.count("<img") >= 1
    assert probe["broken"] == [] and probe["errors"] == []
    assert probe["h1"].startswith("printgen: ") and probe["height"] > 1000
    console = [line for line in run.stderr.splitlines() if ":CONSOLE(" in line]
    assert console == [], console


@pytest.mark.slow
def test_screenshot_is_kept_as_an_artifact(report, tmp_path):
    exe = require_tool("chromium")
    ARTIFACTS.mkdir(exist_ok=True)
    shot = ARTIFACTS / "report.png"
    shot.unlink(missing_ok=True)
    run = chromium(exe, tmp_path, "--window-size=1200,2400", f"--screenshot={shot}",
                   report.as_uri())
    assert shot.is_file(), run.stderr[-2000:]
    data = shot.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n" and len(data) > MIN_SCREENSHOT_BYTES


@pytest.mark.slow
def test_the_probe_sees_a_broken_image_and_an_error(tmp_path):
    """The check above can fail: a missing image file and a script error are both caught."""
    exe = require_tool("chromium")
    page = tmp_path / "broken.html"
    page.write_text("<!DOCTYPE html><html><head>" + PROBE + "</head><body><h1>x</h1>"
                    '<img alt="gone" src="missing.png"><script>undefinedCall();</script>'
                    "</body></html>")
    run = chromium(exe, tmp_path, "--dump-dom", page.as_uri())
    probe = probe_of(run)
    assert probe["broken"] == ["gone"]
    assert any("missing.png" in e for e in probe["errors"])
    assert any("undefinedCall" in e for e in probe["errors"])


FIRST_SCREEN = (1400, 1000)  # px: the summary box ends within the first screen at this width
BOX_PROBE = """<script>
window.addEventListener("load", function () {
  var box = document.getElementById("summary").getBoundingClientRect();
  var probe = document.createElement("pre");
  probe.id = "printgen-probe";
  probe.textContent = JSON.stringify({top: box.top, bottom: box.bottom,
                                      width: window.innerWidth});
  document.body.appendChild(probe);
});
</script>"""
UNIT = re.compile(r"\(([^()]+)\)$")  # an axis label ends with its unit in parentheses
MIN_PDF_PAGES = 5  # the 1:40 report prints on well over five A4/Letter pages
A4_PT = (595.28, 841.89)  # 210 x 297 mm in PDF points (1/72 in)
LETTER_PT = (612.0, 792.0)  # 8.5 x 11 in
PAGE_TOL_PT = 1.0  # Chromium rounds the page to whole device pixels: well under a point
CSV_TOL = 1e-7  # the CSV files keep 8 significant digits
CSV_ZERO = 1e-6  # ... and write values below labfiles.NOISE as 0
# file names a report may mention: an output file, or a file of the package (README, examples)
FILE_REF = re.compile(r"\b[\w.-]+\.(?:md|csv|json|gcode|toml|png|svg|ini|cfg|3mf|stl|step|pdf"
                      r"|html)\b")


@pytest.mark.slow
def test_summary_box_is_in_the_first_screen(report, tmp_path):
    exe = require_tool("chromium")
    probed = tmp_path / "box.html"
    probed.write_text(report.read_text().replace("<head>", "<head>" + BOX_PROBE, 1))
    w, h = FIRST_SCREEN
    run = chromium(exe, tmp_path, f"--window-size={w},{h}", "--dump-dom", probed.as_uri())
    box = probe_of(run)
    assert box["width"] == w
    assert 0 <= box["top"] < box["bottom"] <= h, box
    text = report.read_text()
    start = text.index('id="summary"')
    assert start < text.index("<h2>Similitude targets</h2>")
    summary = text[start:text.index("</section>", start)]
    for what in ("FAIL", "Uncertainty band</b>", "Chosen:", "stiffness", "Printing:", " g ",
                 "Next:"):
        assert what in summary, what


def test_every_plot_axis_has_a_label_with_a_unit(made):
    out, ctx = made
    figures = ctx.report.figures
    assert len(figures) >= 6  # kit, previews, verification, deformed nets
    for f in figures:
        assert f.labels, f.name
        for title, names in f.labels:
            for name in names:
                assert UNIT.search(name), f"{f.name}, axis {title!r}: label {name!r}"
        assert (out / "figures").is_dir()
    written = sorted(p.name for p in (out / "figures").iterdir())
    assert len(written) == 2 * len(figures)
    assert all(n.endswith((".png", ".svg")) for n in written)
    panels = [t for f in figures if f.name == "verification" for t, _ in f.labels]
    assert any("elongation" in t for t in panels)


def test_strains_are_in_percent_and_the_band_cells_read(report):
    text = report.read_text()
    assert "bottom cable elongation (%)" in text or "(sensor wire, strain) (%)" in text
    assert re.search(r"\d\.\d{2} \(central -?\d+\.\d{2} to -?\d+\.\d{2}; envelope "
                     r"-?\d+\.\d{2} to -?\d+\.\d{2}\)", text)
    assert "stiffness (E*A, N)" in text and "stiffness (initial membrane across / up, N/m)" in text


def test_no_reference_to_a_file_the_package_lacks(made):
    out, _ = made
    text = re.sub(r'src="data:[^"]*"', "", (out / "report.html").read_text())
    text = re.sub(r"<[^>]+>", " ", text)
    for bad in ("barrier-physics", "printgen reference", "(issue ", "slicers.md"):
        assert bad not in text, bad
    shipped = {p.name for p in out.rglob("*")} | {p.name for p in ROOT.glob("*")} \
        | {p.name for p in (ROOT / "examples").iterdir()} \
        | {p.name for p in (ROOT / "profiles").rglob("*.toml")}  # provenance names profiles
    for name in set(FILE_REF.findall(text)):
        assert name in shipped, name


@pytest.mark.slow
def test_report_pdf_has_pages_and_text(printed):
    require_tool("chromium")
    pypdf = pytest.importorskip("pypdf")
    out, added = printed
    assert added == ["report.pdf"]
    reader = pypdf.PdfReader(out / "report.pdf")
    assert len(reader.pages) >= MIN_PDF_PAGES
    first = reader.pages[0].extract_text()
    assert "Summary" in first and "FAIL" in first
    box = reader.pages[0].mediabox  # A4 by default: 210 x 297 mm
    assert abs(float(box.width) - A4_PT[0]) < PAGE_TOL_PT
    assert abs(float(box.height) - A4_PT[1]) < PAGE_TOL_PT
    assert not list(out.glob(".*print*")), "the printed copy of report.html is left behind"


@pytest.mark.slow
def test_make_pdf_writes_report_pdf_into_the_folder_and_its_manifest(tmp_path):
    """`make` with options.pdf runs that step and lists report.pdf (targets, selection and
    design only: the PDF step does not depend on the other steps' files)."""
    require_tool("chromium")
    pypdf = pytest.importorskip("pypdf")
    out = tmp_path / "out"
    ctx = make_mod.make(REALISTIC, 40, out, steps=[],
                        options=RunOptions(pdf=True, paper="letter"))
    assert "report.pdf" in json.loads((out / "manifest.json").read_text())["files"]
    assert "report.pdf" in ctx.record["files"] and "pdf_skipped" not in ctx.record
    pages = pypdf.PdfReader(out / "report.pdf").pages
    assert len(pages) >= 1
    box = pages[0].mediabox  # --paper letter: 8.5 x 11 in
    assert abs(float(box.width) - LETTER_PT[0]) < PAGE_TOL_PT
    assert abs(float(box.height) - LETTER_PT[1]) < PAGE_TOL_PT


def test_paged_names_the_page_size_in_the_head():
    html = "<html><head><title>t</title></head><body>x</body></html>"
    assert "@page { size: A4; }</style></head>" in pdf.paged(html, "a4")
    assert "size: letter" in pdf.paged(html, "letter")
    with pytest.raises(ValueError, match="a4, letter"):
        pdf.paged(html, "a3")


@pytest.mark.parametrize("platform", ["win32", "darwin"])
def test_browser_found_where_the_installer_puts_it(platform, tmp_path, monkeypatch):
    """On Windows and macOS Chrome and Edge are seldom on the PATH: their install folders are
    searched after it (here: a fake executable where the second candidate would be)."""
    monkeypatch.delenv("PRINTGEN_CHROMIUM", raising=False)
    monkeypatch.setenv("PATH", str(tmp_path / "empty"))
    fake = tmp_path / "Edge" / "msedge"
    fake.parent.mkdir()
    fake.write_text("")
    monkeypatch.setitem(pdf.INSTALLED, platform, (str(tmp_path / "Chrome" / "chrome"),
                                                  str(fake)))
    assert pdf.browser(platform) == str(fake)
    assert pdf.browser("linux") is None  # nothing on the PATH, no install folders searched


def _read_csv(path) -> dict[str, list[float]]:
    lines = [ln for ln in path.read_text().splitlines() if not ln.startswith("#")]
    rows = list(csv.reader(lines))
    return {h: [float(r[i]) if r[i] else float("nan") for r in rows[1:]]
            for i, h in enumerate(rows[0])}


def test_csv_files_hold_the_numbers_of_report_json(made):
    out, _ = made
    rec = json.loads((out / "report.json").read_text())
    ver, bands = rec["verification"], rec["verification"]["bands"]
    levels = np.array(bands["levels"])
    curves = _read_csv(out / "curves.csv")
    np.testing.assert_allclose(curves["h_over_hb"], levels, rtol=CSV_TOL)
    proto_lv = np.array(ver["prototype"]["levels"])
    at = [int(np.argmin(abs(proto_lv - x))) for x in levels]
    pairs = {"mid_height_elongation_prototype_pct": (ver["prototype"]["values"]["strain_mid"],
                                                     100.0, at),
             "deflection_over_width_band_min": (bands["min"]["deflection"], 1.0, None),
             "top_cable_elongation_band_max_pct": (bands["max"]["strain_top"], 100.0, None),
             "lowering_over_height_model": (ver["model"]["values"]["lowering"], 1.0, at)}
    for col, (ref, f, idx) in pairs.items():
        want = np.array(ref, dtype=float)[idx] * f if idx else np.array(ref, dtype=float) * f
        np.testing.assert_allclose(curves[col], want, rtol=CSV_TOL, atol=CSV_ZERO, err_msg=col)
    reads = _read_csv(out / "expected-readings.csv")
    lab = rec["verification"]["lab"]
    row_mm = lab["units"]["sensor_row_mm"]["mid"]
    nominal = np.array(bands["nominal"]["strain_mid"])
    np.testing.assert_allclose(reads["mid_sensor_nominal_mm"], (nominal - nominal[0]) * row_mm,
                               rtol=CSV_TOL, atol=CSV_ZERO)
    np.testing.assert_allclose(reads["water_depth_mm"], levels * lab["units"]["height_mm"],
                               rtol=CSV_TOL)
    np.testing.assert_allclose(reads["max_strand_tension_n"],
                               np.array(ver["model"]["max_strand_tension_n"])[at], rtol=CSV_TOL,
                               atol=CSV_ZERO)
    with open(out / "sensor-layout.csv", newline="") as fh:
        placed = {r["item"]: r for r in csv.DictReader(fh)}
    for sensor in lab["layout"]["sensors"]:
        r = placed[f"{sensor['row']} wire"]
        np.testing.assert_allclose([float(r[k]) for k in ("x_mm", "z_mm", "x_to_mm", "z_to_mm")],
                                   [*sensor["anchor_mm"], *sensor["potentiometer_mm"]],
                                   rtol=CSV_TOL, atol=CSV_ZERO)
    for i, pin in enumerate(lab["layout"]["anchor_pins_mm"], 1):
        r = placed[f"anchor pin {i}"]
        np.testing.assert_allclose([float(r["x_mm"]), float(r["z_mm"])], pin, rtol=CSV_TOL)


def test_the_filled_measurement_sheet_reads_back(made, tmp_path):
    """The sheet filled with its own expected nominal readings reads as the model's curves."""
    from printgen.scene.readings import FlumeUnits
    from printgen.verification.measured import read_measured

    out, _ = made
    lab = json.loads((out / "report.json").read_text())["verification"]["lab"]
    u = lab["units"]
    units = FlumeUnits(u["width_mm"], u["height_mm"], u["sensor_row_mm"])
    lines = (out / "measurement-sheet.csv").read_text().splitlines()
    header = lines[1].split(",")
    filled = [lines[0], lines[1]]
    for line in lines[2:]:
        cells = line.split(",")
        for i, h in enumerate(header):
            if h.endswith("_mm") and not h.startswith("expected_") and h != "water_depth_mm":
                cells[i] = cells[header.index(f"expected_{h[:-3]}_nominal_mm")]
        filled.append(",".join(cells))
    sheet = tmp_path / "filled.csv"
    sheet.write_text("\n".join(filled) + "\n")
    m = read_measured(sheet, units)
    nominal = np.array(lab["readings"]["mid_sensor_mm"]["nominal"]) / u["sensor_row_mm"]["mid"]
    np.testing.assert_allclose(m.values["strain_mid"], nominal, rtol=CSV_TOL,
                               atol=CSV_ZERO / u["sensor_row_mm"]["mid"])
    assert set(m.values) == {"strain_bottom", "strain_top", "strain_mid", "deflection",
                             "lowering"}
