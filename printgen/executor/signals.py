"""Signals end a run cleanly: within `signals_raise` SIGINT, SIGTERM and SIGHUP (where the
platform defines it) become an `Interrupted` exception in the parent, which stops its workers
(they ignore those signals: `local.init_worker`), lets every `finally` remove its stage
folder, and the command line prints one line and exits with 128 + the signal number (130 for
Ctrl-C, 143 for SIGTERM).

Whenever the signal comes, it is neither lost nor a second line:

- the command line installs the handler before its heavy imports (`printgen.cli.main`), and
  when the command's outcome is known `ending` makes a signal end the process at once;
- a signal is raised once: a second one while the first unwinds (its `finally` removing a
  stage) is only recorded, and one a library swallowed (a bare `except`, an `Exception ignored
  in` callback) is recorded too, for `raise_received` before a folder is swapped in and after
  the command;
- processes started within `signals_deferred` (workers, the fork server, multiprocessing's
  resource tracker) begin with the signals blocked: a worker unblocks them once it ignores
  them, and the servers never see the group's signals (they end when the processes they serve
  end).

This module imports nothing heavy: the command line imports it first.
"""

from __future__ import annotations

import contextlib
import signal
import sys
import threading
from collections.abc import Callable, Iterator
from typing import Any

SIGNAL_NAMES = ("SIGINT", "SIGTERM", "SIGHUP")  # the stop signals; SIGHUP is POSIX only

_received: list[int] = []  # signals seen within `signals_raise`, first first
_active = False  # within `signals_raise`
_ending: Callable[[int], None] | None = None  # `ending`'s: the outcome is known


def handled_signals() -> tuple[int, ...]:
    """SIGINT, SIGTERM and SIGHUP, those the platform defines."""
    return tuple(int(getattr(signal, n)) for n in SIGNAL_NAMES if hasattr(signal, n))


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


def _handle(signum: int, _frame: Any) -> None:
    _received.append(signum)
    if _ending is not None:
        _ending(signum)
    if not isinstance(sys.exc_info()[1], Interrupted):  # else: the run is stopping already
        raise Interrupted(signum)


@contextlib.contextmanager
def signals_raise(*, restore: bool = True) -> Iterator[None]:
    """Within the block SIGINT, SIGTERM and SIGHUP (`handled_signals`) raise `Interrupted` (main
    thread only) but those ignored when it starts (`nohup`, a background job of a shell keep
    them ignored); the previous handlers come back afterwards unless `restore` is False (the
    command line's own process: `ending` then says what a signal does). An `Interrupted` that
    a library's `__del__` or callback could not raise is dropped from stderr, not from
    `received`. Within a `signals_raise` block, one more is a no-op."""
    global _active
    mp = sys.modules.get("multiprocessing")  # not imported yet: not a worker (nor imported here)
    worker = mp is not None and mp.parent_process() is not None
    if _active or worker or not _main_thread():
        yield
        return
    _received.clear()
    _active = True
    hook = sys.unraisablehook
    sys.unraisablehook = _unraisable
    previous: dict[int, Any] = {}
    try:
        for s in handled_signals():
            if signal.getsignal(s) is not signal.SIG_IGN:
                previous[s] = signal.signal(s, _handle)
        yield
    finally:
        if restore:
            for s, h in previous.items():
                signal.signal(s, h)
            sys.unraisablehook = hook
            _active = False


def _unraisable(unraisable: Any) -> None:
    if not isinstance(unraisable.exc_value, Interrupted):
        sys.__unraisablehook__(unraisable)


def received() -> int | None:
    """The first signal seen within the last `signals_raise` (None: none), raised or not."""
    return _received[0] if _received else None


def raise_received() -> None:
    """Raise `Interrupted` for a signal seen within `signals_raise` that did not stop the run
    (a library swallowed it): before an output is swapped in, and after the command."""
    if _active and _received:
        raise Interrupted(_received[0])


def ending(then: Callable[[int], None]) -> None:
    """From now on a signal calls `then(signum)` (which ends the process) instead of raising:
    the command line's outcome is known, and interpreter shutdown is no place for an exception."""
    global _ending
    _ending = then


@contextlib.contextmanager
def signals_deferred() -> Iterator[None]:
    """Within the block SIGINT, SIGTERM and SIGHUP are held and re-sent at its end (main
    thread only), for code that catches BaseException and would swallow `Interrupted`:
    trimesh's imports turn any exception into a placeholder module and carry on. They are
    also blocked in this thread, so that the processes started within the block (workers, the
    fork server, the resource tracker) begin with them blocked (their signal mask is this
    thread's) and are not stopped half-started: a worker ignores them before it unblocks them
    (`local.init_worker`), the servers never unblock them."""
    held: list[int] = []
    previous: dict[int, Any] = {}
    mask = _block(handled_signals())
    try:
        if _main_thread():
            for s in handled_signals():
                previous[s] = signal.signal(s, lambda signum, _frame: held.append(signum))
        yield
    finally:
        _setmask(mask)  # a signal blocked meanwhile arrives now: held
        for s, h in previous.items():
            signal.signal(s, h)
        if held:
            signal.raise_signal(held[0])


def unblock_signals() -> None:
    """Unblock SIGINT, SIGTERM and SIGHUP in this thread (a worker, once it ignores them)."""
    if hasattr(signal, "pthread_sigmask"):
        signal.pthread_sigmask(signal.SIG_UNBLOCK, handled_signals())


def _block(signals: tuple[int, ...]) -> Any:
    """Block `signals` in this thread; the previous mask (None where masks do not exist)."""
    if not hasattr(signal, "pthread_sigmask"):
        return None
    return signal.pthread_sigmask(signal.SIG_BLOCK, signals)


def _setmask(mask: Any) -> None:
    if mask is not None:
        signal.pthread_sigmask(signal.SIG_SETMASK, mask)


def _main_thread() -> bool:
    return threading.current_thread() is threading.main_thread()
