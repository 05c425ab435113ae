"""The documentation: the site builds with no warning (mkdocs.yml, `mkdocs build --strict`), its
generated pages are those the code gives now (scripts/docs_pages.py), the worked numbers of the
tutorial and the README are a run's (scripts/docs_numbers.py), and the README stays a short
front page whose links resolve."""

from __future__ import annotations

import importlib.util
import os
import re
import subprocess
import sys

import pytest
from conftest import ROOT
from test_comments import PATTERNS

README_MAX_BYTES = 12_000  # the front page: what printgen is, install, one example, links


def _script(name: str):
    path = ROOT / "scripts" / f"{name}.py"
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


pages = _script("docs_pages")
numbers = _script("docs_numbers")


@pytest.mark.slow
def test_the_site_builds_with_no_warning(tmp_path):
    """`mkdocs build --strict`: a broken link or anchor, a page left out of the nav, a
    docstring mkdocstrings cannot render, each fails the build (mkdocs.yml's validation)."""
    if importlib.util.find_spec("mkdocs") is None:
        msg = "mkdocs not installed (pip install -e '.[docs]'; scripts/test.sh installs it)"
        if os.environ.get("PRINTGEN_REQUIRE_DOCS") or os.environ.get("CI"):
            pytest.fail(msg)
        pytest.skip(msg)
    env = {**os.environ, "NO_MKDOCS_2_WARNING": "1"}  # Material's notice about MkDocs 2
    run = subprocess.run([sys.executable, "-m", "mkdocs", "build", "--strict", "--site-dir",
                          str(tmp_path / "site")], cwd=ROOT, env=env, capture_output=True,
                         text=True, timeout=300)
    assert run.returncode == 0, run.stderr[-4000:]
    assert "WARNING" not in run.stderr, run.stderr[-4000:]
    for page in ("tutorial", "cli", "api", "benchmarks", "flume", "slicer"):
        assert (tmp_path / "site" / page / "index.html").is_file(), page
    api = (tmp_path / "site" / "api" / "index.html").read_text("utf-8")
    assert "MakeContext" in api  # make's signature, rendered from its annotations


@pytest.mark.slow  # imports every command (about a second)
def test_generated_pages_are_current():
    assert pages.stale() == [], "run python scripts/docs_pages.py"


def test_the_cli_reference_has_every_command_and_option():
    from printgen.commands.parser import build_parser

    text = pages.cli_page()
    found = list(pages._commands(build_parser(), "printgen"))
    assert len(found) >= 14  # one module per command, `profiles` with two of its own
    for prog, _, sub in found:
        section = text.split(f"## `{prog}`\n", 1)[1].split("\n## ", 1)[0]
        for action in sub._actions:
            for option in action.option_strings:
                if option not in ("-h", "--help"):
                    assert f"`{option}" in section, (prog, option)


def test_the_api_page_has_every_public_verb():
    import printgen.calibrate.pipeline  # sets the attribute printgen.calibrate to the module

    entries = dict(pages.api_entries())
    assert set(entries) == set(printgen.__all__) - {"__version__"}
    assert entries["calibrate"] == "printgen.run.api.calibrate"  # the verb, not the subpackage
    text = pages.api_page()
    for home in entries.values():
        assert f"::: {home}\n" in text, home


def test_the_benchmarks_page_has_every_measurement():
    import json

    text = pages.benchmarks_page()
    data = json.loads((ROOT / "benchmarks" / "measurements.json").read_text("utf-8"))
    for entry in data["measurements"]:
        assert f'<a id="{entry["id"]}"></a>' in text and f"## {entry['title']}" in text


@pytest.mark.parametrize(("page", "fresh", "same"), [
    ("706.9 N", "706.9 N", True),
    ("0.70", "0.71", True),    # one unit of the last printed digit
    ("0.70", "0.72", False),
    ("+325 %", "+326 %", True),
    ("+325 %", "+327 %", False),
    ("44m 32s", "44m 33s", True),
    ("FAIL", "PASS", False),
    ("model too stiff in 4 of 5", "model too soft in 4 of 5", False),
    ("3 passes", "3 passes, 2 beads", False),
])
def test_a_page_number_agrees_within_its_last_digit(page, fresh, same):
    assert numbers.agree(page, fresh) is same


