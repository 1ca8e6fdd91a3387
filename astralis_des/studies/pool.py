"""Worker processes for a study that notice a worker's death.

Each worker is forked holding the study and runs the scenarios it is sent, one at a time,
sending back each scenario's rows. The parent waits on the workers' pipes and on their process
sentinels together, so a worker that dies (the OOM killer's SIGKILL, a crash in native code)
is seen at once: the scenario it was running is run once more in a fresh worker, and if that
one dies too, the scenario's rows are failed with the reason ("worker killed by signal 9") and
the study goes on. (``multiprocessing.Pool`` waits for a dead worker's task for ever.)

Workers ignore Ctrl-C and end on SIGTERM: the parent, interrupted, ends them and returns what
came back. A worker also ends when its parent is gone, however it went (SIGKILL, ``os._exit``):
on Linux the kernel sends it SIGTERM (``PR_SET_PDEATHSIG``), and anywhere it holds only its own
end of its pipe, so it reads the end of the file there.
"""

from __future__ import annotations

import contextlib
import ctypes
import logging
import multiprocessing
import os
import signal
import sys
import weakref
from collections import deque
from collections.abc import Generator, Sequence
from multiprocessing.connection import Connection, wait
from pathlib import Path
from typing import TYPE_CHECKING, Any

from astralis_des import compiled
from astralis_des.exits import default_termination, deferred_interrupts
from astralis_des.studies.scenarios import ChunkResult, failed_scenario, run_chunk

if TYPE_CHECKING:
    from multiprocessing.process import BaseProcess

    from astralis_des.studies.spec import Study

log = logging.getLogger(__name__)

RETRIES = 1  # a scenario whose worker died is run once more
# Held while a worker is forked: one arriving then would run Python's handler inside the
# fork's callbacks (logging's lock release), where the KeyboardInterrupt is ignored and lost.
SIGNALS = {signal.SIGINT, signal.SIGTERM, signal.SIGHUP}
STOP_WAIT = 5.0  # s a worker has to end after it is told to, before it is killed
Job = tuple["dict[str, Any] | None", int, "Path | None"]  # (changes, scenario, recordings)
PR_SET_PDEATHSIG = 1  # prctl(2): a signal for this process when its parent ends
_PARENT_ENDS: weakref.WeakSet[Connection] = weakref.WeakSet()  # the parent's ends of pipes


def _orphan_proof(parent: int) -> None:
    """In a worker: end with its parent. SIGTERM when the parent goes (Linux), and none of
    the parent's pipe ends held open here, so a read sees the end of the file anywhere."""
    for end in list(_PARENT_ENDS):  # its own pipe's and the earlier workers' (inherited)
        with contextlib.suppress(OSError):
            end.close()
    if sys.platform.startswith("linux"):
        with contextlib.suppress(OSError, AttributeError):
            ctypes.CDLL(None, use_errno=True).prctl(PR_SET_PDEATHSIG, signal.SIGTERM)
    if os.getppid() != parent:  # it went before the kernel was asked to tell
        os._exit(0)


def _serve(conn: Connection, base: Study, parent: int, fast: bool) -> None:
    """A worker: scenarios of ``base`` (or of ``base.with_changes(**changes)``, made once per
    changes) until told to stop, or until its parent is gone; ``fast``: with the compiled
    kernels (many scenarios to run)."""
    default_termination()  # SIGTERM ends a worker
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # Ctrl-C is the parent's to handle
    _orphan_proof(parent)
    signal.pthread_sigmask(signal.SIG_UNBLOCK, SIGNALS)
    if fast:
        compiled.enable()
    made: tuple[dict[str, Any], Study] | None = None
    while True:
        try:
            job: Job | None = conn.recv()
        except (EOFError, OSError):  # the parent is gone
            return
        if job is None:
            return
        changes, index, recordings = job
        study = base
        if changes is not None:
            if made is None or made[0] != changes:
                made = (changes, base.with_changes(**changes))
            study = made[1]
        result = run_chunk(study, [index], recordings)
        try:
            conn.send(result)
        except OSError:  # the parent is gone (a broken pipe)
            return


