"""Nothing outside the output folder is ever touched (issue 20).

Each trap is planted around a sentinel tree (files, a symbolic link, a foreign folder with a
manifest.json, profiles outside the profile folders); the tree is hashed before and after, and
each case must exit as stated with nothing outside --out changed. Most refusals come before any
work; the cases that need a finished printgen output share one small `make` (module fixture).
"""

from __future__ import annotations

import hashlib
import json
import os
import shutil
import signal
import stat
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest
from proto_files import REALISTIC, SIMPLE, write_variant

from printgen.cli import main, run_command
from printgen.inputs.profiles import BUNDLED
from printgen.outputs import (
    InputFileError,
    LockError,
    OutputError,
    check_folder,
    folder_lock,
    read_input,
    staged_dir,
)
from printgen.outputs import folder as folder_mod

POSIX_ONLY = pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="FIFOs are POSIX")
WATCHDOG_S = 60  # a refusal takes well under a second; a hang (a FIFO read) fails the test


@pytest.fixture(autouse=True)
def watchdog():
    """Fail instead of hanging when a check regresses to reading a FIFO or /dev/zero."""
    def expire(_signum, _frame):
        raise TimeoutError(f"no answer within {WATCHDOG_S} s (a blocking read?)")

    if not hasattr(signal, "SIGALRM"):  # Windows: no alarm, and no FIFO to hang on either
        yield
        return
    previous = signal.signal(signal.SIGALRM, expire)
    signal.alarm(WATCHDOG_S)
    yield
    signal.alarm(0)
    signal.signal(signal.SIGALRM, previous)


def snapshot(root: Path, skip: Path | tuple[Path, ...] = ()) -> dict[str, str]:
    """{relative path: what it is} for everything under `root` (links not followed): a
    file's sha256 and mode, a link's target, a folder; `skip` (the --out folder) left out."""
    skip = (skip,) if isinstance(skip, Path) else skip
    out = {}
    for dirpath, dirs, files in os.walk(root):
        for name in sorted(dirs + files):
            p = Path(dirpath) / name
            if any(p == s or s in p.parents for s in skip):
                continue
            st = p.lstat()
            rel = p.relative_to(root).as_posix()
            if stat.S_ISLNK(st.st_mode):
                out[rel] = f"link -> {os.readlink(p)}"
            elif stat.S_ISREG(st.st_mode):
                out[rel] = f"{hashlib.sha256(p.read_bytes()).hexdigest()} {st.st_mode:o}"
            else:
                out[rel] = f"mode {stat.S_IFMT(st.st_mode):o}"
    return out


@pytest.fixture
def world(tmp_path):
    """The sentinel tree: files, a link, a foreign app folder with its own manifest.json, a
    profile copied outside the profile folders, a commented TOML someone keeps."""
    w = tmp_path / "world"
    (w / "app" / "src").mkdir(parents=True)
    (w / "victim").write_text("precious\n")
    (w / "link").symlink_to(w / "victim")
    (w / "app" / "manifest.json").write_text('{"name": "app"}\n')
    (w / "app" / "src" / "main.js").write_text("code\n")
    (w / "outside").mkdir()
    shutil.copy(BUNDLED / "materials" / "tpe.toml", w / "outside" / "tpe2.toml")
    (w / "outside" / "victim.toml").write_text("# my notes\nname = 'mine'\n")
    (w / "x").mkdir()
    return w


def cli(capsys, *argv) -> tuple[int, str]:
    """Exit code and what a command run in this process printed (stdout, then stderr)."""
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    assert "Traceback" not in err, err
    return code, (out + err).strip()


@pytest.fixture(scope="module")
def made(tmp_path_factory):
    """One real `printgen make` output of the small example (its design, report and manifest;
    no parts: they add nothing here), shared by the cases needing it."""
    from printgen.run.make import make
    from printgen.run.options import RunOptions

    out = tmp_path_factory.mktemp("made") / "out"
    make(SIMPLE, 40, out, steps=[], options=RunOptions(command=["printgen", "make"]))  # plan only
    return out


def earlier_output(made: Path, where: Path) -> Path:
    shutil.copytree(made, where, symlinks=True)
    return where


