"""``diff.rrd``: two runs on one ``sim_time`` timeline. A's recording as it is; B's robots as
pale, see-through ghosts under ``ghost/robots/...`` (its lanes, event log and rounds under
``ghost/`` too); a marker where the runs part: a lane that turns from ``same`` to ``event
differs`` and ``decision differs``, the two lines in both event logs, and in the 3-D view a
red flag over each room the first differing round assigned otherwise (and over the robot of
the first differing event). Written staged (:class:`~astralis_des.outdir.Staging`) and read
back (:func:`~astralis_des.sinks.rrd_check.close_and_check`)."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from astralis_des.compare.chunks import a_side, b_side, read_chunks, same_world
from astralis_des.compare.decisions import Comparison
from astralis_des.compare.layout import (
    DIFF_EVENT,
    DIFF_LANE,
    DIFF_NOTES,
    DIFF_ROUND,
    DIFF_SUMMARY,
    DiffLayout,
    diff_blueprint,
)
from astralis_des.compare.report import brief, decided, markdown
from astralis_des.compare.runs import RECORDING, Run
from astralis_des.errors import InputError
from astralis_des.outdir import Staging, usable
from astralis_des.sinks import paths
from astralis_des.sinks.blueprint import APPLICATION
from astralis_des.sinks.rrd_check import close_and_check

FLAG = (230, 40, 40, 255)
LANE_STATES = {"same": (150, 150, 150), "event differs": (240, 160, 40),
               "decision differs": (230, 40, 40)}
FLAG_HEIGHT, FLAG_STEP = 4.0, 2.0  # m a flag rises over a room's top, more for a neighbour


def check_target(target: Path) -> None:
    """Refuse, before any work, an ``-o`` that cannot be a recording."""
    if target.suffix != ".rrd":
        raise InputError("give a file name ending in .rrd (a Rerun recording)", file=target,
                         key="-o")
    usable(target, file=True)


def recordings(c: Comparison) -> tuple[list[Any], list[Any]]:
    """Both runs' chunks, checked to be drawable together (an :class:`InputError` says, in
    one line, why not)."""
    chunks = []
    for run in (c.a, c.b):
        if run.recording is None:
            raise InputError(f"no {RECORDING}, so -o cannot draw the diff (was the run made "
                             "with --no-recording?)", file=run.folder)
        chunks.append(read_chunks(run.recording))
    if not same_world(*chunks):
        raise InputError(f"of another world than {c.a.folder}: the diff recording draws "
                         "both runs in one world", file=c.b.folder)
    return chunks[0], chunks[1]


def write_diff(c: Comparison, target: str | Path) -> Path:
    """Write ``target`` (a ``.rrd``) from the two runs' recordings; its path."""
    import rerun as rr

    target = Path(target)
    check_target(target)
    for run in (c.a, c.b):
        if target.resolve() == (run.folder / RECORDING).resolve():
            raise InputError(f"is the recording of {run.folder}: write the diff elsewhere",
                             file=target, key="-o")
    a, b = recordings(c)
    with Staging(target, file=True) as folder:
        path = folder / target.name
        rec = rr.RecordingStream(APPLICATION, recording_id=f"diff-{c.a.summary.mission}-"
                                 f"{c.a.folder.name}-{c.b.folder.name}")
        rec.set_log_time_enabled(False)
        rec.save(path)
        rec.send_chunks(a_side(a))
        rec.send_chunks(b_side(b))
        rec.log(DIFF_SUMMARY, rr.TextDocument(markdown(c), media_type=rr.MediaType.MARKDOWN),
                static=True)
        rooms = _rooms(a)
        _log_marker(rr, rec, c, rooms, (_poses(a), _poses(b)))
        rec.send_blueprint(diff_blueprint(_layout(c, rooms, a)), make_active=True,
                           make_default=True)
        close_and_check(rec, path)
    return target


Boxes = dict[str, tuple[np.ndarray, np.ndarray]]  # room -> centre, half sizes
Track = tuple[np.ndarray, np.ndarray]  # a robot's times (s) and positions


