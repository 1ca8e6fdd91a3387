"""The ZeroMQ server: a ROUTER socket answering JSON requests (REQ and DEALER clients both
work), a PUB socket streaming robot states and events by topic, and the loop that moves the
mission's time on between requests.

One thread does everything, so a request never sees the mission half-way through an event:
the loop runs the mission in slices of about a millisecond of wall time and answers whatever
has arrived between them.
"""

from __future__ import annotations

import json
import logging
import time
from typing import Any

import zmq

from astralis_des.api.protocol import DEFAULT_BIND, HARD_LIMIT, ApiError, encode
from astralis_des.api.queries import robot_state
from astralis_des.api.security import check_bind, secure_server
from astralis_des.api.service import Service
from astralis_des.errors import InputError
from astralis_des.kernel.events import Record

log = logging.getLogger(__name__)
BUDGET = 0.001  # wall s a slice of the mission may take before requests are looked at
TICK = 0.005  # wall s between slices when the mission is on time
IDLE = 0.05  # wall s a poll waits when the clock is stopped
MIN_SLICE, MAX_SLICE = 0.001, 10.0  # simulated s of a slice
BATCH = 500  # requests answered before the mission gets a turn
HWM = 10_000  # messages queued per peer before ZeroMQ drops


def stream_address(bind: str) -> str:
    """Where the state stream goes by default: the next port, or a sibling IPC path."""
    scheme, _, rest = bind.partition("://")
    if scheme == "tcp":
        host, _, port = rest.rpartition(":")
        return f"tcp://{host}:{int(port) + 1}" if port.isdigit() else f"tcp://{host}:*"
    return f"{bind}-stream"


class Server:
    """Sockets on ``bind`` (requests) and ``stream`` (the PUB stream), bound at once so that
    a bad address fails before any mission is built; :meth:`attach` gives them a service."""

    def __init__(self, bind: str = DEFAULT_BIND, *, stream: str | None = None,
                 curve_keys: str | None = None, state_rate: float = 10.0) -> None:
        stream = stream or stream_address(bind)
        check_bind(bind, curve_keys)
        check_bind(stream, curve_keys, key="--stream")
        self.ctx: zmq.Context[Any] = zmq.Context()
        self.router = self._socket(zmq.ROUTER)
        self.pub = self._socket(zmq.PUB)
        self.auth = None
        try:
            if curve_keys is not None:
                self.auth = secure_server(self.ctx, [self.router, self.pub], curve_keys)
            self.address = self._bind(self.router, bind, "--bind")
            self.stream = self._bind(self.pub, stream, "--stream")
        except BaseException:
            self.close()
            raise
        self.state_period = 1.0 / state_rate
        self._next_state = 0.0
        self._slice = 0.05
        self.published = 0
        self.service: Service

    def attach(self, service: Service) -> Server:
        """Serve this mission: its requests, its events and robot states on the stream."""
        self.service = service
        service.addresses.update(requests=self.address, stream=self.stream)
        service.sim.log.sinks.append(self._publish_event)
        service.after_advance.append(self._publish_states)
        return self

    def _socket(self, kind: int) -> zmq.Socket[Any]:
        sock = self.ctx.socket(kind)
        sock.linger = 0
        sock.setsockopt(zmq.MAXMSGSIZE, HARD_LIMIT)
        sock.sndhwm = sock.rcvhwm = HWM
        return sock

    @staticmethod
    def _bind(sock: zmq.Socket[Any], address: str, key: str) -> str:
        try:
            sock.bind(address)
        except zmq.ZMQError as exc:
            reason = zmq.strerror(exc.errno) if exc.errno is not None else str(exc)
            raise InputError(f"cannot bind {address}: {reason}",
                             key=key) from None
        return str(sock.getsockopt_string(zmq.LAST_ENDPOINT))

    # -- the loop --------------------------------------------------------------------------
    def serve_forever(self, *, exit_on_end: bool = False) -> None:
        """Answer requests and run the mission until a shutdown (or, with ``exit_on_end``,
        the mission's end). Ctrl-C raises KeyboardInterrupt out of here."""
        svc = self.service
        self._publish_states()
        while not svc.stopping and not (exit_on_end and svc.ended):
            self._serve(self._run_slice())
        # let the last replies (the shutdown's) leave before the sockets close
        self._flush()

    def _run_slice(self) -> float:
        """Move the mission on towards the wall clock; how long the next poll may wait."""
        svc, clock = self.service, self.service.clock
        if svc.ended or not clock.running:
            return IDLE
        now, target = svc.now, clock.target()
        if target <= now:
            return TICK
        until = min(target, now + self._slice)
        t0 = time.perf_counter()
        svc.advance(until)
        spent = time.perf_counter() - t0
        cost = spent / max(until - now, 1e-9)  # wall s per simulated s
        self._slice = min(max(BUDGET / max(cost, 1e-9), MIN_SLICE), MAX_SLICE)
        return 0.0 if clock.target() > svc.now else TICK

    def _serve(self, wait: float) -> None:
        if not self.router.poll(int(wait * 1000), zmq.POLLIN):
            return
        for _ in range(BATCH):
            try:
                frames = self.router.recv_multipart(zmq.NOBLOCK)
            except zmq.Again:
                return
            self._answer(frames)

    def _answer(self, frames: list[bytes]) -> None:
        if len(frames) >= 3 and frames[1] == b"":  # REQ, or a DEALER that sends a delimiter
            envelope, body = frames[:2], frames[2:]
        else:
            envelope, body = frames[:1], frames[1:]
        if len(body) != 1:
            reply = encode(ApiError("bad_request", f"a request is one frame of JSON, not "
                                    f"{len(body)}").reply())
        else:
            reply = self.service.handle_frame(body[0], peer=envelope[0])
        try:
            self.router.send_multipart([*envelope, reply], zmq.NOBLOCK)
        except zmq.ZMQError:  # the peer is gone or not reading: its reply is dropped
            log.debug("reply dropped")

    def _flush(self, seconds: float = 0.2) -> None:
        deadline = time.perf_counter() + seconds
        while time.perf_counter() < deadline and self.router.poll(10, zmq.POLLIN):
            self._serve(0.0)

    # -- the state stream ------------------------------------------------------------------
    def _send(self, topic: str, message: dict[str, Any]) -> None:
        try:
            self.pub.send_multipart([topic.encode(), json.dumps(message).encode()],
                                    zmq.NOBLOCK)
            self.published += 1
        except zmq.ZMQError:
            log.debug("stream message dropped")

    def _publish_event(self, record: Record) -> None:
        self._send(f"event.{record['kind']}", record)

    def _publish_states(self) -> None:
        """Each robot's state on ``state.<id>``, every ``state_period`` simulated seconds."""
        svc = self.service
        if svc.now < self._next_state and not svc.ended:
            return
        self._next_state = svc.now + self.state_period
        for robot in svc.sim.robots.values():
            message = robot_state(svc, robot)
            message["t"] = svc.now
            self._send(f"state.{robot.id}", message)

    def close(self) -> None:
        for sock in (self.router, self.pub):
            sock.close(linger=0)
        if self.auth is not None:
            self.auth.stop()
        self.ctx.term()
