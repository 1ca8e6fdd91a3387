"""The Rerun recording of a run: static world, rooms by risk and messiness, robot poses and
trails, each robot's task and the events as text, on one ``sim_time`` timeline."""

from __future__ import annotations

from collections.abc import Generator, Mapping, Sequence
from functools import lru_cache
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from astralis_des.kernel.catalogue import level_of
from astralis_des.kernel.events import Record
from astralis_des.sinks import paths
from astralis_des.sinks.blueprint import APPLICATION, Layout, send_layout
from astralis_des.sinks.columns import (
    SOLID,
    Columns,
    colors,
    descriptor,
    flags,
    floats,
    one_row,
    rows,
    send,
    send_static,
    static_columns,
    strips,
    texts,
    times,
    vectors,
)
from astralis_des.sinks.looks import (
    ROAD_COLOR,
    by_height,
    by_place,
    log_body,
    placed_color,
    robot_colors,
    solid_color,
)
from astralis_des.sinks.prepared import send_prepared
from astralis_des.sinks.replay import log_lanes, log_metrics, metrics, task_lanes
from astralis_des.sinks.rounds import GRAPH_AGENTS, Grid, log_rounds
from astralis_des.sinks.rrd_check import close_and_check
from astralis_des.sinks.sensor_log import log_detections, log_pose_sensors, log_sensors
from astralis_des.world.clutter import Placed
from astralis_des.world.model import BLOCK, World

if TYPE_CHECKING:
    from astralis_des.simulation import Simulation
    from astralis_des.simulation.result import RunResult


class _TextColumn:
    """Text lines of one entity, kept until the run closes and sent as one column."""

    def __init__(self) -> None:
        self.times: list[float] = []
        self.texts: list[str] = []
        self.levels: list[str] = []

    def add(self, t: float, text: str, level: str) -> None:
        self.times.append(t)
        self.texts.append(text)
        self.levels.append(level)


LIVE_PERIOD = 2.0  # s of simulated time between sends to a live viewer


