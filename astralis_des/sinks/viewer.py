"""``astralis replay``: check that a file is a Rerun recording, then open the viewer on it."""

from __future__ import annotations

import shutil
import subprocess
import sys
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


def open_viewer(path: Path, web: bool = False) -> int:
    check_recording(path)
    return subprocess.call(viewer_command(path, web))
