"""``astralis``: run, validate and describe missions from the command line.

The parser and the small commands are here; ``run`` is in :mod:`.run`, ``world`` in
:mod:`.world`, the API's commands in :mod:`astralis_des.cli_api`, and the options every
command spells the same way (``-o/--out``, ``-q/--quiet``) in :mod:`.options`. Heavy modules
are imported inside the commands, so ``astralis --help`` answers at once.
"""

from __future__ import annotations

import argparse
import atexit
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
from typing import Any, NoReturn

from astralis_des.cli.diff import add_diff_parser, diff_command
from astralis_des.cli.falsify import add_falsify_parser, falsify
from astralis_des.cli.options import (
    Command,
    add_mission_options,
    add_out,
    add_quiet,
    positive,
)
from astralis_des.cli.run import run_command
from astralis_des.cli.world import add_world_parser, world
from astralis_des.exits import (
    EXIT_BAD_INPUT,
    EXIT_INTERRUPTED,
    EXIT_OUTPUT,
    RECEIVED,
    interrupt_on_termination,
    interrupts_never_lost,
)

COMMANDS: dict[str, Command] = {"run": run_command, "world": world, "diff": diff_command,
                                "falsify": falsify}


def command(name: str) -> Callable[[Command], Command]:
    def add(fn: Command) -> Command:
        COMMANDS[name] = fn
        return fn

    return add


def _parser() -> argparse.ArgumentParser:
    """Every command writing a file or folder takes ``-o/--out``, every command printing
    progress ``-q/--quiet``."""
    parser = argparse.ArgumentParser(
        prog="astralis", description="Discrete-event missions for UAV/UGV/human search teams.")
    parser.add_argument("-V", "--version", action="store_true",
                        help="print the version and exit")
    parser.set_defaults(quiet=False)  # the commands that print progress take -q/--quiet
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    run = sub.add_parser("run", help="run a mission file and write its outputs")
    run.add_argument("mission", help="mission YAML file")
    add_mission_options(run)
    add_quiet(run, "no progress bar or summary table")
    run.add_argument("--view", action="store_true", help="also stream the recording to a "
                     "Rerun viewer it spawns (needs a display)")
    run.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                     help="change the mission: KEY a dotted path of the file "
                     "(assignment.strategy, rooms.set[A.1.2.1].risk), VALUE YAML; KEY+=VALUE "
                     "appends to a list (timeline+={event: fault, robot: uav2}); repeatable")
    run.add_argument("--fork-at", metavar="round:N|event:N|time:T",
                     help="run the mission as it is up to this point, then with the --set "
                     "changes (default output folder: out/<mission name>-fork)")
    replay = sub.add_parser("replay", help="open a run's recording in the Rerun viewer",
                            description="Opens the Rerun viewer on a recording; it needs a "
                            "display. Without one (a server, ssh), --web serves the viewer to "
                            "a browser instead.")
    replay.add_argument("recording", help="a recording.rrd")
    replay.add_argument("--web", action="store_true", help="serve the web viewer instead")
    add_diff_parser(sub)
    export = sub.add_parser("export", help="write run.mcap for a run already made")
    export.add_argument("run_dir", help="a run's output folder (with its events.jsonl)")
    export.add_argument("--mcap", action="store_true", required=True,
                        help="ROS 2 messages and the decisions as JSON (the only format)")
    export.add_argument("--mission", help="the run's mission file (default: "
                        "missions/<name>.yaml)")
    val = sub.add_parser("validate", help="check a mission file without running it, or a "
                         "world file (one that has a site)")
    val.add_argument("mission", help="mission or world YAML file")
    add_world_parser(sub)
    _add_study_parsers(sub)
    from astralis_des.cli_api import API_COMMANDS, add_api_parsers

    add_api_parsers(sub, add_mission_options)
    COMMANDS.update(API_COMMANDS)  # not by import: cli_api imports no command module
    schema = sub.add_parser("schema", help="print the JSON Schema of mission or world files")
    schema.add_argument("--world", action="store_true", help="the world file's schema")
    schema.add_argument("--markdown", action="store_true", help="the mission file's reference "
                        "as a Markdown table (docs/missions.md)")
    schema.add_argument("--events", action="store_true", help="the event log's kinds, their "
                        "fields and levels (Markdown: docs/events.md)")
    add_out(schema, "write to this file instead of stdout", metavar="FILE")
    return parser


