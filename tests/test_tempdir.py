"""A run's temporary files stay in its own folder, removed when it ends or by the next run."""

from __future__ import annotations

import os
import subprocess
import sys
import tempfile
import textwrap
from pathlib import Path

import pytest

from printgen.outputs.tempdir import PREFIX, remove_stale


def test_a_killed_runs_folder_is_removed_and_a_live_ones_kept(tmp_path):
    dead = subprocess.Popen([sys.executable, "-c", "pass"])
    dead.wait()
    stale = tmp_path / f"{PREFIX}{dead.pid}-abc"
    (stale / "pymp-x").mkdir(parents=True)
    live = tmp_path / f"{PREFIX}{os.getpid()}-def"
    live.mkdir()
    other = tmp_path / "pymp-someone-else"
    other.mkdir()
    assert remove_stale(tmp_path) == [stale]
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted([live.name, other.name])


def test_a_process_uses_its_folder_and_removes_it():
    """multiprocessing's pymp folder lands in the run's folder, and nothing is left after."""
    base = Path(tempfile.mkdtemp(prefix="pgtmp", dir="/tmp"))  # short: the socket path limit
    code = textwrap.dedent(f"""
        import multiprocessing.util, tempfile
        from printgen.outputs.tempdir import private_tempdir
        mine = private_tempdir({str(base)!r})
        assert multiprocessing.util.get_temp_dir().startswith(str(mine))
        assert tempfile.mkstemp()[1].startswith(str(mine))
    """)
    subprocess.run([sys.executable, "-c", code], check=True)
    assert list(base.iterdir()) == []
    base.rmdir()


@pytest.mark.slow
def test_a_command_leaves_no_temporary_file_even_after_a_sigkill(tmp_path):
    """make's fork server and workers keep their files in the run's folder: gone after the
    run; after a SIGKILL, gone after the next run."""
    import signal
    import time

    from conftest import ROOT

    tmp = Path(tempfile.mkdtemp(prefix="pgtmp", dir="/tmp"))  # short: the socket path limit
    env = {**os.environ, "TMPDIR": str(tmp), "PYTHONPATH": str(ROOT)}
    argv = [sys.executable, "-m", "printgen", "make",
            str(ROOT / "examples" / "simple_barrier.toml"), "-s", "40"]
    killed = subprocess.Popen([*argv, "--out", str(tmp_path / "a")], env=env,
                              stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    time.sleep(3)  # planning done, the verification's workers running
    killed.send_signal(signal.SIGKILL)
    err = killed.communicate()[1].decode()
    left = [p.name for p in tmp.iterdir()]
    assert any(n.startswith(PREFIX) for n in left), (left, err)  # what a SIGKILL leaves
    subprocess.run([*argv, "--out", str(tmp_path / "b")], env=env, check=True,
                   capture_output=True)
    assert list(tmp.iterdir()) == []
    tmp.rmdir()


def test_a_long_temporary_folder_is_left_as_it_is(tmp_path):
    """Beneath a long TMPDIR the fork server's socket path would pass the system's limit."""
    from printgen.outputs.tempdir import private_tempdir

    deep = tmp_path / ("x" * 80)
    deep.mkdir()
    assert private_tempdir(deep) is None and list(deep.iterdir()) == []
