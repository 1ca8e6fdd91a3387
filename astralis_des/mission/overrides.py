"""A mission as the command line and its front ends (``serve``, ``chat``) ask for it: the file
with ``--seed``, ``--fidelity``, ``--no-recording``, ``--manual`` and ``run``'s ``--set``
(unless it forks: the fork makes them) applied, and its output folder."""

from __future__ import annotations

import argparse
from pathlib import Path

from astralis_des.mission.changes import changed_mission, parse_changes
from astralis_des.mission.loader import Mission, load_mission
from astralis_des.outdir import usable


def mission_from_args(args: argparse.Namespace) -> tuple[Mission, Path]:
    """The mission file with the command line's overrides, and its output folder."""
    mission = load_mission(args.mission)
    if args.seed is not None:
        mission = mission.with_changes(seed=args.seed)
    if args.fidelity is not None:
        mission = mission.with_changes(fidelity=args.fidelity)
    if args.no_recording:
        outputs = mission.spec.outputs.model_copy(update={"recording": False})
        mission = mission.with_changes(outputs=outputs.model_dump())
    if getattr(args, "mcap", False):
        outputs = mission.spec.outputs.model_copy(update={"mcap": True})
        mission = mission.with_changes(outputs=outputs.model_dump())
    if getattr(args, "manual", False):  # serve and chat
        assignment = mission.spec.assignment.model_copy(update={"auto": False})
        mission = mission.with_changes(assignment=assignment.model_dump())
    forks = getattr(args, "fork_at", None) is not None
    if not forks:
        mission = changed_mission(mission, parse_changes(getattr(args, "set", None) or []))
    out = Path(args.out or mission.spec.outputs.dir or Path("out") / mission.name)
    if forks and not args.out:  # beside the run it forks, not over it
        out = out.with_name(out.name + "-fork")
    usable(out)
    return mission, out
