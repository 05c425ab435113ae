"""report.pdf: report.html printed by headless Chromium (`chromium --headless
--print-to-pdf`), made byte-reproducible: Chromium's PDF differs between two prints only in
its creation and modification dates, which are set to a fixed date of the same length (the
file's offsets stay valid). The same report and the same Chromium give the same bytes.

The page is A4 unless asked otherwise (`PAPERS`): Chromium prints on Letter unless the page's
CSS names a size, so the printed copy of report.html carries an `@page` rule (report.html itself
is unchanged). Chromium is not a dependency: any Chromium-based browser prints (Chrome, Edge,
Chromium, found on the PATH or where their installers put them on Windows and macOS); without
one `print_pdf` returns the one line saying so and writes nothing.
"""

from __future__ import annotations

import logging
import os
import re
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

log = logging.getLogger(__name__)

BROWSERS = ("chromium", "chromium-browser", "google-chrome", "google-chrome-stable", "chrome",
            "msedge", "microsoft-edge")  # names on the PATH
# where the installers put them when they are not on the PATH (the usual case on Windows and macOS)
INSTALLED = {
    "win32": tuple(rf"{root}\{app}" for root in ("%PROGRAMFILES%", "%PROGRAMFILES(X86)%",
                                                  "%LOCALAPPDATA%")
                   for app in (r"Google\Chrome\Application\chrome.exe",
                               r"Microsoft\Edge\Application\msedge.exe",
                               r"Chromium\Application\chrome.exe")),
    "darwin": tuple(f"{root}/Applications/{app}.app/Contents/MacOS/{app}"
                    for root in ("", "~")
                    for app in ("Google Chrome", "Microsoft Edge", "Chromium")),
}
PAPERS = {"a4": "A4", "letter": "letter"}  # --paper: CSS page sizes; A4 is the default
TIMEOUT_S = 180  # a cold headless start and a long report on a loaded machine
FIXED_DATE = b"20000101000000"  # replaces Chromium's D:YYYYMMDDHHMMSS (same length)
_DATE = re.compile(rb"/(CreationDate|ModDate) \(D:(\d{14})")
FLAGS = ("--headless", "--no-sandbox", "--disable-gpu", "--no-first-run",
         "--disable-background-networking", "--disable-component-update", "--disable-sync",
         "--disable-default-apps", "--no-pdf-header-footer")


def browser(platform: str = sys.platform) -> str | None:
    """The headless browser to print with ($PRINTGEN_CHROMIUM, else the first found on the
    PATH, else the first installed where `platform`'s installers put it)."""
    env = os.environ.get("PRINTGEN_CHROMIUM")
    if env:
        return shutil.which(env)
    found = next((p for b in BROWSERS if (p := shutil.which(b))), None)
    if found is None:
        paths = (Path(os.path.expanduser(os.path.expandvars(p)))
                 for p in INSTALLED.get(platform, ()))
        found = next((str(p) for p in paths if p.is_file()), None)
    return found


def paged(html: str, paper: str) -> str:
    """`html` with an @page rule naming `paper`'s size (a key of PAPERS) before </head>."""
    if paper not in PAPERS:
        raise ValueError(f"paper {paper!r}: one of {', '.join(PAPERS)}")
    rule = f"<style>@page {{ size: {PAPERS[paper]}; }}</style>"
    head = html.find("</head>")
    return html[:head] + rule + html[head:] if head >= 0 else rule + html


def print_pdf(html_path: Path, pdf_path: Path, paper: str = "a4") -> str | None:
    """Print `html_path` to `pdf_path` on `paper` (a key of PAPERS); None when written, else
    the one-line reason it was skipped (no browser, or the browser failed)."""
    exe = browser()
    if exe is None:
        return ("report.pdf skipped: no Chrome, Edge or Chromium found (install one, or set "
                "PRINTGEN_CHROMIUM to its executable)")
    html_path = Path(html_path)
    # the printed copy sits beside report.html so that its relative links (figures) resolve
    copy = html_path.with_name(f".{html_path.stem}-print.html")
    copy.write_text(paged(html_path.read_text(encoding="utf-8"), paper), encoding="utf-8")
    with tempfile.TemporaryDirectory(prefix="printgen-chromium-") as profile:
        tmp = Path(profile) / "report.pdf"
        try:
            run = subprocess.run(
                [exe, *FLAGS, f"--user-data-dir={profile}/user", f"--print-to-pdf={tmp}",
                 copy.resolve().as_uri()], capture_output=True, text=True,
                timeout=TIMEOUT_S, check=False, env={**os.environ, "TZ": "UTC"})
        except (OSError, subprocess.TimeoutExpired) as exc:
            return f"report.pdf skipped: {exe} did not print it ({exc})"
        finally:
            copy.unlink(missing_ok=True)
        if not tmp.is_file() or tmp.stat().st_size == 0:
            tail = run.stderr.strip().splitlines()[-1:] or [f"exit code {run.returncode}"]
            return f"report.pdf skipped: {exe} did not print it ({tail[0][:200]})"
        data = _DATE.sub(lambda m: b"/" + m.group(1) + b" (D:" + FIXED_DATE, tmp.read_bytes())
    Path(pdf_path).write_bytes(data)
    return None
