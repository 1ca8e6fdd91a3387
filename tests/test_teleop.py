"""Teleoperation: the key decoder, keys driving the human operator through a real server, and
``astralis teleop`` fed keys on a pseudo-terminal and through a pipe."""

from __future__ import annotations

import subprocess
import termios
from pathlib import Path

import numpy as np
import pytest
from terminal import Terminal, cli, quiet_env

from astralis_des import Mission
from astralis_des.api.client import Client
from astralis_des.chat.keys import KeyDecoder
from astralis_des.chat.teleop import Teleop, drive

# Inside room A.1.2.3 (x 72.1 to 75.9), half a metre from its east wall.
BY_THE_WALL = [75.4, 73.5, 0.0]


@pytest.fixture(scope="module")
def mission(urban_search: Mission) -> Mission:
    """The paper's mission, waiting for commands, no recording; op1 in a room by a wall."""
    spec = urban_search.spec
    team = [{**member.model_dump(), **({"start": BY_THE_WALL} if member.id == "op1" else {})}
            for member in spec.team]
    return urban_search.with_changes(
        team=team, assignment={**spec.assignment.model_dump(), "auto": False},
        outputs={**spec.outputs.model_dump(), "recording": False})


def position(client: Client, robot: str = "op1") -> np.ndarray:
    return np.array(client.robot(robot)["pose"][:2])


# -- the key decoder -------------------------------------------------------------------------
@pytest.mark.parametrize(("keys", "moves"), [
    (b"wasd", ["north", "west", "south", "east"]),
    (b"WASD", ["north", "west", "south", "east"]),
    (b"\x1b[A\x1b[B\x1b[C\x1b[D", ["north", "south", "east", "west"]),
    (b"\x1bOA\x1bOB\x1bOC\x1bOD", ["north", "south", "east", "west"]),
    (b"\x1b[1;5A\x1b[1;2D", ["north", "west"]),  # with Ctrl, Shift
    (b"x1\r\n \x1b[3~\x1b[15~", []),  # other keys, Delete, F5: nothing
    (b"\x1bxw", ["north"]),  # Alt+x, then w
    (b"dq", ["east", "quit"]),
    (b"Q", ["quit"]),
    (b"\x03", ["quit"]),
    (b"\x04", ["quit"]),
])
def test_keys_to_moves(keys: bytes, moves: list[str]) -> None:
    assert KeyDecoder().feed(keys) == moves


@pytest.mark.parametrize("sequence", [b"\x1b[C", b"\x1bOC", b"\x1b[1;5C"])
def test_an_escape_sequence_split_across_reads_is_one_key(sequence: bytes) -> None:
    """However the arrow's bytes are split up, it is one move east, and only once whole."""
    for cut in range(1, len(sequence)):
        decoder = KeyDecoder()
        assert decoder.feed(sequence[:cut]) == []
        assert decoder.feed(sequence[cut:] + b"w") == ["east", "north"]


def test_byte_by_byte_arrows() -> None:
    decoder = KeyDecoder()
    moves = [m for byte in b"\x1b[A\x1bOD" for m in decoder.feed(bytes([byte]))]
    assert moves == ["north", "west"]


def test_end_of_input_quits_and_drops_a_pending_escape() -> None:
    decoder = KeyDecoder()
    assert decoder.feed(b"\x1b[") == []
    assert decoder.end() == ["quit"]
    assert decoder.feed(b"a") == ["west"]


# -- keys driving the operator through a server ----------------------------------------------
def test_two_steps_east_move_the_operator_a_metre(client: Client) -> None:
    """Two d presses of 0.5 m, then time to walk there: +1.0 m in x, y unchanged."""
    client.teleop("op1", "west")
    client.step(by=5.0)
    start = position(client)
    shown: list[str] = []
    drive(Teleop(client, "op1", 0.5), [b"d", b"d"], shown.append)
    assert [line.split(" | ")[1] for line in shown] == [
        f"east: going to ({start[0] + 0.5:.1f}, {start[1]:.1f})",
        f"east: going to ({start[0] + 1.0:.1f}, {start[1]:.1f})"]
    client.step(by=10.0)
    assert position(client) - start == pytest.approx([1.0, 0.0], abs=0.03)