# -- Must fix 1: a symlinked (or FIFO) lock file is refused, never written through ---------

@pytest.mark.parametrize("command", ["make", "verify", "design"])
def test_symlinked_lock_is_refused(world, capsys, command):
    (world / "x" / ".out.lock").symlink_to(world / "victim")
    before = snapshot(world)
    out = world / "x" / "out"
    argv = {"make": ["make", SIMPLE, "-s", 40, "--out", out],
            "verify": ["verify", SIMPLE, "-s", 40, "--design", world / "none.json", "--out", out],
            "design": ["design", SIMPLE, "-s", 40, "--serial", "--out", out]}[command]
    code, err = cli(capsys, *argv)
    assert code == 2 and "is a symbolic link" in err and ".out.lock" in err
    assert snapshot(world) == before


@POSIX_ONLY
@pytest.mark.parametrize("backend", ["flock", "exclusive"])
@pytest.mark.parametrize("planted", ["link", "hard link", "fifo", "folder"])
def test_lock_never_follows_a_planted_path(world, backend, planted):
    lock = world / "x" / ".out.lock"
    {"link": lambda: lock.symlink_to(world / "victim"), "fifo": lambda: os.mkfifo(lock),
     "hard link": lambda: os.link(world / "victim", lock), "folder": lock.mkdir}[planted]()
    before = snapshot(world)
    with pytest.raises(LockError, match="lock file .* is"), \
            folder_lock(world / "x" / "out", backend=backend):
        pass
    assert snapshot(world) == before


# -- Must fix 2: a folder is replaced only when it is printgen's own ----------------------

def test_foreign_folder_with_a_manifest_is_refused(world, capsys):
    before = snapshot(world)
    code, err = cli(capsys, "make", SIMPLE, "-s", 40, "--out", world / "app")
    assert code == 2 and "not a printgen output folder" in err and "manifest.json" in err
    assert "--force" in err and snapshot(world) == before


@pytest.mark.slow
def test_printgen_output_with_a_foreign_file_names_it(world, made, capsys):
    out = earlier_output(made, world / "x" / "out")
    (out / "notes").mkdir()
    (out / "notes" / "mine.txt").write_text("mine")
    before = snapshot(world)
    code, err = cli(capsys, "make", SIMPLE, "-s", 40, "--out", out)
    assert code == 2 and "it holds notes (a folder)" in err
    assert snapshot(world) == before


@pytest.mark.parametrize("extra", ["link", "empty folder"])
def test_printgen_output_with_a_link_or_folder_is_foreign(world, made, extra):
    out = earlier_output(made, world / "x" / "out")
    if extra == "link":
        (out / "report.html").unlink()
        (out / "report.html").symlink_to(world / "victim")
    else:
        (out / "empty").mkdir()
    before = snapshot(world)
    with pytest.raises(OutputError, match="a symbolic link|empty \\(a folder\\)"), \
            staged_dir(out):
        pass
    assert snapshot(world) == before


def test_own_output_is_replaced_and_force_replaces_a_foreign_one(world, made):
    out = earlier_output(made, world / "x" / "out")
    before = snapshot(world, skip=(out, world / "app"))
    with staged_dir(out) as stage:
        (stage / "a.txt").write_text("new run")
    assert sorted(p.name for p in out.iterdir()) == ["a.txt", "manifest.json"]
    with staged_dir(world / "app", force=True) as stage:
        (stage / "b.txt").write_text("forced")
    assert sorted(p.name for p in (world / "app").iterdir()) == ["b.txt", "manifest.json"]
    assert snapshot(world, skip=(out, world / "app")) == before


# -- Must fix 3 and 4: a material or profile name is a name, never a path -----------------

@pytest.mark.parametrize("material", ["{abs}/outside/tpe2", "../../outside/tpe2", ".hidden",
                                      "tpe/../tpe", "tpe2\x00", "*"])
