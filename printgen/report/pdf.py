"""report.pdf: report.html printed by headless Chromium (`chromium --headless
--print-to-pdf`), made byte-reproducible: Chromium's PDF differs between two prints only in
its creation and modification dates, which are set to a fixed date of the same length (the
file's offsets stay valid). The same report and the same Chromium give the same bytes.

Chromium is not a dependency: without it `print_pdf` returns the one line saying so and
writes nothing.
"""

from __future__ import annotations

import logging
import os
import re
import shutil
import subprocess
import tempfile
from pathlib import Path

log = logging.getLogger(__name__)

BROWSERS = ("chromium", "chromium-browser", "google-chrome")
TIMEOUT_S = 180  # a cold headless start and a long report on a loaded machine
FIXED_DATE = b"20000101000000"  # replaces Chromium's D:YYYYMMDDHHMMSS (same length)
_DATE = re.compile(rb"/(CreationDate|ModDate) \(D:(\d{14})")
FLAGS = ("--headless", "--no-sandbox", "--disable-gpu", "--no-first-run",
         "--disable-background-networking", "--disable-component-update", "--disable-sync",
         "--disable-default-apps", "--no-pdf-header-footer")


def browser() -> str | None:
    """The headless browser to print with ($PRINTGEN_CHROMIUM, else the first found)."""
    env = os.environ.get("PRINTGEN_CHROMIUM")
    if env:
        return shutil.which(env)
    return next((p for b in BROWSERS if (p := shutil.which(b))), None)


def print_pdf(html_path: Path, pdf_path: Path) -> str | None:
    """Print `html_path` to `pdf_path`; None when written, else the one-line reason it was
    skipped (no browser, or the browser failed)."""
    exe = browser()
    if exe is None:
        return ("report.pdf skipped: no chromium found (install Debian's chromium, or set "
                "PRINTGEN_CHROMIUM to a Chrome/Chromium executable)")
    with tempfile.TemporaryDirectory(prefix="printgen-chromium-") as profile:
        tmp = Path(profile) / "report.pdf"
        try:
            run = subprocess.run(
                [exe, *FLAGS, f"--user-data-dir={profile}/user", f"--print-to-pdf={tmp}",
                 Path(html_path).resolve().as_uri()], capture_output=True, text=True,
                timeout=TIMEOUT_S, check=False, env={**os.environ, "TZ": "UTC"})
        except (OSError, subprocess.TimeoutExpired) as exc:
            return f"report.pdf skipped: {exe} did not print it ({exc})"
        if not tmp.is_file() or tmp.stat().st_size == 0:
            tail = run.stderr.strip().splitlines()[-1:] or [f"exit code {run.returncode}"]
            return f"report.pdf skipped: {exe} did not print it ({tail[0][:200]})"
        data = _DATE.sub(lambda m: b"/" + m.group(1) + b" (D:" + FIXED_DATE, tmp.read_bytes())
    Path(pdf_path).write_bytes(data)
    return None
