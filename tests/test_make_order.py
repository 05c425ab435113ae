"""What `make` starts when: its helper process forks from the command line with make's imports
(the status line runs no thread), and the prototype's band variants start once the nominal
pair is done, ahead of the counter-example, without waiting for the loaded prototype's sweep
(printgen.verification.pooled)."""

from __future__ import annotations

import contextlib
import threading
from concurrent.futures import Future
from types import SimpleNamespace

import pytest

from printgen.commands import make as make_cmd
from printgen.commands.parser import build_parser
from printgen.executor import start
from printgen.verification import pooled


class Seen(Exception):
    """Raised by the stand-in of api.make once it has looked around."""


@pytest.mark.skipif(not start.SYSTEM.startswith("linux"), reason="fork: Linux only")
@pytest.mark.parametrize("terminal", ["0", "1"])
def test_the_make_command_runs_make_beside_no_thread(monkeypatch, terminal):
    """On a terminal or off one, `printgen make` runs `make` with no other thread running, so
    that its helper process starts by fork with make's imports (a thread, such as rich's
    animated spinner, sends it to a fork server that imports them again)."""
    monkeypatch.setenv("TTY_COMPATIBLE", terminal)  # rich's switch: stderr is a terminal or not
    seen = {}

    def looks(*_args, progress=None, **_kw):
        seen["threads"] = [t.name for t in threading.enumerate()]
        seen["method"] = start.start_method()
        progress("meshes (STL, 3MF)")  # the status line takes a step's label
        raise Seen

    monkeypatch.setattr(make_cmd.api, "make", looks)
    args = build_parser().parse_args(["make", "examples/simple_barrier.toml", "-s", "40"])
    # the command's own threads: an earlier test in this process may have left one (a Dask
    # client's offload thread), which a command line, a fresh process, does not have
    before = [t.name for t in threading.enumerate()]
    method = start.start_method()
    with pytest.raises(Seen):
        args.func(args)
    assert seen["threads"] == before
    assert seen["method"] == method
    if before == [threading.main_thread().name]:  # as on a command line
        assert method == "fork"


class _Pool:
    """A pool that runs nothing: it records what was submitted, and which futures were waited
    for, in order."""

    def __init__(self) -> None:
        self.log: list[str] = []

    def submit(self, fn, *args, **kw) -> Future:
        name = getattr(fn, "__name__", str(fn))
        self.log.append(f"submit {name}")
        f: Future = Future()
        f.set_result(SimpleNamespace(name=name))
        log = self.log
        result = f.result

        def waited(timeout=None):
            log.append(f"wait {name}")
            return result(timeout)

        f.result = waited  # type: ignore[method-assign]
        return f


def _sweep():
    pass


def _loaded_sweep():
    pass


def _prototype_variant():
    pass


def test_prototype_variants_start_once_the_pair_is_done(monkeypatch):
    """The prototype's variants are submitted as soon as the model's and the prototype's
    nominal sweeps are collected, before the counter-example and before the loaded prototype's
    sweep is waited for (it plays no part in them), from the prototype's run as `verified`
    compares it (`VerifyPlan.compared`)."""
    pool = _Pool()
    plan = SimpleNamespace(
        lv=[0.5, 1.0], kw_m={}, kw_p={}, ms=SimpleNamespace(mounting=None),
        jobs=lambda keep_states: [(_sweep, (), {}), (_sweep, (), {})],
        sensor_jobs=lambda: [(_loaded_sweep, (), {})],
        compared=lambda model, proto: (("the prototype's run", model), {}),
        verified=lambda model, proto, ce, loaded: SimpleNamespace(
            model=model, prototype=proto, sensors=None))
    got = {}

    def jobs(_p, nominal, _kw):
        got["nominal"] = nominal
        return [(_prototype_variant, (), {})]

    @contextlib.contextmanager
    def shared():
        yield pool

    monkeypatch.setattr(pooled, "verify_plan", lambda *_a, **_k: plan)
    monkeypatch.setattr(pooled, "shared_pool", shared)
    monkeypatch.setattr(pooled, "scene_sensor_force", lambda _s: None)
    monkeypatch.setattr(pooled, "meshable", lambda *_a: False)
    monkeypatch.setattr(pooled, "prototype_jobs", jobs)

    def band(*_a, **_k):  # what follows the band's start plays no part here
        raise Seen

    monkeypatch.setattr(pooled, "model_band", band)
    with pytest.raises(Seen):
        pooled.verify_with_band(SimpleNamespace(), SimpleNamespace(scale=40.0),
                                counterexample=True)
    log = pool.log
    assert got["nominal"] == "the prototype's run"
    variant, ce = log.index("submit _prototype_variant"), log.index("submit steel_counterexample")
    assert log.index("wait _sweep") < variant < ce < log.index("wait _loaded_sweep")
