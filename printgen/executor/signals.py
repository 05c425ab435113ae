"""Signals end a run cleanly: within `signals_raise` SIGINT, SIGTERM and SIGHUP (where the
platform defines it) become an `Interrupted` exception in the parent, which stops its workers
(they ignore those signals: `local.init_worker`), lets every `finally` remove its stage
folder, and the command line prints one line and exits with 128 + the signal number (130 for
Ctrl-C, 143 for SIGTERM).
"""

from __future__ import annotations

import contextlib
import multiprocessing
import signal
import threading
from collections.abc import Iterator
from typing import Any

from printgen.executor.start import handled_signals


class Interrupted(BaseException):
    """A signal asked the run to stop (a BaseException, like KeyboardInterrupt, so that no
    `except Exception` swallows it)."""

    def __init__(self, signum: int) -> None:
        super().__init__(signum)
        self.signum = signum

    @property
    def name(self) -> str:
        return signal.Signals(self.signum).name

    @property
    def exit_code(self) -> int:
        return 128 + self.signum


def _raise(signum: int, _frame: Any) -> None:
    raise Interrupted(signum)


@contextlib.contextmanager
def signals_raise() -> Iterator[None]:
    """Within the block SIGINT, SIGTERM and SIGHUP (`handled_signals`) raise `Interrupted` (main
    thread only); the previous handlers come back afterwards."""
    if multiprocessing.parent_process() is not None or not _main_thread():
        yield
        return
    previous = {s: signal.signal(s, _raise) for s in handled_signals()}
    try:
        yield
    finally:
        for s, h in previous.items():
            signal.signal(s, h)


@contextlib.contextmanager
def signals_deferred() -> Iterator[None]:
    """Within the block SIGINT, SIGTERM and SIGHUP are held and re-sent at its end (main
    thread only), for code that catches BaseException and would swallow `Interrupted`:
    trimesh's imports turn any exception into a placeholder module and carry on."""
    if not _main_thread():
        yield
        return
    held: list[int] = []
    previous = {s: signal.signal(s, lambda signum, _frame: held.append(signum))
                for s in handled_signals()}
    try:
        yield
    finally:
        for s, h in previous.items():
            signal.signal(s, h)
        if held:
            signal.raise_signal(held[0])


def _main_thread() -> bool:
    return threading.current_thread() is threading.main_thread()