def test_design_json_material_path_is_refused_before_work(world, made, capsys, material):
    design = json.loads((made / "design.json").read_text())
    design["net"]["material"] = material.format(abs=world)
    evil = world / "evil.json"
    evil.write_text(json.dumps(design))
    good = world / "good.csv"
    good.write_text("h_over_hb,crest_deflection_over_width\n0.5,0.01\n1.0,0.02\n")
    before = snapshot(world)
    code, err = cli(capsys, "verify", SIMPLE, "-s", 40, "--design", evil, "--measured", good,
                    "--out", world / "vout" / "x")
    assert code == 2 and "net.material" in err and "is not a profile name" in err
    assert snapshot(world) == before


@pytest.mark.parametrize(("args", "what"), [
    (["--material", "{abs}/outside/victim", "--out", "{abs}/profout"], "--material"),
    (["--material", "../outside/evilplot", "--plot", "{abs}/plots"], "--material"),
    (["--material", "{abs}/outside/sub/dir/x", "--save", "--out", "{abs}/p"], "--material"),
    (["--material", "lab", "--inherits", "../outside/tpe2", "--out", "{abs}/p"], "--inherits"),
])
def test_calibrate_material_path_is_refused(world, capsys, args, what):
    before = snapshot(world)
    code, err = cli(capsys, "calibrate", world / "victim", *[a.format(abs=world) for a in args])
    assert code == 2 and f"{what}: " in err and "is not a profile name" in err
    assert snapshot(world) == before


@pytest.mark.parametrize(("key", "name"), [
    (("model", "printer"), "../../../{abs}/outside/tpe2"),
    (("model", "net_print"), "{abs}/outside/x"),
    (("model", "materials"), ["tpe", "../outside/tpe2"])])
def test_prototype_profile_names_are_names(world, capsys, key, name):
    value = [n.format(abs=world) for n in name] if isinstance(name, list) else \
        name.format(abs=world)
    proto = write_variant(world, {key: value}, base=REALISTIC)
    before = snapshot(world)
    code, err = cli(capsys, "make", proto, "-s", 40, "--out", world / "x" / "out")
    assert code == 2 and "is not a profile name" in err and key[1] in err
    assert snapshot(world) == before


@pytest.mark.parametrize("argv", [
    ["make", SIMPLE, "-s", 40, "--printer", "{abs}/outside/tpe2", "--out", "{abs}/x/o"],
    ["select", SIMPLE, "-s", 40, "--materials", "tpe", "../outside/tpe2"],
    ["design", SIMPLE, "-s", 40, "--serial", "--materials", "{abs}/outside/tpe2",
     "--out", "{abs}/x/o"],
    ["design", SIMPLE, "-s", 40, "--serial", "--printer", "..", "--out", "{abs}/x/o"]])
def test_printer_and_materials_options_are_names(world, capsys, argv):
    before = snapshot(world)
    code, err = cli(capsys, *[str(a).format(abs=world) for a in argv])
    assert code == 2 and ("--printer: " in err or "--materials: " in err)
    assert "is not a profile name" in err and snapshot(world) == before


def test_profiles_show_and_inherits_do_not_read_outside(world, capsys, monkeypatch, tmp_path):
    code, err = cli(capsys, "profiles", "show", f"../../../../{world}/outside/tpe2")
    assert code == 2 and "is not a profile name" in err
    root = tmp_path / "profiles"
    (root / "materials").mkdir(parents=True)
    (root / "materials" / "child.toml").write_text(f'inherits = "{world}/outside/tpe2"\n')
    monkeypatch.setenv("PRINTGEN_PROFILES", str(root))
    code, err = cli(capsys, "profiles", "show", "child")
    assert code == 2 and "inherits" in err and "is not a profile name" in err


def test_fitted_profile_is_written_inside_out_and_its_manifest(world, made, monkeypatch):
    from printgen.run.verify import _write, fitted_name
    from printgen.scaling.design_file import load_design

    d = load_design(made / "design.json")
    out = world / "vout" / "x"
    before = snapshot(world, skip=world / "vout")
    name = fitted_name(d)
    files = _write(out, {"report.html": "<html></html>\n", name: "inherits = 'x'\n"}, False, [])
    assert name in files and (out / name).is_file()
    assert name in json.loads((out / "manifest.json").read_text())["files"]
    assert snapshot(world, skip=world / "vout") == before


# -- Must fix 5: the rename-aside fallback never loses the previous run --------------------

