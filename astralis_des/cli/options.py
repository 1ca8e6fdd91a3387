"""The options every command spells the same way: ``-o/--out``, ``-q/--quiet``, a mission's."""

from __future__ import annotations

import argparse
from collections.abc import Callable

Command = Callable[[argparse.Namespace], int]


def add_out(parser: argparse.ArgumentParser, help: str, *, metavar: str,
            required: bool = False) -> None:
    """``-o/--out``; ``--output``, its old spelling in some commands, still parses as it but
    is not shown (the parser maps each spelling to the option when it is added; help and
    errors name the option's ``option_strings``)."""
    out = parser.add_argument("-o", "--out", "--output", dest="out", metavar=metavar,
                              required=required, help=help)
    out.option_strings = ["-o", "--out"]


def add_quiet(parser: argparse.ArgumentParser, help: str) -> None:
    parser.add_argument("-q", "--quiet", action="store_true", help=help)


def add_mission_options(parser: argparse.ArgumentParser) -> None:
    """What ``run``, ``serve`` and ``chat`` may change of a mission file."""
    add_out(parser, "output folder (default: the mission's outputs.dir, else "
            "out/<mission name>)", metavar="DIR")
    parser.add_argument("--seed", type=int, help="override the mission's seed")
    parser.add_argument("--fidelity", choices=["kinematic", "physics"],
                        help="override the mission's fidelity")
    parser.add_argument("--no-recording", action="store_true", help="skip the Rerun recording")
    parser.add_argument("--mcap", action="store_true", help="also write run.mcap (ROS 2 "
                        "messages and the decisions as JSON, for ros2 bag, Foxglove, Rerun)")


def positive(text: str) -> int:
    value = int(text)
    if value < 1:
        raise argparse.ArgumentTypeError(f"must be at least 1 (got {value})")
    return value
