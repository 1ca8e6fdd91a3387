"""The API over real sockets on loopback: every query and command, and the state stream."""

from __future__ import annotations

import json
import re
import time
from collections.abc import Iterator
from pathlib import Path

import pytest
import zmq

from astralis_des import Mission
from astralis_des.api import ApiError, Client
from astralis_des.api.local import Background

TABLE_II = {"activity": {"sitting", "laying", "patrolling", "idle"},
            "color": {"yellow", "red", "purple", "blue"}, "gender": {"male", "female"},
            "height": {"tall", "medium", "short"}, "tiedToChair": {True, False}}


@pytest.fixture()
def manual(urban_search: Mission) -> Mission:
    """The default mission with a team that waits for commands."""
    return urban_search.with_changes(assignment={"auto": False, "search": ["A"]})


@pytest.fixture()
def server(manual: Mission, tmp_path: Path) -> Iterator[Background]:
    background = Background(manual, running=False, out_dir=tmp_path / "out")
    background.start()
    yield background
    background.stop()


@pytest.fixture()
def client(server: Background) -> Iterator[Client]:
    with Client(server.address, timeout=5.0) as c:
        yield c


# -- queries -------------------------------------------------------------------------------
def test_info_names_the_team_rooms_and_addresses(client: Client, server: Background) -> None:
    info = client.info()
    assert info["mission"] == "urban_search" and info["fidelity"] == "kinematic"
    assert {r: v["type"] for r, v in info["robots"].items()} == {
        "uav1": "uav", "uav2": "uav", "ugv1": "ugv", "op1": "human"}
    assert "sneak_peek" in info["robots"]["ugv1"]["actions"]
    assert "hover" not in info["robots"]["ugv1"]["actions"]
    assert "A.2.1.3" in info["rooms"] and info["segments"]["A.2.1"] == [
        "A.2.1.1", "A.2.1.2", "A.2.1.3"]
    assert info["addresses"] == {"requests": server.address, "stream": server.stream}


def test_table_ii_avatar(client: Client) -> None:
    avatar = client.avatar()
    for key, values in TABLE_II.items():
        assert avatar[key] in values, key
    assert avatar["found"] is False and "location" not in avatar  # not given away


def test_table_ii_location(client: Client, server: Background) -> None:
    room = client.location("A.1.1.2")
    assert room["location"] == [70.0, 83.0, 0.0]
    assert 0.0 <= room["messiness_level"] <= 1.0 and 0.0 <= room["risk"] <= 1.0
    assert room["sound"] in ("minimal", "moderate", "loud")
    assert room["segment"] == "A.1.1" and room["searched"] is False
    with pytest.raises(ApiError, match=r"no room 'A\.1\.1\.9'.*did you mean 'A\.1\.1\.[123]'"):
        client.location("A.1.1.9")


def test_table_ii_robot(client: Client) -> None:
    robot = client.robot("uav2")
    assert robot["type"] == "uav" and robot["pose"] == [92.0, 60.0, 0.07]  # landed
    assert robot["command"] is None and robot["state"] == "idle"
    with pytest.raises(ApiError, match=r"no robot 'uav9'; did you mean 'uav[12]'") as err:
        client.robot("uav9")
    assert err.value.code == "unknown_robot"


def test_status_queue_and_events(client: Client) -> None:
    status = client.status()
    assert status["t"] == 0.0 and status["clock"] == "paused" and not status["ended"]
    assert set(status["robots"]) == {"uav1", "uav2", "ugv1", "op1"}
    assert list(client.status("op1")["robots"]) == ["op1"]
    assert client.queue("ugv1") == {"robot": "ugv1", "current": None, "queued": []}
    first = client.events()
    assert [e["kind"] for e in first["events"]][:1] == ["mission_start"]
    client.enqueue("uav1", "hover", params={"duration": 4})
    later = client.events(after=first["next"])
    assert [e["kind"] for e in later["events"]] == ["command", "task_queued"]
    client.step(by=7.0)  # it takes off (2.4 s), then hovers 4 s
    kinds = [e["kind"] for e in client.events(since=4.0, robot="uav1")["events"]]
    assert kinds == ["task_finished"]
    assert [e["kind"] for e in client.events(robot="uav1")["events"]] == [
        "command", "task_queued", "task_started", "took_off", "task_finished"]
    page = client.events(kinds=["task_started", "task_finished"], limit=1)
    assert [e["kind"] for e in page["events"]] == ["task_started"]
    assert [e["kind"] for e in client.events(after=page["next"],
                                             kinds=["task_finished"])["events"]] == [
        "task_finished"]
    with pytest.raises(ApiError, match="no event kind 'task_finish'; did you mean "
                       "'task_finished'") as err:  # it selected nothing, silently
        client.events(kinds=["task_finish"])
    assert err.value.code == "unknown_kind"