KILL_BETWEEN_RENAMES = textwrap.dedent("""
    import os, signal, sys
    from pathlib import Path
    from printgen.outputs import folder, staged_dir
    folder.exchange = lambda a, b: False          # a file system without RENAME_EXCHANGE
    real, calls = os.rename, []
    def rename(src, dst):
        calls.append(src)
        if len(calls) == 2:                       # between the fallback's two renames
            os.kill(os.getpid(), signal.SIGKILL)
        return real(src, dst)
    os.rename = rename
    with staged_dir(sys.argv[1]) as stage:
        (stage / "a.txt").write_text("new run")
""")


def test_killed_fallback_swap_is_restored_by_the_next_run(world, capsys):
    out = world / "x" / "out"
    with staged_dir(out) as stage:
        (stage / "a.txt").write_text("previous run")
    before = snapshot(world)
    env = {**os.environ, "PYTHONPATH": str(Path(__file__).resolve().parents[1])}
    proc = subprocess.run([sys.executable, "-c", KILL_BETWEEN_RENAMES, str(out)], env=env,
                          timeout=WATCHDOG_S, check=False)
    assert proc.returncode == -signal.SIGKILL
    assert not out.exists() and [p.name[:9] for p in out.parent.glob(".out.old.*")] == [
        ".out.old."]
    # the next run fails on bad input: the old run must survive it
    code, _ = cli(capsys, "make", world / "missing.toml", "-s", 40, "--out", out)
    assert code == 2 and list(out.parent.glob(".out.old.*"))
    # a run that fails inside its stage still starts by putting the old run back
    with pytest.raises(RuntimeError), staged_dir(out):
        raise RuntimeError("a step failed")
    assert (out / "a.txt").read_text() == "previous run" and check_folder(out) == []
    assert snapshot(world) == before  # the old folder whole, no stage, no aside, no lock


def test_an_aside_outlives_every_run_that_fails(world):
    out = world / "x" / "out"
    with staged_dir(out) as stage:
        (stage / "a.txt").write_text("current")
    aside = world / "x" / ".out.old.0badc0de"  # left by a run killed after its swap
    aside.mkdir()
    (aside / "a.txt").write_text("older")
    with pytest.raises(RuntimeError), staged_dir(out):
        raise RuntimeError("a step failed")
    assert (aside / "a.txt").read_text() == "older"
    with staged_dir(out) as stage:
        (stage / "a.txt").write_text("new")
    assert not aside.exists() and (out / "a.txt").read_text() == "new"


def test_fallback_swap_removes_the_old_run_only_after_the_new_is_in(world, monkeypatch):
    out = world / "x" / "out"
    with staged_dir(out) as stage:
        (stage / "a.txt").write_text("1")
    monkeypatch.setattr(folder_mod, "exchange", lambda a, b: False)
    seen = []
    real_rmtree = shutil.rmtree

    def rmtree(path, *a, **kw):
        if ".old." in Path(path).name:
            seen.append((out / "a.txt").read_text())  # the new run is already in place
        return real_rmtree(path, *a, **kw)

    monkeypatch.setattr(folder_mod.shutil, "rmtree", rmtree)
    with staged_dir(out) as stage:
        (stage / "a.txt").write_text("2")
    assert seen == ["2"] and sorted(p.name for p in out.parent.iterdir()) == ["out"]


# -- Must fix 6: an --out that holds an input of the run is refused -------------------------

def test_input_inside_out_is_refused(world, made, capsys):
    out = earlier_output(made, world / "x" / "out")
    shutil.copy(SIMPLE, out / "my.toml")
    before = snapshot(world)
    for extra in ([], ["--force"]):
        code, err = cli(capsys, "make", out / "my.toml", "-s", 40, "--out", out, *extra)
        assert code == 2 and "is inside the output folder" in err and "my.toml" in err
    code, err = cli(capsys, "verify", SIMPLE, "-s", 40, "--design", out / "design.json",
                    "--out", out)
    assert code == 2 and "design.json is inside the output folder" in err
    assert snapshot(world) == before


# -- Must fix 7: stage and lock names are matched literally ---------------------------------

