"""Compiled kernels (numba) for processes that run many missions: off unless enabled.

Importing numba costs about half a second, more than a whole kinematic mission, so a single
``astralis run`` never does: it takes the numpy path. A process that runs many missions (a
study's worker, a benchmark's) calls :func:`enable` once at its start; from then on the
furnishing's hot loops (the spots a footprint fits, whether a footprint cuts floor off from
the door) and the sight-line test run compiled. Both paths give the same answers, bit for
bit (integer and boolean work, and the sight test's products and comparisons one by one, as
numpy does them), so event logs are the same either way. Without numba installed (the
``fast`` extra) :func:`enable` says so and everything stays on the numpy path.

The kernels are compiled with ``cache=True``: the first process to use them writes the
machine code next to this package (or in numba's cache directory), the later ones load it.
"""

from __future__ import annotations

import importlib.util
import logging
from types import ModuleType

log = logging.getLogger(__name__)

MANY = 20  # missions a process runs from which the kernels repay numba's import (~0.5 s)

_kernels: ModuleType | None = None


def enable() -> bool:
    """Use the compiled kernels in this process from now on; False (the numpy path stays)
    where numba is not installed, or cannot keep its machine code anywhere (a read-only
    install and home: numba refuses to compile with ``cache=True`` there)."""
    global _kernels
    if _kernels is None:
        try:
            from astralis_des.compiled import loops
        except ImportError as missing:  # numba is an optional extra: the numpy path
            log.info("compiled kernels not enabled (%s): the numpy path", missing)
            return False
        except (RuntimeError, OSError) as unusable:  # no folder numba may cache into
            log.warning("compiled kernels not enabled (%s): the numpy path (set "
                        "NUMBA_CACHE_DIR to a writable folder to use them)", unusable)
            return False
        _kernels = loops
    return True


def available() -> bool:
    """Whether numba is installed (without importing it)."""
    return importlib.util.find_spec("numba") is not None


def disable() -> None:
    """Back to the numpy path (the compiled kernels stay imported)."""
    global _kernels
    _kernels = None


def kernels() -> ModuleType | None:
    """The compiled kernels' module when enabled in this process, else None (numpy)."""
    return _kernels
