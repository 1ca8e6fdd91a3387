"""The CLI for tests: in this process (:func:`run_cli`), or as a program on a pseudo-terminal,
for the tests of ``astralis chat`` and ``astralis teleop``: type into it, wait for text on its
screen (with a deadline, so a failure cannot hang)."""

from __future__ import annotations

import contextlib
import fcntl
import io
import os
import pty
import re
import select
import struct
import subprocess
import sys
import termios
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
ANSI = re.compile(rb"\x1b(\[[0-?]*[ -/]*[@-~]|[@-Z\\-_]|\][^\x07]*\x07)")


def cli(*args: str) -> list[str]:
    return [sys.executable, "-m", "astralis_des.cli", *args]


def run_cli(*argv: str) -> tuple[int, str, str]:
    """``astralis ARGV`` in this process, stdout and stderr captured (usable in
    module-scoped fixtures): the exit code, the output and the errors."""
    from astralis_des.cli import main

    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main(list(argv))
    return code, out.getvalue(), err.getvalue()


def quiet_env(home: Path) -> dict[str, str]:
    """No colours, no history file in the real home."""
    return {**os.environ, "NO_COLOR": "1", "TERM": "xterm", "HOME": str(home),
            "ASTRALIS_HISTORY": str(home / "history"), "PYTHONIOENCODING": "utf-8"}


# Run a program with the terminal on its standard input as its controlling terminal, so that
# Ctrl-C there is a SIGINT to it, as in a shell.
CONTROLLING = ("import fcntl, os, sys, termios; fcntl.ioctl(0, termios.TIOCSCTTY, 0); "
               "os.execv(sys.argv[1], sys.argv[1:])")


class Terminal:
    def __init__(self, argv: list[str], env: dict[str, str], cols: int = 120) -> None:
        self.master, self.slave = pty.openpty()
        fcntl.ioctl(self.slave, termios.TIOCSWINSZ, struct.pack("HHHH", 40, cols, 0, 0))
        argv = [sys.executable, "-c", CONTROLLING, *argv]
        self.proc = subprocess.Popen(argv, stdin=self.slave, stdout=self.slave,
                                     stderr=self.slave, env=env, cwd=ROOT,
                                     start_new_session=True)
        self.screen = b""  # everything shown, escape sequences taken out
        self._raw = b""

    def send(self, data: bytes) -> None:
        os.write(self.master, data)

    def expect(self, text: str, timeout: float = 15.0, after: int = 0) -> int:
        """Wait until ``text`` is on the screen past ``after``; where it ends."""
        needle = text.encode()
        deadline = time.monotonic() + timeout
        while (at := self.screen.find(needle, after)) < 0:
            left = deadline - time.monotonic()
            if left <= 0 or not self._read(left):
                raise AssertionError(f"{text!r} not shown; the screen:\n"
                                     f"{self.screen.decode(errors='replace')}")
        return at + len(needle)

    def prompt(self, prompt: str, after: int = 0, timeout: float = 15.0) -> int:
        """Wait for ``prompt`` and for the program to read keys at it (the terminal out of
        line mode), then a moment more: a Ctrl-C sent sooner could come before the program
        is listening."""
        at = self.expect(prompt, timeout, after)
        deadline = time.monotonic() + timeout
        while termios.tcgetattr(self.slave)[3] & termios.ICANON:
            if time.monotonic() > deadline:
                raise AssertionError(f"the terminal is still in line mode at {prompt!r}")
            self._read(0.01)
        time.sleep(0.1)
        return at

    def _read(self, wait: float) -> bool:
        if not select.select([self.master], [], [], wait)[0]:
            return False
        try:
            data = os.read(self.master, 65536)
        except OSError:  # the program has gone: EIO
            return False
        self._raw += data
        self.screen = ANSI.sub(b"", self._raw).replace(b"\r", b"").replace(b"\x07", b"")
        return bool(data)

    def wait(self, timeout: float = 15.0) -> int:
        deadline = time.monotonic() + timeout
        while self.proc.poll() is None and time.monotonic() < deadline:
            self._read(0.05)
        if self.proc.poll() is None:
            raise AssertionError(f"still running after {timeout:g} s; the screen:\n"
                                 f"{self.screen.decode(errors='replace')}")
        return self.proc.returncode

    def close(self) -> None:
        if self.proc.poll() is None:
            self.proc.kill()
            self.proc.wait(5)
        for fd in (self.master, self.slave):
            os.close(fd)