def test_help_lists_every_operation(client: Client) -> None:
    ops = client.request("help")["ops"]
    assert {"avatar", "location", "robot", "status", "queue", "events", "enqueue", "cancel",
            "preempt", "pause", "resume", "step", "assign", "teleop", "shutdown"} <= set(ops)
    assert ops["enqueue"]["command"] and not ops["robot"]["command"]
    assert ops["robot"]["usage"] == "robot(robot!)"


# -- commands ------------------------------------------------------------------------------
def test_enqueue_runs_the_task_and_logs_the_command(client: Client) -> None:
    queued = client.enqueue("uav1", "spiral_inward", "A.1.1.2")
    assert queued["position"] == 0
    assert client.queue("uav1")["queued"][0]["action"] == "spiral_inward"
    client.step(by=0.5)
    robot = client.robot("uav1")
    assert robot["command"] == "spiral_inward A.1.1.2" and robot["state"] == "busy"
    command = client.events(kinds=["command"])["events"][0]
    assert command["op"] == "enqueue" and command["source"] == "api"
    assert command["robot"] == "uav1" and command["room"] == "A.1.1.2"


def test_a_ugv_asked_to_hover_is_refused(client: Client) -> None:
    with pytest.raises(ApiError, match="ugv1 is a ugv and has no action 'hover'; its "
                       "actions: move, observe_corridor, sneak_peek") as err:
        client.enqueue("ugv1", "hover")
    assert err.value.code == "bad_action"
    with pytest.raises(ApiError, match="sneak_peek needs a room"):
        client.enqueue("ugv1", "sneak_peek")
    with pytest.raises(ApiError, match="move needs a room or params x and y"):
        client.enqueue("op1", "move")
    assert client.events(kinds=["command"])["events"] == []  # refused: not logged


def test_preempt_interrupts_and_cancel_empties(client: Client) -> None:
    first = client.enqueue("uav2", "hover", params={"duration": 30})
    second = client.enqueue("uav2", "hover", params={"duration": 30})
    client.step(by=1.0)
    now = client.preempt("uav2", "move", "A.1.1.1")
    assert now["interrupted"] == first["task"] and now["position"] == 0
    client.step(by=0.1)
    queue = client.queue("uav2")
    assert queue["current"]["id"] == now["task"]
    assert [t["id"] for t in queue["queued"]] == [second["task"]]
    finished = client.events(kinds=["task_finished"])["events"]
    assert [(e["task"], e["status"]) for e in finished] == [(first["task"], "preempted")]
    with pytest.raises(ApiError, match=r"uav2 has no task 999 \(its tasks: "):
        client.cancel("uav2", 999)
    assert client.cancel("uav2", second["task"])["cancelled"] == [second["task"]]
    assert sorted(client.cancel("uav2")["cancelled"]) == [now["task"]]
    client.step(by=0.1)
    assert client.queue("uav2") == {"robot": "uav2", "current": None, "queued": []}


def test_pause_resume_and_step(client: Client) -> None:
    with pytest.raises(ApiError, match="give one of 'until'"):
        client.step()
    assert client.step(until=2.5)["t"] == 2.5
    with pytest.raises(ApiError, match="is not after now"):
        client.step(until=1.0)
    assert client.resume(pace=50)["clock"] == "running at 50x"
    with pytest.raises(ApiError, match="pause it first") as err:
        client.step(by=1.0)
    assert err.value.code == "clock_running"
    time.sleep(0.1)  # 5 simulated s at 50x
    paused = client.pause()
    assert paused["clock"] == "paused" and paused["t"] > 2.5  # time ran meanwhile
    ops = [e["op"] for e in client.events(kinds=["command"])["events"]]
    assert ops == ["step", "resume", "pause"]