class RerunRecorder:
    """Writes ``recording.rrd``: the world at once, then events, task states and poses in
    columns when the run closes (also when it is interrupted), each entity's a chunk built
    straight into Arrow arrays (:mod:`astralis_des.sinks.columns`)."""

    def __init__(self, sim: Simulation, path: Path, view: bool = False) -> None:
        import rerun as rr

        self.rr = rr
        self.sim = sim
        spec = sim.mission.spec
        self.recording_id = f"{spec.name}-{spec.seed}"
        self.rec = rr.RecordingStream(APPLICATION, recording_id=self.recording_id)
        self.rec.set_log_time_enabled(False)  # one timeline: simulated time
        self.path = path
        self.rec.save(path)
        self._texts: dict[str, _TextColumn] = {}
        self._sent: dict[str, int] = {}  # entity -> rows of its column already sent
        if view:
            self.connect_viewer(path)
            sim.env.process(self._stream())
        self._log_world()

    def connect_viewer(self, path: Path) -> None:
        """Spawn a Rerun viewer and send to it as well as to the file."""
        rr = self.rr
        self.rec.spawn(connect=False)
        self.rec.set_sinks(rr.FileSink(str(path)), rr.GrpcSink())

    def _stream(self) -> Generator[Any, Any, None]:
        """With a live viewer: send what the columns gained every ``LIVE_PERIOD`` simulated
        seconds, rather than all of it when the run closes."""
        while True:
            yield self.sim.env.timeout(LIVE_PERIOD)
            self._send_new()

    def _log_world(self) -> None:
        rr, rec, sim = self.rr, self.rec, self.sim
        world = sim.world
        send_prepared(rr, rec, ("solids", id(world)), world, lambda s: log_solids(rr, s, world))
        target = sim.target
        send_static(rec, paths.WORLD_TARGET, "Points3D", positions=vectors([target.position], 3),
                    radii=floats([0.3]), colors=colors([(255, 0, 255)]),
                    labels=texts([f"target ({target.avatar['color']})"]))
        log_rooms(rec, self.sim.world, self.sim.rooms, 0.0)

    def _log_movers(self, end: float) -> None:
        """Patrolling avatars and moving obstacles, sampled at 2 Hz, in columns."""
        scene = self.sim.scene
        at = np.arange(0.0, end + 0.5, 0.5)
        for mover in [*scene.movers, *scene.avatar_movers()]:
            path = paths.mover(mover.id)
            send(self.rec, path, times(at), {descriptor("Boxes3D", "centers"): rows(vectors(
                mover.positions_at(at), 3))})
            send_static(self.rec, path, "Boxes3D",
                        half_sizes=vectors([np.array(mover.size) / 2], 3),
                        labels=texts([mover.id]),
                        colors=colors([(255, 0, 255, 255) if mover.id == "target" else
                                       (200, 120, 40, 255)]))

    def _text(self, entity: str) -> _TextColumn:
        return self._texts.setdefault(entity, _TextColumn())

    def on_event(self, record: Record) -> None:
        """Every event into the event log, at its catalogue's level (also a robot's task
        text, for the task starts and ends)."""
        t, kind, robot = record["t"], record["kind"], record.get("robot")
        level = level_of(record)
        self._text(paths.MISSION_EVENTS).add(t, describe(record), level)
        if robot and kind in ("task_started", "task_finished"):
            state = record["action"] if kind == "task_started" else f"idle ({record['status']})"
            self._text(paths.robot_task(robot)).add(t, f"{state} {record.get('room') or ''}",
                                                    level)
        if kind == "room_change":
            log_rooms(self.rec, self.sim.world, self.sim.rooms, t)

    def close(self, result: RunResult) -> None:
        rr, rec = self.rr, self.rec
        log_furniture(rec, self.sim.scene.furnished(), self.sim.world)
        navigator = self.sim.navigator
        if navigator.map_built:  # the planner's occupancy map, when this run used it
            points = navigator.occupied_points()
            send_static(rec, paths.WORLD_OCCUPANCY, "Points3D", positions=vectors(points, 3),
                        radii=floats([0.1]), colors=colors(by_height(points[:, 2])))
        self._log_movers(result.end_time)
        perception = self.sim.cosim.perception
        if perception is not None:
            log_sensors(rr, rec, perception)
        log_pose_sensors(rr, rec, self.sim.pose_sensors)
        log_detections(rec, self.sim.log.records)
        self._send_new()
        palette = robot_colors(list(self.sim.robots))
        for rid, robot in self.sim.robots.items():
            pts = np.array(robot.trail_p, dtype=float)
            color = palette[rid]
            log_body(rr, rec, robot, color)
            pose, plan = robot_styles(rid, color)
            send(rec, paths.robot_pose(rid), None, pose)
            send_static(rec, paths.robot_trail(rid), "LineStrips3D",
                        strips=strips([pts.reshape(-1, 3)]), colors=colors([color]),
                        radii=floats([0.05]))
            if robot.plans:  # each leg's planned path, from when it was set out on
                send(rec, paths.robot_plan(rid), times([t for t, _ in robot.plans]), {
                    descriptor("LineStrips3D", "strips"): rows(strips(
                        [np.asarray(p, dtype=float).reshape(-1, 3) for _, p in robot.plans]))})
                send(rec, paths.robot_plan(rid), None, plan)
        self._log_replay(result, perception)
        rec.flush(timeout_sec=0.0)  # Rerun's threads encode and write it from now on

    def finish(self) -> None:
        close_and_check(self.rec, self.path)  # Rerun's file sink only logs a failed write

    def discard(self) -> None:
        """The run's outputs are abandoned: stop writing (what it wrote is removed)."""
        self.rec.disconnect()

    def _send_new(self) -> None:
        """Send the rows of the text and pose columns not sent yet."""
        rec = self.rec
        for entity, column in self._texts.items():
            start = self._sent.get(entity, 0)
            if start < len(column.times):
                send(rec, entity, times(column.times[start:]), {
                    descriptor("TextLog", "text"): rows(texts(column.texts[start:])),
                    descriptor("TextLog", "level"): rows(texts(column.levels[start:]))})
                self._sent[entity] = len(column.times)
        for rid, robot in self.sim.robots.items():
            entity = paths.robot_pose(rid)
            start = self._sent.get(entity, 0)
            if start < len(robot.trail_t):
                send(rec, entity, times(np.array(robot.trail_t[start:], dtype=float)), {
                    descriptor("Points3D", "positions"): rows(vectors(
                        np.array(robot.trail_p[start:], dtype=float), 3))})
                self._sent[entity] = len(robot.trail_t)

    def _log_replay(self, result: RunResult, perception: Any) -> None:
        """Task lanes, assignment rounds, metrics, and the layout that shows them."""
        rec, sim = self.rec, self.sim
        kinds = {rid: robot.kind for rid, robot in sim.robots.items()}
        records = sim.log.records
        log_lanes(rec, task_lanes(records, list(sim.robots)))
        graph = len(kinds) <= GRAPH_AGENTS
        log_rounds(rec, sim.rounds, kinds, graph)
        cfg = sim.mission.spec.assignment
        log_metrics(rec, metrics(records, sim.rounds, kinds, cfg.high_risk,
                                 cfg.high_messiness), robot_colors(list(sim.robots)))
        framed = {f.robot for f in perception.frames} if perception is not None else set()
        cameras = [rid for rid in sim.robots if rid in framed]
        searched = [sim.world.rooms[r] for r in sim.mission.searched_rooms()]
        rooms = [r.box for r in searched]
        focus = ((min(b.lo[0] for b in rooms), min(b.lo[1] for b in rooms), 0.0),
                 (max(b.hi[0] for b in rooms), max(b.hi[1] for b in rooms),
                  max(b.hi[2] for b in rooms)))
        shown = [sim.world.rooms[result.target["room"]]] if result.found_by else \
            [min(searched, key=lambda r: r.floor)]  # up to where it was found, or began
        send_layout(rec, self.recording_id, Layout(
            team=kinds, focus=focus, end=result.end_time, finder=result.found_by,
            cameras=cameras, hidden=above(sim.world, shown),
            sensed=sorted({rid for rid, _ in sim.pose_sensors.sensors}), graph=graph,
            matrix=Grid.largest(sim.rounds).bounds()))


