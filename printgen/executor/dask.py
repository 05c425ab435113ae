"""Dask, for work that may leave the machine: a client to a running `dask.distributed`
scheduler (`--scheduler tcp://HOST:PORT`), its address checked before the (slow) import of
distributed. Work that stays on this machine runs on the local pool (`printgen.executor`)."""

from __future__ import annotations

import ipaddress
import logging
import re
from collections.abc import Iterator
from contextlib import ExitStack, contextmanager
from typing import Any

from printgen.errors import InputError

INSTALL_HINT = "pip install 'printgen[sweep]' (dask[distributed])"
ADDRESS = re.compile(r"tcp://(?P<host>\[[0-9A-Fa-f:.]+\]|[A-Za-z0-9](?:[A-Za-z0-9.-]*[A-Za-z0-9])?)"
                     r":(?P<port>[0-9]{1,5})")
CONNECT_TIMEOUT_S = 20  # a scheduler that does not answer within this is reported, not awaited


def distributed_module() -> Any:
    """dask.distributed, or InputError with the install hint."""
    try:
        import distributed
    except ImportError as exc:  # pragma: no cover - depends on the environment
        raise InputError(f"runs on a Dask scheduler need dask.distributed: {INSTALL_HINT}") \
            from exc
    return distributed


@contextmanager
def client(scheduler: str) -> Iterator[Any]:
    """A Client of the scheduler at `scheduler`, closed on exit, error or Ctrl-C; InputError
    when it does not answer within CONNECT_TIMEOUT_S."""
    check_address(scheduler)  # before the (slow) import of distributed
    distributed = distributed_module()
    with ExitStack() as stack:
        quiet = logging.getLogger("distributed")
        stack.callback(quiet.setLevel, quiet.level)
        quiet.setLevel(logging.ERROR)  # the cluster's chatter is not the user's business
        try:
            c = stack.enter_context(distributed.Client(
                scheduler, timeout=CONNECT_TIMEOUT_S, set_as_default=False))
        except (OSError, TimeoutError) as exc:
            raise InputError(f"cannot reach the Dask scheduler {scheduler!r} within "
                             f"{CONNECT_TIMEOUT_S} s ({exc}); start one with "
                             "`dask scheduler` or leave out --scheduler") from exc
        yield c


def map_on(c: Any, fn: Any, items: Any, shared: Any, advance: Any) -> list[Any]:
    """[fn(shared, item) for item in items] on client `c`, in order, `shared` sent once to
    every worker; `advance()` after each task ends. A failing task raises its error."""
    distributed = distributed_module()
    shared_f = c.scatter(shared, broadcast=True, hash=False)
    futures = [c.submit(_task, fn, shared_f, item, pure=False) for item in items]
    try:
        for _ in distributed.as_completed(futures, loop=c.loop):
            advance()
        return c.gather(futures)
    finally:
        c.cancel([*futures, shared_f])


def _task(fn: Any, shared: Any, item: Any) -> Any:
    """fn(shared, item) on a worker, its heap roomy (`heap.roomy`: distributed's workers fix
    glibc's thresholds, which maps a solver's larger arrays afresh at each allocation)."""
    from printgen.executor.heap import roomy

    with roomy():
        return fn(shared, item)


def check_address(address: str) -> str:
    """`address` when it is tcp://HOST:PORT (a host name, an IPv4 address or [IPv6]), else
    InputError: other schemes (file://, inproc://, tls://, ucx://) are not connected to."""
    m = ADDRESS.fullmatch(address)
    ok = m is not None and 1 <= int(m["port"]) <= 65535
    if ok and m is not None and m["host"].startswith("["):
        try:
            ipaddress.IPv6Address(m["host"][1:-1])
        except ValueError:
            ok = False
    if not ok:
        raise InputError(f"--scheduler {address[:100]!r} is not a Dask scheduler address: give "
                         "tcp://HOST:PORT, e.g. tcp://10.0.0.5:8786 (the address `dask "
                         "scheduler` prints), or leave out --scheduler for this machine's "
                         "workers")
    return address
