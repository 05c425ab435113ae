"""printgen's version, from git: setuptools-scm names it from `git describe` (the last tag, the
commits since and the commit: `0.1.1.dev594+g5267b93`, counted from the first commit and the
last release `FALLBACK` while no tag is set; a tree with uncommitted edits adds the date), so a
manifest tells which code made its folder. An installed wheel carries the version
it was built with in its metadata; a git checkout (an editable install, a clone on PYTHONPATH)
is asked now, when setuptools-scm is installed (the `test` extra), since its metadata names the
commit it was installed at; a source tree with neither is `FALLBACK`, as its build is."""

from __future__ import annotations

import functools
import subprocess
from importlib.metadata import PackageNotFoundError
from importlib.metadata import version as dist_version
from pathlib import Path

# [tool.setuptools_scm] fallback_version: the version of a source tree without git (and the base
# of the count while the repository has no tag): the last release, CHANGELOG.md's
FALLBACK = "0.1.0"
ROOT = Path(__file__).resolve().parents[1]  # a checkout's root; site-packages when installed


@functools.cache
def version() -> str:
    """This code's version: the checkout's (`checkout_version`), else the installed
    package's, else `FALLBACK`."""
    return checkout_version(ROOT) or installed_version() or FALLBACK


def checkout_version(root: Path) -> str | None:
    """setuptools-scm's version of the git checkout `root` (None when `root` is no checkout
    of printgen, setuptools-scm is not installed, or git cannot describe it)."""
    if not ((root / ".git").exists() and (root / "pyproject.toml").is_file()):
        return None
    try:
        from setuptools_scm import get_version
    except ImportError:
        return None
    try:
        return str(get_version(root=str(root), fallback_version=FALLBACK))  # as the build
    except (LookupError, OSError, ValueError, subprocess.SubprocessError):
        return None  # no git on PATH, a repository git refuses to read


def installed_version() -> str | None:
    """The version in the installed package's metadata (None without one)."""
    try:
        return dist_version("printgen")
    except PackageNotFoundError:
        return None
