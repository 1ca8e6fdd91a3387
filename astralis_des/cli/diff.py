"""``astralis diff RUN_A RUN_B [-o diff.rrd]``: two run folders compared in tables, and with
``-o`` one Rerun recording of both (:mod:`astralis_des.compare`)."""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

from astralis_des.cli.options import add_out
from astralis_des.errors import InputError

RUN_HELP = ("a run's folder: what `astralis run -o DIR` wrote, or a study's "
            "DIR/scenarios/NNNNNN/VV_name (--recordings)")


def add_diff_parser(sub: Any) -> None:
    diff = sub.add_parser(
        "diff", help="compare two runs: where they part, what each found and searched",
        description="Compares two run folders (the same mission under two strategies, "
        "fidelities or seeds; a run and its fork): the first assignment round whose matching "
        "differs and the first event that differs, who found the target and when, the rooms "
        "in the order searched, failed tasks, and the metrics with their difference (B - A). "
        "With -o, one Rerun recording of both on one timeline: B's robots as ghosts beside "
        "A's, both runs' task lanes, a marker where they part.")
    diff.add_argument("run_a", metavar="RUN_A", help=RUN_HELP)
    diff.add_argument("run_b", metavar="RUN_B", help="the run to compare with it (B - A)")
    add_out(diff, "also write both runs as one Rerun recording (.rrd; both need their "
            "recording.rrd, of one world)", metavar="FILE")


def diff_command(args: argparse.Namespace) -> int:
    from rich.console import Console

    from astralis_des.compare import compare, load_run

    out = Path(args.out) if args.out else None
    if out is not None:
        from astralis_des.compare.recording import check_target

        check_target(out)
    comparison = compare(load_run(args.run_a), load_run(args.run_b))
    failed: InputError | None = None
    if out is not None:  # before the tables: a reader that goes away (| head) stops no write
        from astralis_des.compare.recording import write_diff

        try:
            write_diff(comparison, out)
        except InputError as exc:  # said after the tables, which still print
            failed = exc
    console = Console(soft_wrap=False)
    print_comparison(console, comparison)
    if failed is not None:
        raise failed
    if out is not None:
        console.print(f"wrote {out} (astralis replay {out})")
    return 0


def headline(comparison: Any) -> str:
    """``they part at round 3 (t = 84.0 s); the first event that differs is line 57 ...``"""
    d, e = comparison.round, comparison.event
    if d is None and e is None:
        return "the runs do not differ: every round and every event is the same"
    parts = []
    if d is not None:
        parts.append(f"the first decision that differs is round {d.number} (t = {d.t:.1f} s)")
    else:
        parts.append("every round's matching is the same")
    if e is not None:
        sides = [(side, r["kind"]) for side, r in (("A", e.a), ("B", e.b)) if r is not None]
        what = sides[0][1] if len(sides) == 2 and sides[0][1] == sides[1][1] else \
            ", ".join(f"{side} {kind}" for side, kind in sides)
        parts.append(f"the first event that differs is line {e.line} (t = {e.t:.1f} s, {what})")
    return "; ".join(parts)


def print_comparison(console: Any, comparison: Any) -> None:
    from rich.table import Table

    from astralis_des.compare.report import sections

    for side, run in (("A", comparison.a), ("B", comparison.b)):
        console.print(f"[bold]{side}[/]: {run.folder} ({run.summary.mission}: {run.label})",
                      soft_wrap=True)
    console.print(headline(comparison), soft_wrap=True)
    for section in sections(comparison):
        if not section.rows:
            console.print(f"{section.title}: none")
            continue
        table = Table(title=section.title, title_justify="left")
        table.add_column("", no_wrap=True)
        table.add_column("A", overflow="fold")
        table.add_column("B", overflow="fold")
        table.add_column("B - A", justify="right")
        for row in section.rows:
            table.add_row(*row, style="yellow" if row[3] not in ("", "0") else None)
        console.print(table)
