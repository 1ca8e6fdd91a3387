"""The chat's and teleop's connection: a :class:`~astralis_des.api.client.Client` to a server
that has answered, or one line saying there is none."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

from astralis_des.errors import InputError

if TYPE_CHECKING:
    from astralis_des.api.client import Client

PROBE = 3.0  # s at most to wait for the first reply: a missing server is told at once
RETRIES = 2  # once it has answered


def connect(address: str, timeout: float, curve_keys: str | Path | None = None
            ) -> tuple[Client, dict[str, Any]]:
    """A client to ``address`` and the server's ``info``; :class:`InputError` (one line, exit
    2) if nothing answers there."""
    import zmq

    from astralis_des.api.client import Client
    from astralis_des.api.protocol import ApiError, ApiTimeout

    if timeout <= 0:
        raise InputError(f"must be above 0 (got {timeout:g})", key="--timeout")
    try:
        client = Client(address, timeout=timeout, retries=RETRIES, curve_keys=curve_keys)
    except zmq.ZMQError as exc:
        raise InputError(f"cannot connect to '{address}': {exc}", key="--connect") from None
    try:
        info = client.request("info", timeout=min(timeout, PROBE), retries=0)
    except ApiTimeout:
        client.close()
        keys = " or it refuses these CURVE keys" if curve_keys is not None else ""
        raise InputError(f"no server at {address} (start one with astralis serve "
                         f"MISSION.yaml){keys}") from None
    except ApiError as exc:
        client.close()
        raise InputError(f"the server at {address} refused 'info': {exc.message}") from None
    return client, info
