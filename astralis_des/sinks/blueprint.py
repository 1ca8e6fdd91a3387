"""The viewer's layout, declared in code and sent with the recording: the 3-D scene and the
task lanes on the left; the assignment graph, a camera panel per robot that kept frames, the
event log and the metrics (rooms searched, coverage and distance each on their own axis) on
the right."""

from __future__ import annotations

from typing import Any

from astralis_des.sinks import paths


def blueprint(finder: str | None, cameras: list[str],
              focus: tuple[tuple[float, float, float], tuple[float, float, float]],
              hidden: list[str] | None = None, sensed: list[str] | None = None) -> Any:
    """The layout; the 3-D view looks down from the south at the box ``focus`` (the rooms
    searched), steep enough to see into rooms over their walls, without the storeys and roofs
    ``hidden`` (``A/3``: those above the ones searched; tick them on to see them). A camera
    panel per robot in ``cameras`` (those that kept frames), the finder's first. The planner's
    occupancy map is in the recording but left out of the view (it hides the building)."""
    import rerun.blueprint as rrb

    (x0, y0, _), (x1, y1, z1) = focus
    cx, cy, span = (x0 + x1) / 2, (y0 + y1) / 2, max(x1 - x0, y1 - y0, 10.0)
    eye = rrb.EyeControls3D(position=(cx, y0 - 1.1 * span, z1 + 1.3 * span),
                            look_target=(cx, cy, 0.0))

    right: list[Any] = [rrb.GraphView(origin=paths.MISSION_ROUNDS, name="assignment rounds")]
    ordered = sorted(cameras, key=lambda rid: rid != finder)
    if ordered:
        right.append(rrb.Tabs(*[rrb.Spatial2DView(
            origin=paths.robot_camera(rid),
            name=f"{rid}'s camera" + (" (found the target)" if rid == finder else ""))
            for rid in ordered]))
    right += [rrb.TextLogView(origin=paths.MISSION_EVENTS, name="events"),
              rrb.Horizontal(
                  rrb.TimeSeriesView(origin=paths.MISSION_METRICS, name="search progress",
                                     contents=["+ /mission/metrics/**",
                                               "- /mission/metrics/distance/**",
                                               "- /mission/metrics/coverage/**"]),
                  rrb.TimeSeriesView(origin=paths.mission_metric("coverage"),
                                     name="coverage of each search (share)"),
                  rrb.TimeSeriesView(origin=paths.mission_metric("distance"),
                                     name="distance travelled (m)"))]
    if sensed:  # robots with GNSS, barometers, magnetometers: their series and a map
        def series(what: str) -> list[str]:
            return [f"+ /robots/{rid}/{what}" for rid in sensed]

        right.append(rrb.Tabs(
            rrb.TimeSeriesView(origin="/robots", name="altitude (barometer, m)",
                               contents=series("barometer/altitude")),
            rrb.TimeSeriesView(origin="/robots", name="GNSS satellites seen",
                               contents=series("gnss/satellites")),
            rrb.TimeSeriesView(origin="/robots", name="heading (magnetometer, deg)",
                               contents=series("magnetometer/heading")),
            rrb.MapView(origin="/robots", name="GNSS fixes on a map",
                        contents=series("gnss/geo"))))
    scene = rrb.Spatial3DView(
        origin="/", name="mission", eye_controls=eye,
        contents=["+ /world/**", "- /world/occupancy/**",
                  *[f"- /world/{part}/**" for part in hidden or []], "+ /robots/**",
                  "+ /mission/detections/**",
                  "- /robots/*/camera/**", "- /robots/*/imu/**", "- /robots/*/state/**",
                  "- /robots/*/task/**",
                  *[f"- /robots/{rid}/{part}/**" for rid in sensed or []
                    for part in ("barometer", "magnetometer", "gnss/geo")]])
    lanes = rrb.StateTimelineView(origin="/robots", name="task lanes")
    return rrb.Blueprint(
        rrb.Horizontal(rrb.Vertical(scene, lanes, row_shares=[3, 1]),
                       rrb.Vertical(*right), column_shares=[3, 2]),
        collapse_panels=True)
