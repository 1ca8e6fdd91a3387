"""The wire format: one JSON object per request and per reply, one ZeroMQ frame each.

A request is ``{"op": NAME, "id": ANY, ...arguments}``; its reply is
``{"id": ID, "ok": true, "result": {...}}`` or
``{"id": ID, "ok": false, "error": {"code": CODE, "message": ONE_LINE}}``.
Nothing but JSON is ever decoded (never pickle).
"""

from __future__ import annotations

import json
import math
from typing import Any

PROTOCOL = 1
DEFAULT_BIND = "tcp://127.0.0.1:5555"
MAX_MESSAGE = 64 * 1024  # bytes: a longer request gets an error reply
HARD_LIMIT = 16 * MAX_MESSAGE  # bytes: ZeroMQ drops a peer that sends more (MAXMSGSIZE)
MAX_ID = 128  # characters of a request id
MAX_PACE = 1000.0  # simulated seconds per wall second
MAX_TELEOP_STEP = 5.0  # m of one teleop step


def read_pace(text: str) -> float:
    """``10``, ``10x`` or ``0.5x``: simulated seconds per wall second (ValueError if not)."""
    try:
        pace = float(text.strip().lower().removesuffix("x"))
    except ValueError:
        raise ValueError(f"'{text}' is not a pace like 1x or 10x") from None
    if not 0.0 < pace <= MAX_PACE:
        raise ValueError(f"the pace must be above 0 and at most {MAX_PACE:g}x (got {text})")
    return pace


class ApiError(Exception):
    """A request the server refused, or a failure the client saw: a code and one line."""

    def __init__(self, code: str, message: str) -> None:
        message = " ".join(message.split())  # one line, whatever the request put in it
        super().__init__(message)
        self.code = code
        self.message = message

    def reply(self, request_id: Any = None) -> dict[str, Any]:
        return {"id": request_id, "ok": False,
                "error": {"code": self.code, "message": self.message}}


class ApiTimeout(ApiError):
    """No reply within the client's timeout, after all its tries."""

    def __init__(self, message: str) -> None:
        super().__init__("timeout", message)


def _constant(name: str) -> Any:
    raise ValueError(f"{name} is not JSON")


def decode(frame: bytes) -> dict[str, Any]:
    """A request frame to its object; an :class:`ApiError` says what is wrong with it."""
    if len(frame) > MAX_MESSAGE:
        raise ApiError("too_large", f"the request is {len(frame):,} bytes; the limit is "
                       f"{MAX_MESSAGE:,}")
    try:
        request = json.loads(frame, parse_constant=_constant)
    except RecursionError:
        raise ApiError("bad_json", "the request is nested too deeply") from None
    except ValueError as exc:  # also UnicodeDecodeError
        raise ApiError("bad_json", f"the request is not JSON: {_short(exc)}") from None
    if not isinstance(request, dict):
        raise ApiError("bad_request", "a request is a JSON object with an 'op', not a "
                       f"{type(request).__name__}")
    request_id = request.get("id")
    if request_id is not None and not (isinstance(request_id, str | int)
                                       and len(str(request_id)) <= MAX_ID):
        raise ApiError("bad_request", f"'id' must be a string or an integer of at most "
                       f"{MAX_ID} characters")
    if not isinstance(request.get("op"), str):
        raise ApiError("bad_request", "the request has no 'op' (a string): "
                       "try {\"op\": \"help\"}")
    return request


def encode(reply: dict[str, Any]) -> bytes:
    return json.dumps(reply, separators=(",", ":"), allow_nan=False,
                      default=_default).encode()


def _default(value: Any) -> Any:
    """numpy scalars and arrays, tuples of them: plain JSON; non-finite floats: null."""
    if hasattr(value, "tolist"):
        return finite(value.tolist())
    raise TypeError(f"{type(value).__name__} is not JSON")


def finite(value: Any) -> Any:
    """Non-finite floats (no route, an infinite cost) as null: JSON has no infinity."""
    if isinstance(value, float):
        return value if math.isfinite(value) else None
    if isinstance(value, list | tuple):
        return [finite(v) for v in value]
    if isinstance(value, dict):
        return {k: finite(v) for k, v in value.items()}
    return value


def _short(exc: Exception) -> str:
    text = str(exc)
    return text if len(text) <= 120 else text[:117] + "..."
