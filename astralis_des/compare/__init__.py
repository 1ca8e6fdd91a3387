"""Two runs side by side (``astralis diff RUN_A RUN_B``): where they part, and what each
found, searched and cost; and one Rerun recording with B's robots as ghosts beside A's
(:func:`astralis_des.compare.recording.write_diff`, imported apart: it needs Rerun and the
sinks, the comparison does not).

    >>> from astralis_des.compare import compare, load_run
    >>> from astralis_des.compare.recording import write_diff
    >>> c = compare(load_run("out/mixed"), load_run("out/greedy"))
    >>> c.round.number, c.event.line          # the first round and event that differ
    >>> write_diff(c, "diff.rrd")
"""

from __future__ import annotations

from astralis_des.compare.decisions import Comparison, EventDiff, RoundDiff, compare
from astralis_des.compare.runs import Run, load_run

__all__ = ["Comparison", "EventDiff", "RoundDiff", "Run", "compare", "load_run"]
