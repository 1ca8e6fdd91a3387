"""Keys to teleoperation moves: arrow keys (``ESC [ A`` and ``ESC O A``, with modifiers too)
and WASD (either case) to directions; ``q``, Ctrl-C, Ctrl-D to quit. Pure: bytes in, moves
out, an escape sequence split across reads held until it is whole."""

from __future__ import annotations

QUIT = "quit"
ESC = 0x1B
KEYS: dict[bytes, str] = {
    b"w": "north", b"s": "south", b"d": "east", b"a": "west",
    b"q": QUIT, b"\x03": QUIT, b"\x04": QUIT,
}
ARROWS: dict[bytes, str] = {b"A": "north", b"B": "south", b"C": "east", b"D": "west"}
MAX_SEQUENCE = 16  # bytes: a longer "escape sequence" is junk, dropped


class KeyDecoder:
    """``feed(bytes)`` the moves it completes: ``north``, ``south``, ``east``, ``west`` or
    ``quit``; other keys are dropped."""

    def __init__(self) -> None:
        self._pending = b""

    def feed(self, data: bytes) -> list[str]:
        buf = self._pending + data
        out: list[str] = []
        i = 0
        while i < len(buf):
            if buf[i] == ESC:
                end, key = _escape(buf, i)
                if end is None:  # the rest of the sequence is still to come
                    break
                i = end
            else:
                key = KEYS.get(buf[i:i + 1].lower())
                i += 1
            if key is not None:
                out.append(key)
        self._pending = buf[i:]
        return out

    def end(self) -> list[str]:
        """End of input: whatever is pending is dropped (a lone ESC is not a move)."""
        self._pending = b""
        return [QUIT]


def _escape(buf: bytes, i: int) -> tuple[int | None, str | None]:
    """Decode the escape sequence at ``buf[i]``: (where it ends, its move); (None, None) if
    it is not complete yet."""
    if i + 1 >= len(buf):
        return None, None
    intro = buf[i + 1:i + 2]
    if intro == b"O":  # SS3: ESC O A (application cursor keys)
        if i + 2 >= len(buf):
            return None, None
        return i + 3, ARROWS.get(buf[i + 2:i + 3])
    if intro != b"[":  # Alt+key, or a lone ESC before another key: drop the ESC
        return i + 1, None
    j = i + 2
    while j < len(buf) and 0x30 <= buf[j] <= 0x3F:  # parameters: ESC [ 1 ; 5 A
        j += 1
    if j >= len(buf):
        return (None, None) if j - i < MAX_SEQUENCE else (j, None)
    return j + 1, ARROWS.get(buf[j:j + 1])
