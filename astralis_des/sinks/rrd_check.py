"""Is a Rerun recording whole? Rerun's file sink writes on a thread of its own and, when a
write fails (a full disk), logs an error and goes on, so a recording is read back with
``rerun rrd verify`` once it is flushed: a short one is an ``OSError``, like any other
failed write."""

from __future__ import annotations

import errno
import logging
import os
import subprocess
from pathlib import Path
from typing import Any

log = logging.getLogger(__name__)
VERIFY_TIMEOUT = 600.0  # s: reading back a recording of several GB


def rerun_binary() -> Path | None:
    """The ``rerun`` program the SDK ships (the ``rerun_cli`` package), if installed."""
    try:
        import rerun_cli
    except ImportError:
        return None
    found = Path(rerun_cli.__file__).with_name("rerun")
    return found if found.is_file() else None


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
    binary = rerun_binary()
    if binary is None:  # cannot read it back: a full disk is the likely cause of a bad one
        _full_disk(path)
        if suspect:
            raise OSError(errno.EIO, "Rerun could not write it whole", str(path))
        log.debug("no rerun program to verify %s with", path)
        return
    try:
        done = subprocess.run([str(binary), "rrd", "verify", str(path)], capture_output=True,
                              text=True, timeout=VERIFY_TIMEOUT, stdin=subprocess.DEVNULL,
                              env={**os.environ, "RUST_LOG": "off"})
    except subprocess.TimeoutExpired:
        log.warning("%s: not verified (rerun rrd verify took over %.0f s)", path,
                    VERIFY_TIMEOUT)
        return
    except OSError as exc:  # cannot start it (no memory for a process): say so, go on
        log.warning("%s: not verified (%s)", path, exc.strerror or exc)
        return
    if done.returncode != 0:
        _full_disk(path)
        lines = [line for line in done.stderr.splitlines() if line.strip()]
        reason = lines[0] if lines else f"rerun rrd verify exit {done.returncode}"
        reason = reason.split(": ", 1)[-1] if reason.startswith('"') else reason
        raise OSError(errno.EIO, f"the recording does not read back ({reason})", str(path))


def _full_disk(path: Path) -> None:
    """An ``ENOSPC`` if the file system of ``path`` has no room left."""
    try:
        stats = os.statvfs(path.parent)
    except OSError:
        return
    if stats.f_bavail == 0:
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC), str(path))
