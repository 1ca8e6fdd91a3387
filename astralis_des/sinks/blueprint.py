"""The viewer's layout, declared in code and sent with the recording: the 3-D scene over the
task lanes on the left; on the right the assignment (the matrix of Eq. 1's costs, beside the
round's graph for a small team), a camera panel per robot that kept frames, the event log and
the metrics (rooms searched, coverage and distance each on their own axis).

It is sized for a 1600 x 900 window and stays readable with 16 robots: the lanes of a team of
more than :data:`LANES_PER_VIEW` are grouped by kind, side by side, no view holding more than
that many; the panels' heights follow the lanes' and the matrix's rows; names are short where
three views share a row (about 12 characters show there)."""

from __future__ import annotations

from collections import OrderedDict
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

from astralis_des.kinds import KIND_DEFAULTS
from astralis_des.sinks import paths

Point = tuple[float, float, float]

LANES_PER_VIEW = 6  # lanes a view shows at once in the height left under the 3-D scene
WIDTH, HEIGHT = 1600.0, 830.0  # px of a 1600 x 900 window left to the panels
RIGHT = 0.4  # the right column's share of the width
TITLE = 26.0  # px: a view's title bar
LANE = 40.0  # px: one lane of a state timeline (its label, its band, the gap)
LANES_AXIS = 24.0  # px: the state timeline's time axis
MATRIX_ROW = 26.0  # px: a row of the cost matrix, as high as its labels
GRAPH = 250.0  # px: the least height of the assignment row when it shows the graph
MATRIX_SHARE = 0.4  # of the assignment row's width, the matrix's beside the graph
CAMERAS = 210.0  # px: the camera tabs, a frame of 160 x 120 at about 1.5 times
LEGEND_ROBOTS = 6  # up to this many robots, the distances' plot has a legend


@dataclass(frozen=True)
class Layout:
    """What the layout depends on: the team (robot -> kind, in team order); the box the 3-D
    view looks at (the rooms searched); the mission's end (the lanes span it); the robot that
    found the target and those that kept camera frames; the storeys left out of the 3-D view;
    the robots with pose sensors (GNSS, barometer, magnetometer); whether the rounds are
    drawn as graphs too; the bounds of the largest round's cost matrix (x from, x to, y from,
    y to: :meth:`astralis_des.sinks.rounds.Grid.bounds`)."""

    team: Mapping[str, str]
    focus: tuple[Point, Point]
    end: float
    finder: str | None = None
    cameras: Sequence[str] = ()
    hidden: Sequence[str] = ()
    sensed: Sequence[str] = ()
    graph: bool = True
    matrix: tuple[float, float, float, float] = (-2.0, 6.0, -2.0, 4.0)


APPLICATION = "astralis_des"  # the recordings' application id (a blueprint is for one)
KEPT = 16  # layouts a process remembers
_SEEN: OrderedDict[tuple[str, str], bytes | None] = OrderedDict()


def send_layout(rec: Any, recording_id: str, layout: Layout) -> None:
    """Send ``layout``'s blueprint with the recording ``rec`` (made active and default).

    Making a blueprint costs about 5-10 ms of Rerun calls. A layout a process sends a second
    time for the same recording (the same mission run again) is kept encoded, as the bytes of
    a recording holding only it, and sent as a file's contents from then on (1.5 ms)."""
    key = (recording_id, repr(layout))
    encoded = _SEEN.pop(key, b"")
    if encoded is None:  # the second time: keep it encoded
        encoded = _encoded(recording_id, layout)
    _SEEN[key] = encoded or None
    while len(_SEEN) > KEPT:
        _SEEN.popitem(last=False)
    if encoded:
        rec.log_file_from_contents(file_path="layout.rrd", file_contents=encoded)
    else:
        rec.send_blueprint(blueprint(layout))


def _encoded(recording_id: str, layout: Layout) -> bytes | None:
    """The bytes of a recording ``recording_id`` that holds ``layout``'s blueprint alone."""
    import rerun as rr

    stream = rr.RecordingStream(APPLICATION, recording_id=recording_id, send_properties=False)
    sink = rr.binary_stream(recording=stream)
    stream.send_blueprint(blueprint(layout))
    stream.disconnect()
    return sink.read(flush=True)


