"""The Python client: ``Client(address).status()``; timeouts and retries, never wedged.

It talks through a DEALER socket, so a lost reply leaves nothing stuck (a REQ socket would
wait for it forever): each try waits ``timeout`` seconds, a retry resends the same request id
(the server answers a repeated command from its cache instead of running it twice), and
replies to earlier tries are told apart by their id and dropped.
"""

from __future__ import annotations

import itertools
import json
import os
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import zmq

from astralis_des.api.protocol import DEFAULT_BIND, MAX_MESSAGE, ApiError, ApiTimeout
from astralis_des.api.security import secure_client


class Client:
    def __init__(self, address: str = DEFAULT_BIND, *, timeout: float = 2.0, retries: int = 2,
                 curve_keys: str | Path | None = None) -> None:
        self.address = address
        self.timeout = timeout
        self.retries = retries
        self.curve_keys = curve_keys
        self._ctx: zmq.Context[Any] = zmq.Context()
        self._prefix = f"{os.getpid():x}{id(self) & 0xFFFFFF:x}"
        self._ids = itertools.count(1)
        self._sock = self._connect()

    def _connect(self) -> zmq.Socket[Any]:
        sock = self._ctx.socket(zmq.DEALER)
        sock.linger = 0
        if self.curve_keys is not None:
            secure_client(sock, self.curve_keys)
        sock.connect(self.address)
        return sock

    def request(self, op: str, *, timeout: float | None = None, retries: int | None = None,
                **args: Any) -> Any:
        """Send ``{"op": op, **args}``; the reply's result, or :class:`ApiError` (the server
        refused: its code and message) or :class:`ApiTimeout` (no reply after the retries).
        ``timeout`` and ``retries`` override the client's for this request."""
        reserved = sorted({"op", "id"} & set(args))
        if reserved:  # the envelope's own keys: the request would lose its id and time out
            raise ApiError("bad_args", f"'{reserved[0]}' is the request's own key, not an "
                           f"argument of '{op}'")
        request_id = f"{self._prefix}-{next(self._ids)}"
        frame = json.dumps({"op": op, "id": request_id, **args}).encode()
        if len(frame) > MAX_MESSAGE:  # the server would refuse it, or (over its hard limit)
            raise ApiError("too_large", f"the request is {len(frame):,} bytes; the limit is "
                           f"{MAX_MESSAGE:,}")  # drop the connection: not sent at all
        wait = self.timeout if timeout is None else timeout
        tries = 1 + (self.retries if retries is None else retries)
        for _ in range(tries):
            self._sock.send_multipart([b"", frame])
            reply = self._await(request_id, wait)
            if reply is not None:
                if reply.get("ok"):
                    return reply.get("result")
                error = reply.get("error") or {}
                raise ApiError(str(error.get("code", "error")), str(error.get("message", "")))
        self._sock.close(linger=0)  # start clean: nothing stale queued for a dead server
        self._sock = self._connect()
        raise ApiTimeout(f"no reply from {self.address} to '{op}' after {tries} "
                         f"{'try' if tries == 1 else 'tries'} of {wait:g} s")

    def _await(self, request_id: str, wait: float) -> dict[str, Any] | None:
        deadline = time.monotonic() + wait
        while (left := deadline - time.monotonic()) > 0:
            if not self._sock.poll(max(1, int(left * 1000)), zmq.POLLIN):
                return None
            frames = self._sock.recv_multipart()
            try:
                reply = json.loads(frames[-1])
            except ValueError:
                continue
            if isinstance(reply, dict) and reply.get("id") == request_id:
                return reply
        return None

    # -- queries ---------------------------------------------------------------------------
    def info(self) -> dict[str, Any]:
        return self.request("info")

    def status(self, robot: str | None = None) -> dict[str, Any]:
        return self.request("status", **_given(robot=robot))

    def avatar(self, avatar: str | None = None) -> dict[str, Any]:
        """The target's Table II attributes, or a bystander's by its id (``avatars``)."""
        return self.request("avatar", avatar=avatar) if avatar is not None else \
            self.request("avatar")

    def avatars(self, room: str | None = None) -> dict[str, Any]:
        """The bystanders of the rooms furnished so far (or of ``room``)."""
        return self.request("avatars", room=room) if room is not None else \
            self.request("avatars")

    def location(self, room: str) -> dict[str, Any]:
        return self.request("location", room=room)

    def robot(self, robot: str) -> dict[str, Any]:
        return self.request("robot", robot=robot)

    def reading(self, robot: str, sensor: str) -> dict[str, Any]:
        """The latest reading of a robot's ``gnss``, ``barometer`` or ``magnetometer``."""
        return self.request("reading", robot=robot, sensor=sensor)

    def queue(self, robot: str) -> dict[str, Any]:
        return self.request("queue", robot=robot)

    def events(self, since: float | None = None, after: int = 0,
               kinds: list[str] | None = None, robot: str | None = None,
               limit: int = 1000, last: int | None = None) -> dict[str, Any]:
        return self.request("events", after=after, limit=limit,
                            **_given(since=since, kinds=kinds, robot=robot, last=last))

    # -- commands --------------------------------------------------------------------------
    def enqueue(self, robot: str, action: str, room: str | None = None,
                params: dict[str, Any] | None = None, preempt: bool = False) -> dict[str, Any]:
        return self.request("enqueue", robot=robot, action=action,
                            preempt=preempt, **_given(room=room, params=params))

    def preempt(self, robot: str, action: str, room: str | None = None,
                params: dict[str, Any] | None = None) -> dict[str, Any]:
        return self.request("preempt", robot=robot, action=action,
                            **_given(room=room, params=params))

    def cancel(self, robot: str, task: int | None = None) -> dict[str, Any]:
        return self.request("cancel", robot=robot, **_given(task=task))

    def pause(self) -> dict[str, Any]:
        return self.request("pause")

    def resume(self, pace: float | None = None) -> dict[str, Any]:
        return self.request("resume", **_given(pace=pace))

    def step(self, until: float | None = None, by: float | None = None,
             timeout: float = 120.0) -> dict[str, Any]:
        """Run a paused mission on; physics may take a while, hence the longer timeout."""
        return self.request("step", timeout=timeout,
                            **_given(until=until, by=by))

    def assign(self, segment: str, rooms: list[str] | None = None,
               robots: list[str] | None = None) -> dict[str, Any]:
        return self.request("assign", segment=segment,
                            **_given(rooms=rooms, robots=robots))

    def teleop(self, robot: str, direction: str, distance: float = 0.5) -> dict[str, Any]:
        return self.request("teleop", robot=robot,
                            direction=direction, distance=distance)

    def shutdown(self) -> dict[str, Any]:
        return self.request("shutdown")

    # -- the state stream ------------------------------------------------------------------
    def subscribe(self, *topics: str, address: str | None = None) -> Subscription:
        """The server's PUB stream (``state.<robot>``, ``event.<kind>``), filtered by topic
        prefixes (all of it by default)."""
        address = address or self.info()["addresses"]["stream"]
        return Subscription(self._ctx, address, topics or ("",), self.curve_keys,
                            self.timeout)

    def close(self) -> None:
        self._ctx.destroy(linger=0)  # its subscriptions too

    def __enter__(self) -> Client:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