def test_assign_runs_a_round_and_queues_its_tasks(client: Client) -> None:
    round_ = client.assign("A.2.1")
    assert round_["round"] == 1
    assert sorted(m["room"] for m in round_["matching"]) == ["A.2.1.1", "A.2.1.2", "A.2.1.3"]
    for match in round_["matching"]:
        queued = client.queue(match["agent"])["queued"]
        assert [(t["action"], t["room"]) for t in queued] == [
            ("move", match["room"]), (match["action"], match["room"])]
    assert client.events(kinds=["assignment"])["events"][0]["segment"] == "A.2.1"
    with pytest.raises(ApiError, match=r"no segment 'A\.2\.9'; did you mean"):
        client.assign("A.2.9")
    with pytest.raises(ApiError, match=r"room A\.1\.1\.1 is not in segment A\.2\.1"):
        client.assign("A.2.1", rooms=["A.1.1.1"])


def test_teleop_steps_add_up(client: Client) -> None:
    start = client.robot("op1")["pose"]
    client.teleop("op1", "east")
    second = client.teleop("op1", "east")
    assert second["goal"][0] == pytest.approx(start[0] + 1.0)
    client.step(by=3.0)
    pose = client.robot("op1")["pose"]
    assert pose[0] == pytest.approx(start[0] + 1.0, abs=0.02)
    assert pose[1] == pytest.approx(start[1], abs=0.02)
    with pytest.raises(ApiError, match="direction"):
        client.request("teleop", robot="op1", direction="up")


def test_shutdown_ends_the_mission_and_writes_the_outputs(client: Client,
                                                          server: Background) -> None:
    client.enqueue("op1", "inspect", "A.1.1.3")
    client.step(by=2.0)
    assert client.shutdown() == {"t": 2.0}
    server.stop()
    assert server.result is not None and server.result.outcome == "interrupted"
    out = Path(server._args["out_dir"])
    lines = [json.loads(x) for x in (out / "events.jsonl").read_text().splitlines()]
    assert [r["op"] for r in lines if r["kind"] == "command"] == ["enqueue", "step",
                                                                  "shutdown"]
    assert lines[-1] == {"t": 2.0, "kind": "mission_end", "outcome": "interrupted"}
    assert (out / "summary.json").exists()


def test_commands_are_refused_once_the_mission_has_ended(manual: Mission) -> None:
    short = manual.with_changes(time_limit=3.0)
    background = Background(short, running=False)
    with Client(background.start(), timeout=5.0) as client:
        assert client.step(by=10.0) == {"t": 3.0, "ended": True, "outcome": "time_limit"}
        with pytest.raises(ApiError, match=r"the mission has ended \(time_limit") as err:
            client.enqueue("uav1", "hover")
        assert err.value.code == "ended"
        assert client.status()["outcome"] == "time_limit"  # queries still answered
        client.shutdown()
    background.stop()


# -- the state stream ----------------------------------------------------------------------
def test_the_stream_publishes_states_and_events_by_topic(client: Client) -> None:
    with client.subscribe("state.uav1", "event.task_") as stream:
        client.enqueue("uav1", "hover", params={"duration": 1})
        seen: dict[str, list[dict]] = {}
        for _ in range(20):  # the subscription joins asynchronously: step until it hears
            client.step(by=0.5)
            try:
                while True:
                    topic, message = stream.receive(timeout=0.2)
                    seen.setdefault(topic, []).append(message)
            except ApiError:
                pass
            if "event.task_finished" in seen:
                break
    assert set(seen) <= {"state.uav1", "event.task_queued", "event.task_started",
                         "event.task_finished"}
    assert seen["event.task_finished"][0]["robot"] == "uav1"
    states = seen["state.uav1"]
    assert all(s["id"] == "uav1" and s["type"] == "uav" and len(s["pose"]) == 3
               for s in states)
    assert [s["t"] for s in states] == sorted(s["t"] for s in states)


