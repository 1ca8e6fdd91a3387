"""The chat: its line language (parsing, suggestions, completion), the chat against a real
server on loopback, and ``astralis chat`` on a pseudo-terminal."""

from __future__ import annotations

import importlib.util
import re
import socket
import subprocess
from pathlib import Path
from typing import Any

import pytest
from terminal import Terminal, cli, quiet_env

from astralis_des import Mission
from astralis_des.api.client import Client
from astralis_des.api.local import serving
from astralis_des.chat import ChatError, Parsed, Team, complete, parse
from astralis_des.chat.repl import Chat

ROBOTS = {"uav1": "uav", "uav2": "uav", "ugv1": "ugv", "op1": "human"}


@pytest.fixture(scope="module")
def mission(urban_search: Mission) -> Mission:
    """The paper's mission, waiting for commands (no rounds of its own), no recording."""
    spec = urban_search.spec
    return urban_search.with_changes(
        assignment={**spec.assignment.model_dump(), "auto": False},
        outputs={**spec.outputs.model_dump(), "recording": False})


@pytest.fixture(scope="module")
def team(mission: Mission, tmp_path_factory: pytest.TempPathFactory) -> Team:
    with serving(mission, running=False, out_dir=tmp_path_factory.mktemp("info")) as address, \
            Client(address) as client:
        return Team.from_info(client.info())


@pytest.fixture
def chat(client: Client) -> Chat:
    return Chat(client)


# -- the language ----------------------------------------------------------------------------
@pytest.mark.parametrize(("line", "op", "args"), [
    ("status", "status", {}),
    ("status uav1", "status", {"robot": "uav1"}),
    ("uav1 search A.2.1.3 inward", "enqueue",
     {"robot": "uav1", "action": "spiral_inward", "room": "A.2.1.3"}),
    ("ugv1 sneak-peek A.1.2.1", "enqueue",
     {"robot": "ugv1", "action": "sneak_peek", "room": "A.1.2.1"}),
    ("op1 move A.1.1.2", "enqueue", {"robot": "op1", "action": "move", "room": "A.1.1.2"}),
    ("queue uav2", "queue", {"robot": "uav2"}),
    ("cancel uav2", "cancel", {"robot": "uav2"}),
    ("assign segment A.2.1", "assign", {"segment": "A.2.1"}),
])
def test_the_issues_examples(team: Team, line: str, op: str, args: dict[str, Any]) -> None:
    """Each example line of issue 10 is the API request it says."""
    assert parse(line, team) == Parsed(op, args)


