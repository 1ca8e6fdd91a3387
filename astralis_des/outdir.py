"""Outputs written as a unit: a lock against a second writer, a staging folder beside the
target, renamed into place when the writer is done, and every failed write one clear error.

For a target ``out/run`` (a folder) or ``worlds/twin.yaml`` (a file and its sidecars)::

    out/.run.lock      the writer's pid and command line; a dead writer's is taken over
    out/.run.partial/  what the writer is writing: all a killed writer leaves behind
    out/run/           put in place at the end: renamed whole if new, else the files this
                       writer owns replaced in it (the ``last`` one, the key file, last)

A folder that holds the key file (a run's ``summary.json``, a study's ``meta.json``, the world
file) is a whole result: the old key file goes first and the new one comes last. The lock
and the errors a failed write becomes are :mod:`astralis_des.outlock`'s.
"""

from __future__ import annotations

import logging
import os
import shutil
import threading
from collections.abc import Collection
from pathlib import Path

from astralis_des.exits import Deferral
from astralis_des.outlock import (  # noqa: F401 (theirs, re-exported)
    MACHINE_ERRNOS,
    Lock,
    OutputError,
    acquire,
    checked,
    holding,
    lock_path,
    release,
    staging_path,
    target_names,
    took_over,
    usable,
    write_failure,
)
from astralis_des.strict_json import (  # noqa: F401 (theirs, re-exported)
    dumps,
    finite,
    journal_dumps,
    journal_loads,
)

log = logging.getLogger(__name__)


def write_file(path: Path, text: str, *, sync: bool = True) -> None:
    """Write ``text`` to ``path`` whole: to disk (``fsync``), so that a full disk or an I/O
    error is an ``OSError`` here and not a short file later (``sync=False``: a staged file,
    which :meth:`Staging.settle` puts on disk)."""
    with path.open("w", encoding="utf-8") as f:
        f.write(text)
        if sync:
            f.flush()
            os.fsync(f.fileno())


def sync(path: Path) -> None:
    """To disk (``fsync``): what a write left in the cache fails here, if it is to fail."""
    fd = os.open(path, os.O_RDONLY)
    try:
        os.fsync(fd)
    finally:
        os.close(fd)


class _Sync(threading.Thread):
    """:func:`sync` of one file on a thread of its own (``fsync`` lets go of the GIL): the
    disk's wait overlaps the writer's work; :meth:`wait` raises its ``OSError``, if any. A
    plain thread, not a pool's: a process forked meanwhile inherits no idle pool."""

    def __init__(self, path: Path) -> None:
        super().__init__(name=f"sync {path.name}", daemon=True)
        self.path = path
        self.error: OSError | None = None
        self.start()

    def run(self) -> None:
        try:
            sync(self.path)
        except OSError as exc:
            self.error = exc

    def wait(self) -> None:
        self.join()
        if self.error is not None:
            raise self.error


# -- what a result is made of ----------------------------------------------------------------
RESULT_FILES: set[str] = set()  # the names any command writes into its output folder
RESULT_KEYS: set[str] = set()  # the file that makes a folder a whole result, of any command


def result_files(*names: str, key: str) -> tuple[str, ...]:
    """Register the names a command writes into its output folder, ``key`` among them, and
    return them. A writer whose target holds a registered key file (it is an earlier result
    of any command) replaces every registered name there, so a run's files never stay beside
    a study's; in any other folder only its own names, and other files stay."""
    RESULT_FILES.update(names)
    RESULT_KEYS.add(key)
    return names


