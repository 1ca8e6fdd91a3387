"""``astralis replay``: check that a file is a Rerun recording, then open the viewer on it."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from collections.abc import Mapping
from pathlib import Path

from astralis_des.errors import InputError

MAGIC = b"RRF"  # every .rrd starts with it (RRF2 since rerun 0.21)


def check_recording(path: Path) -> None:
    """Refuse a missing, empty or non-Rerun file with one line naming it."""
    if not path.exists():
        raise InputError("no such recording", file=path)
    if not path.is_file():
        raise InputError("is a folder, not a recording", file=path)
    with path.open("rb") as f:
        head = f.read(4)
    if not head:
        raise InputError("the file is empty, not a Rerun recording", file=path)
    if not head.startswith(MAGIC):
        raise InputError(f"not a Rerun recording (it starts with {head!r}, a .rrd with "
                         f"{MAGIC!r})", file=path)


def viewer_command(path: Path, web: bool = False) -> list[str]:
    """The command that opens the viewer: the ``rerun`` executable of rerun-sdk."""
    exe = shutil.which("rerun") or str(Path(sys.executable).with_name("rerun"))
    return [exe, *(["--web-viewer"] if web else []), str(path)]


def no_display(environ: Mapping[str, str] = os.environ, platform: str = sys.platform) -> bool:
    """Whether the native viewer has nowhere to open: Linux without an X11 or Wayland
    display (a server, a container, ssh without -X)."""
    return platform.startswith("linux") and not (environ.get("DISPLAY")
                                                 or environ.get("WAYLAND_DISPLAY"))


def require_display(instead: str) -> None:
    """Refuse in one line, before the viewer fails in its own words, saying what to do
    ``instead``."""
    if no_display():
        raise InputError(f"no display to open the Rerun viewer on (DISPLAY and "
                         f"WAYLAND_DISPLAY are not set); {instead}")


def open_viewer(path: Path, web: bool = False) -> int:
    check_recording(path)
    if not web:
        require_display(f"use --web to serve it to a browser: astralis replay {path} --web")
    return subprocess.call(viewer_command(path, web))
