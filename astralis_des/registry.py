"""One registry idiom for actions, strategies, co-simulations, sinks and timeline events.

A registry may name its ``plugins``: modules imported (by name, with :mod:`importlib`) the
first time it is looked into, whose import registers the entries. So a lower layer can hold a
registry whose entries live in a higher one (the mission layer checks action names; the
actions, which need the kernel, register them), and nothing imports upward.
"""

from __future__ import annotations

import importlib
from collections.abc import Callable, Hashable, Iterator
from typing import Generic, TypeVar

from astralis_des.errors import suggest

K = TypeVar("K", bound=Hashable)
V = TypeVar("V")


class UnknownEntry(LookupError):
    """A failed lookup; the message lists what exists."""


class Registry(Generic[K, V]):
    """Entries registered by decorator; a duplicate key is a bug and is refused."""

    def __init__(self, what: str, plugins: tuple[str, ...] = ()) -> None:
        self.what = what
        self._entries: dict[K, V] = {}
        self._plugins = plugins  # modules to import before the first look-up
        self.version = 0  # counts changes: what is derived from the entries may be cached by it

    def _load(self) -> None:
        plugins, self._plugins = self._plugins, ()
        for module in plugins:
            importlib.import_module(module)

    def register(self, key: K) -> Callable[[V], V]:
        def add(entry: V) -> V:
            if key in self._entries:
                raise ValueError(f"{self.what} {key!r} is registered twice")
            self._entries[key] = entry
            self.version += 1
            return entry

        return add

    def remove(self, key: K) -> V:
        """Take an entry out again (a plug-in tried in a test or a notebook)."""
        self.version += 1
        return self._entries.pop(key)

    def get(self, key: K) -> V:
        if self._plugins:
            self._load()
        try:
            return self._entries[key]
        except KeyError:
            names = [self._name(k) for k in self._entries]
            raise UnknownEntry(
                f"unknown {self.what} {self._name(key)!r}; {suggest(self._name(key), names)}"
            ) from None

    def __contains__(self, key: object) -> bool:
        if self._plugins:
            self._load()
        return key in self._entries

    def __iter__(self) -> Iterator[K]:
        if self._plugins:
            self._load()
        return iter(sorted(self._entries, key=self._name))

    def registered(self) -> list[tuple[K, V]]:
        """The entries in the order they were registered."""
        if self._plugins:
            self._load()
        return list(self._entries.items())

    @staticmethod
    def _name(key: object) -> str:
        return "/".join(map(str, key)) if isinstance(key, tuple) else str(key)
