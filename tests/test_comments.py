"""Comments say why, not when (shared/style.md): no comment, docstring or message in the code
holds an internal issue number, a commit hash, a date or a machine load. Those go in commit
messages and benchmarks/measurements.json."""

from __future__ import annotations

import io
import re
import tokenize
from pathlib import Path

import pytest
from conftest import ROOT

FOLDERS = ("printgen", "solver", "benchmarks", "scripts", "examples")
MONTHS = ("January|February|March|April|May|June|July|August|September|October|November"
          "|December")
PATTERNS = {
    "issue number": re.compile(r"\bissues?[ -]#?\d+|\bissue\d+", re.IGNORECASE),
    # 7 to 40 hex digits with a letter and a digit among them: a commit; 0x literals and
    # sha256 digests (64) are not
    "commit hash": re.compile(
        r"(?<![\w#-])(?=[0-9a-f]*[a-f])(?=[0-9a-f]*\d)[0-9a-f]{7,40}(?![\w-])"),
    "date": re.compile(rf"\b20\d\d-[01]\d-[0-3]\d\b|\b(?:{MONTHS}) 20\d\d\b"),
    "machine load": re.compile(r"\bload(?: average)?(?: of)? \d+(?:\.\d+)?(?:\s*(?:-|to)\s*"
                               r"\d+(?:\.\d+)?)?(?: on \d| on a)", re.IGNORECASE),
}


def _texts(path: Path) -> list[tuple[int, str]]:
    """(line, text) of every comment and string literal of a Python file, every comment line of
    a shell script."""
    source = path.read_text("utf-8")
    if path.suffix == ".sh":
        return [(i, line.split("#", 1)[1]) for i, line in enumerate(source.splitlines(), 1)
                if "#" in line]
    tokens = tokenize.generate_tokens(io.StringIO(source).readline)
    kinds = {tokenize.COMMENT, tokenize.STRING, getattr(tokenize, "FSTRING_MIDDLE", -1)}
    return [(t.start[0], t.string) for t in tokens if t.type in kinds]


def findings(root: Path) -> list[str]:
    """'file:line: what: the match' for every text matching one of PATTERNS."""
    out = []
    for folder in FOLDERS:
        for path in sorted([*(root / folder).rglob("*.py"), *(root / folder).rglob("*.sh")]):
            if not any(p.search(path.read_text("utf-8")) for p in PATTERNS.values()):
                continue  # nothing to find: skip tokenizing it
            for line, text in _texts(path):
                out += [f"{path.relative_to(root)}:{line}: {what}: {m.group(0)!r}"
                        for what, pattern in PATTERNS.items() for m in pattern.finditer(text)]
    return out


def test_no_comment_says_when():
    found = findings(ROOT)
    assert not found, ("comments say why, not when (move measurements to "
                       "benchmarks/measurements.json):\n" + "\n".join(found))


@pytest.mark.parametrize(("text", "what"), [
    ("# was 6500 (issue 28)", "issue number"),
    ("# see Issue #12", "issue number"),
    ("# the issue-12 measurement", "issue number"),
    ("# solver of main's 7e27773: one factorization", "commit hash"),
    ("# measured 2026-11-30 on the lab machine", "date"),
    ("# installed sizes, December 2026", "date"),
    ("# bench make, load 0.7-1.9 on a 2-core machine", "machine load"),
    ("# took 6 min under a load of 20 on 2 cores", "machine load"),
])
def test_each_pattern_is_caught(tmp_path, text, what):
    (tmp_path / "printgen").mkdir()
    (tmp_path / "printgen" / "m.py").write_text(f"X = 1  {text}\n")
    assert [f.split(": ")[1] for f in findings(tmp_path)] == [what]


@pytest.mark.parametrize("text", [
    "# sha256 of the file: 9f86d081884c7d659a2feaa0c55ad015a3bf4f1dbd1b0b6c2b2b0b0c2b2b0b0c",
    "# the load 0.5 rho U^2 on the net", "# 0xdeadbeef7 is a literal", "# 1e-300 or 5e-324",
    "# piecewise-linear law, ISO 527-1", "# Lambert et al. 2023, doi:10.1061/JHEND8.HYENG-13070",
    "# default branch of the fit", "# 20000101000000: PDF's fixed date",
])
def test_legitimate_text_is_not_caught(tmp_path, text):
    (tmp_path / "printgen").mkdir()
    (tmp_path / "printgen" / "m.py").write_text(f"X = 1  {text}\n")
    assert findings(tmp_path) == []
