"""``astralis teleop ROBOT``: walk a robot (the human operator) with the arrow or WASD keys.

Each key is a ``teleop`` request (a step north, south, east or west); one status line says
where the robot is and what the last key did. On a terminal the keys are read one by one
(the terminal's mode is always restored); from a pipe they are read as they come, so
``printf 'wwdd' | astralis teleop op1`` works too.
"""

from __future__ import annotations

import argparse
import os
import select
import sys
from collections.abc import Callable, Iterable, Iterator
from contextlib import AbstractContextManager, contextmanager, nullcontext
from typing import TYPE_CHECKING, Any

from rich.console import Console
from rich.text import Text

from astralis_des.api.protocol import MAX_TELEOP_STEP, ApiError
from astralis_des.chat.keys import QUIT, KeyDecoder
from astralis_des.chat.show import where
from astralis_des.errors import InputError, suggest
from astralis_des.exits import EXIT_INTERRUPTED

if TYPE_CHECKING:
    from astralis_des.api.client import Client

REFRESH = 0.25  # wall s between status refreshes on a terminal while no key comes


class Teleop:
    """Moves to ``teleop`` requests for one robot, and the status line after each."""

    def __init__(self, client: Client, robot: str, step: float) -> None:
        self.client = client
        self.robot = robot
        self.step = step
        self.last = "ready"

    def press(self, move: str) -> str:
        """Send one move; the status line."""
        try:
            result = self.client.teleop(self.robot, move, distance=self.step)
            self.last = f"{move}: going to {where(result['goal'][:2])}"
        except ApiError as exc:
            self.last = f"{move}: {exc.code}: {exc.message}"
        return self.line()

    def line(self) -> str:
        try:
            at = where(self.client.robot(self.robot)["pose"][:2])
        except ApiError:
            at = "?"
        return f"{self.robot} at {at} | {self.last}"


def drive(session: Teleop, chunks: Iterable[bytes | None], show: Callable[[str], None]) -> None:
    """Keys to moves until a quit key or the end of input (an empty chunk); ``None`` (no key
    for a while) refreshes the status line."""
    decoder = KeyDecoder()
    for data in chunks:
        if data is None:
            show(session.line())
            continue
        for move in decoder.feed(data) if data else decoder.end():
            if move == QUIT:
                return
            show(session.press(move))


def reads(fd: int, refresh: float | None) -> Iterator[bytes | None]:
    """What arrives on ``fd``, ending with ``b""``; ``None`` after ``refresh`` s of nothing."""
    while True:
        if refresh is not None and not select.select([fd], [], [], refresh)[0]:
            yield None
            continue
        data = os.read(fd, 64)
        yield data
        if not data:
            return


@contextmanager
def key_by_key(fd: int) -> Iterator[None]:
    """The terminal without line editing, echo or signals (Ctrl-C arrives as a key), put
    back as it was however this ends."""
    import termios

    saved = termios.tcgetattr(fd)
    mode = termios.tcgetattr(fd)
    mode[0] &= ~(termios.IXON | termios.ICRNL)
    mode[3] &= ~(termios.ICANON | termios.ECHO | termios.ISIG | termios.IEXTEN)
    mode[6][termios.VMIN], mode[6][termios.VTIME] = 1, 0
    termios.tcsetattr(fd, termios.TCSANOW, mode)
    try:
        yield
    finally:
        termios.tcsetattr(fd, termios.TCSADRAIN, saved)


class StatusLine:
    """One line rewritten in place on a terminal; one line per update elsewhere."""

    def __init__(self, console: Console, in_place: bool) -> None:
        self.console = console
        self.in_place = in_place
        self._shown = ""

    def show(self, text: str) -> None:
        if text == self._shown:
            return
        self._shown = text
        if self.in_place:  # spaces rub out the longer line before: no escape codes needed
            width = max(self.console.width - 1, 20)
            self.console.file.write("\r" + text[:width].ljust(width))
            self.console.file.flush()
        else:
            self.console.print(Text(text), soft_wrap=True)

    def close(self) -> None:
        if self.in_place:
            self.console.file.write("\n")
            self.console.file.flush()


def teleop_command(args: argparse.Namespace) -> int:
    from astralis_des.chat.link import connect

    if not 0.0 < args.step <= MAX_TELEOP_STEP:
        raise InputError(f"must be above 0 and at most {MAX_TELEOP_STEP:g} m (got {args.step:g})",
                         key="--step")
    client, info = connect(args.connect, args.timeout, args.curve_keys)
    with client:
        team = info["robots"]
        if args.robot not in team:
            raise InputError(f"no robot '{args.robot}'; {suggest(args.robot, team)}")
        console = Console(highlight=False)
        if args.gamepad:
            return _gamepad(args, client, console, team[args.robot]["type"])
        fd = sys.stdin.fileno()
        terminal = os.isatty(fd)
        console.print(Text(f"driving {args.robot} ({team[args.robot]['type']}) at "
                           f"{args.connect}: arrow keys or WASD step {args.step:g} m; "
                           "q quits"), soft_wrap=True)
        status = StatusLine(console, in_place=terminal and console.is_terminal)
        session = Teleop(client, args.robot, args.step)
        try:
            with _keys_mode(fd, terminal):  # before the status line: keys may follow at once
                status.show(session.line())
                drive(session, reads(fd, REFRESH if terminal else None), status.show)
        except KeyboardInterrupt:
            return EXIT_INTERRUPTED
        finally:
            status.close()
    return 0


def _gamepad(args: argparse.Namespace, client: Client, console: Console, kind: str) -> int:
    from astralis_des.chat.gamepad import Gamepad, drive_pad, load_mapping, open_pad

    mapping = load_mapping(args.mapping)
    pad = Gamepad(client, args.robot, open_pad(), mapping)
    session = Teleop(client, args.robot, mapping.step)
    console.print(Text(f"driving {args.robot} ({kind}) at {args.connect} with the game "
                       f"controller: the left stick steps up to {mapping.step:g} m; "
                       + ", ".join(f"button {n}: {_does(b)}"
                                   for n, b in sorted(mapping.buttons.items()))),
                  soft_wrap=True)
    status = StatusLine(console, in_place=console.is_terminal)
    try:
        drive_pad(pad, status.show, session.line)
    except KeyboardInterrupt:
        return EXIT_INTERRUPTED
    finally:
        status.close()
    return 0


def _does(button: Any) -> str:
    return "quit" if button.quit else "stop" if button.stop else str(button.action)


def _keys_mode(fd: int, terminal: bool) -> AbstractContextManager[None]:
    if not terminal:
        return nullcontext()
    try:
        import termios  # noqa: F401
    except ImportError:  # no termios (Windows): keys come a line at a time
        return nullcontext()
    return key_by_key(fd)
