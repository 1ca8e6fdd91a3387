"""Silence what a C library prints on the process's stdout (PyBullet's banner, URDF warnings)."""

from __future__ import annotations

import contextlib
import ctypes
import os
import sys
from collections.abc import Iterator

_LIBC = ctypes.CDLL(None)


@contextlib.contextmanager
def quiet_c_output() -> Iterator[None]:
    """Point file descriptor 1 at /dev/null meanwhile; C's buffer is flushed before and after."""
    try:
        sys.stdout.flush()
        saved = os.dup(1)
    except (OSError, ValueError):  # no stdout to silence
        yield
        return
    with open(os.devnull, "w") as devnull:
        _LIBC.fflush(None)
        os.dup2(devnull.fileno(), 1)
        try:
            yield
        finally:
            _LIBC.fflush(None)
            os.dup2(saved, 1)
            os.close(saved)
