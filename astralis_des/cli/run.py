"""``astralis run``: run a mission file under a progress bar, then print its summary."""

from __future__ import annotations

import argparse
import gc
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Any

from astralis_des.exits import EXIT_INTERRUPTED

if TYPE_CHECKING:
    from astralis_des.simulation.result import RunResult


class _Collector:
    """Python's cyclic garbage collector held off while ``astralis run`` starts. Its imports
    and the mission's load make about a million objects that stay alive, and the 280-odd
    collections they would set off walk them again and again (two of them whole): 0.12-0.24
    s, a tenth of the process, with no cyclic garbage worth collecting among them. At the
    run's first event (its outputs open, what it imports imported) they are frozen
    (``gc.freeze``: left out of every later collection) and the collector goes on; at the
    command's end they are unfrozen, as they were for Python's exit. A caller that froze
    objects of its own (a server before it forks) has nothing frozen or unfrozen for it."""

    def __init__(self) -> None:
        self.held = gc.isenabled()
        self.may_freeze = gc.get_freeze_count() == 0
        self.frozen = False
        gc.disable()

    def release(self) -> None:
        if self.held:
            self.held = False
            if self.may_freeze:
                gc.freeze()
                self.frozen = True
            gc.enable()

    def end(self) -> None:
        self.release()
        if self.frozen:
            self.frozen = False
            gc.unfreeze()


def run_command(args: argparse.Namespace) -> int:
    """``astralis run MISSION``: a progress bar on stderr, then a summary on stdout."""
    collector = _Collector()
    try:
        return _run(args, collector.release)
    finally:
        collector.end()


def _run(args: argparse.Namespace, started: Callable[[], None]) -> int:
    """The command, ``started()`` called at the run's first event."""
    from rich.console import Console

    from astralis_des.mission.overrides import mission_from_args
    from astralis_des.outdir import holding
    from astralis_des.simulation import Simulation

    mission, out = mission_from_args(args)
    fork = None
    if args.fork_at is not None:  # checked before the outputs open: bad input writes nothing
        from astralis_des.simulation.fork import prepare

        fork = prepare(mission, args.fork_at, args.set)
        fork.check_times(Simulation)
    if args.view:
        from astralis_des.sinks.viewer import require_display

        require_display(f"run without --view, then: astralis replay {out}/recording.rrd --web")
    if mission.spec.outputs.mcap:
        from astralis_des.sinks.mcap_out import require

        require()
    console = Console(stderr=True, quiet=args.quiet, soft_wrap=True)  # never wrapped
    made: list[Simulation] = []

    def run(progress: Callable[[float, float], None]) -> RunResult:
        def advance(now: float, limit: float) -> None:
            started()
            progress(now, limit)

        made.append(Simulation(mission, out_dir=out, progress=advance, view=args.view))
        return made[0].run() if fork is None else fork.run(made[0], Simulation)

    try:
        with holding(out):  # a second writer is refused before the world is built
            result = _with_progress(console, mission.spec.time_limit, run)
    except KeyboardInterrupt:
        recorded = bool(made) and made[0].started
        console.print("[yellow]interrupted[/]; " + (f"what was recorded is in {out}/"
                                                     if recorded else "nothing written"))
        return EXIT_INTERRUPTED
    if not args.quiet:
        _print_summary(Console(), result, out)
    return 0


def _with_progress(console: Any, limit: float,
                   run: Callable[[Callable[[float, float], None]], RunResult]) -> RunResult:
    from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn

    columns = (TextColumn("[bold]mission"), BarColumn(),
               TextColumn("sim {task.completed:>7.1f} s of {task.total:.0f} s"),
               TimeElapsedColumn())
    with Progress(*columns, console=console, transient=False) as bar:
        task = bar.add_task("mission", total=limit)
        last = [0.0]

        def advance(now: float, _limit: float) -> None:
            if now - last[0] >= limit / 200:
                last[0] = now
                bar.update(task, completed=now)

        result = run(advance)
        bar.update(task, total=result.end_time, completed=result.end_time)
    return result


def _print_summary(console: Any, result: RunResult, out: Path) -> None:
    from rich.table import Table

    found = (f"found by {result.found_by} at t = {result.time_to_find:.1f} s"
             if result.found else result.outcome.replace("_", " "))
    console.print(f"[bold]{result.mission}[/] (seed {result.seed}, {result.fidelity}): {found}; "
                  f"target in {result.target['room']}; {len(result.rounds)} assignment rounds, "
                  f"{len(result.rooms_searched)} rooms searched; "
                  f"{result.end_time:.1f} s simulated in {result.wall_time:.2f} s")
    if result.fork is not None:
        changed = [f"{k} = {v}" for k, v in result.fork["changes"].items()]
        changed += [f"{e['event']} at {e['at']:.1f} s" for e in result.fork["timeline"]]
        console.print(f"forked at {result.fork['point']} (t = {result.fork['t']:.1f} s, after "
                      f"line {result.fork['lines']} of the event log): {'; '.join(changed)}")
    table = Table(title="team")
    table.add_column("robot", no_wrap=True)
    for header in ("kind", "dist m", "busy s", "idle s", "ok", "failed", "cancel", "preempt"):
        table.add_column(header, justify="right" if header != "kind" else "left")
    for rid, s in result.robots.items():
        table.add_row(rid, s.kind, f"{s.distance:.1f}", f"{s.busy_time:.1f}",
                      f"{s.idle_time:.1f}", str(s.tasks_succeeded), str(s.tasks_failed),
                      str(s.tasks_cancelled), str(s.tasks_preempted))
    console.print(table)
    if not result.found:
        _print_rooms(console, result)
    console.print(_metrics_line(result.metrics))
    console.print(f"outputs: {out}/")


# the metrics the run's summary line names (all are in summary.json's ``metrics``)
SHOWN = (("human_high_risk_s", "human searching high-risk rooms", "{:.1f} s"),
         ("ugv_high_mess_s", "UGV searching high-messiness rooms", "{:.1f} s"),
         ("tasks_failed", "failed tasks", "{}"),
         ("makespan", "makespan", "{:.1f} s"),
         ("human_min_distance", "closest moving robot to a person", "{:.2f} m"))


def _metrics_line(metrics: dict[str, Any]) -> str:
    shown = [f"{label} {fmt.format(metrics[key])}" for key, label, fmt in SHOWN
             if metrics.get(key) is not None]
    return "metrics (summary.json has them all): " + "; ".join(shown)


def _print_rooms(console: Any, result: RunResult) -> None:
    """Per room, what was seen of it and by whom: "hidden by furniture" is not "never looked"."""
    from rich.table import Table

    table = Table(title="rooms")
    for header in ("room", "status", "seen", "searches"):
        table.add_column(header, justify="right" if header == "seen" else "left")
    for room, entry in result.rooms.items():
        seen = "-" if entry["coverage"] is None else f"{entry['coverage']:.0%}"
        searches = ", ".join(
            f"{s['robot']} {s['action']} {s['status']}"
            + ("" if s["coverage"] is None else f" {s['coverage']:.0%}")
            for s in entry["searches"])
        mark = " (target)" if room == result.target["room"] else ""
        table.add_row(room + mark, entry["status"].replace("_", " "), seen, searches or "-")
    console.print(table)