@pytest.mark.parametrize(("line", "op", "args"), [
    ("uav1 search A.2.1.3", "enqueue",
     {"robot": "uav1", "action": "spiral_inward", "room": "A.2.1.3"}),
    ("uav2 search A.2.1.3 outward", "enqueue",
     {"robot": "uav2", "action": "spiral_outward", "room": "A.2.1.3"}),
    ("uav1 search A.2.1.3 horizontal", "enqueue",
     {"robot": "uav1", "action": "sweep_horizontal", "room": "A.2.1.3"}),
    ("uav1 search vertical a.2.1.3", "enqueue",
     {"robot": "uav1", "action": "sweep_vertical", "room": "A.2.1.3"}),
    ("uav1 hover", "enqueue", {"robot": "uav1", "action": "hover"}),
    ("uav1 hover 30", "enqueue", {"robot": "uav1", "action": "hover",
                                  "params": {"duration": 30.0}}),
    ("uav1 hover 2m", "enqueue", {"robot": "uav1", "action": "hover",
                                  "params": {"duration": 120.0}}),
    ("ugv1 observe A.1.1.1", "enqueue",
     {"robot": "ugv1", "action": "observe_corridor", "room": "A.1.1.1"}),
    ("op1 inspect A.1.1.1", "enqueue", {"robot": "op1", "action": "inspect",
                                        "room": "A.1.1.1"}),
    ("op1 search A.1.1.1", "enqueue", {"robot": "op1", "action": "inspect",
                                       "room": "A.1.1.1"}),
    ("uav2 move 90 62.5", "enqueue", {"robot": "uav2", "action": "move",
                                      "params": {"x": 90.0, "y": 62.5}}),
    ("uav1 sweep_vertical A.1.1.1", "enqueue",
     {"robot": "uav1", "action": "sweep_vertical", "room": "A.1.1.1"}),
    ("uav1 sweep-vertical A.1.1.1", "enqueue",
     {"robot": "uav1", "action": "sweep_vertical", "room": "A.1.1.1"}),
    ("ugv1 sneak_peek A.1.2.1", "enqueue",
     {"robot": "ugv1", "action": "sneak_peek", "room": "A.1.2.1"}),
    ("uav1 search A.2.1.3 now", "preempt",
     {"robot": "uav1", "action": "spiral_inward", "room": "A.2.1.3"}),
    ("op1 move 90 62 now", "preempt", {"robot": "op1", "action": "move",
                                       "params": {"x": 90.0, "y": 62.0}}),
    ("uav1 search A.2.1.3 spacing=2 mode=fast", "enqueue",
     {"robot": "uav1", "action": "spiral_inward", "room": "A.2.1.3",
      "params": {"spacing": 2.0, "mode": "fast"}}),
    ("uav2 queue", "queue", {"robot": "uav2"}),
    ("uav2 status", "status", {"robot": "uav2"}),
    ("robot ugv1", "robot", {"robot": "ugv1"}),
    ("room a.1.1.2", "location", {"room": "A.1.1.2"}),
    ("location A.1.1.2", "location", {"room": "A.1.1.2"}),
    ("avatar", "avatar", {}),
    ("cancel uav1 3", "cancel", {"robot": "uav1", "task": 3}),
    ("assign A.2.1", "assign", {"segment": "A.2.1"}),
    ("assign segment A.2.1 A.2.1.1 uav1 ugv1", "assign",
     {"segment": "A.2.1", "rooms": ["A.2.1.1"], "robots": ["uav1", "ugv1"]}),
    ("pause", "pause", {}),
    ("resume", "resume", {}),
    ("resume 10x", "resume", {"pace": 10.0}),
    ("step 5", "step", {"by": 5.0}),
    ("step 2m", "step", {"by": 120.0}),
    ("step to 600", "step", {"until": 600.0}),
    ("events since 30", "events", {"since": 30.0, "limit": 50}),
    ("shutdown", "shutdown", {}),
    ("  STATUS   uav1 ", "status", {"robot": "uav1"}),
])
def test_lines_to_requests(team: Team, line: str, op: str, args: dict[str, Any]) -> None:
    """The rest of the language: variants, raw action names, now, params, the clock."""
    assert parse(line, team) == Parsed(op, args)


@pytest.mark.parametrize(("line", "op", "args"), [
    ("help", "help", {}),
    ("help uav1", "help", {"word": "uav1"}),
    ("quit", "quit", {}),
    ("exit", "quit", {}),
    ("robots", "robots", {}),
    ("rooms", "rooms", {}),
    ("rooms a.2.1", "rooms", {"segment": "A.2.1"}),
    ("queue", "queues", {}),
    ("events", "tail", {"last": 10}),
    ("events 3", "tail", {"last": 3}),
    ("", "nothing", {}),
])
def test_lines_the_chat_answers_itself(team: Team, line: str, op: str,
                                       args: dict[str, Any]) -> None:
    assert parse(line, team) == Parsed(op, args, local=True)


