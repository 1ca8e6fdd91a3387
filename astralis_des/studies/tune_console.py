"""``astralis tune``: run a tune with a progress bar over its trials and print its report."""

from __future__ import annotations

import argparse
from pathlib import Path

from rich.console import Console
from rich.markdown import Markdown

from astralis_des.errors import InputError
from astralis_des.exits import EXIT_INTERRUPTED
from astralis_des.studies.backends import make_backend
from astralis_des.studies.console import with_progress
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
    result = with_progress(console, tune.name, "trials", tune.spec.trials,
                           lambda progress: run_tune(
        tune, workers=args.workers, backend=args.backend, address=args.address, out=out,
        resume=args.resume, progress=progress))
    if result.interrupted:
        console.print(f"[yellow]interrupted[/]; the {len(result.rows)} trials done are in "
                      f"{out}/ (go on with --resume)")
        return EXIT_INTERRUPTED
    if not args.quiet:
        Console().print(Markdown("\n".join(report(result))))
        Console().print(f"{len(result.rows)} trials; outputs: {out}/")
    return 0
