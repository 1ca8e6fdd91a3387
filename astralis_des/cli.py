"""``astralis``: run, validate and describe missions from the command line.

Heavy modules are imported inside the commands, so ``astralis --help`` answers at once.
"""

from __future__ import annotations

import argparse
import contextlib
import json
import logging
import os
import signal
import sys
import threading
import warnings
from collections.abc import Callable, Iterator, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

from astralis_des.exits import (
    EXIT_BAD_INPUT,
    EXIT_INTERRUPTED,
    EXIT_OUTPUT,
    RECEIVED,
    interrupt_on_termination,
    interrupts_never_lost,
)

if TYPE_CHECKING:
    from astralis_des.simulation.result import RunResult

Command = Callable[[argparse.Namespace], int]
COMMANDS: dict[str, Command] = {}


def command(name: str) -> Callable[[Command], Command]:
    def add(fn: Command) -> Command:
        COMMANDS[name] = fn
        return fn

    return add


def _parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="astralis", description="Discrete-event missions for UAV/UGV/human search teams.")
    parser.add_argument("--version", action="store_true", help="print the version and exit")
    parser.set_defaults(quiet=False)  # the commands that print progress take --quiet
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    run = sub.add_parser("run", help="run a mission file and write its outputs")
    run.add_argument("mission", help="mission YAML file")
    _add_mission_options(run)
    run.add_argument("--quiet", action="store_true", help="no progress bar or summary table")
    run.add_argument("--view", action="store_true", help="also stream the recording to a "
                     "Rerun viewer it spawns")
    replay = sub.add_parser("replay", help="open a run's recording in the Rerun viewer")
    replay.add_argument("recording", help="a recording.rrd")
    replay.add_argument("--web", action="store_true", help="serve the web viewer instead")
    export = sub.add_parser("export", help="write run.mcap for a run already made")
    export.add_argument("run_dir", help="a run's output folder (with its events.jsonl)")
    export.add_argument("--mcap", action="store_true", required=True,
                        help="ROS 2 messages and the decisions as JSON (the only format)")
    export.add_argument("--mission", help="the run's mission file (default: "
                        "missions/<name>.yaml)")
    val = sub.add_parser("validate", help="check a mission file without running it")
    val.add_argument("mission", help="mission YAML file")
    world = sub.add_parser("world", help="look at worlds")
    world_sub = world.add_subparsers(dest="world_command", metavar="WORLD_COMMAND",
                                     required=True)
    rooms = world_sub.add_parser("rooms", help="list a world's buildings, storeys, segments, "
                                 "rooms and doors (the ids a mission names)")
    rooms.add_argument("world", help="world YAML file")
    show = world_sub.add_parser("show", help="write a recording of a world, furnished")
    show.add_argument("world", help="world YAML file")
    show.add_argument("--messiness", type=float, nargs="+", default=[0.5],
                      help="messiness of every room, or values cycled over the rooms in id "
                           "order (default 0.5)")
    show.add_argument("--seed", type=int, default=0)
    show.add_argument("--catalogue", help="clutter catalogue file (default: the packaged one)")
    show.add_argument("-o", "--output", help="recording to write (default out/world_NAME.rrd)")
    _add_import_parser(world_sub)
    study = sub.add_parser("study", help="run a scheduling study: scenarios x variants, "
                           "a table, plots and a report in one folder")
    study.add_argument("study", help="study YAML file")
    study.add_argument("--workers", type=_positive, help="processes (default: the CPUs)")
    study.add_argument("--backend", default="local",
                       help="local (a process pool, the default) or ray")
    study.add_argument("--address", help="ray: the address of an existing cluster "
                       "(default: a local instance)")
    study.add_argument("--out", help="output folder (default out/<study name>)")
    study.add_argument("--scenarios", type=int, help="override the study's scenario count")
    study.add_argument("--recordings", action="store_true",
                       help="write each mission's outputs under the folder's scenarios/")
    study.add_argument("--replay", type=int, metavar="N",
                       help="run scenario N alone, here, as the study does; show its rows, "
                       "or its traceback if it fails")
    study.add_argument("--variant", help="with --replay: only this variant")
    study.add_argument("--quiet", action="store_true", help="no progress bar or report")
    tune = sub.add_parser("tune", help="fit study parameters to target figures, or find the "
                          "front of several objectives (Optuna); a folder of trials, the "
                          "best or the front, plots and a report")
    tune.add_argument("tune", help="tune YAML file")
    tune.add_argument("--workers", type=_positive, help="processes (default: the CPUs)")
    tune.add_argument("--backend", default="local", help="local (a process pool) or ray")
    tune.add_argument("--address", help="ray: the address of an existing cluster")
    tune.add_argument("--out", help="output folder (default out/<tune name>)")
    tune.add_argument("--trials", type=_positive, help="override the tune's trials")
    tune.add_argument("--resume", action="store_true",
                      help="go on after the trials the output folder holds")
    tune.add_argument("--quiet", action="store_true", help="no progress bar or report")
    from astralis_des.cli_api import API_COMMANDS, add_api_parsers

    add_api_parsers(sub, _add_mission_options)
    COMMANDS.update(API_COMMANDS)  # not by import: under python -m this module is __main__
    schema = sub.add_parser("schema", help="print the JSON Schema of mission or world files")
    schema.add_argument("--world", action="store_true", help="the world file's schema")
    schema.add_argument("--markdown", action="store_true", help="the mission file's reference "
                        "as a Markdown table (docs/missions.md)")
    schema.add_argument("--events", action="store_true", help="the event log's kinds, their "
                        "fields and levels (Markdown: docs/events.md)")
    schema.add_argument("-o", "--output", help="write to this file instead of stdout")
    return parser


