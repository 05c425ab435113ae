"""The command line never shows a traceback (issues 13, 16): bad input and bad output paths
exit 2, the machine's errors and printgen's own bugs exit 1, signals 128 + the signal, each with
one line on stderr. Also `printgen check` and the documented ranges."""

from __future__ import annotations

import errno
import json
import os
import re
import signal

import pytest
from conftest import ROOT
from proto_files import REALISTIC, SIMPLE, write_variant

import printgen.run.make as make_mod
from printgen.cli import main
from printgen.inputs.prototype import ranges_markdown
from printgen.run import api
from printgen.workers import Interrupted


def run(capsys, *argv):
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


def one_line(err: str) -> str:
    assert "Traceback" not in err and err.count("\n") == 1, err
    return err.strip()


def make_args(out, proto=SIMPLE):
    return ["make", proto, "-s", 40, "--out", out]


def test_out_is_an_existing_file(capsys, tmp_path):
    f = tmp_path / "notes.txt"
    f.write_text("keep me")
    code, out, err = run(capsys, *make_args(f))
    assert code == 2 and out == "" and "exists and is not a folder" in one_line(err)
    assert f.read_text() == "keep me"


def test_out_under_a_file(capsys, tmp_path):
    f = tmp_path / "notes.txt"
    f.write_text("x")
    code, _, err = run(capsys, *make_args(f / "out"))
    assert code == 2 and f"{f} is a file" in one_line(err)


def test_out_under_proc(capsys):
    code, _, err = run(capsys, *make_args("/proc/printgen-test-out"))
    assert code in (1, 2) and "/proc/" in one_line(err)


def test_out_in_a_foreign_folder_needs_force(capsys, tmp_path):
    (tmp_path / "data.csv").write_text("1,2")
    code, _, err = run(capsys, *make_args(tmp_path))
    assert code == 2 and "--force" in one_line(err) and (tmp_path / "data.csv").exists()


def test_second_make_into_a_busy_folder_names_the_pid(capsys, tmp_path):
    import subprocess
    import sys

    from test_outputs import LOCK_HOLDER

    out = tmp_path / "out"
    holder = subprocess.Popen([sys.executable, "-c", LOCK_HOLDER, str(out)],
                              stdout=subprocess.PIPE, text=True)
    try:
        assert holder.stdout.readline().strip() == "locked"
        code, _, err = run(capsys, *make_args(out))
    finally:
        holder.kill()
        holder.wait()
    assert code == 2 and f"another printgen (pid {holder.pid})" in one_line(err)
    assert not out.exists()


@pytest.mark.parametrize("eno, code", [(errno.ENOSPC, 1), (errno.EROFS, 2), (errno.EIO, 1)])
def test_os_errors_are_one_line(capsys, tmp_path, monkeypatch, eno, code):
    def failing(*a, **k):
        raise OSError(eno, os.strerror(eno), str(tmp_path / "out" / "net.stl"))

    monkeypatch.setattr(api, "make", failing)
    got, _, err = run(capsys, *make_args(tmp_path / "out"))
    assert got == code and os.strerror(eno) in one_line(err) and "net.stl" in err


def test_targets_on_a_folder(capsys):
    code, _, err = run(capsys, "targets", ROOT / "examples", "--scale", 40)
    assert code == 2 and "is a folder, not a TOML file" in one_line(err)
    assert "realistic_barrier.toml" in err


@pytest.mark.skipif(os.geteuid() == 0, reason="root reads files whatever their permissions")
def test_unreadable_prototype(capsys, tmp_path):
    p = write_variant(tmp_path, {})
    p.chmod(0)
    code, _, err = run(capsys, "targets", p, "--scale", 40)
    assert code == 2 and "cannot read" in one_line(err)


def test_unexpected_error_is_one_line_with_a_hint(capsys, monkeypatch):
    def bug(*a, **k):
        raise ZeroDivisionError("float division by zero")

    monkeypatch.setattr(api, "targets", bug)
    monkeypatch.delenv("PRINTGEN_DEBUG", raising=False)
    code, _, err = run(capsys, "targets", REALISTIC, "--scale", 40)
    line = one_line(err)
    assert code == 1 and "internal error: ZeroDivisionError" in line and "report" in line


def test_a_dead_worker_is_one_line(capsys, monkeypatch):
    from concurrent.futures.process import BrokenProcessPool

    def died(*a, **k):
        raise BrokenProcessPool("A process in the process pool was terminated abruptly")

    monkeypatch.setattr(api, "make", died)
    code, _, err = run(capsys, *make_args("unused-out"))
    assert code == 1 and "a worker process died" in one_line(err)


@pytest.mark.parametrize("exc, code, name", [(KeyboardInterrupt(), 130, "SIGINT"),
                                             (Interrupted(signal.SIGTERM), 143, "SIGTERM"),
                                             (Interrupted(signal.SIGHUP), 129, "SIGHUP")])
def test_interrupts_are_one_line(capsys, monkeypatch, exc, code, name):
    def stop(*a, **k):
        raise exc

    monkeypatch.setattr(api, "targets", stop)
    got, _, err = run(capsys, "targets", REALISTIC, "--scale", 40)
    assert got == code and f"stopped by {name}" in one_line(err)


def test_signal_handlers_are_restored_after_a_command(capsys):
    before = signal.getsignal(signal.SIGTERM)
    run(capsys, "targets", REALISTIC, "--scale", 40)
    assert signal.getsignal(signal.SIGTERM) is before


@pytest.mark.parametrize("argv, message", [
    (["select", REALISTIC, "--scale", "1e9"], "exceeds 100: the similitude is established"),
    (["targets", REALISTIC, "--scale", "101"], "Lambert et al. 2023's scale series"),
])
def test_scale_is_limited_with_the_reason(capsys, argv, message):
    code, out, err = run(capsys, *argv)
    assert code == 2 and message in one_line(err) and out == ""


def test_flow_depth_against_barrier_height(capsys, tmp_path):
    bad = write_variant(tmp_path, {("flow", "depth_m"): 99.0})
    code, _, err = run(capsys, "targets", bad, "--scale", 40)
    assert code == 2 and "more than 2 x the barrier height (4 m)" in one_line(err)
    ok = write_variant(tmp_path, {("flow", "depth_m"): 8.0}, name="ok.toml")
    assert run(capsys, "targets", ok, "--scale", 40)[0] == 0


def test_readme_documents_every_prototype_range():
    readme = (ROOT / "README.md").read_text()
    assert ranges_markdown() in readme, "README's ranges table differs from ranges_markdown()"


def test_check_command(capsys, tmp_path):
    out = tmp_path / "out"
    make_mod.make(SIMPLE, 40, out, steps=[s for s in make_mod.default_steps()
                                          if s[1] is not make_mod.verify_step])
    code, text, _ = run(capsys, "check", out)
    assert code == 0 and re.search(r"\d+ files match manifest.json", text)
    (out / "net.gcode").write_text("G1 X0\n")
    (out / "stray.txt").write_text("?")
    code, text, _ = run(capsys, "check", out, "--json")
    rep = json.loads(text)
    assert code == 1 and not rep["matches"]
    assert rep["differences"][0].startswith("changed: net.gcode")
    assert rep["differences"][1] == "extra: stray.txt"
    code, _, err = run(capsys, "check", tmp_path)
    assert code == 2 and "no manifest.json" in one_line(err)
