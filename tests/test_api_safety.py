"""The API's safety: loopback by default, CURVE elsewhere, malformed requests answered, a
client that never wedges, and ``astralis serve`` from the command line."""

from __future__ import annotations

import json
import os
import signal
import socket
import subprocess
import sys
import threading
import time
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest
import zmq

from astralis_des import Mission
from astralis_des.api import ApiTimeout, Client
from astralis_des.api.local import Background
from astralis_des.api.protocol import HARD_LIMIT, MAX_MESSAGE
from astralis_des.api.security import check_bind, create_keys, is_local
from astralis_des.errors import InputError

ROOT = Path(__file__).resolve().parents[1]
MISSION = ROOT / "missions" / "urban_search.yaml"


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


@pytest.fixture()
def server(urban_search: Mission) -> Iterator[Background]:
    background = Background(urban_search.with_changes(assignment={"auto": False,
                                                                  "search": ["A"]}),
                            running=False)
    background.start()
    yield background
    background.stop()


# -- where a server may listen -------------------------------------------------------------
@pytest.mark.parametrize(("address", "local"), [
    ("tcp://127.0.0.1:5555", True), ("tcp://localhost:5555", True), ("tcp://[::1]:5555", True),
    ("ipc:///tmp/astralis", True), ("inproc://x", True), ("tcp://0.0.0.0:5555", False),
    ("tcp://*:5555", False), ("tcp://192.168.1.20:5555", False)])
def test_only_loopback_counts_as_local(address: str, local: bool) -> None:
    assert is_local(address) is local


def test_binding_beyond_loopback_needs_keys() -> None:
    with pytest.raises(InputError, match=r"--bind: tcp://0.0.0.0:5555 is reachable from other "
                       "machines; serving there needs CURVE keys"):
        check_bind("tcp://0.0.0.0:5555", None)
    check_bind("tcp://0.0.0.0:5555", "keys")  # with keys, it may


def test_serve_refuses_an_open_bind_without_keys(tmp_path: Path) -> None:
    run = subprocess.run([sys.executable, "-m", "astralis_des.cli", "serve", str(MISSION),
                          "--bind", "tcp://0.0.0.0:5555", "--out", str(tmp_path / "out")],
                         capture_output=True, text=True, timeout=60)
    assert run.returncode == 2
    assert run.stderr.strip().splitlines() == [
        "error: --bind: tcp://0.0.0.0:5555 is reachable from other machines; serving there "
        "needs CURVE keys: --curve-keys DIR (make them with astralis keys DIR)"]
    assert not (tmp_path / "out").exists()


def test_curve_lets_in_only_the_clients_with_keys(urban_search: Mission,
                                                  tmp_path: Path) -> None:
    keys, strangers = tmp_path / "keys", tmp_path / "strangers"
    names = sorted(p.relative_to(keys).as_posix() for p in create_keys(keys))
    assert names == ["client.key", "client.key_secret", "clients/client.key", "server.key",
                     "server.key_secret"]
    create_keys(strangers)
    with pytest.raises(InputError, match="exists; not overwriting"):
        create_keys(keys)
    port = free_port()
    background = Background(urban_search, bind=f"tcp://0.0.0.0:{port}", running=False,
                            curve_keys=str(keys))
    background.start()
    try:
        address = f"tcp://127.0.0.1:{port}"
        with Client(address, curve_keys=keys, timeout=5.0) as ok:
            assert ok.robot("op1")["type"] == "human"
            with ok.subscribe("state.") as stream:  # the stream is encrypted too
                for _ in range(20):
                    ok.step(by=0.5)
                    try:
                        assert stream.receive(timeout=0.2)[0].startswith("state.")
                        break
                    except ApiTimeout:
                        continue
                else:
                    pytest.fail("no state on the CURVE stream")
        with Client(address, timeout=0.5, retries=0) as plain, pytest.raises(ApiTimeout):
            plain.status()
        # a stranger's keys are well-formed but not among the server's clients
        (strangers / "server.key").write_bytes((keys / "server.key").read_bytes())
        with Client(address, curve_keys=strangers, timeout=0.5, retries=0) as stranger, \
                pytest.raises(ApiTimeout):
            stranger.status()
        ok_again = Client(address, curve_keys=keys, timeout=5.0)
        ok_again.shutdown()
        ok_again.close()
    finally:
        background.stop()


def test_a_busy_port_is_one_line_and_nothing_written(tmp_path: Path) -> None:
    with socket.socket() as busy:
        busy.bind(("127.0.0.1", 0))
        busy.listen()
        port = busy.getsockname()[1]
        run = subprocess.run([sys.executable, "-m", "astralis_des.cli", "serve", str(MISSION),
                              "--bind", f"tcp://127.0.0.1:{port}", "--out",
                              str(tmp_path / "out")], capture_output=True, text=True,
                             timeout=60)
    assert run.returncode == 2
    assert run.stderr.strip() == (f"error: --bind: cannot bind tcp://127.0.0.1:{port}: "
                                  "Address already in use")
    assert not (tmp_path / "out").exists()