class Subscription:
    def __init__(self, ctx: zmq.Context[Any], address: str, topics: tuple[str, ...],
                 curve_keys: str | Path | None, timeout: float) -> None:
        self.timeout = timeout
        self._sock = ctx.socket(zmq.SUB)
        self._sock.linger = 0
        if curve_keys is not None:
            secure_client(self._sock, curve_keys)
        for topic in topics:
            self._sock.setsockopt_string(zmq.SUBSCRIBE, topic)
        self._sock.connect(address)

    def receive(self, timeout: float | None = None) -> tuple[str, dict[str, Any]]:
        """The next ``(topic, message)``; :class:`ApiTimeout` if none comes in time."""
        wait = self.timeout if timeout is None else timeout
        if not self._sock.poll(max(1, int(wait * 1000)), zmq.POLLIN):
            raise ApiTimeout(f"nothing on the stream for {wait:g} s")
        topic, body = self._sock.recv_multipart()
        return topic.decode(), json.loads(body)

    def __iter__(self) -> Iterator[tuple[str, dict[str, Any]]]:
        while True:
            yield self.receive()

    def close(self) -> None:
        self._sock.close(linger=0)

    def __enter__(self) -> Subscription:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def _given(**values: Any) -> dict[str, Any]:
    return {k: v for k, v in values.items() if v is not None}
