"""``python -m astralis_des.cli``: the ``astralis`` command."""

from astralis_des.cli import end_process, exit_now, main
from astralis_des.exits import RECEIVED

code = main()
if RECEIVED:  # interrupted: under python -m, an interrupt that went through an exec() (a
    exit_now(code)  # dataclass being made) makes CPython end by killing itself with
    # SIGINT (its "unhandled KeyboardInterrupt" flag), not with this code
end_process(code)  # Python's exit less its finalization: the threads, atexit, the flush