class _Worker:
    def __init__(self, base: Study, fast: bool) -> None:
        self.conn, child = multiprocessing.Pipe()
        _PARENT_ENDS.add(self.conn)
        self.process: BaseProcess = multiprocessing.get_context("fork").Process(
            target=_serve, args=(child, base, os.getpid(), fast), daemon=True)
        held = signal.pthread_sigmask(signal.SIG_BLOCK, SIGNALS)
        try:
            self.process.start()
        finally:
            signal.pthread_sigmask(signal.SIG_SETMASK, held)  # a signal held meanwhile lands
        child.close()
        self.index: int | None = None  # the scenario it runs

    def send(self, job: Job) -> None:
        self.index = job[1]
        self.conn.send(job)


class WorkerPool:
    """Up to ``workers`` processes holding ``base``, started as needed and kept until
    :meth:`close` (a tune's trials reuse them); ``fast``: their missions on the compiled
    kernels (:mod:`astralis_des.compiled`), for pools that run many."""

    def __init__(self, base: Study, workers: int, fast: bool = True) -> None:
        self.base = base
        self.workers = max(1, workers)
        self.fast = fast
        self._idle: list[_Worker] = []

    def run(self, study: Study, changes: dict[str, Any] | None, indices: Sequence[int],
            recordings: Path | None) -> Generator[ChunkResult, None, None]:
        """Each scenario's rows as it ends, in no fixed order; ``study`` is ``base`` with
        ``changes`` (to write a failed row)."""
        todo = deque(indices)
        tries = dict.fromkeys(indices, 0)
        busy: dict[Any, _Worker] = {}
        try:
            while todo or busy:
                while todo and len(busy) < self.workers:
                    with deferred_interrupts():  # an interrupt (a signal, or one the import
                        # guard of exits.py raises again) lands once the worker is known, to
                        # be ended below: never between its fork and ``busy``
                        worker = self._idle.pop() if self._idle else _Worker(self.base, self.fast)
                        busy[worker.conn] = worker
                    worker.send((changes, todo.popleft(), recordings))
                ready = wait([*busy, *(w.process.sentinel for w in busy.values())])
                for worker in {w for w in busy.values()
                               if w.conn in ready or w.process.sentinel in ready}:
                    result = self._receive(worker)
                    del busy[worker.conn]
                    if result is not None:
                        self._idle.append(worker)
                        yield result
                        continue
                    lost = worker.index
                    assert lost is not None
                    reason = _death(worker.process)
                    tries[lost] += 1
                    if tries[lost] <= RETRIES:
                        log.warning("scenario %d: %s; running it again in a fresh worker",
                                    lost, reason)
                        todo.appendleft(lost)
                    else:
                        yield failed_scenario(study, lost, f"{reason} (twice)")
        finally:
            for worker in busy.values():  # interrupted: what they run is not waited for
                _end(worker)

    @staticmethod
    def _receive(worker: _Worker) -> ChunkResult | None:
        """The worker's result, or None when it died."""
        try:
            if worker.conn.poll():
                result: ChunkResult = worker.conn.recv()
                return result
        except (EOFError, OSError):
            pass
        worker.process.join(timeout=STOP_WAIT)
        worker.conn.close()
        return None

    def close(self) -> None:
        for worker in self._idle:
            with contextlib.suppress(OSError):  # a worker that died since
                worker.conn.send(None)
        for worker in self._idle:
            worker.process.join(timeout=STOP_WAIT)
            _end(worker)
        self._idle = []


def _death(process: BaseProcess) -> str:
    code = process.exitcode
    if code is not None and code < 0:
        try:
            return f"worker killed by signal {-code} ({signal.Signals(-code).name})"
        except ValueError:
            return f"worker killed by signal {-code}"
    return f"worker exited with code {code}"


def _end(worker: _Worker) -> None:
    if worker.process.is_alive():
        worker.process.terminate()
        worker.process.join(timeout=STOP_WAIT)
        if worker.process.is_alive():
            worker.process.kill()
            worker.process.join()
    worker.conn.close()
