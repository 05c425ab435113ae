"""conftest.shared_run: one build per session for every pytest-xdist worker (the first worker
to ask builds, the others load its result; a failed build fails the others' tests too)."""

from __future__ import annotations

from pathlib import Path

import pytest
from conftest import shared_run


class Workers:
    """Two workers' tmp_path_factory under one session folder, as pytest-xdist lays them."""

    def __init__(self, session: Path, worker: str):
        self.base = session / f"popen-{worker}"
        self.base.mkdir(parents=True, exist_ok=True)

    def getbasetemp(self) -> Path:
        return self.base

    def mktemp(self, name: str) -> Path:
        path = self.base / name
        path.mkdir()
        return path


def test_the_first_worker_builds_and_the_others_load(tmp_path, monkeypatch):
    built: list[Path] = []

    def build(folder: Path) -> dict:
        built.append(folder)
        (folder / "out.txt").write_text("made")
        return {"folder": folder, "value": 42}

    monkeypatch.setenv("PYTEST_XDIST_WORKER", "gw0")
    first = shared_run(Workers(tmp_path, "gw0"), "run", build)
    monkeypatch.setenv("PYTEST_XDIST_WORKER", "gw1")
    second = shared_run(Workers(tmp_path, "gw1"), "run", build)
    assert built == [tmp_path / "popen-gw0" / "run"]  # built once, in the first worker's folder
    assert second == first and (second["folder"] / "out.txt").read_text() == "made"


def test_a_failed_build_fails_the_waiting_workers(tmp_path, monkeypatch):
    def broken(folder: Path) -> None:
        raise ValueError("no such barrier")

    monkeypatch.setenv("PYTEST_XDIST_WORKER", "gw0")
    with pytest.raises(ValueError, match="no such barrier"):
        shared_run(Workers(tmp_path, "gw0"), "run", broken)
    monkeypatch.setenv("PYTEST_XDIST_WORKER", "gw1")
    with pytest.raises(pytest.fail.Exception,
                       match="failed in another worker: ValueError: no such"):
        shared_run(Workers(tmp_path, "gw1"), "run", broken)


def test_a_later_run_in_the_same_basetemp_builds_its_own(tmp_path, monkeypatch):
    """--basetemp reused: the second test run (another xdist run id) never loads the first's."""
    monkeypatch.setenv("PYTEST_XDIST_WORKER", "gw0")
    monkeypatch.setenv("PYTEST_XDIST_TESTRUNUID", "first")
    assert shared_run(Workers(tmp_path, "gw0"), "run", lambda folder: "old") == "old"
    monkeypatch.setenv("PYTEST_XDIST_TESTRUNUID", "second")
    monkeypatch.setenv("PYTEST_XDIST_WORKER", "gw1")
    assert shared_run(Workers(tmp_path, "gw1"), "run", lambda folder: "new") == "new"


def test_without_xdist_it_builds_in_place(tmp_path, monkeypatch):
    monkeypatch.delenv("PYTEST_XDIST_WORKER", raising=False)
    got = shared_run(Workers(tmp_path, "main"), "run", lambda folder: folder)
    assert got == tmp_path / "popen-main" / "run" and not list(tmp_path.glob("run.*"))