@pytest.mark.parametrize(("line", "message"), [
    ("stauts", "unknown command 'stauts'; did you mean 'status'?"),
    ("asign segment A.2.1", "unknown command 'asign'; did you mean 'assign'?"),
    ("uav11 search A.2.1.3", "no robot 'uav11'; did you mean 'uav1'?"),
    ("status uav11", "no robot 'uav11'; did you mean 'uav1'?"),
    ("cancel ugv2", "no robot 'ugv2'; did you mean 'ugv1'?"),
    ("uav1 search A.2.1.33", "no room 'A.2.1.33'; did you mean 'A.2.1.3'?"),
    ("room A.1.1.22", "no room 'A.1.1.22'; did you mean 'A.1.1.2'?"),
    ("assign segment A.2.11", "no segment 'A.2.11'; did you mean 'A.2.1'?"),
    ("ugv1 hover", "ugv1 is a ugv: it cannot hover; it can move, sneak-peek, observe"),
    ("ugv1 search A.1.1.1",
     "ugv1 is a ugv: it cannot search; it can move, sneak-peek, observe"),
    ("op1 sneak-peek A.1.1.1",
     "op1 is a human: it cannot sneak-peek; it can move, inspect, search"),
    ("uav1 serch A.2.1.3",
     "uav1 has no command 'serch'; did you mean 'search'? (it can move, search, hover, "
     "take-off, land)"),
    ("op1 move", "op1 move needs a room or x y: op1 move ROOM|X Y"),
    ("uav1 search A.2.1.3 inward outward",
     "uav1 search: one of inward, outward, horizontal, vertical, not inward and outward"),
    ("status uav1 uav2", "'uav2' makes no sense here; usage: status [ROBOT]"),
    ("step", "for how long? usage: step SECONDS | step to T (e.g. step 30, step 2m, "
             "step to 600)"),
    ("step soon", "step: 'soon' is not a time like 30, 30s, 2m or 1h"),
    ("resume fast", "resume: 'fast' is not a pace like 1x or 10x"),
    ("cancel uav1 first", "cancel: 'first' is not a task number (queue uav1 lists them)"),
])
def test_bad_lines_say_what_would_do(team: Team, line: str, message: str) -> None:
    """A typo gets a suggestion; a verb the robot's kind lacks says what it can do."""
    with pytest.raises(ChatError) as caught:
        parse(line, team)
    assert str(caught.value) == message


@pytest.mark.parametrize(("line", "expected"), [
    ("st", ["status", "step"]),
    ("ug", ["ugv1"]),
    ("uav1 se", ["search"]),
    ("ugv1 s", ["sneak-peek", "status"]),
    ("op1 ", ["cancel", "inspect", "move", "queue", "search", "status"]),
    ("uav1 search A.2.1", ["A.2.1.1", "A.2.1.2", "A.2.1.3"]),
    ("op1 move a.1.1", ["A.1.1.1", "A.1.1.2", "A.1.1.3"]),
    ("uav1 search A.2.1.3 ", ["horizontal", "inward", "now", "outward", "vertical"]),
    ("uav1 search A.2.1.3 in", ["inward"]),
    ("uav1 search A.2.1.3 inward ", ["now"]),
    ("assign segment A.2", ["A.2.1", "A.2.2"]),
    ("assign se", ["segment"]),
    ("assign A.2.1 A", ["A.2.1.1", "A.2.1.2", "A.2.1.3"]),
    ("status ", ["op1", "uav1", "uav2", "ugv1"]),
    ("rooms B", ["B.1.1", "B.2.1"]),
    ("step ", ["to"]),
    ("events s", ["since"]),
    ("stauts ", []),
])
def test_completion_candidates(team: Team, line: str, expected: list[str]) -> None:
    """Tab after a partial word: commands and robots, then verbs, rooms, variants."""
    assert complete(line, team) == expected


def test_first_word_completes_to_commands_and_robots(team: Team) -> None:
    words = complete("", team)
    assert {"status", "assign", "help", "quit", *ROBOTS} <= set(words)
    assert "uav1" in complete("u", team) and "status" not in complete("u", team)


def test_a_uav_is_offered_only_its_own_verbs(team: Team) -> None:
    verbs = complete("uav1 ", team)
    assert {"search", "hover", "move", "spiral-inward", "sweep-vertical"} <= set(verbs)
    assert not {"sneak-peek", "observe", "inspect"} & set(verbs)


# -- the chat against a server ---------------------------------------------------------------
def test_status_shows_the_team_and_the_time(chat: Chat) -> None:
    text = chat.text("status")
    assert text.splitlines()[0].startswith("t = 0.0 s, clock paused; mission running")
    rows = {line.split()[0]: line.split() for line in text.splitlines()[2:]}
    assert {rid: row[1] for rid, row in rows.items()} == ROBOTS
    assert all(row[2] == "idle" for row in rows.values())
    assert "(90.0, 60.0, 0.1)" in text  # uav1 where the mission starts it, landed


