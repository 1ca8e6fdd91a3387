"""The API's commands: ``astralis serve``, ``keys``, ``chat`` and ``teleop``."""

from __future__ import annotations

import argparse
import importlib
from collections.abc import Callable
from pathlib import Path
from typing import Any

from astralis_des.api.protocol import read_pace

Command = Callable[[argparse.Namespace], int]


def _lazy(module: str, function: str) -> Command:
    """A command whose module is imported only when it runs: ``astralis --help`` stays quick."""
    def run(args: argparse.Namespace) -> int:
        return int(getattr(importlib.import_module(module), function)(args))

    return run


API_COMMANDS: dict[str, Command] = {
    "serve": _lazy("astralis_des.api.console", "serve_command"),
    "keys": _lazy("astralis_des.api.console", "keys_command"),
    "chat": _lazy("astralis_des.chat.repl", "chat_command"),
    "teleop": _lazy("astralis_des.chat.teleop", "teleop_command"),
}


def parse_pace(text: str) -> float:
    """``10``, ``10x`` or ``0.5x``: simulated seconds per wall second."""
    try:
        return read_pace(text)
    except ValueError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None


def _add_clock_options(parser: argparse.ArgumentParser) -> None:
    clock = parser.add_mutually_exclusive_group()
    clock.add_argument("--pace", type=parse_pace, default=1.0, metavar="FACTOR",
                       help="simulated seconds per wall second, e.g. 1x (the default) or 10x")
    clock.add_argument("--stepped", action="store_true",
                       help="start paused: time moves only on step requests (or resume)")
    parser.add_argument("--manual", action="store_true",
                        help="the team waits for commands: no automatic assignment rounds "
                        "(assignment.auto: false)")


def add_api_parsers(sub: Any, add_mission_options: Callable[[Any], None]) -> None:
    """serve, keys, chat and teleop."""
    serve = sub.add_parser("serve", help="run a mission behind the ZeroMQ API: queries, "
                           "commands and a state stream",
                           description="Requests: JSON on a ROUTER socket (REQ and DEALER "
                           "clients). State stream: a PUB socket, topics state.<robot> and "
                           "event.<kind>. See docs/api.md.")
    serve.add_argument("mission", help="mission YAML file")
    serve.add_argument("--bind", default="tcp://127.0.0.1:5555",
                       help="request address (default tcp://127.0.0.1:5555); an address "
                       "other machines reach needs --curve-keys")
    serve.add_argument("--stream", help="state stream address (default: the next port)")
    serve.add_argument("--curve-keys", metavar="DIR", help="encrypt and authenticate with "
                       "the CURVE keys in DIR (made by astralis keys DIR)")
    serve.add_argument("--state-rate", type=float, default=10.0, metavar="HZ",
                       help="robot states published per simulated second (default 10)")
    serve.add_argument("--exit-on-end", action="store_true",
                       help="stop when the mission ends (default: keep answering queries)")
    serve.add_argument("-q", "--quiet", action="store_true", help="print nothing but errors")
    _add_clock_options(serve)
    add_mission_options(serve)
    keys = sub.add_parser("keys", help="make CURVE keys for serving beyond this machine")
    keys.add_argument("folder", metavar="DIR", help="folder to write the keys to")
    chat = sub.add_parser("chat", help="command the team in a line language (help, tab "
                          "completion)")
    chat.add_argument("mission", nargs="?", help="serve this mission file here and talk to "
                      "it (default: connect to a server)")
    chat.add_argument("--connect", metavar="ADDR", default="tcp://127.0.0.1:5555",
                      help="the server (default tcp://127.0.0.1:5555); with a MISSION, the "
                      "address to serve it on (if taken, a free port, shown)")
    chat.add_argument("--curve-keys", metavar="DIR", help="the client keys for a CURVE server")
    chat.add_argument("--timeout", type=float, default=5.0, help="s to wait for a reply")
    _add_clock_options(chat)
    add_mission_options(chat)
    teleop = sub.add_parser("teleop", help="walk a robot (the human operator) with the arrow "
                            "or WASD keys, or drive any robot with a game controller")
    teleop.add_argument("robot", help="robot id, e.g. op1")
    teleop.add_argument("--connect", metavar="ADDR", default="tcp://127.0.0.1:5555",
                        help="the server (default tcp://127.0.0.1:5555)")
    teleop.add_argument("--curve-keys", metavar="DIR", help="the client keys for a CURVE "
                        "server")
    teleop.add_argument("--step", type=float, default=0.5, metavar="M",
                        help="metres a key press moves (default 0.5)")
    teleop.add_argument("--timeout", type=float, default=2.0, help="s to wait for a reply")
    teleop.add_argument("--gamepad", action="store_true", help="drive it with a game "
                        "controller (the gamepad extra: SDL) instead of the keys")
    teleop.add_argument("--mapping", type=Path, metavar="FILE", help="the controller's "
                        "mapping (default astralis_des/data/gamepad.yaml)")
