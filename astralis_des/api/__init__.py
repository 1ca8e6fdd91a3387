"""The external API: a ZeroMQ request/reply server for the paper's Table II queries and the
team's commands, a PUB state stream, and :class:`Client`.

``astralis serve MISSION.yaml`` serves a mission; ``Client("tcp://127.0.0.1:5555")`` talks
to it. See ``docs/api.md`` for the operations.
"""

from astralis_des.api.client import Client, Subscription
from astralis_des.api.protocol import ApiError, ApiTimeout

__all__ = ["ApiError", "ApiTimeout", "Client", "Subscription"]
