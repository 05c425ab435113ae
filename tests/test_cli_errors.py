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
from printgen.executor.signals import Interrupted
from printgen.inputs.prototype import ranges_markdown
from printgen.run import api
from printgen.run.options import RunOptions


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


@pytest.mark.slow
def test_out_under_proc(capsys):
    code, _, err = run(capsys, *make_args("/proc/printgen-test-out"))
    assert code in (1, 2) and "/proc/" in one_line(err)


def test_out_in_a_foreign_folder_needs_force(capsys, tmp_path):
    (tmp_path / "data.csv").write_text("1,2")
    code, _, err = run(capsys, *make_args(tmp_path))
    assert code == 2 and "--force" in one_line(err) and (tmp_path / "data.csv").exists()


@pytest.mark.slow
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


def test_a_solve_that_did_not_converge_exits_2(capsys, monkeypatch):
    """One SolverError class, the solver's: printgen's error handling reports it like its own
    errors (one line, exit 2), and printgen.errors names the same class."""
    from printgen import errors, solver

    def diverged(*a, **k):
        raise errors.SolverError("simple barrier prototype: no convergence")

    assert errors.SolverError is solver.SolverError
    monkeypatch.setattr(api, "targets", diverged)
    code, _, err = run(capsys, "targets", REALISTIC, "--scale", 40)
    assert code == 2 and one_line(err) == ("printgen targets: error: simple barrier prototype: "
                                           "no convergence")


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
    readme = (ROOT / "docs" / "user-guide.md").read_text()
    assert ranges_markdown() in readme, "docs/user-guide.md's ranges table is not ranges_markdown()"


@pytest.mark.slow
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


# Issue 20: bad inputs that ended as "internal error" exit 1 (or passed silently), each now
# one line and exit 2, at the input stage (nothing is solved or written).
BASE_TEXT = REALISTIC.read_text()
TOML_CASES = {
    "width_m 400 digits": (BASE_TEXT.replace("width_m = 13.2", "width_m = " + "9" * 400),
                           "too large for a number"),
    "anchors 400 digits": (BASE_TEXT.replace("anchors = 4", "anchors = " + "9" * 400),
                           "too large for a number"),
    "anchors 5000 digits": (BASE_TEXT.replace("anchors = 4", "anchors = " + "9" * 5000),
                            "not valid TOML"),
    "nested inline tables": (BASE_TEXT.replace("anchors = 4", "anchors = 4\nx = " + "{a = " * 1500
                                               + "1" + "}" * 1500), "nested too deeply"),
    "materials = [1, 2]": (BASE_TEXT + "materials = [1, 2]\n",
                           "materials[0]: 1 (int) is not a profile name"),
    "20 000 materials": (BASE_TEXT + "materials = [" + '"tpe", ' * 20000 + "]\n",
                         "at most 100 are allowed"),
    "velocity 1e-300": (BASE_TEXT.replace("velocity_m_per_s = 2.2", "velocity_m_per_s = 1e-300"),
                        "must be >= 0.01 m/s"),
    "mesh_x_m 5e-324": (BASE_TEXT.replace("mesh_x_m = 0.63", "mesh_x_m = 5e-324"),
                        "must be >= 0.001 m"),
    "[model] mesh_x_mm 1e-9": (BASE_TEXT.replace("mesh_x_mm = 20.6", "mesh_x_mm = 1e-9"),
                               "must be >= 0.5 mm"),
    "froude_min > froude_max": (BASE_TEXT.replace("froude_min = 0.5", "froude_min = 2.0"),
                                "froude_min = 2 is above froude_max = 1.4"),
    "control characters in the name": (
        BASE_TEXT.replace('name = "Realistic', 'name = "\\u001b[31m'), "control character U+001B"),
}


@pytest.mark.parametrize("case", sorted(TOML_CASES))
def test_bad_prototype_values_are_one_line_exit_2(capsys, tmp_path, case):
    text, message = TOML_CASES[case]
    path = tmp_path / "bad.toml"
    path.write_text(text)
    code, out, err = run(capsys, "select", path, "--scale", 40)
    assert code == 2 and out == "" and message in one_line(err), err


def _design_text(tmp_path, edit) -> str:
    d = api.plan(REALISTIC, 40).to_dict()
    edit(d)
    return json.dumps(d)


