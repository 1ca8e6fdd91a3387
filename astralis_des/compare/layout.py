"""The diff recording's viewer layout: the 3-D scene (A's world and robots, B's robots as
ghosts, the marker where the runs part) over both runs' task lanes side by side, each with
the lane of the difference; on the right the comparison's tables, the two event logs side by
side (the differences among their lines) and the progress of both runs."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

from astralis_des.sinks import paths

Point = tuple[float, float, float]
DIFF = "diff"  # the marker's entities: diff/lane, diff/notes, diff/round, diff/event
DIFF_LANE, DIFF_NOTES, DIFF_SUMMARY = f"{DIFF}/lane", f"{DIFF}/notes", f"{DIFF}/summary"
DIFF_ROUND, DIFF_EVENT = f"{DIFF}/round", f"{DIFF}/event"
HEIGHT = 830.0  # px of a 1600 x 900 window left to the panels
TITLE, LANE, AXIS = 26.0, 40.0, 24.0  # px: a view's title, a lane, the lanes' time axis
HIDDEN_PARTS = ("camera", "imu", "lidar", "state", "task")


@dataclass(frozen=True)
class DiffLayout:
    """What the layout depends on: each run's robots and name (``mixed, seed 42, ...``), the
    box the 3-D view looks at, the world's parts left out of it (storeys above the rooms
    shown), the longer run's end, and when the runs part (``None``: they do not)."""

    robots_a: Sequence[str]
    robots_b: Sequence[str]
    name_a: str
    name_b: str
    focus: tuple[Point, Point]
    hidden: Sequence[str]
    end: float
    parted: float | None


def diff_blueprint(layout: DiffLayout) -> Any:
    import rerun.blueprint as rrb

    lanes = max(len(layout.robots_a), len(layout.robots_b)) + 1
    lanes_px = TITLE + AXIS + LANE * lanes
    left = rrb.Vertical(_scene(layout), _lanes(layout), row_shares=[HEIGHT - lanes_px, lanes_px])
    right = rrb.Vertical(
        rrb.TextDocumentView(origin=DIFF_SUMMARY, name="A vs B"),
        rrb.Horizontal(_events(paths.MISSION_EVENTS, f"A events: {layout.name_a}"),
                       _events(f"ghost/{paths.MISSION_EVENTS}", f"B events: {layout.name_b}")),
        rrb.TimeSeriesView(origin="/", name="progress: rooms searched", axis_x=_span(layout),
                           contents=[f"+ /{paths.mission_metric('rooms_searched')}",
                                     f"+ /ghost/{paths.mission_metric('rooms_searched')}"]),
        row_shares=[3, 3, 2])
    from rerun.blueprint.components import AbsoluteTimeRange

    chosen = None if layout.parted is None else AbsoluteTimeRange(  # from where they part
        min=round(layout.parted * 1e9), max=round(layout.end * 1e9))
    panel = rrb.TimePanel(timeline=paths.TIMELINE, state="collapsed", play_state="following",
                          time_selection=chosen)  # opens at the end: both runs' whole paths
    return rrb.Blueprint(rrb.Horizontal(left, right, column_shares=[3, 2]), panel,
                         collapse_panels=True)


def _scene(layout: DiffLayout) -> Any:
    import rerun.blueprint as rrb

    (x0, y0, _), (x1, y1, z1) = layout.focus
    cx, cy, span = (x0 + x1) / 2, (y0 + y1) / 2, max(x1 - x0, y1 - y0, 10.0)
    # steeper than a replay's, so that both runs' trails show; the rooms a little right of
    # and below the middle, toward where the team starts (south-east in the default world)
    cx, cy = cx - 0.3 * span, cy + 0.2 * span
    eye = rrb.EyeControls3D(position=(cx, cy - 0.75 * span, z1 + 1.8 * span),
                            look_target=(cx, cy, 0.0))
    left_out = [f"- /{side}robots/*/{part}/**" for side in ("", "ghost/")
                for part in HIDDEN_PARTS]
    return rrb.Spatial3DView(
        origin="/", name="A, and B's robots as ghosts", eye_controls=eye,
        contents=["+ /world/**", "- /world/occupancy/**",
                  *[f"- /world/{part}/**" for part in layout.hidden],
                  "+ /robots/**", "+ /ghost/robots/**", "+ /ghost/world/**",
                  f"+ /{paths.MISSION_DETECTIONS}/**", f"+ /ghost/{paths.MISSION_DETECTIONS}/**",
                  f"+ /{DIFF_ROUND}/**", f"+ /{DIFF_EVENT}/**", *left_out])


def _lanes(layout: DiffLayout) -> Any:
    """A's lanes beside B's, both over the longer run, each with the difference's lane."""
    import rerun.blueprint as rrb

    span = _span(layout)
    return rrb.Horizontal(
        rrb.StateTimelineView(origin="/", name=f"A lanes: {layout.name_a}", time_view=span,
                              contents=[f"+ /{DIFF_LANE}",
                                        *[f"+ /{paths.robot_state(r)}" for r in layout.robots_a]]),
        rrb.StateTimelineView(origin="/", name=f"B lanes (ghosts): {layout.name_b}",
                              time_view=span, contents=[
                                  f"+ /{DIFF_LANE}",
                                  *[f"+ /ghost/{paths.robot_state(r)}" for r in layout.robots_b]]))


def _span(layout: DiffLayout) -> Any:
    """The time axis over both runs, whole."""
    import rerun as rr
    import rerun.blueprint as rrb

    return rrb.TimeAxis(view_range=rr.TimeRange(
        start=rr.TimeRangeBoundary.absolute(seconds=0.0),
        end=rr.TimeRangeBoundary.absolute(seconds=layout.end * 1.03 + 1.0)))


def _events(origin: str, name: str) -> Any:
    """A run's event log with the differences among its lines."""
    import rerun.blueprint as rrb
    from rerun.blueprint.encodings import TextLogColumn, TimelineColumn

    return rrb.TextLogView(origin="/", name=name, contents=[f"+ /{origin}", f"+ /{DIFF_NOTES}"],
                           columns=rrb.TextLogColumns(
                               timeline_columns=[TimelineColumn(paths.TIMELINE)],
                               text_log_columns=[TextLogColumn("LogLevel"), TextLogColumn("Body"),
                                                 TextLogColumn("EntityPath", visible=False)]))