def _rooms(chunks: Sequence[Any]) -> Boxes:
    """Each room's box, from the first row of A's ``world/rooms`` (labels start with the id)."""
    for chunk in chunks:
        if chunk.entity_path == f"/{paths.WORLD_ROOMS}":
            row = chunk.to_record_batch().slice(0, 1).to_pylist()[0]
            labels, centres, halves = (row.get(f"Boxes3D:{k}") or []
                                       for k in ("labels", "centers", "half_sizes"))
            if not len(labels) == len(centres) == len(halves):
                return {}
            return {str(label).split()[0]: (np.array(c), np.array(h))
                    for label, c, h in zip(labels, centres, halves, strict=True) if label}
    return {}


def _poses(chunks: Sequence[Any]) -> dict[str, Track]:
    """Each robot's pose track in a run's recording: times (s) and positions."""
    tracks: dict[str, list[tuple[float, list[float]]]] = {}
    for chunk in chunks:
        parts = chunk.entity_path.strip("/").split("/")
        if chunk.is_static or parts[0] != "robots" or parts[-1] != "pose":
            continue
        batch = chunk.to_record_batch()
        if not {paths.TIMELINE, "Points3D:positions"} <= set(batch.schema.names):
            continue
        times = batch.column(paths.TIMELINE).cast("int64").to_numpy() / 1e9
        for t, points in zip(times, batch.column("Points3D:positions").to_pylist(), strict=True):
            if points:
                tracks.setdefault(parts[1], []).append((float(t), points[0]))
    out = {}
    for rid, track in tracks.items():
        track.sort(key=lambda tp: tp[0])
        out[rid] = (np.array([t for t, _ in track]), np.array([p for _, p in track]))
    return out


def _at(track: Track, t: float) -> np.ndarray:
    times, points = track
    return points[max(int(np.searchsorted(times, t, side="right")) - 1, 0)]


def _log_marker(rr: Any, rec: Any, c: Comparison, rooms: Boxes,
                poses: tuple[dict[str, Track], dict[str, Track]]) -> None:
    """The lane and the notes of the difference, and its flags in the 3-D view: over the
    rooms the first differing round assigned otherwise, over the robots of the first
    differing event (A's and B's, where each was then)."""
    lane_t, lane_s = [0.0], ["same"]
    notes_t, notes, levels = [], [], []
    e, d = c.event, c.round
    if e is not None:
        lane_t.append(e.t)
        lane_s.append("event differs")
        notes_t.append(e.t)
        notes.append(f"first event that differs, line {e.line}: A {brief(e.a)} | "
                     f"B {brief(e.b)}")
        levels.append("WARN")
        named = [(side, r) for side, r, mine in (("A", e.a, poses[0]), ("B", e.b, poses[1]))
                 if r is not None and r.get("robot") in mine]
        _flag(rr, rec, DIFF_EVENT, e.t,
              [_at((poses[0] if side == "A" else poses[1])[r["robot"]], e.t) for side, r in named],
              [f"line {e.line}: {side} {r['robot']} {r['kind']}" for side, r in named])
    if d is not None:
        lane_t.append(d.t)
        lane_s.append("decision differs")
        notes_t.append(d.t)
        notes.append(f"first decision that differs, round {d.number}: A "
                     f"{decided(d.only_a)} | B {decided(d.only_b)}")
        levels.append("ERROR")
        shown = [r for r in d.rooms if r in rooms]
        tops = [rooms[r][0] + np.array([0.0, 0.0, rooms[r][1][2]]) for r in shown]
        labels = [f"{r}: " + ", ".join([f"A {p[0]}" for p in d.only_a if p[1] == r] +
                                       [f"B {p[0]}" for p in d.only_b if p[1] == r])
                  for r in shown]
        _flag(rr, rec, DIFF_ROUND, d.t, tops, labels)
    values = list(LANE_STATES)
    rec.log(DIFF_LANE, rr.StateConfiguration(values=values, labels=values,
                                             colors=list(LANE_STATES.values())), static=True)
    rec.send_columns(DIFF_LANE, indexes=[rr.TimeColumn(paths.TIMELINE, duration=lane_t)],
                     columns=rr.StateChange.columns(state=lane_s))
    if notes:
        rec.send_columns(DIFF_NOTES, indexes=[rr.TimeColumn(paths.TIMELINE, duration=notes_t)],
                         columns=rr.TextLog.columns(text=notes, level=levels))