DESIGN_CASES = {
    "5000-digit scale": (lambda d: d.update(scale=0), "not valid JSON"),
    "nested array": (lambda d: d["net"].update(width_mm=[[1.0]]), "is not a number"),
    "integer material": (lambda d: d["net"].update(material=3),
                         "net.material: 3 (int) is not a profile name"),
    "width_mm 1e300": (lambda d: d["net"].update(width_mm=1e300), "must be <= 10000 mm"),
    "printer as a list": (lambda d: d.update(printer=["generic-350"]),
                          "printer: ['generic-350'] (list) is not a profile name"),
    "2000 cables": (lambda d: d.update(cables=d["cables"] * 500), "a second 'top' cable"),
    "cable of no side": (lambda d: d["cables"][0].update(name="x"), "is not one of: top"),
}


@pytest.mark.slow
@pytest.mark.parametrize("case", sorted(DESIGN_CASES))
def test_bad_design_files_are_one_line_exit_2(capsys, tmp_path, case):
    edit, message = DESIGN_CASES[case]
    text = _design_text(tmp_path, edit)
    if case == "5000-digit scale":
        text = text.replace('"scale": 0', '"scale": ' + "4" * 5000)
    design = tmp_path / "design.json"
    design.write_text(text)
    code, out, err = run(capsys, "verify", REALISTIC, "-s", 40, "--design", design,
                         "--out", tmp_path / "v")
    assert code == 2 and out == "" and message in one_line(err), err
    assert not (tmp_path / "v").exists()


def test_deeply_nested_design_file(capsys, tmp_path):
    design = tmp_path / "design.json"
    design.write_text("[" * 100_000 + "]" * 100_000)
    code, _, err = run(capsys, "verify", REALISTIC, "-s", 40, "--design", design)
    assert code == 2 and "nested too deeply" in one_line(err)


MANIFEST_CASES = {
    "command not a list": (lambda m: m.update(command=5), "command = 5 is not a list of strings"),
    "file entry a string": (lambda m: m["files"].update({"a.txt": "abc"}), "file entry 'a.txt'"),
    "file entry null": (lambda m: m["files"].update({"a.txt": None}), "file entry 'a.txt'"),
    "volatile = 5": (lambda m: m.update(volatile=5),
                     "volatile = 5: only ['timings.json'] may be volatile"),
    "version not text": (lambda m: m.update(printgen_version=5), "'printgen_version' is not text"),
}


@pytest.mark.parametrize("case", sorted(MANIFEST_CASES))
def test_bad_manifest_entries_are_one_line_exit_2(capsys, tmp_path, case):
    edit, message = MANIFEST_CASES[case]
    (tmp_path / "a.txt").write_text("x")
    manifest = {"format": 1, "files": {"a.txt": {"sha256": "0" * 64, "bytes": 1}},
                "volatile": [], "command": ["printgen"], "printgen_version": "0"}
    edit(manifest)
    (tmp_path / "manifest.json").write_text(json.dumps(manifest))
    code, _, err = run(capsys, "check", tmp_path)
    assert code == 2 and message in one_line(err), err


@pytest.mark.parametrize("argv, message", [
    (["targets", REALISTIC], "the following arguments are required: --scale/-s"),
    (["make", REALISTIC, "-s", "40", "--time-limit", "abc"], "'abc' is not a number of seconds"),
    (["frobnicate"], "invalid choice: 'frobnicate'"),
])
def test_argparse_errors_are_one_line_with_a_hint(capsys, argv, message):
    code, out, err = run(capsys, *argv)
    line = one_line(err)
    assert code == 2 and out == "" and message in line and "--help`" in line, err


@pytest.mark.parametrize("command", ["make", "verify"])
@pytest.mark.parametrize("limit", ["0", "-1", "nan", "inf"])
def test_time_limit_must_be_positive_seconds(capsys, tmp_path, command, limit):
    argv = [command, REALISTIC, "-s", "40", "--time-limit", limit, "--out", tmp_path / "o"]
    if command == "verify":
        argv += ["--design", tmp_path / "never-read.json"]
    code, _, err = run(capsys, *argv)
    assert code == 2 and "must be a positive number of seconds" in one_line(err), err
    assert not (tmp_path / "o").exists()


def test_time_limit_zero_is_refused_by_the_api_too(tmp_path):
    from printgen.errors import InputError

    with pytest.raises(InputError, match="must be a positive number of seconds"):
        make_mod.make(REALISTIC, 40, tmp_path / "o", options=RunOptions(time_limit_s=0),
                      steps=[])


def test_terminal_escapes_in_a_path_are_shown_not_sent(tmp_path, capsys):
    """A path holding ESC sequences (set the title, clear the screen) is echoed escaped."""
    from printgen.cli import main

    bad = tmp_path / "x\x1b]0;pwned\x07\x1b[2J.toml"
    assert main(["make", str(bad), "-s", "40"]) == 2
    err = capsys.readouterr().err
    assert "\x1b" not in err and "\x07" not in err
    assert "x\\x1b]0;pwned\\x07\\x1b[2J.toml" in err