def test_glob_characters_in_out_match_nothing_else(world):
    other_stage = world / "x" / ".other.stage.0123abcd"
    other_stage.mkdir()
    (other_stage / "net.gcode").write_text("another run, still writing")
    (world / "x" / ".other.old.deadbeef").mkdir()
    (world / "x" / ".other.lock").write_text("4242\n")
    before = snapshot(world)
    for name in ("*", "?ther", "[o]ther", ".*"):
        out = world / "x" / name
        with staged_dir(out) as stage:
            (stage / "a.txt").write_text(name)
        shutil.rmtree(out)
    assert snapshot(world) == before


# -- Also wrong today ---------------------------------------------------------------------

@pytest.mark.parametrize("address", ["file:///etc/passwd", "inproc://", "tls://localhost:1",
                                     "ucx://x", "tcp://[::1", "http://localhost:8786",
                                     "tcp://host:99999", "tcp://:8786"])
def test_scheduler_address_is_checked_first(world, capsys, address):
    before = snapshot(world)
    code, err = cli(capsys, "design", SIMPLE, "-s", 40, "--scheduler", address,
                    "--out", world / "x" / "d")
    assert code == 2 and "is not a Dask scheduler address" in err and err.count("\n") == 0
    assert snapshot(world) == before


def test_check_covers_the_manifest_and_every_entry(world, made, capsys):
    out = earlier_output(made, world / "x" / "out")
    assert cli(capsys, "check", out)[0] == 0
    m = json.loads((out / "manifest.json").read_text())
    cases = {
        "volatile": lambda m: m.update(volatile=["timings.json", "net.gcode"]),
        "version": lambda m: m.update(printgen_version="9.9"),
        "command": lambda m: m.update(command=["printgen", "make", "other.toml"])}
    for label, edit in cases.items():
        changed = json.loads(json.dumps(m))
        edit(changed)
        (out / "manifest.json").write_text(json.dumps(changed))
        code, err = cli(capsys, "check", out)
        assert code in (1, 2) and "manifest" in err, label
    (out / "manifest.json").write_text(json.dumps(m))
    (out / "empty").mkdir()
    (out / "l").symlink_to(world / "victim")
    code, _ = cli(capsys, "check", out)
    lines = check_folder(out)
    assert code == 1 and lines == ["extra: empty (a folder)", "extra: l (a symbolic link)"]


@pytest.mark.slow
@POSIX_ONLY
@pytest.mark.parametrize("kind", ["fifo", "dev-zero", "big"])
def test_non_regular_and_oversized_inputs_are_refused(world, made, capsys, kind):
    if kind == "fifo":
        path = world / "pipe"
        os.mkfifo(path)
        what = "FIFO"
    elif kind == "dev-zero":
        path, what = Path("/dev/zero"), "character device"
    else:
        path, what = world / "big.csv", "over the"
        with open(path, "wb") as fh:
            fh.truncate(80 << 20)  # sparse: 80 MiB without writing them
    before = snapshot(world)
    cases = [["make", path, "-s", 40, "--out", world / "x" / "o"],
             ["verify", SIMPLE, "-s", 40, "--design", path, "--out", world / "x" / "o"],
             ["verify", SIMPLE, "-s", 40, "--design", made / "design.json", "--measured", path,
              "--out", world / "x" / "o"],
             ["calibrate", path, "--material", "lab"]]
    for argv in cases:
        code, err = cli(capsys, *argv)
        assert code == 2 and what in err and "file not found" not in err, (argv, err)
    assert snapshot(world) == before


@POSIX_ONLY
def test_fifo_manifest_is_refused_by_make_and_check(world, made, capsys):
    out = earlier_output(made, world / "x" / "out")
    (out / "manifest.json").unlink()
    os.mkfifo(out / "manifest.json")
    before = snapshot(world)
    code, err = cli(capsys, "make", SIMPLE, "-s", 40, "--out", out)
    assert code == 2 and "FIFO" in err
    code, err = cli(capsys, "check", out)
    assert code == 2 and "FIFO" in err
    assert snapshot(world) == before


def test_read_input_checks_what_it_opened(world):
    assert read_input(world / "link") == b"precious\n"  # a link to a file is that file
    with pytest.raises(InputFileError, match="is a folder"):
        read_input(world / "app")