@lru_cache(maxsize=256)
def robot_styles(rid: str, color: tuple[int, int, int, int]) -> tuple[Columns, Columns]:
    """The static looks of a robot's pose (its colour, labelled) and of its planned path (its
    colour, faint): the same from run to run, made once."""
    return (static_columns("Points3D", radii=floats([0.35]), colors=colors([color]),
                           labels=texts([rid])),
            static_columns("LineStrips3D", colors=colors([(*color[:3], 140)]),
                           radii=floats([0.03])))


def above(world: World, shown: Sequence[Any]) -> list[str]:
    """The storeys (and roofs) above the highest storey of the ``shown`` rooms in each
    building or interior (all of one with none): the 3-D view leaves them out, so that it looks
    into the storey where the target was found (or where the search began)."""
    top: dict[str, int] = {}
    for room in shown:
        if room.building in world.indoors:
            top[room.building] = max(top.get(room.building, 0), room.floor)
    storeys = {bid: b.floors for bid, b in world.buildings.items()}
    if world.interior is not None:
        storeys[world.interior.group] = len(world.interior.storeys)
    hidden = []
    for bid, floors in storeys.items():
        highest = top.get(bid, floors)
        hidden += [f"{bid}/{n}" for n in range(highest + 1, floors + 1)]
        hidden.append(f"{bid}/roof")
    return hidden


def describe(record: Record) -> str:
    """One line a person can read, e.g. ``uav1 task_finished spiral_inward A.1.1.2: ...``."""
    parts = [record.get("robot", ""), record["kind"]]
    for key in ("op", "action", "room", "direction", "status", "message", "segment", "outcome",
                "reason"):
        if record.get(key) not in (None, ""):
            parts.append(str(record[key]))
    if record["kind"] == "assignment":
        parts.append(", ".join(f"{m['agent']}->{m['room']} {m['action']}"
                               for m in record["matching"]))
    return " ".join(p for p in parts if p)


