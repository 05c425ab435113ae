"""`printgen make` killed during the verification (issue 16): SIGKILL, SIGTERM and SIGINT to
the process group leave no printgen process, no traceback, the previous folder whole, and the
next run removes what a SIGKILL left behind."""

from __future__ import annotations

import contextlib
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
from proto_files import REALISTIC, SIMPLE

import printgen.run.make as make_mod
from printgen.outputs import check_folder

PRINTGEN = Path(sys.executable).with_name("printgen")
REACH_VERIFICATION_S = 120.0  # generous: a loaded CI machine takes ~5 s to reach the sweep
GONE_AFTER_S = 5.0  # issue 16: no printgen process 5 s after the kill
EXIT_S = 30.0  # the killed make returns well within this (it kills its workers at once)


def children(pid: int) -> list[int]:
    out = []
    for task in Path(f"/proc/{pid}/task").glob("*"):
        with contextlib.suppress(OSError):
            out += [int(c) for c in (task / "children").read_text().split()]
    return out


def descendants(pid: int) -> list[int]:
    """Children, grandchildren, ... of `pid` (make's verification runs in a worker process
    that has the sweeps' workers as its own children)."""
    out, todo = [], children(pid)
    while todo:
        out.append(todo.pop())
        todo += children(out[-1])
    return out


def live_in_session(sid: int) -> list[int]:
    """Processes of session `sid` that are not zombies."""
    pids = []
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            text = stat.read_text()
        except OSError:
            continue
        fields = text[text.rindex(")") + 2:].split()  # after "pid (comm) "
        if int(fields[3]) == sid and fields[0] != "Z":
            pids.append(int(stat.parent.name))
    return pids


def start_and_wait_for_workers(out: Path) -> subprocess.Popen:
    proc = subprocess.Popen([str(PRINTGEN), "make", str(REALISTIC), "-s", "40", "--out",
                             str(out)], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True, start_new_session=True)
    deadline = time.monotonic() + REACH_VERIFICATION_S
    while len(descendants(proc.pid)) < 3:  # the verification's worker and its two workers
        assert proc.poll() is None, proc.communicate()
        assert time.monotonic() < deadline, "make never reached the verification"
        time.sleep(0.1)
    time.sleep(0.3)
    return proc


@pytest.mark.slow
def test_kills_during_verification_leave_nothing_behind(tmp_path):
    if (os.cpu_count() or 1) < 2 or os.environ.get("PRINTGEN_SERIAL"):
        import pytest

        pytest.skip("the verification runs in worker processes only on 2 cores or more")
    out = tmp_path / "out"
    fast = [s for s in make_mod.default_steps() if s[1] is not make_mod.verify_step]
    make_mod.make(SIMPLE, 40, out, steps=fast)  # the previous run, to be kept whole
    before = sorted(p.name for p in out.iterdir())
    # (signal, to the whole process group?, exit code); SIGKILL to make alone is what a batch
    # system's timeout does: only the workers' parent-death signal stops them then.
    cases = [(signal.SIGKILL, False, -9), (signal.SIGKILL, True, -9),
             (signal.SIGTERM, True, 143), (signal.SIGINT, True, 130)]
    for sig, group, code in cases:
        proc = start_and_wait_for_workers(out)
        os.killpg(proc.pid, sig) if group else os.kill(proc.pid, sig)
        _, err = proc.communicate(timeout=EXIT_S)
        assert proc.returncode == code, (sig, err)
        assert "Traceback" not in err, err
        if sig != signal.SIGKILL:
            assert err.strip() == f"printgen make: stopped by {sig.name}; outputs left as they were"
        deadline = time.monotonic() + GONE_AFTER_S
        while live_in_session(proc.pid) and time.monotonic() < deadline:
            time.sleep(0.1)
        assert live_in_session(proc.pid) == [], f"{sig.name}: processes left after 5 s"
        assert sorted(p.name for p in out.iterdir()) == before and check_folder(out) == []
        left = sorted(p.name for p in tmp_path.iterdir() if p.name != "out")
        if sig == signal.SIGKILL:
            assert any(n.startswith(".out.stage.") for n in left)  # what a SIGKILL leaves
        else:  # this run removed the SIGKILL's stage at start and its own at the end
            assert left == [], left
