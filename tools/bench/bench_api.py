"""API benchmark: request latency and throughput while a physics mission runs, and a soak.

    python tools/bench/bench_api.py [--seconds 20] [--soak 10000]

``astralis serve`` runs in its own process (as users run it) on loopback; this process is
the client. Measured in one run:
- latency of sequential requests (a mix of robot, status, location and queue queries) while
  the default mission runs in physics fidelity at 1x, then at 10x (median, p99, max);
- throughput: sequential, and with 16 requests in flight on one DEALER socket;
- a soak on a paused physics server: ``--soak`` requests, one in five malformed (not JSON,
  wrong shapes, unknown ops, robots and rooms, oversized) or a refused command; the server's
  resident memory before (after 1,000 warm-up requests) and after. The clock is paused so
  that the mission's own growth (its event log, trails, recording) does not count.
"""

from __future__ import annotations

import argparse
import json
import os
import socket
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np
import zmq

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))

from astralis_des.api import Client  # noqa: E402

MISSION = ROOT / "missions" / "urban_search.yaml"
QUERIES = [b'{"op":"robot","robot":"uav1","id":%d}', b'{"op":"status","id":%d}',
           b'{"op":"location","room":"A.1.2.1","id":%d}', b'{"op":"queue","robot":"ugv1","id":%d}']
JUNK = [b"not json at all", b"[1, 2, 3]", b'{"op": "stauts"}', b'{"op": "robot"}',
        b'{"op": "robot", "robot": "uav9"}', b'{"op": "location", "room": "Z.1"}',
        b'{"op": "step", "by": "5"}', b'{"op": "enqueue", "robot": "ugv1", "action": "hover"}',
        b'{"op": "robot", "robot": "uav1", "x": 1}', b"{" * 3000, b"\xff\xfe\x00garbage",
        b'{"op": "location", "room": "' + b"A" * 70_000 + b'"}']


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def serve(*extra: str) -> tuple[subprocess.Popen[bytes], str]:
    port = free_port()
    address = f"tcp://127.0.0.1:{port}"
    proc = subprocess.Popen([sys.executable, "-m", "astralis_des.cli", "serve", str(MISSION),
                             "--bind", address, "--fidelity", "physics", "--quiet",
                             "--no-recording", "--out", f"/tmp/bench_api_{port}", *extra],
                            stdout=subprocess.DEVNULL)
    with Client(address, timeout=2.0, retries=30) as client:
        client.info()
    return proc, address


def stop(proc: subprocess.Popen[bytes], address: str) -> None:
    with Client(address, timeout=5.0) as client:
        client.shutdown()
    proc.wait(60)


def sequential(address: str, seconds: float) -> tuple[np.ndarray, float]:
    """Latencies (ms) of back-to-back requests for ``seconds``; and the simulated time then."""
    ctx = zmq.Context()
    sock = ctx.socket(zmq.DEALER)
    sock.connect(address)
    lat = []
    end = time.perf_counter() + seconds
    i = 0
    while time.perf_counter() < end:
        i += 1
        t0 = time.perf_counter()
        sock.send_multipart([b"", QUERIES[i % len(QUERIES)] % i])
        reply = json.loads(sock.recv_multipart()[-1])
        lat.append(time.perf_counter() - t0)
        assert reply["ok"], reply
    sock.send_multipart([b"", b'{"op":"status"}'])
    now = json.loads(sock.recv_multipart()[-1])["result"]["t"]
    ctx.destroy(linger=0)
    return np.array(lat) * 1e3, now


def pipelined(address: str, seconds: float, window: int = 16) -> float:
    """Requests per second with ``window`` requests in flight."""
    ctx = zmq.Context()
    sock = ctx.socket(zmq.DEALER)
    sock.connect(address)
    sent = done = 0
    for _ in range(window):
        sent += 1
        sock.send_multipart([b"", QUERIES[sent % 4] % sent])
    t0 = time.perf_counter()
    while time.perf_counter() - t0 < seconds:
        sock.recv_multipart()
        done += 1
        sent += 1
        sock.send_multipart([b"", QUERIES[sent % 4] % sent])
    rate = done / (time.perf_counter() - t0)
    ctx.destroy(linger=0)
    return rate


def rss_kib(pid: int) -> int:
    for line in Path(f"/proc/{pid}/status").read_text().splitlines():
        if line.startswith("VmRSS:"):
            return int(line.split()[1])
    raise RuntimeError("no VmRSS")


def soak(proc: subprocess.Popen[bytes], address: str, count: int) -> dict[str, Any]:
    gen = np.random.default_rng(0)
    ctx = zmq.Context()
    sock = ctx.socket(zmq.DEALER)
    sock.connect(address)
    sock.rcvtimeo = 10_000

    def one(i: int) -> bool:
        frame = (JUNK[int(gen.integers(len(JUNK)))] if gen.random() < 0.2
                 else QUERIES[i % 4] % i)
        sock.send_multipart([b"", frame])
        return bool(json.loads(sock.recv_multipart()[-1])["ok"])

    for i in range(1000):
        one(i)
    before = rss_kib(proc.pid)
    t0 = time.perf_counter()
    refused = sum(not one(i) for i in range(count))
    seconds = time.perf_counter() - t0
    after = rss_kib(proc.pid)
    ctx.destroy(linger=0)
    return {"refused": refused, "seconds": seconds, "before": before, "after": after,
            "alive": proc.poll() is None}


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--seconds", type=float, default=20.0)
    parser.add_argument("--soak", type=int, default=10_000)
    args = parser.parse_args()
    print(f"astralis serve, default mission in physics fidelity, loopback; {os.cpu_count()} "
          "CPUs")
    for pace, seconds in (("1x", args.seconds), ("10x", min(args.seconds, 6.0))):
        proc, address = serve("--pace", pace)
        time.sleep(1.0)  # the mission's first round and its first motions
        lat, now = sequential(address, seconds)
        rate = pipelined(address, 3.0) if pace == "1x" else float("nan")
        stop(proc, address)
        print(f"pace {pace}: {len(lat):,} requests in {seconds:g} s while the mission ran to "
              f"t = {now:.1f} s: latency median {np.median(lat):.3f} ms (goal < 1), p99 "
              f"{np.percentile(lat, 99):.3f} ms (goal < 5), max {lat.max():.1f} ms; "
              f"sequential {len(lat) / seconds:,.0f} req/s"
              + (f", 16 in flight {rate:,.0f} req/s (goal >= 2,000)" if pace == "1x" else ""))
    proc, address = serve("--stepped")
    result = soak(proc, address, args.soak)
    growth = result["after"] / result["before"] - 1.0
    with Client(address, timeout=5.0) as client:
        still = client.robot("uav1")["type"] == "uav"
    stop(proc, address)
    print(f"soak: {args.soak:,} requests ({result['refused']:,} refused) in "
          f"{result['seconds']:.1f} s; server alive and answering: {result['alive'] and still}; "
          f"resident memory {result['before'] / 1024:.1f} -> {result['after'] / 1024:.1f} MiB "
          f"({growth:+.1%}, goal < +10%)")


if __name__ == "__main__":
    main()
