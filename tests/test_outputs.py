"""The output folder (printgen/outputs.py): whole-folder swap, lock, stale stages, manifest."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

from printgen.errors import InputError
from printgen.outputs import OutputError, check_folder, staged_dir
from printgen.outputs import folder as outputs


def run_into(out, files: dict[str, str], **kw):
    with staged_dir(out, meta={"command": ["test"]}, **kw) as stage:
        for name, text in files.items():
            (stage / name).parent.mkdir(parents=True, exist_ok=True)
            (stage / name).write_text(text)
    return out


def listing(folder):
    return sorted(p.relative_to(folder).as_posix() for p in folder.rglob("*") if p.is_file())


def test_new_run_replaces_the_whole_folder(tmp_path):
    out = run_into(tmp_path / "out", {"a.txt": "1", "cable-left.gcode": "old", "sub/x": "s"})
    run_into(out, {"a.txt": "2", "b.txt": "new"})
    assert listing(out) == ["a.txt", "b.txt", "manifest.json"]  # nothing of the first run
    assert (out / "a.txt").read_text() == "2"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out"]  # no stage, no lock left
    assert check_folder(out) == []


def test_failure_inside_leaves_the_previous_folder(tmp_path):
    out = run_into(tmp_path / "out", {"a.txt": "1"})
    with pytest.raises(RuntimeError), staged_dir(out) as stage:
        (stage / "a.txt").write_text("half")
        raise RuntimeError("step failed")
    assert (out / "a.txt").read_text() == "1" and check_folder(out) == []
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out"]


def test_swap_failing_part_way_leaves_one_whole_run(tmp_path, monkeypatch):
    """The final step fails (the exchange, then the rename-aside's second rename): the old
    folder is there, whole, and the stage is gone."""
    out = run_into(tmp_path / "out", {"a.txt": "1", "b.txt": "1"})

    def broken_exchange(a, b):
        raise OSError(5, "Input/output error", str(a))

    monkeypatch.setattr(outputs, "exchange", broken_exchange)
    with pytest.raises(OSError):
        run_into(out, {"a.txt": "2"})
    assert listing(out) == ["a.txt", "b.txt", "manifest.json"] and check_folder(out) == []

    monkeypatch.setattr(outputs, "exchange", lambda a, b: False)  # no renameat2: rename aside
    real_rename, calls = os.rename, []

    def rename_second_fails(src, dst):
        calls.append((src, dst))
        if len(calls) == 2:
            raise OSError(28, "No space left on device", str(src))
        return real_rename(src, dst)

    monkeypatch.setattr(os, "rename", rename_second_fails)
    with pytest.raises(OSError):
        run_into(out, {"a.txt": "3"})
    monkeypatch.setattr(os, "rename", real_rename)
    assert listing(out) == ["a.txt", "b.txt", "manifest.json"] and check_folder(out) == []
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out"]


def test_rename_aside_fallback_swaps_whole_folders(tmp_path, monkeypatch):
    monkeypatch.setattr(outputs, "exchange", lambda a, b: False)
    out = run_into(tmp_path / "out", {"a.txt": "1", "c.txt": "1"})
    run_into(out, {"a.txt": "2"})
    assert listing(out) == ["a.txt", "manifest.json"]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out"]


def test_renameat2_exchanges(tmp_path):
    a, b = tmp_path / "a", tmp_path / "b"
    a.mkdir()
    b.mkdir()
    (a / "x").write_text("a")
    if not outputs.exchange(a, b):
        pytest.skip("this file system has no RENAME_EXCHANGE (the rename-aside path is tested)")
    assert (b / "x").read_text() == "a" and not (a / "x").exists()


def test_stale_stages_are_removed_at_start(tmp_path):
    stale = tmp_path / ".out.stage.dead1234"
    stale.mkdir()
    (stale / "net.gcode").write_text("from a killed run")
    (tmp_path / ".out.old.99").mkdir()
    (tmp_path / ".other.stage.x").mkdir()  # another output's stage is not ours to remove
    run_into(tmp_path / "out", {"a.txt": "1"})
    assert sorted(p.name for p in tmp_path.iterdir()) == [".other.stage.x", "out"]


def test_a_previous_run_that_cannot_be_removed_is_named(tmp_path, monkeypatch, caplog):
    """A file of the previous run that cannot be removed (immutable, another user's): the new
    run is in, and a warning names the folder left beside it and why."""
    run_into(tmp_path / "out", {"a.txt": "1"})
    real = outputs.shutil.rmtree

    def stuck(path, onerror=None, **kw):
        if ".out." in str(path) and (Path(path) / "a.txt").exists():
            onerror(os.unlink, str(Path(path) / "a.txt"), (PermissionError,
                    PermissionError(1, "Operation not permitted"), None))
            return
        real(path, onerror=onerror, **kw)

    monkeypatch.setattr(outputs.shutil, "rmtree", stuck)
    with caplog.at_level("WARNING", logger=outputs.log.name):
        run_into(tmp_path / "out", {"b.txt": "2"})
    assert (tmp_path / "out" / "b.txt").read_text() == "2"
    left = [p for p in tmp_path.iterdir() if p.name != "out"]
    assert len(left) == 1 and "could not remove the previous run in" in caplog.text
    assert str(left[0]) in caplog.text and "Operation not permitted" in caplog.text


def test_foreign_folder_needs_force(tmp_path):
    out = tmp_path / "thesis"
    out.mkdir()
    (out / "chapter1.tex").write_text("precious")
    with pytest.raises(OutputError, match=r"not a printgen output folder: it holds chapter1.tex "
                                          r"\(the folder has no manifest.json\).*--force"):
        run_into(out, {"a.txt": "1"})
    assert (out / "chapter1.tex").read_text() == "precious"
    run_into(out, {"a.txt": "1"}, force=True)
    assert listing(out) == ["a.txt", "manifest.json"]
    empty = tmp_path / "empty"
    empty.mkdir()
    run_into(empty, {"a.txt": "1"})  # an empty folder is fine


def test_output_given_as_dot(tmp_path, monkeypatch):
    out = run_into(tmp_path / "out", {"a.txt": "1"})
    monkeypatch.chdir(out)
    run_into(".", {"b.txt": "2"})  # the stage is a sibling of the folder, not inside it
    assert listing(out) == ["b.txt", "manifest.json"]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out"]


def test_symlinked_output_is_refused(tmp_path):
    real = run_into(tmp_path / "real", {"a.txt": "1"})
    (tmp_path / "link").symlink_to(real)
    with pytest.raises(OutputError, match="is a symbolic link"):
        run_into(tmp_path / "link", {"a.txt": "2"})
    assert (real / "a.txt").read_text() == "1"


@pytest.mark.parametrize("kind", ["file", "under-a-file"])
def test_output_that_is_or_is_under_a_file(tmp_path, kind):
    f = tmp_path / "notes.txt"
    f.write_text("x")
    out = f if kind == "file" else f / "sub" / "out"
    with pytest.raises(OutputError, match="is not a folder|is a file"):
        run_into(out, {"a.txt": "1"})
    assert f.read_text() == "x"


LOCK_HOLDER = textwrap.dedent("""
    import sys, time
    from printgen.outputs import folder_lock
    from pathlib import Path
    with folder_lock(Path(sys.argv[1])):
        print("locked", flush=True)
        time.sleep(60)
""")


@pytest.mark.slow
def test_second_run_into_the_same_folder_names_the_holder(tmp_path):
    out = tmp_path / "out"
    holder = subprocess.Popen([sys.executable, "-c", LOCK_HOLDER, str(out)],
                              stdout=subprocess.PIPE, text=True)
    try:
        assert holder.stdout.readline().strip() == "locked"
        with pytest.raises(OutputError, match=f"another printgen \\(pid {holder.pid}\\)"):
            run_into(out, {"a.txt": "1"})
        assert not out.exists()
    finally:
        holder.kill()
        holder.wait()
    run_into(out, {"a.txt": "1"})  # the dead holder's lock is free
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out"]


def test_manifest_lists_every_file_and_the_volatile_one(tmp_path):
    out = run_into(tmp_path / "out", {"a.txt": "abc", "sub/b.bin": "zz", "timings.json": "{}"},
                   volatile=("timings.json",))
    m = json.loads((out / "manifest.json").read_text())
    assert set(m["files"]) == {"a.txt", "sub/b.bin"} and m["volatile"] == ["timings.json"]
    assert m["files"]["a.txt"] == {
        "bytes": 3, "sha256": "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad"}
    assert m["command"] == ["test"]
    (out / "timings.json").write_text('{"total": 1}')  # volatile: may change
    assert check_folder(out) == []


def test_check_folder_names_each_difference(tmp_path):
    out = run_into(tmp_path / "out", {"a.txt": "abc", "b.txt": "b", "timings.json": "{}"},
                   volatile=("timings.json",))
    (out / "a.txt").write_text("abd")
    (out / "b.txt").unlink()
    (out / "timings.json").unlink()
    (out / "c.txt").write_text("new")
    diff = check_folder(out)
    assert diff[0].startswith("changed: a.txt (3 bytes")
    assert diff[1:] == ["missing: b.txt", "missing: timings.json (volatile)", "extra: c.txt"]


def test_check_folder_without_manifest_is_an_input_error(tmp_path):
    with pytest.raises(InputError, match="no manifest.json"):
        check_folder(tmp_path)
    with pytest.raises(InputError, match="not a folder"):
        check_folder(tmp_path / "missing")


def test_a_failed_write_leaves_no_empty_folders(tmp_path, monkeypatch):
    """A full disk while `calibrate --out/--plot` writes into new folders: none is left."""
    from printgen.outputs import files

    def full(p, data):
        raise OSError(28, "No space left on device", str(p))

    monkeypatch.setattr(files, "_write_new", full)
    (tmp_path / "kept").mkdir()
    with pytest.raises(OSError, match="No space"):
        files.write_bytes(tmp_path / "kept" / "a" / "b" / "x.png", b"png")
    assert [p.name for p in tmp_path.rglob("*")] == ["kept"]
