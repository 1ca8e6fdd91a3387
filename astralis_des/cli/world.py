"""``astralis world rooms | spots | show | import``: look at worlds, and make them."""

from __future__ import annotations

import argparse
import contextlib
import sys
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

from astralis_des.cli.options import Command, add_out, positive
from astralis_des.exits import EXIT_INTERRUPTED

WORLD_COMMANDS: dict[str, Command] = {}


def world_command(name: str) -> Callable[[Command], Command]:
    def add(fn: Command) -> Command:
        WORLD_COMMANDS[name] = fn
        return fn

    return add


def world(args: argparse.Namespace) -> int:
    """``astralis world SUBCOMMAND``."""
    return WORLD_COMMANDS[args.world_command](args)


def add_world_parser(sub: Any) -> None:
    parser = sub.add_parser("world", help="look at worlds")
    world_sub = parser.add_subparsers(dest="world_command", metavar="WORLD_COMMAND",
                                      required=True)
    rooms = world_sub.add_parser("rooms", help="list a world's buildings, storeys, segments, "
                                 "rooms and doors (the ids a mission names)")
    rooms.add_argument("world", help="world YAML file")
    _add_spots_parser(world_sub)
    show = world_sub.add_parser("show", help="write a recording of a world, furnished")
    show.add_argument("world", help="world YAML file")
    show.add_argument("--messiness", type=float, nargs="+", default=[0.5],
                      help="messiness of every room, or values cycled over the rooms in id "
                           "order (default 0.5)")
    show.add_argument("--seed", type=int, default=0)
    show.add_argument("--catalogue", help="clutter catalogue file (default: the packaged one)")
    add_out(show, "recording to write (default out/world_NAME.rrd)", metavar="FILE")
    _add_import_parser(world_sub)


def _add_spots_parser(world_sub: Any) -> None:
    spots = world_sub.add_parser(
        "spots", help="list free points where a robot may start, the nearest first",
        description="Points a mission's start may name: outdoors on a grid over the site, "
                    "indoors at each room's centre and along each corridor; each clear of "
                    "every solid by the body's radius, as the mission validator checks a "
                    "start. Nearest first to --near, else to the first building's entrance.")
    spots.add_argument("world", help="world YAML file")
    where = spots.add_mutually_exclusive_group()
    where.add_argument("--outdoor", dest="where", action="store_const", const="outdoor",
                       default="both", help="only outdoors")
    where.add_argument("--indoor", dest="where", action="store_const", const="indoor",
                       help="only in rooms and corridors")
    spots.add_argument("--near", nargs=2, type=float, metavar=("X", "Y"),
                       help="the nearest to this point first (default: the first building's "
                       "entrance, else the site's middle)")
    spots.add_argument("-n", type=positive, default=10, dest="count", metavar="N",
                       help="how many (default 10)")
    spots.add_argument("--kind", help="free for this kind of robot (default: for every kind)")
    spots.add_argument("--spacing", type=_metres, default=2.0, metavar="M",
                       help="m between outdoor points, and between a corridor's (default 2)")


def _metres(text: str) -> float:
    value = float(text)
    if not value > 0:
        raise argparse.ArgumentTypeError(f"must be above 0 (got {text})")
    return value


def _add_import_parser(world_sub: Any) -> None:
    imp = world_sub.add_parser(
        "import", help="make a world (a digital twin) of a point cloud or a mesh",
        description="Point clouds: LAS, LAZ, PLY, PCD, XYZ/CSV. Meshes: OBJ, glTF/GLB, STL "
                    "(and PLY with faces). Writes the world file and, beside it, its blocks, "
                    "mesh and cloud.")
    imp.add_argument("file", help="the cloud or mesh to import")
    add_out(imp, "world file to write (worlds/NAME.yaml)", metavar="FILE", required=True)
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
    imp.add_argument("--indoor", action="store_true", help="an indoor scan or model: find its "
                     "storeys, rooms, doors and stairs, searched like a built-in building's "
                     "(instead of --areas)")
    imp.add_argument("--group", default="A", help="--indoor: the building's id, the first part "
                     "of its rooms' ids (default: A)")
    imp.add_argument("--door-max", type=float, default=1.4, help="--indoor: the widest "
                     "passage, in m, that still parts two rooms (default: 1.4; wider openings "
                     "join them, as an open-plan space)")


@world_command("rooms")
def _world_rooms(args: argparse.Namespace) -> int:
    from astralis_des.world.build import load_world
    from astralis_des.world.describe import room_lines

    print("\n".join(room_lines(load_world(args.world))))
    return 0


@world_command("spots")
def _world_spots(args: argparse.Namespace) -> int:
    from astralis_des.errors import InputError
    from astralis_des.kinds import KINDS, known_kind
    from astralis_des.world.build import load_world
    from astralis_des.world.spots import free_spots, spot_lines

    try:
        kinds = [known_kind(args.kind)] if args.kind is not None else list(KINDS)
    except ValueError as exc:
        raise InputError(str(exc), key="--kind") from None
    world = load_world(args.world)
    near = tuple(args.near) if args.near is not None else None
    spots = free_spots(world, kinds, near=near, count=args.count, where=args.where,
                       spacing=args.spacing)
    print("\n".join(spot_lines(world, spots, kinds, near)))
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
        max_points=args.max_points, keep_strays=args.keep_strays, indoor=args.indoor,
        group=args.group, door_max=args.door_max)
    command_line = " ".join(["astralis world import", *sys.argv[3:]]) if \
        sys.argv[1:3] == ["world", "import"] else None
    console = Console(highlight=False, stderr=True, soft_wrap=True)  # a line is one line
    try:  # the output locked (and found writable) before the import
        with holding(args.out), _import_progress(console) as progress:
            report = import_world(args.file, args.out, options, command=command_line,
                                  progress=progress)
    except KeyboardInterrupt:
        console.print(f"[yellow]interrupted[/]; {args.out} was not written")
        return EXIT_INTERRUPTED
    out = Console(highlight=False)
    what = (f"{report.points:,} points" if report.kind == "cloud" else
            f"{report.points:,} triangles")
    if report.dropped:
        what += f" ({report.dropped:,} with NaN or infinite coordinates dropped)"
    out.print(f"[bold]{report.world}[/]: {what}, site {report.site[0]:g} x "
              f"{report.site[1]:g} m, voxel {report.voxel:g} m, {report.blocks:,} blocks, "
              + (f"{report.rooms} rooms, {report.doors} doors" if options.indoor else
                 f"areas {', '.join(report.areas)}") + f" ({report.seconds:.2f} s)")
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

    out = args.out or str(Path("out") / f"world_{Path(args.world).stem}.rrd")
    shown = show_world(args.world, args.messiness, out, seed=args.seed,
                       catalogue=args.catalogue)
    items = ", ".join(f"{n} {kind}" for kind, n in sorted(shown.placed.items())) or "nothing"
    print(f"{shown.path}: {shown.rooms} rooms furnished: {items}")
    for room, kind, reason in shown.skipped:
        print(f"  not placed in {room}: {kind} ({reason})")
    return 0
