"""The HTML report in a real browser (issue 13): headless Chromium renders it, every image
loads, and the page logs no error. The screenshot is kept in `artifacts/` (ignored by git) for
a person to look at; CI keeps it as an artifact.

Without Chromium the test skips locally and fails under CI (`require_tool`); `scripts/setup.sh
--with-slicers` installs Debian's `chromium` when run as root.
"""

from __future__ import annotations

import json
import re
import subprocess

import pytest
from conftest import ROOT, require_tool
from proto_files import REALISTIC

import printgen.run.make as make_mod

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
def report(tmp_path_factory):
    out = tmp_path_factory.mktemp("browser") / "out"
    fast = [s for s in make_mod.default_steps() if s[1] is not make_mod.verify_step]
    make_mod.make(REALISTIC, 40, out, steps=fast)  # the figures of parts and previews
    return out / "report.html"


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
