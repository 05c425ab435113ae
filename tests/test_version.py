"""printgen's version comes from git (setuptools-scm): it names the commit, so it changes with
each one; a build from a clone carries it, a source tree without git the fallback; the `all`
extra holds every feature and no test tool."""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest
from conftest import ROOT

import printgen
from printgen import version as pv
from printgen.cli import main

PYPROJECT = tomllib.loads((ROOT / "pyproject.toml").read_text("utf-8"))
EXTRAS = PYPROJECT["project"]["optional-dependencies"]
# a throwaway author for the commits of a scratch repository (no user configuration needed)
GIT_ENV = {"GIT_AUTHOR_NAME": "t", "GIT_AUTHOR_EMAIL": "t@example.org",
           "GIT_COMMITTER_NAME": "t", "GIT_COMMITTER_EMAIL": "t@example.org",
           "GIT_CONFIG_GLOBAL": os.devnull, "GIT_CONFIG_NOSYSTEM": "1"}


def git(folder: Path, *args: str) -> str:
    done = subprocess.run(["git", "-C", str(folder), *args], capture_output=True, text=True,
                          env={**os.environ, **GIT_ENV}, check=True)
    return done.stdout.strip()


def need_scm() -> None:
    """Skip without git or setuptools-scm (the `test` extra installs it)."""
    if shutil.which("git") is None:
        pytest.skip("git is not installed")
    pytest.importorskip("setuptools_scm", reason="setuptools-scm: the `test` extra")


def test_the_fallback_is_pyproject_s():
    assert PYPROJECT["tool"]["setuptools_scm"]["fallback_version"] == pv.FALLBACK
    assert "setuptools-scm>=8" in PYPROJECT["build-system"]["requires"]
    assert "version" in PYPROJECT["project"]["dynamic"]


def test_all_holds_every_feature_and_no_test_tool():
    names = re.findall(r"printgen\[([\w,]+)\]", " ".join(EXTRAS["all"]))
    extras = {e for group in names for e in group.split(",")}
    assert extras == {"geometry", "plot", "sweep", "fast", "table"}
    tools = {re.split(r"[<>=\[]", d)[0] for d in EXTRAS["test"]}
    pulled = {re.split(r"[<>=\[]", d)[0] for e in extras for d in EXTRAS[e]}
    assert not tools & pulled, tools & pulled
    assert EXTRAS["table"] == ["pandas>=2"]


def test_version_is_the_cli_s_and_the_module_s(capsys):
    with pytest.raises(SystemExit) as exc:
        main(["--version"])
    assert exc.value.code == 0
    assert capsys.readouterr().out == f"printgen {printgen.__version__}\n"
    assert printgen.__version__ == pv.version()
    assert "__version__" in printgen.__all__ and "__version__" in dir(printgen)


def test_without_git_or_metadata_the_version_is_the_fallback(tmp_path, monkeypatch):
    """A source tree without .git and without installed metadata (a tarball on PYTHONPATH)."""
    assert pv.checkout_version(tmp_path) is None  # no .git here
    monkeypatch.setattr(pv, "ROOT", tmp_path)
    monkeypatch.setattr(pv, "installed_version", lambda: None)
    pv.version.cache_clear()
    try:
        assert pv.version() == pv.FALLBACK
    finally:
        pv.version.cache_clear()


def test_the_version_changes_with_each_commit(tmp_path):
    """A scratch repository with printgen's pyproject.toml: two commits, two versions, each
    naming its commit (distance from the root, `g` + the abbreviated hash)."""
    need_scm()
    shutil.copy(ROOT / "pyproject.toml", tmp_path / "pyproject.toml")
    git(tmp_path, "init", "-q")
    git(tmp_path, "add", "pyproject.toml")
    git(tmp_path, "commit", "-q", "-m", "one")
    first = pv.checkout_version(tmp_path)
    git(tmp_path, "commit", "-q", "--allow-empty", "-m", "two")
    second = pv.checkout_version(tmp_path)
    assert first and second and first != second
    for v, count in ((first, 1), (second, 2)):
        head = git(tmp_path, "rev-parse", "--short=7", "HEAD") if v is second else None
        # no tag: counted from the first commit, after the last release (FALLBACK, 0.1.0)
        assert v.startswith(f"0.1.1.dev{count}+g"), v
        if head:
            assert f"+g{head}" in v, (v, head)


def test_this_checkout_s_version_names_its_commit():
    """In a git checkout the version is `git describe`'s: the commits since the last tag (or
    the root) and the commit's hash; on a tag and clean it is the tag alone."""
    need_scm()
    if not (ROOT / ".git").exists():
        pytest.skip("not a git checkout")
    v = pv.checkout_version(ROOT)
    assert v is not None
    try:
        described = git(ROOT, "describe", "--tags", "--long", "--match", "*[0-9]*")
        _, distance, node = described.rsplit("-", 2)
    except subprocess.CalledProcessError:  # no tag yet: counted from the root commit
        distance, node = git(ROOT, "rev-list", "--count", "HEAD"), "g" + git(
            ROOT, "rev-parse", "--short=7", "HEAD")
    if distance == "0" and not git(ROOT, "status", "--porcelain", "--untracked-files=no"):
        pytest.skip(f"on a tag, clean: version {v}")
    assert f".dev{distance}+{node[:8]}" in v, (v, distance, node)


def _built_version(src: Path, tmp_path: Path) -> str:
    """The version setuptools writes into the metadata of a wheel built from `src` (the build
    backend's metadata hook, no build isolation: the environment's setuptools-scm)."""
    env = {k: v for k, v in os.environ.items() if not k.startswith("SETUPTOOLS_SCM_PRETEND")}
    code = ("import sys; from setuptools import build_meta as b; "
            "print(b.prepare_metadata_for_build_wheel(sys.argv[1]))")
    out = tmp_path / f"meta-{src.name}"
    out.mkdir()
    done = subprocess.run([sys.executable, "-c", code, str(out)], cwd=src, capture_output=True,
                          text=True, env=env)
    assert done.returncode == 0, done.stderr[-2000:]
    meta = (out / done.stdout.strip().splitlines()[-1] / "METADATA").read_text("utf-8")
    return re.search(r"^Version: (.+)$", meta, re.MULTILINE).group(1)


@pytest.mark.slow
def test_a_clone_builds_with_its_commit_and_a_tarball_with_the_fallback(tmp_path):
    need_scm()
    if not (ROOT / ".git").exists():
        pytest.skip("not a git checkout")
    clone = tmp_path / "clone"
    head = git(ROOT, "rev-parse", "HEAD")
    subprocess.run(["git", "clone", "-q", "--no-checkout", str(ROOT), str(clone)], check=True,
                   env={**os.environ, **GIT_ENV})
    git(clone, "checkout", "-q", head)
    built = _built_version(clone, tmp_path)
    assert built == pv.checkout_version(clone) and f"+g{head[:7]}" in built, built
    tarball = tmp_path / "tarball"  # the same files, no .git
    shutil.copytree(clone, tarball, ignore=shutil.ignore_patterns(".git", "*.egg-info"))
    assert _built_version(tarball, tmp_path) == pv.FALLBACK
