"""Study backends for tests: what a backend does at its worst."""

from __future__ import annotations

from collections.abc import Iterator


class Interrupted:
    """A backend stopped (Ctrl-C) before its first chunk came back."""

    name, workers = "local", 2

    def run(self, study: object, chunks: object, recordings: object) -> Iterator[object]:
        raise KeyboardInterrupt
        yield

    def hold(self, base: object) -> None: ...

    def close(self) -> None: ...
