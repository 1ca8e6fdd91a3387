"""``astralis falsify``'s options (the command is in :mod:`astralis_des.studies.falsify_console`,
imported when it runs, so ``astralis --help`` stays quick)."""

from __future__ import annotations

import argparse
from typing import Any

from astralis_des.cli.options import add_out, add_quiet, positive

SAMPLER_NAMES = "tpe, tpe-independent, tpe-multivariate, random, qmc, cmaes"  # falsify.SAMPLERS


def add_falsify_parser(sub: Any) -> None:
    p = sub.add_parser("falsify", help="search a mission's scenario space for the worst cases "
                       "of a strategy (Optuna, against random search): the worst as mission "
                       "files, every trial, a report")
    p.add_argument("mission", help="mission YAML file")
    p.add_argument("--strategy", help="the strategy to falsify (default: the mission's)")
    p.add_argument("--metric", default="time_to_find", help="a study metric (default "
                   "time_to_find; not found counts as the time limit); an unknown name "
                   "lists them")
    p.add_argument("--against", metavar="S2", help="search for the largest gap between the "
                   "strategy and S2 on the same scenario")
    p.add_argument("--worst-is", choices=("largest", "smallest"),
                   help="which end of the metric is bad (default: by metric; smallest for "
                   "found and human_min_distance)")
    p.add_argument("--trials", type=positive, default=100,
                   help="trials of the optimiser (default 100), and as many random ones")
    p.add_argument("--space", metavar="FILE", help="the space's bounds (YAML; default: the "
                   "mission's own ranges)")
    p.add_argument("--sampler", default="tpe",
                   help=f"Optuna sampler: {SAMPLER_NAMES} (default tpe)")
    p.add_argument("--seed", type=int, default=0, help="the samplers' seed (default 0)")
    p.add_argument("--batch", type=positive, default=4, help="trials asked, run side by side, "
                   "then told (default 4; the trials depend on it, not on --workers)")
    p.add_argument("--no-baseline", action="store_true",
                   help="no random search beside the optimiser")
    p.add_argument("--worst", type=positive, default=5, metavar="K",
                   help="worst scenarios written as mission files (default 5)")
    p.add_argument("--recordings", action="store_true",
                   help="run the worst again with their outputs: recordings/NN/STRATEGY/")
    p.add_argument("--workers", type=positive, help="processes (default: the CPUs)")
    p.add_argument("--backend", default="local", help="local (a process pool) or ray")
    p.add_argument("--address", help="ray: the address of an existing cluster")
    add_out(p, "output folder (default out/<mission name>_falsify)", metavar="DIR")
    add_quiet(p, "no progress bar or summary")


def falsify(args: argparse.Namespace) -> int:
    from astralis_des.studies.falsify_console import falsify_command

    return falsify_command(args)