def test_a_search_is_queued_then_listed_then_cancelled(chat: Chat, client: Client) -> None:
    """uav1 search, queue uav1, cancel uav1: the replies and the server agree."""
    assert chat.text("uav1 search A.2.1.3 inward") == \
        "queued task 1 for uav1: spiral_inward A.2.1.3 (next to run)"
    assert chat.text("uav1 hover 20") == \
        "queued task 2 for uav1: hover duration=20 (1 queued ahead of it)"
    assert chat.text("queue uav1") == ("uav1: nothing running; queued, in order:\n"
                                       "  task 1: spiral_inward A.2.1.3\n"
                                       "  task 2: hover duration=20")
    assert [t["action"] for t in client.queue("uav1")["queued"]] == ["spiral_inward", "hover"]
    assert chat.text("cancel uav1") == "cancelled uav1's tasks 1, 2"
    assert chat.text("queue uav1") == "uav1: nothing running, nothing queued"
    assert client.queue("uav1")["queued"] == []


def test_now_interrupts_the_running_task(chat: Chat, client: Client) -> None:
    chat.text("uav1 search A.2.1.3")
    chat.text("step 1")
    assert client.queue("uav1")["current"]["id"] == 1
    assert chat.text("uav1 hover 5 now") == \
        "task 2 for uav1 runs now: hover duration=5; task 1 interrupted"


def test_assign_segment_queues_a_task_for_each_robot_matched(chat: Chat,
                                                             client: Client) -> None:
    text = chat.text("assign segment A.2.1")
    lines = text.splitlines()
    assert lines[0] == "round 1 over A.2.1: 3 tasks queued"
    matched = {line.split()[0]: line.split()[-1] for line in lines[1:4]}
    assert sorted(matched.values()) == ["A.2.1.1", "A.2.1.2", "A.2.1.3"]
    for robot, room in matched.items():
        assert room in {t["room"] for t in client.queue(robot)["queued"]}
    assert lines[4] == "  unassigned: op1"


def test_step_moves_time_on(chat: Chat, client: Client) -> None:
    assert chat.text("step 5") == "t = 5.0 s"
    assert chat.text("step to 12.5") == "t = 12.5 s"
    assert client.status()["t"] == 12.5
    assert chat.text("status").startswith("t = 12.5 s")


def test_errors_come_back_as_one_line(chat: Chat) -> None:
    """From the language and from the server alike."""
    assert chat.text("stauts") == "error: unknown command 'stauts'; did you mean 'status'?"
    assert chat.text("cancel uav1 7") == "error: uav1 has no task 7 (its tasks: none)"
    assert chat.text("resume 5000x") == ("error: resume: the pace must be above 0 and at most "
                                         "1000x (got 5000x)")
    chat.text("resume")
    assert chat.text("step 5") == ("error: the clock is running at 1x; pause it first "
                                   "(or serve with --stepped)")


def test_queries_of_table_ii(chat: Chat) -> None:
    assert chat.text("robot ugv1").startswith("ugv1 (ugv): idle, idle, 0 queued; at "
                                              "(94.0, 66.0, 0.5)")
    assert chat.text("room A.1.1.2").startswith("A.1.1.2 (segment A.1.1) at (70.0, 83.0, 0.0)")
    avatar = chat.text("avatar")
    assert avatar.startswith("target: activity ") and avatar.endswith("not found yet")


def test_the_last_events_are_the_commands_just_given(chat: Chat) -> None:
    chat.text("ugv1 sneak-peek A.1.2.1")
    chat.text("op1 move A.1.1.2")
    lines = [line.split()[3:6] for line in chat.text("events 4").splitlines()]
    assert lines == [["command", "ugv1", "op=enqueue"], ["task_queued", "ugv1", "task=1"],
                     ["command", "op1", "op=enqueue"], ["task_queued", "op1", "task=2"]]
    assert len(chat.text("events 1").splitlines()) == 1
    assert chat.text("events since 0").splitlines()[0].split()[3] == "mission_start"


