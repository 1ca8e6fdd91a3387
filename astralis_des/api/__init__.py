"""The external API: a ZeroMQ request/reply server for the paper's Table II queries and the
team's commands, a PUB state stream, and :class:`Client`.

``astralis serve MISSION.yaml`` serves a mission; ``Client("tcp://127.0.0.1:5555")`` talks
to it. See ``docs/api.md`` for the operations.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from astralis_des.api.protocol import ApiError, ApiTimeout

if TYPE_CHECKING:
    from astralis_des.api.client import Client, Subscription

__all__ = ["ApiError", "ApiTimeout", "Client", "Subscription"]


def __getattr__(name: str) -> Any:  # the client (and ZeroMQ) load on first use
    if name in ("Client", "Subscription"):
        from astralis_des.api import client

        return getattr(client, name)
    raise AttributeError(name)