def test_mount_point_out_is_refused_first(world, capsys, monkeypatch):
    target = world / "x" / "mnt"
    target.mkdir()
    real = os.path.ismount
    monkeypatch.setattr(os.path, "ismount", lambda p: Path(p) == target or real(p))
    before = snapshot(world)
    code, err = cli(capsys, "make", SIMPLE, "-s", 40, "--out", target)
    assert code == 2 and "is a mount point" in err and snapshot(world) == before


def _fake_command(body):
    import argparse

    return argparse.Namespace(func=lambda _args: body() or 0)


def test_signal_just_after_the_swap_says_the_folder_was_replaced(world, capsys, monkeypatch):
    out = world / "x" / "out"
    real_swap = folder_mod.swap_in

    def swap_then_term(stage, dest):
        real_swap(stage, dest)
        os.kill(os.getpid(), signal.SIGTERM)  # held until the swap's cleanup is done

    monkeypatch.setattr(folder_mod, "swap_in", swap_then_term)

    def body():
        with staged_dir(out) as stage:
            (stage / "a.txt").write_text("new")

    code = run_command(_fake_command(body), "printgen make")
    err = capsys.readouterr().err.strip()
    assert code == 143 and "after the run was complete" in err and str(out) in err
    assert check_folder(out) == [] and sorted(p.name for p in out.parent.iterdir()) == ["out"]


def test_disk_full_names_the_path(world, capsys):
    out = world / "x" / "out"

    def body():
        with staged_dir(out) as stage:
            (stage / "a.txt").write_text("x")
            raise OSError(28, "No space left on device")  # as write() raises it: no file name

    code = run_command(_fake_command(body), "printgen make")
    err = capsys.readouterr().err.strip()
    assert code == 1 and ".out.stage." in err and "No space left on device" in err
    assert "free space" in err and not out.exists()


def test_disk_already_full_names_the_lock_path(world, capsys, monkeypatch):
    """The disk is full before the run: the first write is the lock's pid."""
    out = world / "x" / "out"
    real_write = os.write

    def full(fd, data):
        if data.strip().isdigit():  # the pid into the lock file
            raise OSError(28, "No space left on device")
        return real_write(fd, data)

    def body():
        monkeypatch.setattr(os, "write", full)
        with staged_dir(out):
            pass

    code = run_command(_fake_command(body), "printgen make")
    err = capsys.readouterr().err.strip()
    assert code == 1 and ".out.lock" in err and "No space left on device" in err, err
    assert "free space" in err and not out.exists()


def test_verify_checks_out_before_computing(world, made, capsys, monkeypatch):
    import printgen.run.verify as verify_mod

    def no_work(*_a, **_k):
        raise AssertionError("verify computed before checking --out")

    monkeypatch.setattr(verify_mod, "verify_with_band", no_work)
    before = snapshot(world)
    code, err = cli(capsys, "verify", SIMPLE, "-s", 40, "--design", made / "design.json",
                    "--out", world / "app")
    assert code == 2 and "not a printgen output folder" in err and snapshot(world) == before


# -- The lock where fcntl does not exist ----------------------------------------------------

def test_exclusive_lock_refuses_a_live_holder_and_breaks_a_stale_one(world):
    out = world / "x" / "out"
    with folder_lock(out, backend="exclusive"):
        assert (world / "x" / ".out.lock").read_text() == f"{os.getpid()}\n"
        with pytest.raises(LockError, match=f"pid {os.getpid()}"), \
                folder_lock(out, backend="exclusive"):
            pass
    assert not (world / "x" / ".out.lock").exists()
    dead = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"],
                          capture_output=True, text=True, check=True).stdout.strip()
    (world / "x" / ".out.lock").write_text(f"{dead}\n")  # a killed run's lock
    with folder_lock(out, backend="exclusive"):
        assert (world / "x" / ".out.lock").read_text() == f"{os.getpid()}\n"
    assert sorted(p.name for p in (world / "x").iterdir()) == []