def test_arrow_keys_go_north_and_south(client: Client) -> None:
    start = position(client)
    drive(Teleop(client, "op1", 0.5), [b"\x1b[A\x1b[A\x1b", b"[A\x1bOB"], lambda line: None)
    client.step(by=10.0)
    assert position(client) - start == pytest.approx([0.0, 1.0], abs=0.03)


def test_a_key_into_a_wall_is_refused_and_the_operator_stays(client: Client) -> None:
    """The first step east reaches the wall; the second would go through it: blocked."""
    start = position(client)
    shown: list[str] = []
    drive(Teleop(client, "op1", 0.5), [b"dd"], shown.append)
    assert shown[1].split(" | ")[1].startswith("east: blocked: op1 cannot step to [76.40, 73.50]")
    client.step(by=10.0)
    assert position(client) - start == pytest.approx([0.5, 0.0], abs=0.03)


def test_quit_stops_the_keys_that_follow(client: Client) -> None:
    shown: list[str] = []
    drive(Teleop(client, "op1", 0.5), [b"aq", b"aaa"], shown.append)
    assert len(shown) == 1


def test_each_key_is_a_command_event(client: Client) -> None:
    drive(Teleop(client, "op1", 0.5), [b"a\x1b[Aq"], lambda line: None)
    events = client.events(kinds=["command"])["events"]
    assert [(e["robot"], e["op"], e["direction"], e["distance"]) for e in events] == [
        ("op1", "teleop", "west", 0.5), ("op1", "teleop", "north", 0.5)]


# -- the program ---------------------------------------------------------------------------
def test_teleop_on_a_terminal(address: str, client: Client, tmp_path: Path) -> None:
    """Keys one at a time (the terminal in key mode), Ctrl-C quits with 0, the terminal's
    mode is put back."""
    term = Terminal(cli("teleop", "op1", "--connect", address), quiet_env(tmp_path))
    try:
        before = termios.tcgetattr(term.slave)
        at = term.expect("q quits")
        at = term.prompt("op1 at (75.4, 73.5) | ready", after=at)
        term.send(b"a")  # no Enter: a key is read as it is pressed
        at = term.expect("west: going to (74.9, 73.5)", after=at)
        term.send(b"\x1b[")
        term.send(b"A")
        at = term.expect("north: going to (74.9, 74.0)", after=at)
        term.send(b"\x03")
        assert term.wait() == 0
        assert termios.tcgetattr(term.slave) == before
    finally:
        term.close()
    client.step(by=10.0)
    assert position(client) == pytest.approx([74.9, 74.0], abs=0.03)


def test_teleop_reads_keys_from_a_pipe(address: str, client: Client, tmp_path: Path) -> None:
    """printf 'awsq' | astralis teleop op1: a status line per key, exit 0 at q."""
    proc = subprocess.run(cli("teleop", "op1", "--connect", address), input=b"aawsqaaaa",
                          capture_output=True, timeout=30, env=quiet_env(tmp_path))
    assert proc.returncode == 0, proc.stderr
    lines = proc.stdout.decode().splitlines()
    assert [line.split(" | ")[1] for line in lines[1:]] == [
        "ready", "west: going to (74.9, 73.5)", "west: going to (74.4, 73.5)",
        "north: going to (74.4, 74.0)", "south: going to (74.4, 73.5)"]
    client.step(by=10.0)
    assert position(client) == pytest.approx([74.4, 73.5], abs=0.03)


def test_teleop_of_an_unknown_robot_is_one_line_and_exit_2(address: str,
                                                           tmp_path: Path) -> None:
    proc = subprocess.run(cli("teleop", "opp1", "--connect", address), input="",
                          capture_output=True, text=True, timeout=30, env=quiet_env(tmp_path))
    assert proc.returncode == 2
    assert proc.stderr == "error: no robot 'opp1'; did you mean 'op1'?\n"
