"""Exit codes the command line and its front ends (studies, the API, the chat) share, and
how they are interrupted."""

from __future__ import annotations

import contextlib
import signal
import threading
from collections.abc import Iterator

EXIT_BAD_INPUT = 2  # a mission, world or study file (or an argument) is wrong: one-line error
EXIT_INTERRUPTED = 130  # Ctrl-C or SIGTERM: what was recorded is kept (128 + SIGINT)


TERMINATION = ("SIGTERM", "SIGHUP")  # what ends a command as Ctrl-C does


def _signals(names: tuple[str, ...]) -> list[signal.Signals]:
    """The named signals this platform has."""
    return [getattr(signal, n) for n in names if hasattr(signal, n)]


def _main_thread() -> bool:
    """Only the main thread may set handlers (and it is the one that gets the signals)."""
    return threading.current_thread() is threading.main_thread()


def interrupt_on_termination() -> None:
    """SIGTERM and SIGHUP end a command as Ctrl-C does (a ``KeyboardInterrupt`` in the main
    thread): ``docker stop``, systemd, Kubernetes, Ray's cancellation and CI time-outs send
    SIGTERM, a closed terminal SIGHUP, and a run keeps what it recorded either way."""
    if not _main_thread():
        return

    def interrupt(signum: int, frame: object) -> None:
        raise KeyboardInterrupt(signal.Signals(signum).name)

    for sig in _signals(TERMINATION):
        signal.signal(sig, interrupt)


def default_termination() -> None:
    """Back to the default: for worker processes (a pool terminates them with SIGTERM)."""
    for sig in _signals(TERMINATION):
        signal.signal(sig, signal.SIG_DFL)


@contextlib.contextmanager
def deferred_interrupts() -> Iterator[None]:
    """Hold Ctrl-C, SIGTERM and SIGHUP until the block ends, then interrupt: for short steps
    that must not be cut in half (opening a run's outputs and logging its start)."""
    if not _main_thread():
        yield
        return
    caught: list[int] = []
    # only the signals that interrupt already (a handler in Python); one left to its default
    # (a library user's process) keeps it
    before = {sig: signal.getsignal(sig) for sig in _signals(("SIGINT", *TERMINATION))
              if callable(signal.getsignal(sig))}
    for sig in before:
        signal.signal(sig, lambda signum, frame: caught.append(signum))
    try:
        yield
    finally:
        for sig, handler in before.items():
            signal.signal(sig, handler)
    if caught:
        raise KeyboardInterrupt(signal.Signals(caught[0]).name)
