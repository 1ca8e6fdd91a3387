"""Plug-ins: modules that register actions, strategies, sensors, fidelities and event kinds,
imported before a mission is read so that its names resolve, without an edit to the package.

Two ways in:

- **the mission names them**: ``plugins: [my_robots.py, mypkg.strategies]``, a ``.py`` file
  (relative to the mission file) or a module on ``sys.path``;
- **an installed package declares them**: an entry point in the group
  ``astralis_des.plugins`` (``[project.entry-points."astralis_des.plugins"]`` in its
  ``pyproject.toml``), loaded once per process, before the first mission is read.

A plug-in is code: a mission that names one runs it, as a Python script would. One that cannot
be imported, or fails as it is, is one line naming the file, line and key (exit 2).
"""

from __future__ import annotations

import hashlib
import importlib
import importlib.util
import re
import sys
from importlib.metadata import entry_points
from pathlib import Path
from types import ModuleType

from astralis_des.errors import InputError
from astralis_des.yamlio import LocatedYaml

GROUP = "astralis_des.plugins"
_entry_points_loaded = False


def load_entry_points() -> None:
    """Import the plug-ins installed packages declare (once per process)."""
    global _entry_points_loaded
    if _entry_points_loaded:
        return
    _entry_points_loaded = True
    for point in sorted(entry_points(group=GROUP), key=lambda p: p.name):
        try:
            point.load()
        except Exception as exc:  # a broken package: say which, in one line
            package = point.dist.name if point.dist is not None else "?"
            raise InputError(f"the plug-in '{point.name}' of the installed package {package} "
                             f"({point.value}) failed as it was imported: {_said(exc)}") \
                from None


def load_named(doc: LocatedYaml) -> None:
    """Import the plug-ins a mission file names (``plugins:``), in order. A key of the wrong
    shape is left to the schema to refuse."""
    names = doc.data.get("plugins") if isinstance(doc.data, dict) else None
    if not isinstance(names, list):
        return
    for index, name in enumerate(names):
        if not isinstance(name, str) or not name:
            continue
        where = ("plugins", index)
        try:
            if name.endswith(".py"):
                _import_file(doc.file_at(where, name, "plug-in file"))
            else:
                importlib.import_module(name)
        except InputError:
            raise
        except ModuleNotFoundError as exc:
            missing = f" (no module '{exc.name}')" if exc.name and exc.name != name else ""
            raise doc.error(where, f"cannot import the plug-in '{name}'{missing}: not on "
                            "the path; name a .py file relative to the mission, or install "
                            "its package") from None
        except Exception as exc:
            raise doc.error(where, f"the plug-in '{name}' failed as it was imported: "
                            f"{_said(exc)}") from None


def _import_file(path: Path) -> ModuleType:
    """Import the file at ``path`` as a module of its own (once per process and file)."""
    digest = hashlib.sha1(str(path).encode(), usedforsecurity=False).hexdigest()[:8]
    name = f"_astralis_plugin_{re.sub(r'[^0-9A-Za-z_]', '_', path.stem)}_{digest}"
    if name in sys.modules:
        return sys.modules[name]
    spec = importlib.util.spec_from_file_location(name, path)
    if spec is None or spec.loader is None:
        raise ImportError(f"{path} cannot be imported")
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    try:
        spec.loader.exec_module(module)
    except BaseException:
        del sys.modules[name]
        raise
    return module


def _said(exc: BaseException) -> str:
    """An exception as one line: its type and message (a syntax error's line too)."""
    if isinstance(exc, SyntaxError):
        return f"SyntaxError: {exc.msg} ({Path(exc.filename or '?').name}, line {exc.lineno})"
    text = " ".join(str(exc).split())
    return f"{type(exc).__name__}: {text}" if text else type(exc).__name__