# -- staging ---------------------------------------------------------------------------------
class Staging:
    """A target written as a unit. ``with Staging(target, ...) as folder``: write into
    ``folder``; at the end it is put in place (also on Ctrl-C, with ``keep_interrupted``),
    or removed on an error. An ``OSError`` inside is raised as :func:`write_failure`.

    ``owned``: the names this writer puts in a target folder; those of an earlier result
    not written again are removed (all :data:`RESULT_FILES` where the folder holds one of
    :data:`RESULT_KEYS`), other files stay. ``last``: the key file, put in place last.
    ``file``: the target is a file (``worlds/twin.yaml``) whose staged files all go beside it,
    itself last. ``reuse``: keep what a dead writer staged (a tune resumes its journal).
    """

    def __init__(self, target: str | Path, *, owned: Collection[str] = (),
                 last: str | None = None, file: bool = False, keep_interrupted: bool = False,
                 reuse: bool = False) -> None:
        self.target = Path(target)
        self.full, name = target_names(self.target)
        self.owned = set(owned)
        self.file = file
        self.last = self.full.name if file else last
        self.keep_interrupted = keep_interrupted
        self.reuse = reuse
        self.folder = self.full.parent / f".{name}.partial"
        self._lock: Lock | None = None
        self._syncing: dict[Path, _Sync] = {}  # staged files already being put on disk

    def open(self) -> Path:
        """Lock the target and make the staging folder; return it."""
        usable(self.target, file=self.file)
        self._lock, before = acquire(self.target)
        try:
            reused = self.reuse and self.folder.is_dir()
            if before is not None:
                took_over(self.target, before, reused=reused)
            with checked(self.target):
                if os.path.lexists(self.folder) and not reused:
                    _remove(self.folder)  # a dead writer's (we hold the lock)
                self.folder.mkdir(exist_ok=self.reuse)
        except BaseException:
            self._unlock()
            raise
        return self.folder

    def commit(self) -> list[Path]:
        """Put the staged files in place (signals held meanwhile); the paths placed."""
        with Deferral() as shield, checked(self.target):
            shield.hold()
            try:
                try:  # what the cache holds fails here, before anything moves
                    _sync_tree(self.folder, self._syncing)
                except BaseException:
                    if not self.reuse:  # nothing moved, nothing is left (a tune's journal
                        _remove(self.folder)  # stays, to resume from)
                    raise
                finally:
                    self._syncing = {}
                return self._place()
            finally:
                self._unlock()

    def settle(self, path: Path) -> None:
        """The staged file ``path`` is whole: start putting it on disk now, on a thread, while
        the writer goes on with the others. The commit waits for it (and fails, before
        anything moves, if it could not be written), as it syncs every other staged file."""
        if path not in self._syncing:
            self._syncing[path] = _Sync(path)

    def abandon(self) -> None:
        """Remove what was staged: nothing half-written is left (once: the lock is let go)."""
        if self._lock is None:
            return
        try:
            _remove(self.folder)
        finally:
            self._unlock()

    def __enter__(self) -> Path:
        return self.open()

    def __exit__(self, kind: type[BaseException] | None, exc: BaseException | None,
                 tb: object) -> None:
        if kind is None or (self.keep_interrupted and kind is KeyboardInterrupt):
            self.commit()
            return
        self.abandon()
        if isinstance(exc, OSError):
            raise write_failure(self.target, exc) from exc

    def _unlock(self) -> None:
        if self._lock is not None:
            lock, self._lock = self._lock, None
            release(lock)

    def _place(self) -> list[Path]:
        place = self.full.parent if self.file else self.full
        if not self.file and not os.path.lexists(self.full):
            os.rename(self.folder, self.full)  # new: in place at once, whole
            return [self.full / n for n in sorted(os.listdir(self.full))]
        names = sorted(os.listdir(self.folder), key=lambda n: (n == self.last, n))
        trash = self.full.parent / f".{self.full.name}.old"
        _remove(trash)
        trash.mkdir()
        old = [self.last] if self.last is not None else []
        # a folder that is an earlier result loses its other files; a file written into one
        # (astralis diff -o RUN/diff.rrd) replaces itself and its sidecars, nothing more
        result = not self.file and any(os.path.lexists(place / key) for key in RESULT_KEYS)
        old += sorted(self.owned | RESULT_FILES if result else self.owned) + names
        for name in dict.fromkeys(old):  # the old key file first
            if os.path.lexists(place / name):
                os.rename(place / name, trash / name)
        placed = []
        for name in names:
            os.rename(self.folder / name, place / name)
            placed.append(place / name)
        os.rmdir(self.folder)
        _remove(trash)
        return placed


def _sync_tree(folder: Path, syncing: dict[Path, _Sync]) -> None:
    """Every file under ``folder`` on disk: those ``syncing`` already once their threads are
    done, the others here (the first error is raised once all are done)."""
    failed: OSError | None = None
    try:
        for root, _, files in os.walk(folder):
            for name in files:
                if Path(root) / name not in syncing:
                    sync(Path(root) / name)
    except OSError as exc:
        failed = exc
    for thread in syncing.values():  # each done before the folder may be removed
        try:
            thread.wait()
        except OSError as exc:
            failed = failed or exc
    if failed is not None:
        raise failed


def _remove(path: Path) -> None:
    if path.is_dir() and not path.is_symlink():
        shutil.rmtree(path, ignore_errors=True)
    elif os.path.lexists(path):
        path.unlink(missing_ok=True)
