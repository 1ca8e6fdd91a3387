"""Exit codes the command line and its front ends (studies, the API, the chat) share, and
how they are interrupted."""

from __future__ import annotations

import _thread
import contextlib
import signal
import sys
import threading
from collections.abc import Iterator
from types import FrameType
from typing import Any

EXIT_BAD_INPUT = 2  # a mission, world or study file (or an argument) is wrong: one-line error;
# also an output folder that cannot be written (a read-only file system, a path under a
# file, /proc) or that another command is writing (the line names its pid)
EXIT_OUTPUT = 74  # the machine could not write the outputs (a full disk, an I/O error): one
# line, and nothing put in place (74 is EX_IOERR of BSD's sysexits.h)
EXIT_INTERRUPTED = 130  # Ctrl-C, SIGTERM or SIGHUP: what was recorded is kept (128 + SIGINT)


TERMINATION = ("SIGTERM", "SIGHUP")  # what ends a command as Ctrl-C does


def _signals(names: tuple[str, ...]) -> list[signal.Signals]:
    """The named signals this platform has."""
    return [getattr(signal, n) for n in names if hasattr(signal, n)]


def _main_thread() -> bool:
    """Only the main thread may set handlers (and it is the one that gets the signals)."""
    return threading.current_thread() is threading.main_thread()


RECEIVED: list[int] = []  # the signals that interrupted this process, in order


IMPORT_RETRY = 0.005  # s between tries to raise an interrupt that came during an import


def _interrupt(signum: int, frame: FrameType | None) -> None:
    RECEIVED.append(signum)
    if _importing(frame):  # raised in an import, C code can clear it, or turn it into an
        timer = threading.Timer(IMPORT_RETRY, _thread.interrupt_main,  # ImportError of a
                                (signal.Signals(signum),))            # module half made:
        timer.daemon = True                                           # raised again after
        timer.start()
        return
    raise KeyboardInterrupt(signal.Signals(signum).name)


def _importing(frame: FrameType | None) -> bool:
    while frame is not None:
        if frame.f_code.co_filename.startswith("<frozen importlib._bootstrap"):
            return True
        frame = frame.f_back
    return False


def interrupt_on_termination(*, ctrl_c: bool = False) -> None:
    """SIGTERM and SIGHUP end a command as Ctrl-C does (a ``KeyboardInterrupt`` in the main
    thread): ``docker stop``, systemd, Kubernetes, Ray's cancellation and CI time-outs send
    SIGTERM, a closed terminal SIGHUP, and a run keeps what it recorded either way. Each is
    noted in ``RECEIVED``, and with ``ctrl_c`` Ctrl-C too (unless the process ignores it, as
    a background job of a shell does): an interrupt that a library turned into another
    error (a C extension's import fails with ``ImportError``) is still known for one."""
    if not _main_thread():
        return
    for sig in _signals(TERMINATION):
        signal.signal(sig, _interrupt)
    if ctrl_c and signal.getsignal(signal.SIGINT) is signal.default_int_handler:
        signal.signal(signal.SIGINT, _interrupt)


@contextlib.contextmanager
def interrupts_never_lost() -> Iterator[None]:
    """An interrupt that lands in a callback Python cannot raise from (a weak reference's,
    as an import lets go of its lock) is "ignored" there: meanwhile it is raised again at the
    next chance instead, and nothing is printed of it."""
    before = sys.unraisablehook

    def again(unraisable: Any) -> None:
        if issubclass(unraisable.exc_type, KeyboardInterrupt) and RECEIVED:
            _thread.interrupt_main(signal.Signals(RECEIVED[-1]))
            return
        before(unraisable)

    sys.unraisablehook = again
    try:
        yield
    finally:
        sys.unraisablehook = before


def default_termination() -> None:
    """Back to the default: for worker processes (a pool terminates them with SIGTERM)."""
    for sig in _signals(TERMINATION):
        signal.signal(sig, signal.SIG_DFL)


class Deferral:
    """Ctrl-C, SIGTERM and SIGHUP held from :meth:`hold` until the ``with`` block ends, then
    given to the handler that was there before (which raises ``KeyboardInterrupt``, or holds
    it in turn if it is an outer Deferral's): for steps that must not be cut in half (opening
    a run's outputs, writing a study's folder and putting it in place). Only the signals that
    interrupt already (a handler in Python) are held; one left to its default (a library
    user's process) keeps it."""

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
        held, self.before = self.before, {}
        if self.caught and exc[0] is None and self.raise_after:
            if signal.Signals(self.caught[0]) in held:  # to the handler there was: it raises
                signal.raise_signal(self.caught[0])   # KeyboardInterrupt, or an outer
                return                                 # Deferral holds it in turn
            raise KeyboardInterrupt(signal.Signals(self.caught[0]).name)


@contextlib.contextmanager
def deferred_interrupts() -> Iterator[None]:
    """Hold Ctrl-C, SIGTERM and SIGHUP until the block ends, then interrupt."""
    with Deferral() as deferral:
        deferral.hold()
        yield
