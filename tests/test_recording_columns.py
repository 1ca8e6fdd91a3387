"""The recording's Arrow builders (astralis_des.sinks.columns) make what Rerun's archetypes
make: the same arrays, of the same types, under the same descriptors, and a file that reads
back row for row as the archetypes' would."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest

from astralis_des.sinks import columns

rr = pytest.importorskip("rerun")

COLOR = (0, 114, 178, 255)


def batches(archetype: Any) -> dict[str, Any]:
    """An archetype's components: name -> its Arrow array."""
    return {str(b.component_descriptor().component): b.as_arrow_array()
            for b in archetype.as_component_batches()}


def test_each_builder_makes_the_array_of_its_component() -> None:
    """Positions, colours (RGB made opaque), radii, labels, flags, fill mode, line strips
    and scalars: equal arrays of equal types to the archetypes'."""
    pts = np.array([[0.1, 0.2, 0.3], [1.5, -2.25, 3.0]])
    made = batches(rr.Boxes3D(centers=pts, half_sizes=pts / 2, colors=[COLOR, (1, 2, 3)],
                              labels=["a", "b"], show_labels=False, fill_mode="solid"))
    assert made["Boxes3D:centers"].equals(columns.vectors(pts, 3))
    assert made["Boxes3D:half_sizes"].equals(columns.vectors(pts / 2, 3))
    assert made["Boxes3D:colors"].equals(columns.colors([COLOR, (1, 2, 3)]))
    assert made["Boxes3D:labels"].equals(columns.texts(["a", "b"]))
    assert made["Boxes3D:show_labels"].equals(columns.flags([False]))
    assert made["Boxes3D:fill_mode"].equals(columns.SOLID)
    strips = batches(rr.LineStrips3D([pts, pts[:1]], radii=0.05))
    assert strips["LineStrips3D:strips"].equals(columns.strips([pts, pts[:1]]))
    assert strips["LineStrips3D:radii"].equals(columns.floats([0.05]))
    scalars = rr.Scalars.columns(scalars=[1.0, 2.5])
    assert next(iter(scalars)).as_arrow_array().equals(
        columns.rows(columns.doubles([1.0, 2.5])))
    assert columns.descriptor("Points3D", "positions") == rr.Points3D.descriptor_positions()


def test_a_recording_sent_in_columns_reads_back_as_the_archetypes_one(tmp_path: Path) -> None:
    """A static point style, a trail and a column of poses, logged both ways: the same rows."""
    from rerun.chunk import RrdReader

    pts = np.random.default_rng(0).random((5, 3)) * 10
    at = [0.0, 0.5, 1.25, 2.0, 3.1]

    def recording(name: str) -> Any:
        rec = rr.RecordingStream("astralis_des", recording_id="columns")
        rec.set_log_time_enabled(False)
        rec.save(tmp_path / name)
        return rec

    a = recording("a.rrd")
    a.log("r/pose", rr.Points3D.from_fields(radii=0.35, colors=[COLOR], labels=["uav1"]),
          static=True)
    a.log("r/trail", rr.LineStrips3D([pts], colors=[COLOR], radii=0.05), static=True)
    a.send_columns("r/pose", indexes=[rr.TimeColumn("sim_time", duration=at)],
                   columns=rr.Points3D.columns(positions=pts))
    b = recording("b.rrd")
    columns.send_static(b, "r/pose", "Points3D", radii=columns.floats([0.35]),
                        colors=columns.colors([COLOR]), labels=columns.texts(["uav1"]))
    columns.send_static(b, "r/trail", "LineStrips3D", strips=columns.strips([pts]),
                        colors=columns.colors([COLOR]), radii=columns.floats([0.05]))
    columns.send(b, "r/pose", columns.times(at), {
        columns.descriptor("Points3D", "positions"): columns.rows(columns.vectors(pts, 3))})
    for rec in (a, b):
        rec.flush()
        rec.disconnect()

    def rows(path: Path) -> list[tuple[Any, ...]]:
        out = []
        for chunk in RrdReader(path).stream().to_chunks():
            if chunk.entity_path.startswith("/__"):
                continue
            batch = chunk.to_record_batch()
            for field in batch.schema:
                if field.name != "rerun.controls.RowId":
                    out.append((chunk.entity_path, chunk.is_static, field.name, str(field.type),
                                batch.column(field.name).cast("int64").to_pylist()
                                if field.name == "sim_time" else
                                batch.column(field.name).to_pylist()))
        return sorted(out, key=repr)

    assert rows(tmp_path / "a.rrd") == rows(tmp_path / "b.rrd")