def test_paced_clock_runs_the_mission_on_its_own(manual: Mission) -> None:
    background = Background(manual.with_changes(assignment={"auto": True, "search": ["A"]}),
                            pace=200.0)
    with Client(background.start(), timeout=5.0) as client:
        with client.subscribe("event.assignment") as stream:
            topic, message = stream.receive(timeout=10.0) if client.status()["rounds"] == 0 \
                else ("event.assignment", {"round": 1})
        assert topic == "event.assignment" and message["round"] >= 1
        assert client.status()["t"] > 0.0
        client.shutdown()
    background.stop()


# -- clients of other kinds ----------------------------------------------------------------
def test_a_req_client_and_a_raw_dealer_work(server: Background) -> None:
    ctx = zmq.Context()
    try:
        req = ctx.socket(zmq.REQ)
        req.connect(server.address)
        req.send(b'{"op": "robot", "robot": "ugv1", "id": 7}')
        assert req.poll(5000)
        reply = json.loads(req.recv())
        assert reply["id"] == 7 and reply["result"]["type"] == "ugv"
        dealer = ctx.socket(zmq.DEALER)
        dealer.connect(server.address)
        dealer.send(b'{"op": "avatar"}')  # no empty delimiter frame
        assert dealer.poll(5000)
        assert json.loads(dealer.recv())["ok"] is True
    finally:
        ctx.destroy(linger=0)


def test_a_team_without_automatic_rounds_waits(manual: Mission) -> None:
    """assignment.auto: false: no rounds, nobody moves, the mission runs to its time limit."""
    from astralis_des import Simulation

    result = Simulation(manual.with_changes(time_limit=60.0)).run()
    assert result.outcome == "time_limit" and result.rounds == []
    assert all(s.distance == 0.0 for s in result.robots.values())


def test_physics_poses_come_from_the_bodies(manual: Mission) -> None:
    background = Background(manual.with_changes(fidelity="physics"), running=False)
    with Client(background.start(), timeout=10.0) as client:
        client.enqueue("uav1", "take_off")
        client.step(by=3.0)
        start = client.robot("uav1")["pose"]
        assert start[2] == pytest.approx(1.975, abs=0.05)  # up at its flight height
        client.enqueue("uav1", "move", params={"x": start[0], "y": start[1] + 2.0})
        client.step(by=0.5)
        moving = client.robot("uav1")
        assert moving["state"] == "busy" and moving["command"] == "move"
        assert 0.0 < moving["pose"][1] - start[1] < 2.0  # under way, read from the body
        client.step(by=6.0)
        pose = client.robot("uav1")["pose"]
        assert pose[1] == pytest.approx(start[1] + 2.0, abs=0.15)
        assert client.events(kinds=["task_finished"])["events"][0]["status"] == "succeeded"
        client.shutdown()
    background.stop()


def test_commands_are_in_the_recording(manual: Mission, tmp_path: Path) -> None:
    import subprocess
    import sys

    background = Background(manual, running=False, out_dir=tmp_path)
    with Client(background.start(), timeout=5.0) as client:
        client.enqueue("uav1", "hover", params={"duration": 2})
        client.teleop("op1", "north")
        client.step(by=1.0)
        client.shutdown()
    background.stop()
    rerun = str(Path(sys.executable).with_name("rerun"))
    shown = subprocess.run([rerun, "rrd", "print", "-vvv", str(tmp_path / "recording.rrd")],
                           capture_output=True, text=True, check=True).stdout
    for line in ("uav1 command enqueue hover", "op1 command teleop north", "command step",
                 "command shutdown"):
        assert line in shown, line


