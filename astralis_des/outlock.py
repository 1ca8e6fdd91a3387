"""Who writes an output, and what a failed write says: the lock beside a target against a
second writer (a dead writer's is taken over), and every ``OSError`` of writing as one line a
person reads (:func:`write_failure`). Re-exported by :mod:`astralis_des.outdir`."""

from __future__ import annotations

import errno
import fcntl
import logging
import os
import stat
import sys
import time
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

from astralis_des.errors import InputError

log = logging.getLogger("astralis_des.outdir")

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


# -- the lock --------------------------------------------------------------------------------
@dataclass
class Lock:
    path: Path
    fd: int
    count: int = 1
    made: Path | None = None  # the first folder made to hold it: removed with it if empty


_HELD: dict[Path, Lock] = {}  # this process's locks (a writer may re-enter its own)


def target_names(target: Path) -> tuple[Path, str]:
    """The target as a real path (one lock whatever the path it is named by), and the name
    its lock and staging folder take."""
    full = Path(os.path.realpath(target))
    if not full.name:
        raise InputError("cannot be an output folder: give one below it", file=target)
    return full, full.name


def lock_path(target: str | Path) -> Path:
    full, name = target_names(Path(target))
    return full.parent / f".{name}.lock"


def staging_path(target: str | Path) -> Path:
    """Where a writer of ``target`` stages its outputs (a run's event log grows there)."""
    full, name = target_names(Path(target))
    return full.parent / f".{name}.partial"


def acquire(target: Path) -> tuple[Lock, str | None]:
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
    lock = _HELD[path] = Lock(path, fd, made=made)
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


def release(lock: Lock) -> None:
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
    lock, before = acquire(Path(target))
    if before is not None:
        took_over(Path(target), before)
    try:
        yield
    finally:
        release(lock)


def took_over(target: Path, before: str, *, reused: bool = False) -> None:
    pid = before.partition(" ")[0]
    log.warning("%s: took over from pid %s, which ended without finishing (killed?); %s",
                target, pid, "going on from what it left" if reused else
                "what it left unfinished is discarded")
