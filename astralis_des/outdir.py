"""Outputs written as a unit: a lock against a second writer, a staging folder beside the
target, renamed into place when the writer is done, and every failed write one clear error.

For a target ``out/run`` (a folder) or ``worlds/twin.yaml`` (a file and its sidecars)::

    out/.run.lock      the writer's pid and command line; a dead writer's is taken over
    out/.run.partial/  what the writer is writing: all a killed writer leaves behind
    out/run/           put in place at the end: renamed whole if new, else the files this
                       writer owns replaced in it (the ``last`` one, the key file, last)

A folder that holds the key file (a run's ``summary.json``, a study's ``meta.json``, the world
file) is a whole result: the old key file goes first and the new one comes last.
"""

from __future__ import annotations

import errno
import fcntl
import logging
import os
import shutil
import stat
import sys
import threading
import time
from collections.abc import Collection, Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

from astralis_des.errors import InputError
from astralis_des.exits import Deferral
from astralis_des.strict_json import (  # noqa: F401 (theirs, re-exported)
    dumps,
    finite,
    journal_dumps,
    journal_loads,
)

log = logging.getLogger(__name__)

# what a machine does wrong (exit EXIT_OUTPUT); any other errno is a path that cannot be used
# (a read-only file system, a path under a file, /proc, no permission: exit 2, bad input)
MACHINE_ERRNOS = frozenset({errno.ENOSPC, errno.EDQUOT, errno.EIO, errno.EFBIG, errno.ENOMEM,
                            errno.ESTALE, errno.EREMOTEIO})


class OutputError(Exception):
    """The machine could not write the outputs (a full disk, an I/O error): nothing was put
    in place. ``str(error)`` is one line."""

    def __init__(self, path: str | Path, reason: str) -> None:
        super().__init__(str(path), reason)  # as SimPy re-raises it: type(e)(*e.args)
        self.path = str(path)
        self.reason = reason

    def __str__(self) -> str:
        return f"{self.path}: cannot be written ({self.reason}); nothing was put in place"


def write_failure(path: str | Path, exc: OSError) -> Exception:
    """An ``OSError`` from writing ``path`` as the error a person reads: a machine error
    (:class:`OutputError`), or a path that cannot be used (:class:`InputError`)."""
    # a machine error in the system's words for its errno (pyarrow's strerror reads "error
    # writing bytes to file. Detail: [errno 28] No space left on device")
    reason = (os.strerror(exc.errno) if exc.errno in MACHINE_ERRNOS else
              exc.strerror or str(exc))
    reason = reason[:1].lower() + reason[1:]
    if exc.errno in MACHINE_ERRNOS:
        return OutputError(path, reason)
    blocker = _file_above(Path(path))
    if blocker is not None:
        reason = f"{blocker} is a file, not a folder"
    return InputError(f"cannot write there: {reason}", file=path)


def _file_above(path: Path) -> Path | None:
    """The first existing folder above ``path``, if it is a file instead."""
    for above in Path(os.path.abspath(path)).parents:
        if os.path.lexists(above):
            return above if not above.is_dir() else None
    return None


def usable(target: str | Path, *, file: bool = False) -> None:
    """Refuse, before any work, a target that is there as the wrong thing (a file where a
    folder goes, or the other way), or that cannot be looked at (a name too long)."""
    try:
        mode = os.stat(target).st_mode
    except FileNotFoundError:
        return
    except OSError as exc:
        raise write_failure(target, exc) from exc
    if file and stat.S_ISDIR(mode):
        raise InputError("is a folder: give a file name", file=target)
    if not file and not stat.S_ISDIR(mode):
        raise InputError("exists and is not a folder", file=target)


@contextmanager
def checked(path: str | Path) -> Iterator[None]:
    """An ``OSError`` in the block becomes :func:`write_failure` of ``path``."""
    try:
        yield
    except OSError as exc:
        raise write_failure(path, exc) from exc


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


# -- the lock --------------------------------------------------------------------------------
@dataclass
class _Lock:
    path: Path
    fd: int
    count: int = 1
    made: Path | None = None  # the first folder made to hold it: removed with it if empty


_HELD: dict[Path, _Lock] = {}  # this process's locks (a writer may re-enter its own)


def _names(target: Path) -> tuple[Path, str]:
    """The target as a real path (one lock whatever the path it is named by), and the name
    its lock and staging folder take."""
    full = Path(os.path.realpath(target))
    if not full.name:
        raise InputError("cannot be an output folder: give one below it", file=target)
    return full, full.name