def test_events_since_a_time_in_and_out_of_time_order(manual: Mission,
                                                      request: pytest.FixtureRequest) -> None:
    """``since`` skips ahead by bisection while the log is in time order, and still finds every
    event once a contact stamped inside a macro-step has put it out of order."""
    from astralis_des import Simulation
    from astralis_des.api.service import Clock, Service
    from astralis_des.kernel.catalogue import EVENTS, EventKind, event

    event(EventKind("probe", "a test's", ("n",)))  # a plug-in's kind
    request.addfinalizer(lambda: EVENTS.remove("probe"))
    service = Service(Simulation(manual), Clock(running=False))
    log = service.sim.log
    for t in (1.0, 2.0, 2.0, 3.0):
        log.emit("probe", at=t, n=t)

    def since(t: float) -> list[float]:
        reply = service.handle({"op": "events", "since": t, "kinds": ["probe"]})
        return [e["n"] for e in reply["result"]["events"]]

    assert log.in_order and since(2.0) == [2.0, 2.0, 3.0] and since(3.5) == []
    log.emit("probe", at=2.5, n=2.5)
    assert not log.in_order and since(2.0) == [2.0, 2.0, 3.0, 2.5]
    last = service.handle({"op": "events", "since": 2.2, "last": 2})["result"]["events"]
    assert [e["n"] for e in last] == [3.0, 2.5]


@pytest.mark.parametrize(("params", "message"), [
    ({"duration": -5}, "hover: duration must be at least 0 (got -5)"),
    ({"duration": "abc"}, "hover: duration must be a number (got 'abc')"),
    ({"seconds": 3}, "hover has no parameter 'seconds' (its parameters: duration)"),
])
def test_bad_parameters_are_an_error_reply_and_the_robot_is_untouched(
        client: Client, params: dict, message: str) -> None:
    with pytest.raises(ApiError, match=re.escape(message)) as caught:
        client.enqueue("uav1", "hover", params=params)
    assert caught.value.code == "bad_args"
    assert client.robot("uav1")["queued"] == 0 and client.robot("uav1")["task"] is None
    client.enqueue("uav1", "hover", params={"duration": 2})
    client.step(by=5.0)  # take-off and hover
    assert client.robot("uav1")["task"] is None


def test_a_request_keeps_its_own_id(client: Client) -> None:
    """Issue 24: ``request("avatar", id=...)`` overwrote the request's id and timed out."""
    started = time.monotonic()
    with pytest.raises(ApiError, match="'id' is the request's own key, not an argument of "
                                       "'avatar'") as caught:
        client.request("avatar", id="a1")
    assert caught.value.code == "bad_args" and time.monotonic() - started < 1.0
    assert client.avatar()["found"] is False  # the client still works


def test_every_bystander_is_queryable_by_its_id(client: Client) -> None:
    """Issue 24: only the target avatar could be queried. Once a room is furnished (the team
    looked into it), ``avatars`` lists its bystanders and ``avatar`` with an id gives one's
    Table II attributes, room and where it is; a walker's location moves with the clock."""
    assert client.avatars("A.1.1.2") == {"avatars": []}  # not looked into yet
    client.enqueue("uav1", "spiral_inward", "A.1.1.2")
    client.step(by=5.0)
    listed = client.avatars("A.1.1.2")["avatars"]
    assert listed and all(a["id"].startswith("A.1.1.2/avatar-") for a in listed)
    assert [a["id"] for a in client.avatars()["avatars"] if a["room"] == "A.1.1.2"] == [
        a["id"] for a in listed]
    for entry in listed:
        one = client.avatar(entry["id"])
        assert one["room"] == "A.1.1.2" and one["target"] is False
        assert {k: one[k] for k in ("activity", "color", "gender", "height", "tiedToChair")} \
            == {k: entry[k] for k in ("activity", "color", "gender", "height", "tiedToChair")}
        assert len(one["location"]) == 3
        if one["activity"] == "patrolling":
            client.step(by=3.0)
            assert client.avatar(entry["id"])["location"] != one["location"]
    with pytest.raises(ApiError, match=r"no avatar 'A\.1\.1\.2/avatar-99'") as err:
        client.avatar("A.1.1.2/avatar-99")
    assert err.value.code == "unknown_avatar"
    assert client.avatar()["found"] is False  # without an id: the target, as before
