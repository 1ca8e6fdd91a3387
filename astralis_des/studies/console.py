"""``astralis study``: run a study with a progress bar and print its report, or replay one
scenario of it alone."""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

from rich.console import Console
from rich.table import Table

from astralis_des.errors import InputError
from astralis_des.exits import EXIT_INTERRUPTED
from astralis_des.outdir import holding
from astralis_des.studies.backends import make_backend
from astralis_des.studies.reports import report
from astralis_des.studies.runner import run_scenario, run_study
from astralis_des.studies.spec import Study, load_study
from astralis_des.studies.terminal import fitted

EXIT_FAILED = 1


def study_command(args: argparse.Namespace) -> int:
    study = load_study(args.study)
    if args.scenarios is not None:
        study = study.with_changes(scenarios=args.scenarios)
    if args.replay is not None:
        return replay(study, args)
    if args.variant is not None:
        raise InputError("--variant picks a variant to replay: use it with --replay",
                         key="--variant")
    try:  # checked before the progress bar starts
        make_backend(args.backend, args.workers or 1, args.address)
    except InputError as exc:
        raise InputError(exc.message, key=f"--{exc.key}") from None
    out = Path(args.out or Path("out") / study.name)
    console = Console(stderr=True, quiet=args.quiet, soft_wrap=True)  # never wrapped
    try:
        with holding(out):  # a second writer is refused before any scenario runs
            result = with_progress(console, study.name, "scenarios", study.scenarios,
                                   lambda progress: run_study(
                study, workers=args.workers, backend=args.backend, address=args.address,
                out=out, recordings=True if args.recordings else None, progress=progress))
    except KeyboardInterrupt:  # before the first scenario was under way
        console.print("[yellow]interrupted[/]; nothing written")
        return EXIT_INTERRUPTED
    if result.interrupted:
        console.print(f"[yellow]interrupted[/]; the {len(result.rows):,} rows of the scenarios "
                      f"done are in {out}/")
        return EXIT_INTERRUPTED
    if not args.quiet:
        stdout = Console()
        for table in report(result):
            if table.shown:
                for part in fitted(table, stdout.width):
                    stdout.print(part)
        stdout.print(f"{len(result.rows):,} runs in {result.wall_time:.1f} s "
                     f"({result.backend}, {result.workers} worker"
                     f"{'s' if result.workers > 1 else ''}); outputs: {out}/")
        stdout.print("also there: report.md (every metric), table.csv (every run)")
    if result.failed:
        first = next(r for r in result.rows if r["status"] == "failed")
        console.print(f"[red]{result.failed} failed run(s)[/] (tracebacks in "
                      f"{out}/failures.txt); replay the first alone with: astralis study "
                      f"{args.study} --replay {first['scenario']} --variant '{first['variant']}'")
    return 0


def replay(study: Study, args: argparse.Namespace) -> int:
    """Scenario N alone, in this process, as the study runs it; an error shows its traceback."""
    index = args.replay
    if not 0 <= index < study.scenarios:
        raise InputError(f"scenario {index} is not in the study (0 to {study.scenarios - 1})",
                         key="--replay")
    variants = [study.variant(args.variant).name] if args.variant is not None else None
    out = Path(args.out or Path("out") / f"{study.name}-replay-{index}")
    console = Console()
    try:
        result = run_scenario(study, index, variants=variants, raise_errors=True,
                              recordings=out if args.recordings else None)
    except Exception:
        scenario = study.scenario(index)
        console.print(f"[red]scenario {index} (seed {scenario.seed}) fails:[/]")
        console.print_exception()
        return EXIT_FAILED
    table = Table(title=f"{study.name}: scenario {index}")
    table.add_column("column", no_wrap=True)
    for row in result.rows:
        table.add_column(row["variant"], overflow="fold")
    for column in dict.fromkeys(k for row in result.rows for k in row):
        table.add_row(column, *(_cell(row.get(column)) for row in result.rows))
    console.print(table)
    if args.recordings:
        console.print(f"outputs: {out}/")
    return 0


def _cell(value: Any) -> str:
    if isinstance(value, float):
        return f"{value:.4g}"
    return "" if value is None else str(value)


def with_progress(console: Console, name: str, unit: str, total: int, run: Any) -> Any:
    """``run(progress)`` under a progress bar of ``total`` ``unit``; ``progress(done, total)``
    moves it (and may change its total)."""
    from rich.progress import (
        BarColumn,
        MofNCompleteColumn,
        Progress,
        TextColumn,
        TimeElapsedColumn,
        TimeRemainingColumn,
    )

    columns = (TextColumn(f"[bold]{name}"), BarColumn(), MofNCompleteColumn(),
               TextColumn(unit), TimeElapsedColumn(), TimeRemainingColumn())
    with Progress(*columns, console=console, transient=False) as bar:
        task = bar.add_task(name, total=total)
        return run(lambda done, all_: bar.update(task, completed=done, total=all_))
