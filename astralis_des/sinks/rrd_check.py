"""Is a Rerun recording whole? Rerun's file sink writes on a thread of its own and, when a
write fails (a full disk), logs an error and goes on, so a recording is read back once it is
flushed: a short one is an ``OSError``, like any other failed write.

The read-back walks the file's framing, in this process (``rerun rrd verify`` in a
subprocess cost 25 ms a run, a quarter of a kinematic mission): the header, each message's
header (kind and length) up to the end message, whose payload is the manifest of the chunks,
and the footer that points back at that manifest. A write cut short anywhere breaks the
chain; it does not decode the chunks themselves."""

from __future__ import annotations

import errno
import logging
import os
import struct
from pathlib import Path
from typing import Any

log = logging.getLogger(__name__)

FILE_MAGIC = b"RRF2"
HEADER = 12  # magic, version (4 bytes), options (4 bytes)
MESSAGE = struct.Struct("<QQ")  # kind, payload length
END, KINDS = 0, frozenset({1, 2, 3})  # end; store info, Arrow chunk, blueprint activation
FOOTER = struct.Struct("<QQI8sI")  # manifest offset and length, checksum, magic, version
FOOTER_MAGIC = b"RRF2FOOT"


def close_and_check(rec: Any, path: Path) -> None:
    """Flush and close the recording stream ``rec`` saving to ``path``, then read the file
    back: a recording that is not whole is an ``OSError`` here."""
    suspect = False
    try:
        rec.flush()
    except RuntimeError as exc:  # its writer thread stopped: the file is checked below
        log.debug("%s: %s", path, exc)
        suspect = True
    rec.disconnect()
    check_recording(path, suspect=suspect)


def check_recording(path: Path, *, suspect: bool = False) -> None:
    """Raise an ``OSError`` if the recording at ``path`` is not whole (``suspect``: Rerun
    said a write failed)."""
    reason = broken(path)
    if reason is None and not suspect:
        return
    _full_disk(path)
    reason = reason or "Rerun could not write it whole"
    raise OSError(errno.EIO, f"the recording does not read back ({reason})", str(path))


def broken(path: Path) -> str | None:
    """Why the recording at ``path`` is not whole, or ``None`` if its framing holds."""
    with path.open("rb") as f:
        size = os.fstat(f.fileno()).st_size
        head = f.read(HEADER)
        if len(head) < HEADER or not head.startswith(FILE_MAGIC):
            return "no Rerun file header"
        at = HEADER
        while True:
            f.seek(at)
            raw = f.read(MESSAGE.size)
            if len(raw) < MESSAGE.size:
                return f"cut short at byte {at} of {size}"
            kind, length = MESSAGE.unpack(raw)
            if kind != END and kind not in KINDS:
                return f"unknown message kind {kind} at byte {at}"
            payload, at = at + MESSAGE.size, at + MESSAGE.size + length
            if at > size:
                return f"a message at byte {payload - MESSAGE.size} runs past the end ({size})"
            if kind == END:
                break
        f.seek(at)
        tail = f.read(FOOTER.size + 1)
    if len(tail) != FOOTER.size:
        return "no footer" if len(tail) < FOOTER.size else f"bytes after the footer ({size})"
    offset, length, _, magic, _ = FOOTER.unpack(tail)
    if magic != FOOTER_MAGIC or (offset, length) != (payload, at - payload):
        return "its footer does not point at its manifest"
    return None


def _full_disk(path: Path) -> None:
    """An ``ENOSPC`` if the file system of ``path`` has no room left."""
    try:
        stats = os.statvfs(path.parent)
    except OSError:
        return
    if stats.f_bavail == 0:
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC), str(path))