def blueprint(layout: Layout) -> Any:
    """The layout; the 3-D view looks down from the south at ``layout.focus``, steep enough to
    see into rooms over their walls, without the storeys and roofs ``layout.hidden`` (``A/3``:
    those above the ones searched; tick them on to see them). The planner's occupancy map is
    in the recording but left out of the view (it hides the building)."""
    import rerun.blueprint as rrb

    groups = lane_groups(layout.team)
    lanes_px = TITLE + LANES_AXIS + LANE * max(len(robots) for _, robots in groups)
    left = rrb.Vertical(_scene(layout), _lanes(groups, layout.end),
                        row_shares=[HEIGHT - lanes_px, lanes_px])
    return rrb.Blueprint(rrb.Horizontal(left, _right(layout), column_shares=[3, 2]),
                         collapse_panels=True)


def _right(layout: Layout) -> Any:
    """The right column: the assignment as high as the matrix's rows need (the graph's
    least height for a small team); the cameras under it, or beside the event log when the
    matrix is tall; the event log; the metrics; the pose sensors' tabs."""
    import rerun.blueprint as rrb

    x0, x1, y0, y1 = layout.matrix
    width = WIDTH * RIGHT * (MATRIX_SHARE if layout.graph else 1.0) - 16.0  # its panel's
    unit = min(MATRIX_ROW, width / (x1 - x0))
    panels: list[Any] = [_assignment(layout.graph, layout.matrix)]
    shares = [max(TITLE + unit * (y1 - y0), GRAPH if layout.graph else 0.0)]
    events = _events()
    if layout.cameras and layout.graph:
        panels.append(_cameras(layout.finder, layout.cameras))
        shares.append(CAMERAS)
    elif layout.cameras:
        events = rrb.Horizontal(_cameras(layout.finder, layout.cameras), events,
                                column_shares=[2, 3])
    panels += [events, _metrics(len(layout.team))]
    rest = max(HEIGHT - sum(shares), 300.0)
    shares += [rest / 2, rest / 2]
    if layout.sensed:
        panels.append(_sensed(layout.sensed))
        shares.append(rest / 2)
    return rrb.Vertical(*panels, row_shares=shares)


def lane_groups(team: Mapping[str, str]) -> list[tuple[str, list[str]]]:
    """The task lanes' views, each a name and its robots: the whole team in one for up to
    :data:`LANES_PER_VIEW` robots, else one per kind (``UAV lanes``), in the team's order, a
    kind of more robots than that split (``UAV lanes 1``, ``UAV lanes 2``)."""
    if len(team) <= LANES_PER_VIEW:
        return [("task lanes", list(team))]
    by_kind: dict[str, list[str]] = {}
    for rid, kind in team.items():
        by_kind.setdefault(kind, []).append(rid)
    groups = []
    for kind, robots in by_kind.items():
        record = KIND_DEFAULTS.get(kind)
        name = f"{(record.label if record is not None else '') or kind} lanes"
        parts = [robots[i:i + LANES_PER_VIEW] for i in range(0, len(robots), LANES_PER_VIEW)]
        groups += [(name if len(parts) == 1 else f"{name} {n}", part)
                   for n, part in enumerate(parts, start=1)]
    return groups


def _scene(layout: Layout) -> Any:
    import rerun.blueprint as rrb

    (x0, y0, _), (x1, y1, z1) = layout.focus
    cx, cy, span = (x0 + x1) / 2, (y0 + y1) / 2, max(x1 - x0, y1 - y0, 10.0)
    eye = rrb.EyeControls3D(position=(cx, y0 - 1.1 * span, z1 + 1.3 * span),
                            look_target=(cx, cy, 0.0))
    return rrb.Spatial3DView(
        origin="/", name="mission", eye_controls=eye,
        contents=["+ /world/**", "- /world/occupancy/**",
                  *[f"- /world/{part}/**" for part in layout.hidden], "+ /robots/**",
                  "+ /mission/detections/**",
                  "- /robots/*/camera/**", "- /robots/*/imu/**", "- /robots/*/state/**",
                  "- /robots/*/task/**",
                  *[f"- /robots/{rid}/{part}/**" for rid in layout.sensed
                    for part in ("barometer", "magnetometer", "gnss/geo")]])


