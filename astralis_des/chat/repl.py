"""``astralis chat``: :class:`Chat` runs one line against a server and says what came back;
:func:`run` is the terminal loop around it (a prompt, Tab completion, history)."""

from __future__ import annotations

import argparse
import contextlib
import io
import os
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Any

from rich.console import Console, Group, RenderableType
from rich.table import Table
from rich.text import Text

from astralis_des.api.protocol import ApiError, ApiTimeout
from astralis_des.chat import robots
from astralis_des.chat.language import Parsed, complete, help_rows, parse
from astralis_des.chat.show import events_text, queue_text, reply, unwrapped
from astralis_des.chat.team import ChatError, Team
from astralis_des.exits import EXIT_INTERRUPTED
from astralis_des.kinds import KIND_DEFAULTS
from astralis_des.registry import Registry

if TYPE_CHECKING:
    from astralis_des.api.client import Client

STEP_TIMEOUT = 120.0  # s a step may take: a physics mission runs it before replying
PROMPT = "astralis> "
HISTORY = "~/.astralis_history"  # or $ASTRALIS_HISTORY

Local = Callable[["Chat", Parsed], RenderableType]
LOCAL: Registry[str, Local] = Registry("chat answer")


def local(op: str) -> Callable[[Local], Local]:
    return LOCAL.register(op)


def error(message: str) -> Text:
    return Text(f"error: {message}", style="red")


class Chat:
    """One line in, what to show out; ``done`` once the line was ``quit``."""

    def __init__(self, client: Client, info: dict[str, Any] | None = None) -> None:
        self.client = client
        self.info = info if info is not None else client.info()
        self.team = Team.from_info(self.info)
        self.done = False

    def execute(self, line: str) -> RenderableType:
        try:
            parsed = parse(line, self.team)
            if parsed.local:
                return LOCAL.get(parsed.op)(self, parsed)
            wait = max(self.client.timeout, STEP_TIMEOUT) if parsed.op == "step" else None
            result = self.client.request(parsed.op, timeout=wait, **parsed.args)
        except ChatError as exc:
            return error(str(exc))
        except ApiTimeout as exc:
            return error(f"{exc.message}; is the server still running?")
        except ApiError as exc:
            return error(exc.message)
        if parsed.op == "shutdown":
            self.done = True
        return reply(parsed, result)

    def text(self, line: str, width: int = 120) -> str:
        """What :meth:`execute` shows, as plain text (for scripts and tests)."""
        out = io.StringIO()
        Console(file=out, width=width, color_system=None, highlight=False).print(
            self.execute(line))
        return "\n".join(line.rstrip() for line in out.getvalue().rstrip().splitlines())

    def last_events(self, n: int) -> list[dict[str, Any]]:
        """The log's last ``n`` events."""
        return list(self.client.events(last=n)["events"])


# -- what the chat answers itself ------------------------------------------------------------
@local("nothing")
def _nothing(chat: Chat, parsed: Parsed) -> RenderableType:
    return Text("")


@local("quit")
def _quit(chat: Chat, parsed: Parsed) -> RenderableType:
    chat.done = True
    return Text("bye")


@local("help")
def _help(chat: Chat, parsed: Parsed) -> RenderableType:
    word = parsed.args.get("word")
    table = Table(box=None, show_header=False, pad_edge=False)
    table.add_column(style="bold", no_wrap=True)
    table.add_column()
    for usage, what in help_rows(word, chat.team):
        table.add_row(Text(usage), Text(what))
    if word is not None:
        return table
    return Group(table, Text("Tab completes a word; a trailing 'now' runs a robot's task at "
                             "once; key=value words are the action's parameters."))


@local("robots")
def _robots(chat: Chat, parsed: Parsed) -> RenderableType:
    table = Table(box=None, pad_edge=False, header_style="bold")
    for name in ("robot", "kind", "verbs"):
        table.add_column(name)
    for rid, kind in chat.team.robots.items():
        table.add_row(rid, kind, ", ".join(robots.friendly_verbs(rid, chat.team)))
    return table


@local("rooms")
def _rooms(chat: Chat, parsed: Parsed) -> RenderableType:
    segments = chat.team.segments
    chosen = [parsed.args["segment"]] if "segment" in parsed.args else sorted(segments)
    return Text("\n".join(f"{s}: {', '.join(segments[s])}" for s in chosen))


