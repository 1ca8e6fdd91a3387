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


class Deferral:
    """Ctrl-C, SIGTERM and SIGHUP held from :meth:`hold` until the ``with`` block ends, then
    raised as a ``KeyboardInterrupt``: for steps that must not be cut in half (opening a run's
    outputs, writing a study's folder and putting it in place). Only the signals that interrupt
    already (a handler in Python) are held; one left to its default (a library user's process)
    keeps it."""

    def __init__(self, *, raise_after: bool = True) -> None:
        self.raise_after = raise_after  # False: the caller reads ``caught``
        self.caught: list[int] = []
        self.before: dict[signal.Signals, object] = {}

    def hold(self) -> None:
        if self.before or not _main_thread():
            return
        self.before = {sig: signal.getsignal(sig) for sig in _signals(("SIGINT", *TERMINATION))
                       if callable(signal.getsignal(sig))}
        for sig in self.before:
            signal.signal(sig, lambda signum, frame: self.caught.append(signum))

    def __enter__(self) -> Deferral:
        return self

    def __exit__(self, *exc: object) -> None:
        for sig, handler in self.before.items():
            signal.signal(sig, handler)  # type: ignore[arg-type]
        self.before = {}
        if self.caught and exc[0] is None and self.raise_after:
            raise KeyboardInterrupt(signal.Signals(self.caught[0]).name)


@contextlib.contextmanager
def deferred_interrupts() -> Iterator[None]:
    """Hold Ctrl-C, SIGTERM and SIGHUP until the block ends, then interrupt."""
    with Deferral() as deferral:
        deferral.hold()
        yield
