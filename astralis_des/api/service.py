"""The mission behind the API: requests in, replies out, no sockets.

:class:`Service` owns a started :class:`~astralis_des.simulation.core.Simulation` and its
:class:`Clock`. The server (:mod:`.server`) moves time on and hands it frames; tests and the
in-process chat can call :meth:`Service.handle` directly.
"""

from __future__ import annotations

import logging
from collections import OrderedDict
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

from astralis_des.api.ops import OPS
from astralis_des.api.protocol import ApiError, decode, encode, finite
from astralis_des.api.session import Clock
from astralis_des.errors import suggest
from astralis_des.registry import UnknownEntry

if TYPE_CHECKING:
    from astralis_des.kernel.robot import Robot
    from astralis_des.simulation import Simulation
    from astralis_des.simulation.result import RunResult
    from astralis_des.world.model import Room

log = logging.getLogger(__name__)
REPLAYS = 1024  # replies to commands kept by connection and request id: a retry is not run
# twice (and two clients that both count their ids from 1 do not meet)


class Service:
    """A started mission answering requests (a :class:`~astralis_des.api.session.Session`)."""

    def __init__(self, sim: Simulation, clock: Clock | None = None) -> None:
        self.sim = sim
        self.clock = clock or Clock()
        self.result: RunResult | None = None
        self.stopping = False  # a shutdown was asked for
        self.addresses: dict[str, str] = {}  # requests, stream: where the server listens
        self.after_advance: list[Callable[[], None]] = []
        self.teleop_goals: dict[str, tuple[int, Any]] = {}  # robot -> (task, goal)
        self.requests = 0
        self.errors = 0
        self._replies: OrderedDict[tuple[bytes, Any], bytes] = OrderedDict()
        sim.navigator.prepare()
        sim.start()
        self.clock.anchor(sim.env.now)

    # -- time ------------------------------------------------------------------------------
    @property
    def now(self) -> float:
        return float(self.sim.env.now)

    @property
    def ended(self) -> bool:
        return self.result is not None

    def advance(self, until: float | None) -> bool:
        """Run the mission to ``until`` (or its end); true once it has ended."""
        if self.result is None and self.sim.advance(until):
            self.end()
        for listener in self.after_advance:
            listener()
        return self.result is not None

    def end(self) -> RunResult:
        """Finish the run where it is (writes the outputs) unless it has ended already."""
        if self.result is None:
            self.result = self.sim.finish()
        return self.result

    # -- requests --------------------------------------------------------------------------
    def handle_frame(self, frame: bytes, peer: bytes = b"") -> bytes:
        """One request frame (from the connection ``peer``) to its reply frame; never
        raises."""
        request_id: Any = None
        try:
            request = decode(frame)
            request_id = request.get("id")
            key = (peer, request_id) if request_id is not None else None
            if key is not None and key in self._replies:  # a client's retry of a command
                return self._replies[key]
            reply, command = self._answer(request)
            data = encode(reply)
            if key is not None and reply["ok"] and command:
                self._replies[key] = data
                if len(self._replies) > REPLAYS:
                    self._replies.popitem(last=False)
            return data
        except ApiError as exc:
            self.errors += 1
            return encode(exc.reply(request_id))
        except Exception as exc:  # a bug must not take the server down with it
            log.exception("request failed")
            self.errors += 1
            return encode(ApiError("internal", f"{type(exc).__name__}: {exc}").reply(request_id))

    def handle(self, request: dict[str, Any]) -> dict[str, Any]:
        """A decoded request to its reply (``ok`` true or false)."""
        return self._answer(request)[0]

    def _answer(self, request: dict[str, Any]) -> tuple[dict[str, Any], bool]:
        """The reply, and whether the request was a command that ran (its reply is kept
        for retries)."""
        self.requests += 1
        request_id = request.get("id")
        try:
            try:
                spec = OPS.get(request["op"])
            except UnknownEntry:
                raise ApiError("unknown_op", f"no op '{request['op']}'; "
                               f"{suggest(str(request['op']), list(OPS))}") from None
            args = spec.parse(request)
            if spec.command and self.result is not None and spec.name != "shutdown":
                raise ApiError("ended", f"the mission has ended ({self.result.outcome}, "
                               f"t = {self.now:.1f} s); only queries are answered")
            result = spec.fn(self, args)
        except ApiError as exc:
            self.errors += 1
            return exc.reply(request_id), False
        return {"id": request_id, "ok": True, "result": finite(result)}, spec.command

    # -- what requests name ----------------------------------------------------------------
    def robot(self, robot_id: str) -> Robot:
        robot = self.sim.robots.get(robot_id)
        if robot is None:
            raise ApiError("unknown_robot", f"no robot '{robot_id}'; "
                           f"{suggest(robot_id, self.sim.robots)}")
        return robot

    def room(self, room_id: str) -> Room:
        room = self.sim.world.rooms.get(room_id)
        if room is None:
            raise ApiError("unknown_room", f"no room '{room_id}' in world "
                           f"'{self.sim.world.name}'; {suggest(room_id, self.sim.world.rooms)}")
        return room

    def command_event(self, op: str, robot: str | None = None, **fields: Any) -> None:
        """A command, as an event of the mission's log (and so of its recording)."""
        given = {k: v for k, v in fields.items() if v is not None}
        self.sim.log.emit("command", robot, op=op, source="api", **given)