def test_missing_keys_are_one_line(tmp_path: Path) -> None:
    run = subprocess.run([sys.executable, "-m", "astralis_des.cli", "serve", str(MISSION),
                          "--bind", f"tcp://0.0.0.0:{free_port()}", "--curve-keys",
                          str(tmp_path / "none"), "--out", str(tmp_path / "out")],
                         capture_output=True, text=True, timeout=60)
    assert run.returncode == 2
    assert run.stderr.strip() == (f"error: --curve-keys: {tmp_path / 'none'}/server.key_secret "
                                  f"is missing (make keys with astralis keys "
                                  f"{tmp_path / 'none'})")


# -- malformed requests --------------------------------------------------------------------
def _junk(gen: np.random.Generator) -> list[bytes]:
    """One malformed request, drawn: what a fuzzer or a careless client sends."""
    choices = [
        lambda: [gen.bytes(int(gen.integers(1, 200)))],
        lambda: [b"{" * int(gen.integers(1, 5000))],
        lambda: [b"[" * 100_000 + b"]" * 100_000],  # too large, deeply nested
        lambda: [json.dumps(gen.integers(0, 9, 3).tolist()).encode()],
        lambda: [b'{"op": "robot", "robot": 7}'],
        lambda: [b'{"op": "robot", "robot": "uav1", "extra": 1}'],
        lambda: [b'{"op": "stats"}'],
        lambda: [b'{"op": null}'],
        lambda: [b'{"op": "step", "by": NaN}'],
        lambda: [b'{"op": "step", "by": "5"}'],
        lambda: [b'{"op": "enqueue", "robot": "ugv1", "action": "hover"}'],
        lambda: [b'{"op": "enqueue", "robot": "uav1", "action": "move", "room": "Z.9"}'],
        lambda: [b'{"op": "location", "room": "' + b"A" * (MAX_MESSAGE + 10) + b'"}'],
        lambda: [b'{"op": "avatar", "id": ' + b'"' + b"x" * 300 + b'"}'],
        lambda: [b'{"op": "avatar"}', b"second frame"],
        lambda: ['{"op": "r\u00f6bot"}'.encode("utf-16")],
    ]
    return choices[int(gen.integers(len(choices)))]()


def test_malformed_requests_get_error_replies_and_the_server_keeps_serving(
        server: Background) -> None:
    gen = np.random.default_rng(10)
    ctx = zmq.Context()
    dealer = ctx.socket(zmq.DEALER)
    dealer.connect(server.address)
    codes: dict[str, int] = {}
    try:
        for _ in range(400):
            dealer.send_multipart([b"", *_junk(gen)])
            assert dealer.poll(5000), "no reply: the server hung"
            reply = json.loads(dealer.recv_multipart()[-1])
            assert reply["ok"] is False and reply["error"]["message"]
            codes[reply["error"]["code"]] = codes.get(reply["error"]["code"], 0) + 1
        assert {"bad_json", "bad_request", "bad_args", "unknown_op", "too_large",
                "bad_action", "unknown_room"} <= set(codes)
        assert "internal" not in codes
        # a message over ZeroMQ's hard limit drops that connection, not the server
        dealer.send_multipart([b"", b"x" * (HARD_LIMIT + 1)])
        with Client(server.address, timeout=5.0) as client:
            assert client.robot("uav1")["type"] == "uav"
    finally:
        ctx.destroy(linger=0)


def test_a_retried_command_runs_once(server: Background) -> None:
    ctx = zmq.Context()
    dealer = ctx.socket(zmq.DEALER)
    dealer.connect(server.address)
    try:
        frame = b'{"op": "enqueue", "robot": "uav1", "action": "hover", "id": "abc-1"}'
        replies = []
        for _ in range(2):
            dealer.send_multipart([b"", frame])
            assert dealer.poll(5000)
            replies.append(dealer.recv_multipart()[-1])
        assert replies[0] == replies[1]
        with Client(server.address) as client:
            assert len(client.queue("uav1")["queued"]) == 1
    finally:
        ctx.destroy(linger=0)


def test_two_clients_counting_ids_alike_both_run(server: Background) -> None:
    ctx = zmq.Context()
    try:
        for _ in range(2):  # each its own connection, both with id 1
            dealer = ctx.socket(zmq.DEALER)
            dealer.connect(server.address)
            dealer.send_multipart([b"", b'{"op": "enqueue", "robot": "uav2", '
                                   b'"action": "hover", "id": 1}'])
            assert dealer.poll(5000)
            assert json.loads(dealer.recv_multipart()[-1])["ok"]
        with Client(server.address) as client:
            assert len(client.queue("uav2")["queued"]) == 2
    finally:
        ctx.destroy(linger=0)