def test_outputs_work_without_fcntl(tmp_path):
    """No module-level fcntl import: with fcntl missing, the exclusive lock is used."""
    code = textwrap.dedent("""
        import sys
        sys.modules["fcntl"] = None
        from printgen.outputs import lock, staged_dir
        assert lock.BACKEND == "exclusive", lock.BACKEND
        with staged_dir(sys.argv[1]) as stage:
            (stage / "a.txt").write_text("1")
        print("ok")
    """)
    env = {**os.environ, "PYTHONPATH": str(Path(__file__).resolve().parents[1])}
    proc = subprocess.run([sys.executable, "-c", code, str(tmp_path / "out")], env=env,
                          capture_output=True, text=True, timeout=WATCHDOG_S, check=False)
    assert proc.stdout.strip() == "ok", proc.stderr
    assert (tmp_path / "out" / "a.txt").read_text() == "1"


def test_realistic_example_is_untouched_by_refusals(capsys, tmp_path):
    """The example itself never moves: a refused run reads it and leaves it."""
    before = snapshot(REALISTIC.parent)
    code, err = cli(capsys, "make", REALISTIC, "-s", 40, "--out", REALISTIC.parent, "--force")
    assert code == 2 and "is inside the output folder" in err
    assert snapshot(REALISTIC.parent) == before


# -- A design is checked against the prototype it is used with ------------------------------

@pytest.mark.parametrize(("proto", "other"), [(SIMPLE, REALISTIC), (REALISTIC, SIMPLE)])
def test_make_refuses_the_design_of_another_barrier(world, capsys, proto, other):
    from printgen.run.api import plan

    design = world / "other.json"
    design.write_text(json.dumps(plan(other, 40).to_dict()))
    before = snapshot(world)
    code, err = cli(capsys, "make", proto, "-s", 40, "--design", design, "--out",
                    world / "x" / "out")
    assert code == 2 and "design of another barrier" in err and "other.json" in err, err
    assert snapshot(world) == before


def test_a_design_of_its_own_barrier_is_accepted():
    from printgen.inputs.prototype import load_prototype
    from printgen.run.api import plan
    from printgen.scaling.design_file import check_design_of

    for proto in (SIMPLE, REALISTIC):
        check_design_of(plan(proto, 40), load_prototype(proto), where="design")


# -- A lab's readings typed into an output folder are never replaced silently ---------------

def test_an_edited_measurement_sheet_stops_the_next_run(world, made_1_40, capsys):
    out = earlier_output(made_1_40[1], world / "x" / "out")
    sheet = out / "measurement-sheet.csv"
    sheet.write_text(sheet.read_text() + "1.0,,,12.5\n")  # a lab's reading
    before = snapshot(world)
    code, err = cli(capsys, "make", REALISTIC, "-s", 40, "--out", out)
    assert code == 2 and "measurement-sheet.csv, edited since printgen wrote it" in err, err
    assert "--force" in err and snapshot(world) == before


# -- A small file system that fills up during the run (where this machine lets us mount one) --

@pytest.fixture
def small_fs(tmp_path):
    """A 400 kB tmpfs: root only, and a machine (or container) that allows mounting."""
    where = tmp_path / "small"
    where.mkdir()
    if not hasattr(os, "geteuid") or os.geteuid() != 0 or shutil.which("mount") is None:
        pytest.skip("mounting a small file system needs root")
    done = subprocess.run(["mount", "-t", "tmpfs", "-o", "size=400k", "tmpfs", str(where)],
                          capture_output=True)
    if done.returncode:
        pytest.skip(f"cannot mount a tmpfs here: {done.stderr.decode().strip()}")
    try:
        yield where
    finally:
        subprocess.run(["umount", str(where)], check=True)


@POSIX_ONLY
def test_a_disk_filling_up_keeps_the_previous_run_and_leaves_nothing(small_fs, made, capsys):
    out = earlier_output(made, small_fs / "out")
    assert check_folder(out) == []
    code, err = cli(capsys, "make", REALISTIC, "-s", 40, "--out", out)
    assert code == 1 and "No space left on device" in err and "nothing was replaced" in err
    assert len(err.splitlines()) == 1, err
    assert check_folder(out) == [] and sorted(p.name for p in small_fs.iterdir()) == ["out"]