def log_solids(rr: Any, rec: Any, world: World) -> None:
    """Walls, slabs and outdoor obstacles, once (static); an imported world's blocks, mesh
    and cloud (:mod:`astralis_des.sinks.imported`)."""
    from astralis_des.sinks.imported import log_imported

    solids = [s for s in world.solids if s.kind != BLOCK]
    for place, idx in by_place(world, [s.box for s in solids]).items():
        mine = [solids[i] for i in idx]
        lo = np.array([s.box.lo for s in mine]).reshape(-1, 3)
        hi = np.array([s.box.hi for s in mine]).reshape(-1, 3)
        send_static(rec, paths.world_part(place, "solids"), "Boxes3D",
                    centers=vectors((lo + hi) / 2, 3), half_sizes=vectors((hi - lo) / 2, 3),
                    colors=colors([solid_color(s.kind) for s in mine]), fill_mode=SOLID)
    if world.surfaces:
        lo = np.array([s.box.lo for s in world.surfaces])
        hi = np.array([s.box.hi for s in world.surfaces])
        send_static(rec, paths.WORLD_ROADS, "Boxes3D", centers=vectors((lo + hi) / 2, 3),
                    half_sizes=vectors((hi - lo) / 2, 3), colors=colors([ROAD_COLOR]),
                    fill_mode=SOLID)
    log_imported(rr, rec, world)


def room_boxes(world: World, states: Mapping[str, Any]) -> tuple[
        np.ndarray, np.ndarray, list[tuple[int, int, int, int]], list[str]]:
    """The rooms in id order, their corners (low, high), colours (red by risk, blue by
    messiness, translucent) and labels."""
    ids = sorted(world.rooms)
    lo = np.array([world.rooms[r].box.lo for r in ids])
    hi = np.array([world.rooms[r].box.hi for r in ids])
    shades = [(int(255 * states[r].risk), 60, int(255 * states[r].messiness), 90) for r in ids]
    labels = [f"{r} risk {states[r].risk:.2f} mess {states[r].messiness:.2f} "
              f"{states[r].sound}" for r in ids]
    return lo, hi, shades, labels


def log_rooms(rec: Any, world: World, states: Mapping[str, Any], at: float | None) -> None:
    """Rooms as translucent boxes, red by risk and blue by messiness, labelled: as they are at
    ``at`` (None: static, a world shown without a run)."""
    lo, hi, shades, labels = room_boxes(world, states)
    columns = {descriptor("Boxes3D", "centers"): vectors((lo + hi) / 2, 3),
               descriptor("Boxes3D", "half_sizes"): vectors((hi - lo) / 2, 3),
               descriptor("Boxes3D", "colors"): colors(shades),
               descriptor("Boxes3D", "labels"): texts(labels),
               descriptor("Boxes3D", "show_labels"): flags([False])}
    send(rec, paths.WORLD_ROOMS, None if at is None else times([at]),
         {key: one_row(values) for key, values in columns.items()})


def log_furniture(rec: Any, placed: Sequence[Placed], world: World) -> None:
    """Furniture and avatars, once (static), by building and storey, coloured by kind (an
    avatar in its Table II colour)."""
    for place, idx in by_place(world, [p.box for p in placed]).items():
        mine = [placed[i] for i in idx]
        lo = np.array([p.box.lo for p in mine])
        hi = np.array([p.box.hi for p in mine])
        labels = [p.kind if p.kind != "avatar" else
                  "avatar " + " ".join(str(v) for _, v in p.attributes) for p in mine]
        send_static(rec, paths.world_part(place, "furniture"), "Boxes3D",
                    centers=vectors((lo + hi) / 2, 3), half_sizes=vectors((hi - lo) / 2, 3),
                    colors=colors([placed_color(p) for p in mine]), labels=texts(labels),
                    show_labels=flags([False]), fill_mode=SOLID)
