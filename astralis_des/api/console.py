"""``astralis serve`` and ``astralis keys``: what they print, and Ctrl-C."""

from __future__ import annotations

import argparse
from typing import Any

from rich.console import Console

from astralis_des.exits import EXIT_INTERRUPTED


def serve_command(args: argparse.Namespace) -> int:
    from astralis_des.api.server import Server
    from astralis_des.api.service import Service
    from astralis_des.api.session import Clock
    from astralis_des.mission.overrides import mission_from_args
    from astralis_des.simulation import Simulation

    if args.state_rate <= 0:
        from astralis_des.errors import InputError

        raise InputError(f"must be above 0 (got {args.state_rate:g})", key="--state-rate")
    mission, out = mission_from_args(args)
    # the sockets before the mission: a bad or busy address fails with nothing written
    server = Server(args.bind, stream=args.stream, curve_keys=args.curve_keys,
                    state_rate=args.state_rate)
    console = Console(stderr=True, quiet=args.quiet, highlight=False, soft_wrap=True)
    try:
        service = Service(Simulation(mission, out_dir=out), Clock(args.pace, not args.stepped))
    except BaseException:
        server.close()
        raise
    server.attach(service)
    spec = mission.spec
    console.print(f"[bold]{spec.name}[/] ({spec.fidelity}, seed {spec.seed}): requests on "
                  f"{server.address}, state stream on {server.stream}"
                  f"{' (CURVE)' if args.curve_keys else ''}; clock "
                  f"{service.clock.describe()}. Ctrl-C stops.")
    service.sim.log.sinks.append(lambda rec: _announce(console, rec, args.exit_on_end))
    try:
        server.serve_forever(exit_on_end=args.exit_on_end)
    except KeyboardInterrupt:
        result = service.end()
        server.close()
        console.print(f"[yellow]interrupted[/] at t = {result.end_time:.1f} s; what was "
                      f"recorded is in {out}/")
        return EXIT_INTERRUPTED
    result = service.end()
    server.close()
    console.print(f"served {service.requests:,} requests ({service.errors:,} refused); "
                  f"outputs: {out}/")
    return 0


def _announce(console: Console, record: dict[str, Any], exit_on_end: bool) -> None:
    """The mission's milestones on the terminal: commands, detections, its end."""
    kind = record["kind"]
    if kind == "mission_end":
        more = ("; still answering queries (Ctrl-C stops)"
                if record["outcome"] != "interrupted" and not exit_on_end else "")
        console.print(f"t = {record['t']:.1f} s: mission ended: {record['outcome']}{more}")
    elif kind == "detection":
        console.print(f"t = {record['t']:.1f} s: [bold green]target found[/] by "
                      f"{record['robot']}")
    elif kind == "command" and record.get("op") != "step":  # a stepping client steps a lot
        what = " ".join(str(record[k]) for k in ("robot", "op", "action", "room")
                        if record.get(k) is not None)
        console.print(f"t = {record['t']:.1f} s: command: {what}")


def keys_command(args: argparse.Namespace) -> int:
    from astralis_des.api.security import create_keys

    made = create_keys(args.folder)
    console = Console(highlight=False)
    console.print("wrote " + ", ".join(str(p) for p in made))
    console.print(f"serve: astralis serve MISSION --bind tcp://0.0.0.0:5555 --curve-keys "
                  f"{args.folder}\nconnect: Client(ADDR, curve_keys='{args.folder}') or "
                  f"astralis chat --connect ADDR --curve-keys {args.folder}. Give clients "
                  "client.key_secret and server.key only.")
    return 0
