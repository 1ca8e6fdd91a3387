"""``astralis falsify``: search for a strategy's worst scenarios under a progress bar, write
the folder, print the worst and the optimiser against random search."""

from __future__ import annotations

import argparse
import shlex
from pathlib import Path

from rich.console import Console

from astralis_des.errors import InputError
from astralis_des.exits import EXIT_INTERRUPTED
from astralis_des.outdir import Staging, holding, usable
from astralis_des.studies.backends import make_backend
from astralis_des.studies.console import with_progress
from astralis_des.studies.falsify import (
    Falsify,
    base_run,
    check_request,
    run_falsify,
)
from astralis_des.studies.falsify_eval import worst_is_largest
from astralis_des.studies.falsify_output import FALSIFY_FILES, write_falsify
from astralis_des.studies.falsify_report import best_so_far
from astralis_des.studies.falsify_space import load_space


def falsify_command(args: argparse.Namespace) -> int:
    import os

    from astralis_des.mission.loader import load_mission

    mission = load_mission(args.mission)
    strategy = args.strategy or mission.spec.assignment.strategy
    check_request(args.metric, strategy, args.against, args.sampler)
    workers = args.workers or os.cpu_count() or 1
    try:  # checked before any work
        make_backend(args.backend, workers, args.address)
    except InputError as exc:
        raise InputError(exc.message, key=f"--{exc.key}") from None
    out = Path(args.out or Path("out") / f"{mission.name}_falsify")
    usable(out)
    strategies = [strategy] + ([args.against] if args.against else [])
    largest = (worst_is_largest(args.metric) if args.worst_is is None
               else args.worst_is == "largest")
    console = Console(stderr=True, quiet=args.quiet, soft_wrap=True)
    try:
        with holding(out):  # a second writer is refused before any trial runs
            base = base_run(mission, strategy)
            space = load_space(args.space, mission, strategies=strategies,
                               fault_until=base["end_time"])
            f = Falsify(mission, space, strategy, args.metric, args.trials, args.against,
                        largest, args.sampler, args.seed, args.batch, not args.no_baseline)
            total = args.trials * (1 if args.no_baseline else 2)
            result = with_progress(console, "falsify", "trials", total, lambda progress:
                                   run_falsify(f, workers=workers, backend=args.backend,
                                               address=args.address, progress=progress,
                                               base=base))
            with Staging(out, owned=FALSIFY_FILES, last="meta.json") as folder:
                chosen = write_falsify(result, folder, out, worst=args.worst,
                                       recordings=args.recordings,
                                       command=command_line(args, strategy))
    except KeyboardInterrupt:
        console.print("[yellow]interrupted[/]; nothing written")
        return EXIT_INTERRUPTED
    if result.interrupted:
        console.print(f"[yellow]interrupted[/]; the {len(result.rows)} trials done are in "
                      f"{out}/")
        return EXIT_INTERRUPTED
    if not args.quiet:
        stdout = Console(soft_wrap=True)
        for search in ("optimiser", "random"):
            curve = best_so_far(result, search)
            if curve:
                worst = "none" if curve[-1] is None else f"{curve[-1]:.6g}"
                stdout.print(f"{search}: {len(curve)} trials in "
                             f"{result.wall_time.get(search, 0):.1f} s, worst score {worst}")
        for rank, row in enumerate(chosen, 1):
            extra = (f"; {args.against}: {row['value_against']}, gap {row['score']:.6g}"
                     if args.against else "")
            stdout.print(f"{out}/worst/{rank:02d}.yaml: {args.metric} {row['value']} under "
                         f"{strategy}{extra}")
        stdout.print(f"outputs: {out}/ (report.md, trials.parquet, worst/)")
    return 0


def command_line(args: argparse.Namespace, strategy: str) -> str:
    """The command that asks for the same trials (what decides them, not where they run)."""
    words = ["astralis", "falsify", args.mission, "--strategy", strategy, "--metric",
             args.metric]
    for option, value in (("--against", args.against), ("--worst-is", args.worst_is),
                          ("--space", args.space)):
        if value is not None:
            words += [option, value]
    words += ["--trials", str(args.trials), "--sampler", args.sampler, "--seed",
              str(args.seed), "--batch", str(args.batch)]
    return shlex.join(words + (["--no-baseline"] if args.no_baseline else []))