def test_rewrite_replaces_each_marked_number_and_refuses_an_unknown_one():
    text = "E·A <!--n:cable_error-->-0.7 %<!--/n--> off, <!--n:verdict-->FAIL<!--/n-->."
    new = numbers.rewrite(text, {"cable_error": "-0.8 %", "verdict": "PASS"})
    assert new == "E·A <!--n:cable_error-->-0.8 %<!--/n--> off, <!--n:verdict-->PASS<!--/n-->."
    with pytest.raises(KeyError, match="unknown worked number 'nope'"):
        numbers.rewrite("<!--n:nope-->1<!--/n-->", {})


def test_the_pages_mark_only_known_numbers():
    for page in numbers.PAGES:
        keys = [k for k, _ in numbers.marked(page.read_text("utf-8"))]
        assert keys, f"{page.name} holds no worked number"
        assert set(keys) <= set(numbers.NUMBERS), (page.name, set(keys) - set(numbers.NUMBERS))
        # A line that starts with `<!--` starts an HTML block (CommonMark, Python-Markdown): it
        # would cut its paragraph or list item in two and show its Markdown as written.
        starts = [line for line in page.read_text("utf-8").splitlines()
                  if line.lstrip().startswith("<!--n:")]
        assert starts == [], page.name


def test_the_worked_numbers_are_those_of_a_run(made_1_40):
    """The tutorial's and the README's numbers against the session's own `make` of the 1:40
    example (`python scripts/docs_numbers.py` rewrites them after a change of results)."""
    _, out = made_1_40
    assert numbers.differences(numbers.numbers(out)) == []


def test_readme_is_a_short_front_page_whose_links_resolve():
    readme = ROOT / "README.md"
    assert readme.stat().st_size <= README_MAX_BYTES
    text = readme.read_text("utf-8")
    assert "bash scripts/demo.sh" in text and "bash scripts/test.sh" in text
    links = re.findall(r"\]\(([^)#:]+)(?:#[^)]*)?\)", text)
    assert len(links) >= 10
    for link in links:
        assert (ROOT / link).is_file(), link


def test_no_issue_number_in_the_documentation():
    texts = [ROOT / "README.md", ROOT / "mkdocs.yml", *sorted((ROOT / "docs").glob("*.md"))]
    found = [f"{p.name}: {m.group(0)}" for p in texts
             for m in PATTERNS["issue number"].finditer(p.read_text("utf-8"))]
    assert found == []


def test_the_install_table_names_every_extra():
    """docs/index.md's table of extras against pyproject.toml: one row per extra, and the
    `all` row names the extras `all` pulls in."""
    import tomllib

    extras = tomllib.loads((ROOT / "pyproject.toml").read_text("utf-8"))["project"][
        "optional-dependencies"]
    text = (ROOT / "docs" / "index.md").read_text("utf-8").split("## Installing", 1)[1]
    rows = {m.group(1): m.group(2) for m in re.finditer(r"^\| `([\w-]+)` \| ([^|]*)\|", text,
                                                        re.MULTILINE)}
    assert set(rows) == set(extras)
    pulled = set(re.findall(r"printgen\[([^\]]*)\]", " ".join(extras["all"])))
    named = {e for group in pulled for e in group.split(",")}
    assert set(re.findall(r"`([\w-]+)`", rows["all"])) == named
    assert "docs" not in named  # the site's tools stay out of a developer's `all`


def test_the_install_sizes_come_from_the_measurement():
    """Every size in the table of extras sits in a marker that scripts/install_sizes.py fills
    from benchmarks/install_sizes.json, and the page holds the JSON's numbers."""
    import subprocess
    import sys

    text = (ROOT / "docs" / "index.md").read_text("utf-8").split("## Installing", 1)[1]
    rows = re.findall(r"^\|[^|\n]*\|[^|\n]*\| ([^|\n]*) \|$", text, re.MULTILINE)
    sized = [r for r in rows if r not in ("adds", "---")]
    assert len(sized) >= 12  # the default set and every extra
    assert all(re.fullmatch(r"<!--size:[\w-]+-->[^<]*MB[^<]*<!--/size-->", r) for r in sized), sized
    assert not re.search(r"~\s*\d+(\.\d+)?\s*[MG]B", text)  # no size typed by hand
    done = subprocess.run([sys.executable, str(ROOT / "scripts" / "install_sizes.py"), "--check"],
                          capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
