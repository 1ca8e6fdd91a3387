"""The viewer's layout, declared in code and sent with the recording: the 3-D scene and the
task lanes on the left; the assignment graph, the camera of the robot that found the target
(when frames were kept), the event log and the metrics on the right."""

from __future__ import annotations

from typing import Any

from astralis_des.sinks import paths


def blueprint(finder: str | None, camera: bool,
              focus: tuple[tuple[float, float, float], tuple[float, float, float]]) -> Any:
    """The layout; the 3-D view looks down from the south at the box ``focus`` (the rooms
    searched), steep enough to see into rooms over their walls. The planner's occupancy map is
    in the recording but left out of the view (it hides the building): tick it on to see it."""
    import rerun.blueprint as rrb

    (x0, y0, _), (x1, y1, z1) = focus
    cx, cy, span = (x0 + x1) / 2, (y0 + y1) / 2, max(x1 - x0, y1 - y0, 10.0)
    eye = rrb.EyeControls3D(position=(cx, y0 - 1.1 * span, z1 + 1.3 * span),
                            look_target=(cx, cy, 0.0))

    right: list[Any] = [rrb.GraphView(origin=paths.MISSION_ROUNDS, name="assignment rounds")]
    if finder is not None and camera:
        right.append(rrb.Spatial2DView(origin=paths.robot_camera(finder),
                                       name=f"{finder}'s camera (found the target)"))
    right += [rrb.TextLogView(origin=paths.MISSION_EVENTS, name="events"),
              rrb.Horizontal(
                  rrb.TimeSeriesView(origin=paths.MISSION_METRICS, name="search progress",
                                     contents=["+ /mission/metrics/**",
                                               "- /mission/metrics/distance/**"]),
                  rrb.TimeSeriesView(origin=paths.mission_metric("distance"),
                                     name="distance travelled (m)"))]
    scene = rrb.Spatial3DView(
        origin="/", name="mission", eye_controls=eye,
        contents=["+ /world/**", "- /world/occupancy/**", "+ /robots/**",
                  "+ /mission/detections/**",
                  "- /robots/*/camera/**", "- /robots/*/imu/**", "- /robots/*/state/**",
                  "- /robots/*/task/**"])
    lanes = rrb.StateTimelineView(origin="/robots", name="task lanes")
    return rrb.Blueprint(
        rrb.Horizontal(rrb.Vertical(scene, lanes, row_shares=[3, 1]),
                       rrb.Vertical(*right), column_shares=[3, 2]),
        collapse_panels=True)