def _flag(rr: Any, rec: Any, entity: str, t: float, feet: Sequence[np.ndarray],
          labels: Sequence[str]) -> None:
    """A red pole rising ``FLAG_HEIGHT`` over each of ``feet``, labelled at its top, from
    ``t`` on."""
    if not feet:
        return
    tops = [np.asarray(f) + np.array([0.0, 0.0, FLAG_HEIGHT + FLAG_STEP * (i % 3)])
            for i, f in enumerate(feet)]  # staggered: neighbours' labels do not overlap
    rec.set_time(paths.TIMELINE, duration=t)
    rec.log(f"{entity}/poles", rr.LineStrips3D([[f, top] for f, top in zip(feet, tops,
                                                                           strict=True)],
                                               colors=[FLAG], radii=0.12))
    rec.log(f"{entity}/flags", rr.Points3D(tops, colors=[FLAG], radii=0.5, labels=labels))


def _layout(c: Comparison, rooms: Boxes, a: Sequence[Any]) -> DiffLayout:
    """Looking at the rooms either run assigned, without the storeys above the target's room
    if either run found it (else above the first room where they part, or the first
    assigned), as a run's replay looks into the storey where the target was found."""
    assigned = [m.room for run in (c.a, c.b) for r in run.summary.rounds for m in r.matching
                if m.room in rooms] or list(rooms)
    shown = [r for r in ([c.a.summary.target.get("room")] if _found(c.a) or _found(c.b)
                         else c.round.rooms if c.round else []) if r in rooms] or assigned[:1]
    lo = np.min([rooms[r][0] - rooms[r][1] for r in assigned], axis=0) if assigned else \
        np.zeros(3)
    hi = np.max([rooms[r][0] + rooms[r][1] for r in assigned], axis=0) if assigned else \
        np.full(3, 10.0)
    top = float(rooms[shown[0]][0][2] + rooms[shown[0]][1][2]) if shown else None
    robots = [list(run.summary.robots) for run in (c.a, c.b)]
    return DiffLayout(robots[0], robots[1], c.a.label, c.b.label,
                      ((float(lo[0]), float(lo[1]), float(lo[2])),
                       (float(hi[0]), float(hi[1]), float(hi[2]))),
                      _above(a, top), max(c.a.summary.end_time, c.b.summary.end_time),
                      c.first_time)


def _found(run: Run) -> bool:
    return run.summary.found_by is not None


def _above(chunks: Sequence[Any], top: float | None) -> list[str]:
    """The world's parts (``A/3``, ``A/roof``) whose solids mostly lie above ``top`` (just
    the roofs without one)."""
    hidden = []
    for chunk in chunks:
        parts = chunk.entity_path.strip("/").split("/")
        if not (chunk.is_static and len(parts) == 4 and parts[0] == "world"
                and parts[3] == "solids"):
            continue
        place = f"{parts[1]}/{parts[2]}"
        if top is None:
            if parts[2] == "roof":
                hidden.append(place)
            continue
        row = chunk.to_record_batch().to_pylist()[0]
        bottom = np.median([cz - hz for (_, _, cz), (_, _, hz) in zip(  # a storey's floor: a
            row["Boxes3D:centers"], row["Boxes3D:half_sizes"], strict=True)])  # wall may
        if bottom >= top - 0.3:  # rise from the ground, its centre in this storey
            hidden.append(place)
    return sorted(hidden)