def _add_mission_options(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--out", help="output folder (default: the mission's outputs.dir, "
                        "else out/<mission name>)")
    parser.add_argument("--seed", type=int, help="override the mission's seed")
    parser.add_argument("--fidelity", choices=["kinematic", "physics"],
                        help="override the mission's fidelity")
    parser.add_argument("--no-recording", action="store_true", help="skip the Rerun recording")
    parser.add_argument("--mcap", action="store_true", help="also write run.mcap (ROS 2 "
                        "messages and the decisions as JSON, for ros2 bag, Foxglove, Rerun)")


def _positive(text: str) -> int:
    value = int(text)
    if value < 1:
        raise argparse.ArgumentTypeError(f"must be at least 1 (got {value})")
    return value


def main(argv: Sequence[str] | None = None) -> int:
    """The command line. From its first line to its last write, Ctrl-C, SIGTERM and SIGHUP
    end it with exit 130 and at most one line (a run keeps what it recorded)."""
    before = {sig: signal.getsignal(sig) for sig in HANDLED}
    RECEIVED.clear()
    try:
        interrupt_on_termination(ctrl_c=True)  # first: the heavy imports come later
        with interrupts_never_lost():
            return _main(argv)
    except BaseException as exc:  # in the imports, a validation, before the outputs open
        if not isinstance(exc, KeyboardInterrupt) and not (RECEIVED and
                                                         isinstance(exc, Exception)):
            raise  # a bug, not a signal (an import a signal cut short can fail otherwise)
        _ignore_signals()  # one line, even if the signal comes again
        print("interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED
    finally:
        if argv is None:  # the process is ours and its work done: a late signal ends it
            _exit_on_signals()  # at once, without a traceback from an exit handler
        else:  # a caller's (tests): its handlers back
            for sig, handler in before.items():
                signal.signal(sig, handler)


def _main(argv: Sequence[str] | None) -> int:
    os.environ.setdefault("RUST_LOG", "off")  # Rerun's own log lines: the errors are ours
    args = _parser().parse_args(argv)
    if args.version:
        from astralis_des.version import __version__

        print(f"astralis-des {__version__}")
        return 0
    if args.command is None:
        _parser().print_help()
        return 0
    from astralis_des.errors import InputError
    from astralis_des.outdir import MACHINE_ERRNOS, OutputError

    try:
        with _quiet(args.quiet, own_process=argv is None):
            return COMMANDS[args.command](args)
    except BrokenPipeError:  # the reader went away (| head): no traceback, nothing more
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 0
    except InputError as exc:
        print(f"error: {exc.one_line()}", file=sys.stderr)
        return EXIT_BAD_INPUT
    except OutputError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return EXIT_OUTPUT
    except OSError as exc:  # a full disk or an I/O error in a write not staged
        if exc.errno not in MACHINE_ERRNOS:
            raise
        where = f"{exc.filename}: " if exc.filename else ""
        print(f"error: {where}{exc.strerror or exc}", file=sys.stderr)
        return EXIT_OUTPUT


@contextlib.contextmanager
def _quiet(quiet: bool, *, own_process: bool) -> Iterator[None]:
    """``--quiet``: nothing on stderr but errors: no library warnings (``logging`` below
    ERROR), and in a process of its own no Python warnings either (a caller in the same
    process keeps its own warning filters)."""
    if not quiet:
        yield
        return
    level = logging.root.manager.disable
    logging.disable(logging.WARNING)
    try:
        with warnings.catch_warnings():
            if own_process:
                warnings.simplefilter("ignore")
            yield
    finally:
        logging.disable(level)


HANDLED = tuple(getattr(signal, n) for n in ("SIGINT", "SIGTERM", "SIGHUP")
                if hasattr(signal, n))


def _ignore_signals() -> None:
    if threading.current_thread() is threading.main_thread():
        for sig in HANDLED:
            if signal.getsignal(sig) is not signal.SIG_IGN:
                signal.signal(sig, signal.SIG_IGN)


def _exit_on_signals() -> None:
    """From here on a signal ends the process at once, with exit 130 and nothing printed."""
    def end(signum: int, frame: object) -> None:
        _exit_now(EXIT_INTERRUPTED)

    if threading.current_thread() is threading.main_thread():
        for sig in HANDLED:
            if signal.getsignal(sig) is not signal.SIG_IGN:
                signal.signal(sig, end)


def _exit_now(code: int) -> None:
    """End the process with ``code`` once what it printed is out (the outputs are in place)."""
    with contextlib.suppress(Exception):
        sys.stdout.flush()
        sys.stderr.flush()
    os._exit(code)


@command("replay")
def _replay(args: argparse.Namespace) -> int:
    from astralis_des.sinks.viewer import open_viewer

    return open_viewer(Path(args.recording), web=args.web)


@command("export")
def _export(args: argparse.Namespace) -> int:
    from astralis_des.sinks.export import export_mcap

    print(f"wrote {export_mcap(args.run_dir, args.mission)}")
    return 0


@command("validate")
def _validate(args: argparse.Namespace) -> int:
    from astralis_des.mission.loader import load_mission

    mission = load_mission(args.mission)
    search = (f"{len(mission.searched_rooms())} rooms to search" if mission.spec.assignment.auto
              else "no rooms searched but those commanded (assignment.auto is false)")
    print(f"ok: {args.mission}: mission '{mission.name}', {len(mission.spec.team)} agents, "
          f"{search} in world '{mission.world.name}'")
    return 0


def _add_import_parser(world_sub: Any) -> None:
    imp = world_sub.add_parser(
        "import", help="make a world (a digital twin) of a point cloud or a mesh",
        description="Point clouds: LAS, LAZ, PLY, PCD, XYZ/CSV. Meshes: OBJ, glTF/GLB, STL "
                    "(and PLY with faces). Writes the world file and, beside it, its blocks, "
                    "mesh and cloud.")
    imp.add_argument("file", help="the cloud or mesh to import")
    imp.add_argument("-o", "--output", required=True, help="world file to write "
                     "(worlds/NAME.yaml)")
    imp.add_argument("--units", default="auto", help="auto (the file's coordinate system, else "
                     "guessed and said), m, ft or us-ft")
    imp.add_argument("--crs", help="the file's coordinate system, over what the file says "
                     "(EPSG:32617, a WKT or PROJ string): units, and where the world lies")
    imp.add_argument("--voxel", type=float, help="m, of the blocks and the planner's map "
                     "(default: a cloud's point spacing, 0.2 to 10; 0.2 for a mesh)")
    imp.add_argument("--ground", default="auto", help="auto (the classification, else grid), "
                     "classification, grid or ransac")
    imp.add_argument("--fill", default="auto", help="columns (aerial: solid down to the "
                     "ground) or none; auto: columns for LAS/LAZ")
    imp.add_argument("--up", default="auto", help="a mesh's up axis: auto, y or z")
    imp.add_argument("--scale", type=float, default=1.0, help="times the units (default 1)")
    imp.add_argument("--collision", default="auto", help="physics: boxes (clouds), concave "
                     "(meshes, the default) or convex (V-HACD parts)")
    imp.add_argument("--areas", type=int, default=4, help="search areas to place (default 4)")
    imp.add_argument("--area-size", type=float, default=20.0, help="m, their side (default 20)")
    imp.add_argument("--margin", type=float, default=2.0, help="m of site around the geometry")
    imp.add_argument("--cloud-points", type=int, default=50_000,
                     help="points kept for the replay (default 50,000)")
    imp.add_argument("--seed", type=int, default=0, help="of RANSAC and downsampling")
    imp.add_argument("--name", help="the world's name (default: the output file's stem)")
    imp.add_argument("--format", help="read the file as this format (las, laz, pcd, ply, xyz, "
                     "csv, obj, ...), whatever its extension")
    imp.add_argument("--partial", action="store_true", help="import the points a truncated "
                     "file holds, instead of refusing it")
    imp.add_argument("--max-points", type=int, help="keep at most this many points, evenly "
                     "(default: what half the free memory holds, at most 50 million)")
    imp.add_argument("--keep-strays", action="store_true", help="keep points lying far from "
                     "the rest of the cloud (left out by default, and counted)")


WORLD_COMMANDS: dict[str, Command] = {}


@command("world")
def _world(args: argparse.Namespace) -> int:
    return WORLD_COMMANDS[args.world_command](args)


def world_command(name: str) -> Callable[[Command], Command]:
    def add(fn: Command) -> Command:
        WORLD_COMMANDS[name] = fn
        return fn

    return add


@world_command("rooms")
def _world_rooms(args: argparse.Namespace) -> int:
    from astralis_des.world.build import load_world
    from astralis_des.world.describe import room_lines

    print("\n".join(room_lines(load_world(args.world))))
    return 0


@world_command("import")
def _world_import(args: argparse.Namespace) -> int:
    from rich.console import Console

    from astralis_des.importers import ImportOptions, import_world
    from astralis_des.outdir import holding

    options = ImportOptions(
        units=args.units, crs=args.crs, voxel=args.voxel, ground=args.ground, fill=args.fill,
        up=args.up, scale=args.scale, collision=args.collision, areas=args.areas,
        area_size=args.area_size, margin=args.margin, cloud_points=args.cloud_points,
        seed=args.seed, name=args.name, format=args.format, partial=args.partial,
        max_points=args.max_points, keep_strays=args.keep_strays)
    command_line = " ".join(["astralis world import", *sys.argv[3:]]) if \
        sys.argv[1:3] == ["world", "import"] else None
    console = Console(highlight=False, stderr=True, soft_wrap=True)  # a line is one line
    try:  # the output locked (and found writable) before the import
        with holding(args.output), _import_progress(console) as progress:
            report = import_world(args.file, args.output, options, command=command_line,
                                  progress=progress)
    except KeyboardInterrupt:
        console.print(f"[yellow]interrupted[/]; {args.output} was not written")
        return EXIT_INTERRUPTED
    out = Console(highlight=False)
    what = (f"{report.points:,} points" if report.kind == "cloud" else
            f"{report.points:,} triangles")
    if report.dropped:
        what += f" ({report.dropped:,} with NaN or infinite coordinates dropped)"
    out.print(f"[bold]{report.world}[/]: {what}, site {report.site[0]:g} x "
              f"{report.site[1]:g} m, voxel {report.voxel:g} m, {report.blocks:,} blocks, "
              f"areas {', '.join(report.areas)} ({report.seconds:.2f} s)")
    for note in report.notes:
        style = "yellow" if note.startswith("warning:") else "dim"
        out.print(f"[{style}]{note}[/]")
    if report.ground is not None:
        share = f"ground by {report.ground}: {report.ground_share:.1%} of the points"
        if report.classified_share is not None and report.ground != "classification":
            share += f" (the file's classification: {report.classified_share:.1%})"
        out.print(share)
    if len(report.floors) > 1:
        out.print("floors at " + ", ".join(f"{z:g}" for z in report.floors) + " m")
    out.print("wrote " + ", ".join(p.name for p in report.files))
    return 0


@contextlib.contextmanager
def _import_progress(console: Any) -> Iterator[Callable[[int, int], None]]:
    """A progress bar for the points read, on the terminal only, and from the first million."""
    from rich.progress import BarColumn, Progress, TextColumn, TimeRemainingColumn

    bar = Progress(TextColumn("reading"), BarColumn(), TextColumn("{task.completed:,} of "
                   "{task.total:,} points"), TimeRemainingColumn(), console=console,
                   transient=True, disable=not console.is_terminal)
    task = bar.add_task("read", total=None)

    def update(done: int, total: int) -> None:
        if total >= 1_000_000:
            bar.start()
        bar.update(task, completed=done, total=total)

    try:
        yield update
    finally:
        bar.stop()


@world_command("show")
def _world_show(args: argparse.Namespace) -> int:
    from astralis_des.sinks.world_show import show_world

    out = args.output or str(Path("out") / f"world_{Path(args.world).stem}.rrd")
    shown = show_world(args.world, args.messiness, out, seed=args.seed,
                       catalogue=args.catalogue)
    items = ", ".join(f"{n} {kind}" for kind, n in sorted(shown.placed.items())) or "nothing"
    print(f"{shown.path}: {shown.rooms} rooms furnished: {items}")
    for room, kind, reason in shown.skipped:
        print(f"  not placed in {room}: {kind} ({reason})")
    return 0


@command("study")
def _study(args: argparse.Namespace) -> int:
    from astralis_des.studies.console import study_command

    return study_command(args)


@command("tune")
def _tune(args: argparse.Namespace) -> int:
    from astralis_des.studies.tune_console import tune_command

    return tune_command(args)


@command("schema")
def _schema(args: argparse.Namespace) -> int:
    from astralis_des.mission.spec import MissionSpec
    from astralis_des.world.spec import WorldSpec

    model = WorldSpec if args.world else MissionSpec
    text = json.dumps(model.model_json_schema(), indent=2) + "\n"
    if args.markdown:
        from astralis_des.mission.reference import EXAMPLE, reference

        text = reference(Path(EXAMPLE))
    if args.events:
        from astralis_des.kernel.catalogue import markdown

        text = markdown()
    if args.output:
        from astralis_des.outdir import Staging

        target = Path(args.output)
        with Staging(target, file=True) as folder:
            (folder / target.name).write_text(text, encoding="utf-8")
    else:
        sys.stdout.write(text)
    return 0


@command("run")
def _run(args: argparse.Namespace) -> int:
    from rich.console import Console

    from astralis_des.mission.overrides import mission_from_args
    from astralis_des.outdir import holding
    from astralis_des.simulation import Simulation

    mission, out = mission_from_args(args)
    if mission.spec.outputs.mcap:
        from astralis_des.sinks.mcap_out import require

        require()
    console = Console(stderr=True, quiet=args.quiet, soft_wrap=True)  # never wrapped
    made: list[Simulation] = []

    def run(progress: Any) -> RunResult:
        made.append(Simulation(mission, out_dir=out, progress=progress, view=args.view))
        return made[0].run()

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


def _with_progress(console: Any, limit: float, run: Callable[[Any], RunResult]) -> RunResult:
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
    console.print(f"outputs: {out}/")


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


if __name__ == "__main__":
    code = main()
    if RECEIVED:  # interrupted: under python -m, an interrupt that went through an exec() (a
        _exit_now(code)  # dataclass being made) makes CPython end by killing itself with
    sys.exit(code)  # SIGINT (its "unhandled KeyboardInterrupt" flag), not with this code
