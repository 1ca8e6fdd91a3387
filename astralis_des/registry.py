"""One registry idiom for actions, strategies, co-simulations and timeline events."""

from __future__ import annotations

from collections.abc import Callable, Hashable, Iterator
from typing import Generic, TypeVar

from astralis_des.errors import suggest

K = TypeVar("K", bound=Hashable)
V = TypeVar("V")


class UnknownEntry(LookupError):
    """A failed lookup; the message lists what exists."""


class Registry(Generic[K, V]):
    """Entries registered by decorator; a duplicate key is a bug and is refused."""

    def __init__(self, what: str) -> None:
        self.what = what
        self._entries: dict[K, V] = {}

    def register(self, key: K) -> Callable[[V], V]:
        def add(entry: V) -> V:
            if key in self._entries:
                raise ValueError(f"{self.what} {key!r} is registered twice")
            self._entries[key] = entry
            return entry

        return add

    def get(self, key: K) -> V:
        try:
            return self._entries[key]
        except KeyError:
            names = [self._name(k) for k in self._entries]
            raise UnknownEntry(
                f"unknown {self.what} {self._name(key)!r}; {suggest(self._name(key), names)}"
            ) from None

    def __contains__(self, key: object) -> bool:
        return key in self._entries

    def __iter__(self) -> Iterator[K]:
        return iter(sorted(self._entries, key=self._name))

    @staticmethod
    def _name(key: object) -> str:
        return "/".join(map(str, key)) if isinstance(key, tuple) else str(key)
