"""``python -m astralis_des.cli``: the ``astralis`` command."""

import sys

from astralis_des.cli import exit_now, main
from astralis_des.exits import RECEIVED

code = main()
if RECEIVED:  # interrupted: under python -m, an interrupt that went through an exec() (a
    exit_now(code)  # dataclass being made) makes CPython end by killing itself with
sys.exit(code)  # SIGINT (its "unhandled KeyboardInterrupt" flag), not with this code
