"""JSON that any reader takes: a NaN or an infinity is an error naming where it is, never
``NaN`` in a file (``dumps``, ``finite``); a journal's lines keep them tagged
(``journal_dumps``, ``journal_loads``). Re-exported by :mod:`astralis_des.outdir`."""

from __future__ import annotations

import json
import math
from collections.abc import Callable
from typing import Any


def dumps(value: Any, **options: Any) -> str:
    """JSON that any reader takes: a NaN or an infinity is an error naming where it is,
    never ``NaN`` in a file."""
    try:
        return json.dumps(value, allow_nan=False, **options)
    except ValueError as exc:
        where = _non_finite(value, "")
        if where is None:
            raise
        raise ValueError(f"{where or 'the value'} is not a number JSON can hold") from exc


def encoder(**options: Any) -> Callable[[Any], str]:
    """:func:`dumps` with ``options`` set once (a JSON encoder made once rather than at each
    call: an event log's lines)."""
    encode = json.JSONEncoder(allow_nan=False, **options).encode

    def dumps_one(value: Any) -> str:
        try:
            return encode(value)
        except ValueError:
            return dumps(value, **options)  # raises, naming where the NaN is
    return dumps_one


def _non_finite(value: Any, path: str) -> str | None:
    if isinstance(value, float) and not math.isfinite(value):
        return f"{path} = {value}"
    items = value.items() if isinstance(value, dict) else (
        enumerate(value) if isinstance(value, list | tuple) else ())
    for key, item in items:
        found = _non_finite(item, f"{path}[{key}]" if isinstance(key, int) else
                            (f"{path}.{key}" if path else str(key)))
        if found is not None:
            return found
    return None


def finite(value: Any) -> Any:
    """``value`` with each NaN or infinity as ``None``: for files where "no number" is a
    fair reading (a tune's best trial)."""
    if isinstance(value, float) and not math.isfinite(value):
        return None
    if isinstance(value, dict):
        return {k: finite(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [finite(v) for v in value]
    return value


def journal_dumps(value: Any) -> str:
    """One line of a journal this package reads back (a tune's trials): strict JSON, with
    each NaN or infinity as ``{"$float": "inf"}`` so it reads back as it was."""
    return dumps(_tagged(value), default=str)


def journal_loads(line: str) -> Any:
    return json.loads(line, object_hook=lambda d: float(d["$float"]) if d.keys() == {"$float"}
                      else d)


def _tagged(value: Any) -> Any:
    if isinstance(value, float) and not math.isfinite(value):
        return {"$float": str(value)}
    if isinstance(value, dict):
        return {k: _tagged(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [_tagged(v) for v in value]
    return value
