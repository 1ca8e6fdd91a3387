"""``astralis tune``: run a tune with a progress bar over its trials and print its report."""

from __future__ import annotations

import argparse
from pathlib import Path

from rich.console import Console
from rich.markdown import Markdown

from astralis_des.errors import InputError
from astralis_des.exits import EXIT_INTERRUPTED
from astralis_des.studies.backends import make_backend
from astralis_des.studies.tune import run_tune
from astralis_des.studies.tune_output import report
from astralis_des.studies.tune_spec import Tune, load_tune


def tune_command(args: argparse.Namespace) -> int:
    tune = load_tune(args.tune)
    if args.trials is not None:
        tune = Tune(tune.spec.model_copy(update={"trials": args.trials}), tune.study,
                    tune.text, tune.path)
    try:  # checked before the progress bar starts
        make_backend(args.backend, args.workers or 1, args.address)
    except InputError as exc:
        raise InputError(exc.message, key=f"--{exc.key}") from None
    out = Path(args.out or Path("out") / tune.name)
    console = Console(stderr=True, quiet=args.quiet)
    from rich.progress import (
        BarColumn,
        MofNCompleteColumn,
        Progress,
        TextColumn,
        TimeElapsedColumn,
        TimeRemainingColumn,
    )

    columns = (TextColumn(f"[bold]{tune.name}"), BarColumn(), MofNCompleteColumn(),
               TextColumn("trials"), TimeElapsedColumn(), TimeRemainingColumn())
    with Progress(*columns, console=console, transient=False) as bar:
        task = bar.add_task("tune", total=tune.spec.trials)
        result = run_tune(tune, workers=args.workers, backend=args.backend,
                          address=args.address, out=out, resume=args.resume,
                          progress=lambda done, total: bar.update(task, completed=done,
                                                                      total=total))
    if result.interrupted:
        console.print(f"[yellow]interrupted[/]; the {len(result.rows)} trials done are in "
                      f"{out}/ (go on with --resume)")
        return EXIT_INTERRUPTED
    if not args.quiet:
        Console().print(Markdown("\n".join(report(result))))
        Console().print(f"{len(result.rows)} trials; outputs: {out}/")
    return 0
