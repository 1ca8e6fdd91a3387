"""A bounded store of answers that depend only on an immutable world and their key (routes,
places): the least recently asked dropped past its size."""

from __future__ import annotations

from collections import OrderedDict
from collections.abc import Callable, Hashable
from typing import Generic, TypeVar

V = TypeVar("V")


class Kept(Generic[V]):
    """Answers by key, up to ``size`` of them; ``make`` answers a key not kept (what it raises
    is raised, and nothing kept)."""

    def __init__(self, size: int) -> None:
        self.size = size
        self._values: OrderedDict[Hashable, V] = OrderedDict()

    def get(self, key: Hashable, make: Callable[[], V]) -> V:
        values = self._values
        if key in values:
            values.move_to_end(key)
            return values[key]
        value = values[key] = make()
        if len(values) > self.size:
            values.popitem(last=False)
        return value

    def __len__(self) -> int:
        return len(self._values)
