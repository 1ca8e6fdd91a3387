"""Talking to a served mission: ``astralis chat`` (a line language with help and completion)
and ``astralis teleop`` (a robot walked with the arrow or WASD keys).

The language (:mod:`.language`, :mod:`.robots`) turns a line into an API request and knows
nothing of sockets; :class:`~astralis_des.chat.repl.Chat` sends it and says what came back.
"""

from __future__ import annotations

from astralis_des.chat.language import Parsed, complete, parse
from astralis_des.chat.team import ChatError, Team

__all__ = ["ChatError", "Parsed", "Team", "complete", "parse"]