def lock_path(target: str | Path) -> Path:
    full, name = _names(Path(target))
    return full.parent / f".{name}.lock"


def staging_path(target: str | Path) -> Path:
    """Where a writer of ``target`` stages its outputs (a run's event log grows there)."""
    full, name = _names(Path(target))
    return full.parent / f".{name}.partial"


def _acquire(target: Path) -> tuple[_Lock, str | None]:
    """Lock ``target`` for this process; the previous holder's line if it died holding it."""
    path = lock_path(target)
    held = _HELD.get(path)
    if held is not None:
        held.count += 1
        return held, None
    made = _first_missing(path.parent)
    with checked(target):
        path.parent.mkdir(parents=True, exist_ok=True)
    while True:
        with checked(target):
            fd = os.open(path, os.O_RDWR | os.O_CREAT, 0o644)
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            holder = _holder(fd)
            os.close(fd)
            _unmake(path.parent, made)
            pid, _, command = holder.partition(" ")
            raise InputError(f"being written by pid {pid or '?'}"
                             + (f" ({command})" if command else "")
                             + ": wait for it to end, or write elsewhere", file=target) \
                from None
        except BaseException:
            os.close(fd)
            raise
        try:  # the file at the path still (a holder unlinks it as it lets go)
            if os.stat(path).st_ino == os.fstat(fd).st_ino:
                break
        except FileNotFoundError:
            pass
        os.close(fd)
    try:
        before = os.pread(fd, 4096, 0).decode("utf-8", "replace").strip() or None
        line = f"{os.getpid()} {' '.join(['astralis', *sys.argv[1:]])[:300]}\n".encode()
        os.ftruncate(fd, 0)
        os.pwrite(fd, line, 0)
    except OSError as exc:
        os.close(fd)
        raise write_failure(target, exc) from exc
    lock = _HELD[path] = _Lock(path, fd, made=made)
    return lock, before


def _first_missing(folder: Path) -> Path | None:
    """The outermost folder of ``folder`` and its parents that does not exist yet."""
    missing = None
    for above in (folder, *folder.parents):
        if os.path.lexists(above):
            return missing
        missing = above
    return missing


def _unmake(folder: Path, made: Path | None) -> None:
    """Remove ``folder`` and its parents up to ``made`` where they are empty: a command
    refused (bad input, a machine error) leaves no folder it made."""
    if made is None:
        return
    for above in (folder, *folder.parents):
        try:
            os.rmdir(above)
        except OSError:  # not empty (a result is in it), or gone
            return
        if above == made:
            return


def _holder(fd: int) -> str:
    """The line of the lock's holder (it writes it just after it takes the lock)."""
    for _ in range(100):
        line = os.pread(fd, 4096, 0).decode("utf-8", "replace").strip()
        if line:
            return line
        time.sleep(0.01)
    return ""


def _release(lock: _Lock) -> None:
    lock.count -= 1
    if lock.count:
        return
    _HELD.pop(lock.path, None)
    try:
        lock.path.unlink(missing_ok=True)
    finally:
        os.close(lock.fd)
    _unmake(lock.path.parent, lock.made)


@contextmanager
def holding(target: str | Path) -> Iterator[None]:
    """``target`` locked meanwhile (a second writer is refused in one line, naming the
    first); the writers in the block (:class:`Staging`) re-enter the lock. Checks early that
    the target's folder can be written at all."""
    lock, before = _acquire(Path(target))
    if before is not None:
        _took_over(Path(target), before)
    try:
        yield
    finally:
        _release(lock)


def _took_over(target: Path, before: str, *, reused: bool = False) -> None:
    pid = before.partition(" ")[0]
    log.warning("%s: took over from pid %s, which ended without finishing (killed?); %s",
                target, pid, "going on from what it left" if reused else
                "what it left unfinished is discarded")


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
        self.full, name = _names(self.target)
        self.owned = set(owned)
        self.file = file
        self.last = self.full.name if file else last
        self.keep_interrupted = keep_interrupted
        self.reuse = reuse
        self.folder = self.full.parent / f".{name}.partial"
        self._lock: _Lock | None = None
        self._syncing: dict[Path, _Sync] = {}  # staged files already being put on disk

    def open(self) -> Path:
        """Lock the target and make the staging folder; return it."""
        usable(self.target, file=self.file)
        self._lock, before = _acquire(self.target)
        try:
            reused = self.reuse and self.folder.is_dir()
            if before is not None:
                _took_over(self.target, before, reused=reused)
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
            _release(lock)

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