def _lanes(groups: list[tuple[str, list[str]]], end: float) -> Any:
    """The lane views side by side, each spanning the whole mission."""
    import rerun as rr
    import rerun.blueprint as rrb

    span = rrb.TimeAxis(view_range=rr.TimeRange(
        start=rr.TimeRangeBoundary.absolute(seconds=0.0),
        end=rr.TimeRangeBoundary.absolute(seconds=end * 1.03 + 1.0)))
    views = [rrb.StateTimelineView(origin="/robots", name=name, time_view=span,
                                   contents=[f"+ /{paths.robot_state(rid)}" for rid in robots])
             for name, robots in groups]
    return views[0] if len(views) == 1 else rrb.Horizontal(*views)


def _assignment(graph: bool, bounds: tuple[float, float, float, float]) -> Any:
    """The rounds' cost matrix, beside their graph for a small team."""
    import rerun.blueprint as rrb

    x0, x1, y0, y1 = bounds
    matrix = rrb.Spatial2DView(
        origin=paths.MISSION_MATRIX, visual_bounds=rrb.VisualBounds2D(x_range=(x0, x1),
                                                                      y_range=(y0, y1)),
        name="Eq. 1 costs" if graph else "Eq. 1 costs: blue cheapest, red dearest, green chosen")
    if not graph:
        return matrix
    return rrb.Horizontal(rrb.GraphView(origin=paths.MISSION_GRAPH, name="assignment round"),
                          matrix, column_shares=[1.0 - MATRIX_SHARE, MATRIX_SHARE])


def _cameras(finder: str | None, cameras: Sequence[str]) -> Any:
    """A tab per robot that kept frames, the finder's first (``found by uav1``)."""
    import rerun.blueprint as rrb

    ordered = sorted(cameras, key=lambda rid: rid != finder)
    return rrb.Tabs(*[rrb.Spatial2DView(
        origin=paths.robot_camera(rid),
        name=f"found by {rid}" if rid == finder else f"{rid}'s camera")
        for rid in ordered])


def _events() -> Any:
    """The event log: time, level and text (every row is ``mission/events``: no path)."""
    import rerun.blueprint as rrb
    from rerun.blueprint.encodings import TextLogColumn, TimelineColumn

    return rrb.TextLogView(origin=paths.MISSION_EVENTS, name="events", columns=rrb.TextLogColumns(
        timeline_columns=[TimelineColumn(paths.TIMELINE)],
        text_log_columns=[TextLogColumn("LogLevel"), TextLogColumn("Body"),
                          TextLogColumn("EntityPath", visible=False)]))


def _metrics(robots: int) -> Any:
    """Three plots in a row, short names; the distances' legend only for a small team (each
    line has its robot's colour, as in the 3-D view)."""
    import rerun.blueprint as rrb

    legend = rrb.PlotLegend(visible=robots <= LEGEND_ROBOTS)
    return rrb.Horizontal(
        rrb.TimeSeriesView(origin=paths.MISSION_METRICS, name="progress",
                           contents=["+ /mission/metrics/**",
                                     "- /mission/metrics/distance/**",
                                     "- /mission/metrics/coverage/**"]),
        rrb.TimeSeriesView(origin=paths.mission_metric("coverage"), name="coverage"),
        rrb.TimeSeriesView(origin=paths.mission_metric("distance"), name="distance (m)",
                           plot_legend=legend))


def _sensed(sensed: Sequence[str]) -> Any:
    """The pose sensors' series and a map, a tab each."""
    import rerun.blueprint as rrb

    def series(what: str) -> list[str]:
        return [f"+ /robots/{rid}/{what}" for rid in sensed]

    return rrb.Tabs(
        rrb.TimeSeriesView(origin="/robots", name="altitude (m)",
                           contents=series("barometer/altitude")),
        rrb.TimeSeriesView(origin="/robots", name="satellites", contents=series("gnss/satellites")),
        rrb.TimeSeriesView(origin="/robots", name="heading (deg)",
                           contents=series("magnetometer/heading")),
        rrb.MapView(origin="/robots", name="GNSS map", contents=series("gnss/geo")))