def test_help_lists_the_commands_and_a_robots_verbs(chat: Chat) -> None:
    text = chat.text("help")
    for usage in ("status [ROBOT]", "assign [segment] SEGMENT", "step SECONDS | step to T",
                  "cancel ROBOT [TASK]", "events [N] | events since T"):
        assert usage in text
    verbs = chat.text("help uav1")
    assert "uav1 search ROOM [inward|outward|horizontal|vertical]" in verbs
    assert "uav1 hover [DURATION]" in verbs
    assert chat.text("help hlep") .startswith("error: no help on 'hlep'; did you mean 'help'?")


def test_robots_and_rooms(chat: Chat) -> None:
    robots = chat.text("robots").splitlines()
    assert robots[3].split(None, 2) == ["ugv1", "ugv", "move, sneak-peek, observe"]
    assert chat.text("rooms A.2.1") == "A.2.1: A.2.1.1, A.2.1.2, A.2.1.3"
    assert len(chat.text("rooms").splitlines()) == 8


def test_quit_ends_the_chat(chat: Chat) -> None:
    assert not chat.done
    chat.text("quit")
    assert chat.done


# -- the program ---------------------------------------------------------------------------
def test_the_chat_on_a_terminal(address: str, tmp_path: Path) -> None:
    """status, a typo, Tab, quit: what a person at the terminal sees, and exit 0."""
    term = Terminal(cli("chat", "--connect", address), quiet_env(tmp_path))
    try:
        at = term.prompt("astralis> ")
        term.send(b"status\r")
        for robot in ROBOTS:
            term.expect(robot, after=at)
        at = term.prompt("astralis> ", after=at)
        term.send(b"stauts\r")
        at = term.expect("error: unknown command 'stauts'; did you mean 'status'?", after=at)
        at = term.prompt("astralis> ", after=at)
        if importlib.util.find_spec("readline") is not None:
            term.send(b"queue ua\t")
            at = term.expect("queue uav", after=at)  # completed to the common prefix
            term.send(b"2\r")
            at = term.expect("uav2: nothing running, nothing queued", after=at)
        term.send(b"quit\r")
        term.expect("bye", after=at)
        assert term.wait() == 0
    finally:
        term.close()


def test_ctrl_c_clears_the_line_and_twice_quits(address: str, tmp_path: Path) -> None:
    """Ctrl-C drops what was typed; Ctrl-C twice in a row leaves (130)."""
    term = Terminal(cli("chat", "--connect", address), quiet_env(tmp_path))
    try:
        at = term.prompt("astralis> ")
        term.send(b"cancel uav1 99")
        at = term.expect("cancel uav1 99", after=at)
        term.send(b"\x03")
        at = term.expect("(Ctrl-C again or Ctrl-D quits)", after=at)
        at = term.prompt("astralis> ", after=at)
        term.send(b"step 2\r")
        at = term.expect("t = 2.0 s", after=at)
        assert b"no task 99" not in term.screen
        at = term.prompt("astralis> ", after=at)
        term.send(b"\x03")
        at = term.expect("(Ctrl-C again or Ctrl-D quits)", after=at)
        term.prompt("astralis> ", after=at)
        term.send(b"\x03")
        assert term.wait() == 130
    finally:
        term.close()


def test_ctrl_d_quits(address: str, tmp_path: Path) -> None:
    term = Terminal(cli("chat", "--connect", address), quiet_env(tmp_path))
    try:
        term.prompt("astralis> ")
        term.send(b"\x04")
        assert term.wait() == 0
    finally:
        term.close()


