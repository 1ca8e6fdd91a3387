"""Exit codes the command line and its front ends (studies, the API, the chat) share, and
how they are interrupted."""

from __future__ import annotations

import contextlib
from collections.abc import Iterator

EXIT_BAD_INPUT = 2  # a mission, world or study file (or an argument) is wrong: one-line error
EXIT_INTERRUPTED = 130  # Ctrl-C or SIGTERM: what was recorded is kept (128 + SIGINT)


def interrupt_on_termination() -> None:
    """SIGTERM and SIGHUP end a command as Ctrl-C does (a ``KeyboardInterrupt`` in the main
    thread): ``docker stop``, systemd, Kubernetes, Ray's cancellation and CI time-outs send
    SIGTERM, a closed terminal SIGHUP, and a run keeps what it recorded either way."""
    import signal
    import threading

    if threading.current_thread() is not threading.main_thread():
        return  # only the main thread may set handlers (and gets the signals)

    def interrupt(signum: int, frame: object) -> None:
        raise KeyboardInterrupt(signal.Signals(signum).name)

    for name in ("SIGTERM", "SIGHUP"):
        if hasattr(signal, name):
            signal.signal(getattr(signal, name), interrupt)


def default_termination() -> None:
    """Back to the default: for worker processes (a pool terminates them with SIGTERM)."""
    import signal

    for name in ("SIGTERM", "SIGHUP"):
        if hasattr(signal, name):
            signal.signal(getattr(signal, name), signal.SIG_DFL)


@contextlib.contextmanager
def deferred_interrupts() -> Iterator[None]:
    """Hold Ctrl-C, SIGTERM and SIGHUP until the block ends, then interrupt: for short steps
    that must not be cut in half (opening a run's outputs and logging its start)."""
    import signal
    import threading

    if threading.current_thread() is not threading.main_thread():
        yield
        return
    caught: list[int] = []
    # only the signals that interrupt already (a handler in Python); one left to its default
    # (a library user's process) keeps it
    names = [n for n in ("SIGINT", "SIGTERM", "SIGHUP")
             if hasattr(signal, n) and callable(signal.getsignal(getattr(signal, n)))]
    before = {n: signal.getsignal(getattr(signal, n)) for n in names}
    for name in names:
        signal.signal(getattr(signal, name), lambda signum, frame: caught.append(signum))
    try:
        yield
    finally:
        for name, handler in before.items():
            signal.signal(getattr(signal, name), handler)
    if caught:
        raise KeyboardInterrupt(signal.Signals(caught[0]).name)
