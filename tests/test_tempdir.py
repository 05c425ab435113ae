"""A run's temporary files stay in its own folder, removed when it ends or by the next run."""

from __future__ import annotations

import os
import subprocess
import sys
import tempfile
import textwrap

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


def test_a_process_uses_its_folder_and_removes_it(tmp_path):
    """multiprocessing's pymp folder lands in the run's folder, and nothing is left after."""
    code = textwrap.dedent(f"""
        import multiprocessing.util, tempfile
        from printgen.outputs.tempdir import private_tempdir
        mine = private_tempdir({str(tmp_path)!r})
        assert multiprocessing.util.get_temp_dir().startswith(str(mine))
        assert tempfile.mkstemp()[1].startswith(str(mine))
    """)
    subprocess.run([sys.executable, "-c", code], check=True, env={**os.environ,
                   "TMPDIR": tempfile.gettempdir()})
    assert list(tmp_path.iterdir()) == []