# -- the client's timeouts -----------------------------------------------------------------
class Flaky:
    """A ROUTER that loses the first reply to each request id (answers it late instead)."""

    def __init__(self) -> None:
        self.ctx = zmq.Context()
        self.sock = self.ctx.socket(zmq.ROUTER)
        self.address = f"tcp://127.0.0.1:{self.sock.bind_to_random_port('tcp://127.0.0.1')}"
        self.stop = False
        self.seen: list[str] = []
        self.thread = threading.Thread(target=self._run, daemon=True)
        self.thread.start()

    def _run(self) -> None:
        late: list[tuple[float, list[bytes]]] = []
        while not self.stop:
            for due, frames in [x for x in late if x[0] <= time.monotonic()]:
                self.sock.send_multipart(frames)
                late.remove((due, frames))
            if not self.sock.poll(10):
                continue
            ident, empty, body = self.sock.recv_multipart()
            request = json.loads(body)
            reply = [ident, empty, json.dumps({"id": request["id"], "ok": True,
                                               "result": {"op": request["op"]}}).encode()]
            if request["id"] in self.seen:
                self.sock.send_multipart(reply)
            else:  # the reply to a first try is "lost": it arrives 0.4 s later
                late.append((time.monotonic() + 0.4, reply))
            self.seen.append(request["id"])
        self.ctx.destroy(linger=0)


def test_a_lost_reply_never_wedges_the_client() -> None:
    flaky = Flaky()
    try:
        with Client(flaky.address, timeout=0.25, retries=1) as client:
            assert client.request("status") == {"op": "status"}  # answered on the retry
            assert client.request("avatar") == {"op": "avatar"}  # the late reply is skipped
            assert flaky.seen[0] == flaky.seen[1] != flaky.seen[2]  # a retry keeps its id
    finally:
        flaky.stop = True
        flaky.thread.join(5)


def test_no_server_is_a_timeout_naming_the_tries() -> None:
    start = time.monotonic()
    with Client(f"tcp://127.0.0.1:{free_port()}", timeout=0.2, retries=2) as client, \
            pytest.raises(ApiTimeout, match=r"no reply from tcp://127\.0\.0\.1:\d+ to 'status' "
                          r"after 3 tries of 0\.2 s"):
        client.status()
    assert time.monotonic() - start < 5.0  # 3 x 0.2 s, not the default 3 x 2 s


# -- astralis serve ------------------------------------------------------------------------
def test_serve_answers_and_ctrl_c_keeps_what_was_recorded(tmp_path: Path) -> None:
    port = free_port()
    out = tmp_path / "out"
    proc = subprocess.Popen([sys.executable, "-m", "astralis_des.cli", "serve", str(MISSION),
                             "--bind", f"tcp://127.0.0.1:{port}", "--pace", "5x",
                             "--out", str(out)], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, env={**os.environ,
                                                                     "COLUMNS": "200"})
    try:
        with Client(f"tcp://127.0.0.1:{port}", timeout=2.0, retries=15) as client:
            assert client.info()["addresses"]["stream"] == f"tcp://127.0.0.1:{port + 1}"
            client.enqueue("op1", "inspect", "A.1.1.3")
            time.sleep(0.5)
            assert client.status()["t"] > 0.5
        proc.send_signal(signal.SIGINT)
        _, err = proc.communicate(timeout=60)
    finally:
        proc.kill()
    assert proc.returncode == 130
    assert "requests on tcp://127.0.0.1:" in err and "command: op1 enqueue inspect A.1.1.3" in err
    assert "interrupted at t = " in err
    lines = [json.loads(x) for x in (out / "events.jsonl").read_text().splitlines()]
    assert lines[-1]["kind"] == "mission_end" and lines[-1]["outcome"] == "interrupted"
    assert (out / "recording.rrd").stat().st_size > 0


def test_a_50_mb_request_is_refused_at_once_not_left_to_time_out(server: Background) -> None:
    """The client refuses a request over the protocol's 64 KiB with ``too_large`` at once (a
    50 MB one used to be sent, dropped by ZeroMQ's hard limit, and waited for until the
    client's time-out); the server still answers afterwards."""
    from astralis_des.api.protocol import ApiError

    with Client(server.address, timeout=20.0, retries=0) as client:
        t0 = time.monotonic()
        with pytest.raises(ApiError) as refused:
            client.request("status", note="x" * 50_000_000)
        assert refused.value.code == "too_large"
        assert "50,000,0" in str(refused.value)
        assert time.monotonic() - t0 < 5.0
        assert client.robot("uav1")["type"] == "uav"
