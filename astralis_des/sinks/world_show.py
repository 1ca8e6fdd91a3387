"""``astralis world show``: a recording of a world alone, furnished at a messiness."""

from __future__ import annotations

from collections import Counter
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from astralis_des.errors import InputError
from astralis_des.mission.draws import RoomState
from astralis_des.outdir import Staging
from astralis_des.sinks.rrd_check import close_and_check
from astralis_des.world.build import load_world
from astralis_des.world.catalogue import default_catalogue, load_catalogue
from astralis_des.world.model import World
from astralis_des.world.scene import Scene


@dataclass(frozen=True)
class Shown:
    path: Path
    rooms: int
    placed: Counter[str]
    skipped: list[tuple[str, str, str]]


def show_world(world_file: str | Path, messiness: Sequence[float], out: str | Path, *,
               seed: int = 0, catalogue: str | Path | None = None) -> Shown:
    """Furnish every room (``messiness`` given for all rooms, or cycled over them in id order)
    and write the world alone to a Rerun recording at ``out``."""
    import rerun as rr

    from astralis_des.sinks.recording import log_furniture, log_rooms, log_solids

    for value in messiness:
        if not 0.0 <= value <= 1.0:
            raise InputError(f"{value:g} is outside [0, 1]", key="--messiness")
    world = load_world(Path(world_file).resolve())
    cat = load_catalogue(Path(catalogue)) if catalogue is not None else default_catalogue()
    ids = sorted(world.rooms)
    values = {rid: float(messiness[i % len(messiness)]) for i, rid in enumerate(ids)}
    scene = Scene(world, values, seed, cat)
    placed = scene.furnish_all()
    out = Path(out)
    with Staging(out, file=True) as folder:  # in place whole, or not at all
        rec = rr.RecordingStream("astralis_des", recording_id=f"world-{world.name}-{seed}")
        rec.save(folder / out.name, default_blueprint=_overview(world))
        log_solids(rr, rec, world)
        log_rooms(rec, world, {rid: RoomState(0.0, values[rid], "minimal") for rid in ids}, None)
        log_furniture(rec, placed, world)
        close_and_check(rec, folder / out.name)
    return Shown(out, len(ids), Counter(p.kind for p in placed), scene.skipped())


def _overview(world: World) -> Any:
    """A 3-D view looking down at the first building (or the whole site of a world without
    buildings) from the south, steep enough to see into its rooms over the walls."""
    import rerun.blueprint as rrb

    from astralis_des.world.geometry import Box

    buildings = list(world.buildings.values())
    box = buildings[0].footprint if buildings else Box((0.0, 0.0, 0.0), (*world.site, 0.0))
    cx, cy = (box.lo[0] + box.hi[0]) / 2, (box.lo[1] + box.hi[1]) / 2
    span = max(box.hi[0] - box.lo[0], box.hi[1] - box.lo[1])
    eye = rrb.EyeControls3D(position=(cx, box.lo[1] - 0.35 * span, 1.1 * span),
                            look_target=(cx, cy, 0.0))
    return rrb.Blueprint(rrb.Spatial3DView(origin="/", name=world.name, eye_controls=eye),
                         collapse_panels=True)