@local("queues")
def _queues(chat: Chat, parsed: Parsed) -> RenderableType:
    return Text("\n".join(queue_text(chat.client.queue(rid)) for rid in chat.team.robots))


@local("tail")
def _tail(chat: Chat, parsed: Parsed) -> RenderableType:
    events = chat.last_events(parsed.args["last"])
    return unwrapped(events_text(events)) if events else Text("no events yet")


# -- the terminal --------------------------------------------------------------------------
def run(chat: Chat, console: Console, prompt: str = PROMPT) -> int:
    """Read lines until quit or Ctrl-D (0) or two Ctrl-C in a row (130; one clears the
    line)."""
    save = _readline(chat.team)
    interrupted = False
    try:
        while not chat.done:
            try:
                line = input(prompt)
            except EOFError:
                console.print()
                return 0
            except KeyboardInterrupt:
                if interrupted:
                    console.print()
                    return EXIT_INTERRUPTED
                interrupted = True
                console.print("\n(Ctrl-C again or Ctrl-D quits)")
                continue
            interrupted = False
            try:
                console.print(chat.execute(line))
            except KeyboardInterrupt:
                console.print(error("interrupted; the server may still carry the request out"))
    finally:
        save()
    return 0


def _readline(team: Team) -> Callable[[], None]:
    """Tab completion and a history file, where the readline module exists; the function
    that saves the history."""
    try:
        import readline
    except ImportError:  # Windows: lines without completion
        return lambda: None
    found: list[str] = []

    def completer(text: str, state: int) -> str | None:
        if state == 0:
            found[:] = complete(readline.get_line_buffer()[: readline.get_endidx()], team)
        return found[state] if state < len(found) else None

    readline.set_completer(completer)
    readline.set_completer_delims(" \t\n")
    binding = "bind ^I rl_complete" if "libedit" in (readline.__doc__ or "") else "tab: complete"
    readline.parse_and_bind(binding)
    path = Path(os.environ.get("ASTRALIS_HISTORY", HISTORY)).expanduser()
    with contextlib.suppress(OSError):
        readline.read_history_file(path)
    readline.set_history_length(1000)

    def save() -> None:
        with contextlib.suppress(OSError):
            readline.write_history_file(path)

    return save


def chat_command(args: argparse.Namespace) -> int:
    """Chat with the server at ``--connect``, or with a mission served here."""
    from astralis_des.chat.link import connect

    console = Console(highlight=False)
    background, out, code = None, None, 0
    try:
        if args.mission:
            background, out, address = _serve_here(args, console)
        else:
            address = args.connect
        client, info = connect(address, args.timeout, None if background else args.curve_keys)
        with client:
            console.print(Text(f"{info['mission']} ({info['fidelity']}) at {address}: "
                               f"{', '.join(info['robots'])}. help lists the commands; Tab "
                               "completes; Ctrl-D quits."))
            code = run(Chat(client, info), console)
    except KeyboardInterrupt:
        console.print("interrupted")
        return EXIT_INTERRUPTED
    finally:
        if background is not None:
            result = background.stop()
            if result is not None:
                console.print(Text(f"mission ended at t = {result.end_time:.1f} s "
                                   f"({result.outcome}); outputs: {out}/"))
    return code


def _serve_here(args: argparse.Namespace, console: Console) -> tuple[Any, Path, str]:
    from astralis_des.api.local import Background
    from astralis_des.mission.overrides import mission_from_args

    mission, out = mission_from_args(args)
    try:  # the address teleop and other clients look at by default, if it is free
        background = Background(mission, bind=args.connect, pace=args.pace,
                                running=not args.stepped, out_dir=out)
        address = background.start()
    except Exception:  # taken (another server): any free port, shown below
        background = Background(mission, pace=args.pace, running=not args.stepped,
                                out_dir=out)
        address = background.start()
    clock = "paused: step moves time" if args.stepped else f"running at {args.pace:g}x"
    console.print(Text(f"serving {mission.name} here at {address} (clock {clock}); outputs go "
                       f"to {out}/"), soft_wrap=True)  # one line each: a command to copy
    walker = next((m.id for m in mission.spec.team if KIND_DEFAULTS[m.kind].person),
                  mission.spec.team[0].id)
    console.print(Text(f"drive a robot from another terminal: astralis teleop {walker} "
                       f"--connect {address}"), soft_wrap=True)
    return background, out, address
