"""``astralis tune``: run a tune with a progress bar over its trials and print its report."""

from __future__ import annotations

import argparse
import shutil
from pathlib import Path

from rich.console import Console
from rich.markdown import Markdown

from astralis_des.errors import InputError
from astralis_des.exits import EXIT_INTERRUPTED
from astralis_des.outdir import Staging
from astralis_des.studies.backends import make_backend
from astralis_des.studies.console import with_progress
from astralis_des.studies.terminal import fitted
from astralis_des.studies.tune import run_tune
from astralis_des.studies.tune_output import JOURNAL, TUNE_FILES, report
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
    console = Console(stderr=True, quiet=args.quiet, soft_wrap=True)  # never wrapped
    try:
        with Staging(out, owned=TUNE_FILES, last="meta.json", keep_interrupted=True,
                     reuse=args.resume) as folder:
            if args.resume:
                _journal_from(out, folder)
            result = with_progress(console, tune.name, "trials", tune.spec.trials,
                                   lambda progress: run_tune(
                tune, workers=args.workers, backend=args.backend, address=args.address,
                out=folder, resume=args.resume, progress=progress))
            if result.interrupted:
                raise KeyboardInterrupt  # the folder goes in place as it is
    except KeyboardInterrupt:
        console.print(f"[yellow]interrupted[/]; the trials done are in {out}/ (go on with "
                      "--resume)")
        return EXIT_INTERRUPTED
    if not args.quiet:
        stdout = Console()
        for block in report(result):
            if isinstance(block, str):
                stdout.print(Markdown(block))
            else:
                for table in fitted(block, stdout.width):
                    stdout.print(table)
            stdout.print()
        stdout.print(f"{len(result.rows)} trials; outputs: {out}/")
        stdout.print("also there: report.md (this report), trials.csv (every trial), plots/")
    return 0


def _journal_from(out: Path, folder: Path) -> None:
    """The journal to resume: a killed tune's, left in the staging folder, else the one in
    place (copied: the folder in place stays as it is until this tune ends)."""
    if not (folder / JOURNAL).is_file() and (out / JOURNAL).is_file():
        shutil.copyfile(out / JOURNAL, folder / JOURNAL)