def _add_study_parsers(sub: Any) -> None:
    study = sub.add_parser("study", help="run a scheduling study: scenarios x variants, "
                           "a table, plots and a report in one folder")
    study.add_argument("study", help="study YAML file")
    study.add_argument("--workers", type=positive, help="processes (default: the CPUs)")
    study.add_argument("--backend", default="local",
                       help="local (a process pool, the default) or ray")
    study.add_argument("--address", help="ray: the address of an existing cluster "
                       "(default: a local instance)")
    add_out(study, "output folder (default out/<study name>)", metavar="DIR")
    study.add_argument("--scenarios", type=int, help="override the study's scenario count")
    study.add_argument("--recordings", action="store_true",
                       help="write each mission's outputs under the folder's scenarios/")
    study.add_argument("--replay", type=int, metavar="N",
                       help="run scenario N alone, here, as the study does; show its rows, "
                       "or its traceback if it fails")
    study.add_argument("--variant", help="with --replay: only this variant")
    add_quiet(study, "no progress bar or report")
    tune = sub.add_parser("tune", help="fit study parameters to target figures, or find the "
                          "front of several objectives (Optuna); a folder of trials, the "
                          "best or the front, plots and a report")
    tune.add_argument("tune", help="tune YAML file")
    tune.add_argument("--workers", type=positive, help="processes (default: the CPUs)")
    tune.add_argument("--backend", default="local", help="local (a process pool) or ray")
    tune.add_argument("--address", help="ray: the address of an existing cluster")
    add_out(tune, "output folder (default out/<tune name>)", metavar="DIR")
    tune.add_argument("--trials", type=positive, help="override the tune's trials")
    tune.add_argument("--resume", action="store_true",
                      help="go on after the trials the output folder holds")
    add_quiet(tune, "no progress bar or report")
    add_falsify_parser(sub)


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
    from astralis_des.errors import InputError
    from astralis_des.outdir import MACHINE_ERRNOS, OutputError

    try:  # what it prints too (--help, --version) may meet a full disk or a closed pipe
        args = _parser().parse_args(argv)
        if args.version:
            from astralis_des.version import __version__

            print(f"astralis-des {__version__}", flush=True)
            return 0
        if args.command is None:
            _parser().print_help()
            sys.stdout.flush()
            return 0
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
        exit_now(EXIT_INTERRUPTED)

    if threading.current_thread() is threading.main_thread():
        for sig in HANDLED:
            if signal.getsignal(sig) is not signal.SIG_IGN:
                signal.signal(sig, end)


def exit_now(code: int) -> None:
    """End the process with ``code`` once what it printed is out (the outputs are in place)."""
    with contextlib.suppress(Exception):
        sys.stdout.flush()
        sys.stderr.flush()
    os._exit(code)


def entry() -> NoReturn:
    """The ``astralis`` program (and ``python -m astralis_des.cli``): :func:`main`, then the
    end of the process (:func:`end_process`)."""
    end_process(main())


def end_process(code: int) -> NoReturn:
    """End the process with ``code`` as Python's exit does, less its finalization.

    Python's exit ends the threads (the thread pools' exit hooks, then a wait for every
    thread that is not a daemon), runs the ``atexit`` handlers (Rerun's, logging's, temporary
    folders', multiprocessing's), flushes stdout and stderr, then takes every module apart
    and walks the heap: about a million objects after this package's imports, 0.3-0.6 s of
    an ``astralis run`` of 1.5-2 s, with nothing left to write (the outputs are in place
    before :func:`main` returns). This does the same up to the flush and ends there. A stdout
    that cannot be written makes a zero ``code`` 120, as at Python's exit; a reader gone
    away (``| head``) does not."""
    shutdown = getattr(threading, "_shutdown", None)
    handlers = getattr(atexit, "_run_exitfuncs", None)
    if shutdown is None or handlers is None:  # not CPython's exit to mirror: its own
        sys.exit(code)
    shutdown()
    handlers()
    try:
        sys.stdout.flush()
    except BrokenPipeError:
        pass
    except (OSError, ValueError):  # a full disk under a redirect, a closed stdout
        code = code or 120
    with contextlib.suppress(OSError, ValueError):
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
    from astralis_des.yamlio import load_yaml

    data = load_yaml(Path(args.mission)).data
    if isinstance(data, dict) and "site" in data and "team" not in data:
        return _validate_world(Path(args.mission))
    mission = load_mission(args.mission)
    search = (f"{len(mission.searched_rooms())} rooms to search" if mission.spec.assignment.auto
              else "no rooms searched but those commanded (assignment.auto is false)")
    print(f"ok: {args.mission}: mission '{mission.name}', {len(mission.spec.team)} agents, "
          f"{search} in world '{mission.world.name}'")
    return 0


def _validate_world(path: Path) -> int:
    """A world file read, checked and built as a mission would: its rooms and segments."""
    from astralis_des.world.build import read_world

    world = read_world(path)
    inner = (f"; an interior of {len(world.interior.storeys)} storeys, "
             f"{len(world.interior.openings)} doors, {len(world.interior.stairs)} stairs"
             if world.interior is not None else "")
    print(f"ok: {path}: world '{world.name}', {len(world.rooms)} rooms in "
          f"{len(world.segments)} segments{inner}")
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
    if args.out:
        from astralis_des.outdir import Staging

        target = Path(args.out)
        with Staging(target, file=True) as folder:
            (folder / target.name).write_text(text, encoding="utf-8")
    else:
        sys.stdout.write(text)
    return 0
