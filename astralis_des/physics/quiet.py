"""Silence what a C library prints on the process's stdout (PyBullet's banner, URDF warnings)
or stderr (Ray's core retrying a connection)."""

from __future__ import annotations

import contextlib
import ctypes
import os
import sys
from collections.abc import Iterator

_LIBC = ctypes.CDLL(None)


@contextlib.contextmanager
def quiet_c_output(fd: int = 1) -> Iterator[None]:
    """Point file descriptor ``fd`` (1: stdout, 2: stderr) at /dev/null meanwhile; C's
    buffers are flushed before and after."""
    try:
        (sys.stdout if fd == 1 else sys.stderr).flush()
        saved = os.dup(fd)
    except (OSError, ValueError):  # nothing to silence
        yield
        return
    with open(os.devnull, "w") as devnull:
        _LIBC.fflush(None)
        os.dup2(devnull.fileno(), fd)
        try:
            yield
        finally:
            _LIBC.fflush(None)
            os.dup2(saved, fd)
            os.close(saved)