def test_the_chat_serves_a_mission_file_itself(tmp_path: Path) -> None:
    """astralis chat MISSION --stepped: lines from a pipe, then the outputs are written."""
    out = tmp_path / "out"
    proc = subprocess.run(cli("chat", "missions/urban_search.yaml", "--stepped",
                              "--no-recording", "--out", str(out)),
                          input="op1 move A.1.1.2\nstep 10\nstatus op1\nquit\n",
                          capture_output=True, text=True, timeout=60, env=quiet_env(tmp_path),
                          cwd=Path(__file__).resolve().parents[1])
    assert proc.returncode == 0, proc.stderr
    assert "t = 10.0 s" in proc.stdout
    assert f"mission ended at t = 10.0 s (interrupted); outputs: {out}/" in \
        proc.stdout.replace("\n", "")
    address = re.search(r"serving urban_search here at (tcp://127\.0\.0\.1:\d+)",
                        proc.stdout.replace("\n", " ")).group(1)  # type: ignore[union-attr]
    assert f"astralis teleop op1 --connect {address}" in proc.stdout.replace("\n", " ")
    assert (out / "events.jsonl").exists() and (out / "summary.json").exists()


def test_no_server_is_one_line_and_exit_2(tmp_path: Path) -> None:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    address = f"tcp://127.0.0.1:{port}"
    # a chat that waited for ever would raise TimeoutExpired (no wall-time bound here: a
    # loaded machine starts Python slowly)
    proc = subprocess.run(cli("chat", "--connect", address, "--timeout", "1"),
                          capture_output=True, text=True, timeout=60, env=quiet_env(tmp_path))
    assert proc.returncode == 2
    assert proc.stderr == (f"error: no server at {address} (start one with astralis serve "
                           "MISSION.yaml)\n")


def test_bad_parameters_are_refused_when_given_and_the_robot_stays_usable(
        chat: Chat, client: Client) -> None:
    """Issue 24: ``hover -5`` and ``duration=abc`` were accepted, then failed at the next
    step with a traceback, the clock stopped and the robot stayed busy for good."""
    assert chat.text("uav1 hover -5") == "error: hover: duration must be at least 0 (got -5)"
    assert chat.text("uav2 hover duration=abc") == (
        "error: hover: duration must be a number (got 'abc')")
    assert chat.text("uav2 search A.1.1.1 spacing=2 mode=fast") == (
        "error: spiral_inward has no parameter 'mode' (its parameters: spacing)")
    assert client.status()["robots"]["uav1"]["queued"] == 0  # nothing was queued
    assert chat.text("uav1 hover 3") == "queued task 1 for uav1: hover duration=3 (next to run)"
    assert chat.text("step 6") == "t = 6.0 s"  # the clock goes on (take-off, hover)
    assert client.robot("uav1")["task"] is None  # the hover ran and ended
    assert chat.text("queue uav1") == "uav1: nothing running, nothing queued"


def test_the_queue_is_right_just_after_a_preempt(chat: Chat, client: Client) -> None:
    """Issue 24: after ``uav2 hover 5 now`` the interrupted task showed as running until the
    next step."""
    chat.text("uav2 hover 30")
    chat.text("step 1")
    assert chat.text("uav2 hover 5 now") == ("task 2 for uav2 runs now: hover duration=5; "
                                             "task 1 interrupted")
    assert chat.text("queue uav2") == "uav2: running task 2: hover duration=5, nothing queued"
    assert client.robot("uav2")["task"] == 2
    chat.text("step 2")
    assert chat.text("queue uav2") == "uav2: running task 2: hover duration=5, nothing queued"


def test_a_chat_serving_a_mission_is_where_teleop_looks(tmp_path: Path) -> None:
    """Issue 24: ``astralis chat MISSION`` served on a random port, so ``astralis teleop op1``
    could not find it. It serves on teleop's default address when that is free: a client
    with the defaults reaches it while the chat runs."""
    proc = subprocess.Popen(cli("chat", "missions/urban_search.yaml", "--stepped",
                                "--no-recording", "--out", str(tmp_path / "out")),
                            stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True,
                            env=quiet_env(tmp_path), cwd=Path(__file__).resolve().parents[1])
    try:
        assert proc.stdout is not None
        banner = proc.stdout.readline() + proc.stdout.readline()
        assert "at tcp://127.0.0.1:5555" in banner
        assert "astralis teleop op1 --connect tcp://127.0.0.1:5555" in banner
        with Client("tcp://127.0.0.1:5555", timeout=10.0) as client:  # teleop's default
            assert client.robot("op1")["type"] == "human"
    finally:
        proc.communicate("quit\n", timeout=60)
    assert proc.returncode == 0
