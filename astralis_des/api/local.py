"""A server in a thread of this process: for ``astralis chat MISSION.yaml``, notebooks and
tests. ``with serving(mission) as address: Client(address)...``."""

from __future__ import annotations

import threading
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

from astralis_des.api.protocol import ApiError
from astralis_des.api.server import Server
from astralis_des.api.service import Service
from astralis_des.api.session import Clock
from astralis_des.mission.loader import Mission
from astralis_des.simulation.result import RunResult


class Background:
    """Serve a mission from a thread; the mission and its PyBullet world live in that thread."""

    def __init__(self, mission: Mission, *, bind: str = "tcp://127.0.0.1:*",
                 pace: float = 1.0, running: bool = True, out_dir: str | Path | None = None,
                 curve_keys: str | None = None, stream: str | None = None) -> None:
        self._args: dict[str, Any] = dict(mission=mission, bind=bind, pace=pace,
                                          running=running, out_dir=out_dir,
                                          curve_keys=curve_keys, stream=stream)
        self.address = ""
        self.stream = ""
        self.result: RunResult | None = None
        self.error: BaseException | None = None
        self._ready = threading.Event()
        self._service: Service | None = None
        self._thread = threading.Thread(target=self._main, name="astralis-serve", daemon=True)

    def start(self, timeout: float = 60.0) -> str:
        self._thread.start()
        if not self._ready.wait(timeout):
            raise ApiError("timeout", f"the server did not start in {timeout:g} s")
        if self.error is not None:
            raise self.error
        return self.address

    def _main(self) -> None:
        from astralis_des.simulation import Simulation

        a = self._args
        server = None
        try:
            server = Server(a["bind"], stream=a["stream"], curve_keys=a["curve_keys"])
            sim = Simulation(a["mission"], out_dir=a["out_dir"])
            self._service = Service(sim, Clock(a["pace"], a["running"]))
            server.attach(self._service)
            self.address, self.stream = server.address, server.stream
        except BaseException as exc:
            if server is not None:
                server.close()
            self.error = exc
            self._ready.set()
            return
        self._ready.set()
        try:
            server.serve_forever()
        finally:
            server.close()
            self.result = self._service.end()

    def stop(self, timeout: float = 60.0) -> RunResult | None:
        """Ask the loop to stop (as a shutdown request would) and wait for the outputs."""
        if self._service is not None:
            self._service.stopping = True
        self._thread.join(timeout)
        return self.result


@contextmanager
def serving(mission: Mission, **options: Any) -> Iterator[str]:
    background = Background(mission, **options)
    address = background.start()
    try:
        yield address
    finally:
        background.stop()
