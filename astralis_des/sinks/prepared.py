"""Static parts of a recording that are the same from run to run (a world's walls, slabs and
imported blocks, mesh or cloud), prepared once per process and sent to each later recording
as chunks.

Grouping a world's boxes by building and storey and building their columns takes about 2 ms
for the default world; a prepared chunk is sent as it is (0.03 ms). They are prepared by
logging into a throwaway recording saved to a temporary file and read back; where that fails
(no temporary folder), they are logged as before."""

from __future__ import annotations

import logging
import tempfile
from collections import OrderedDict
from collections.abc import Callable, Hashable
from pathlib import Path
from typing import Any

from astralis_des.sinks.blueprint import APPLICATION

log = logging.getLogger(__name__)

KEPT = 32  # prepared parts a process keeps (the least recently sent go first)
# Kept here, not on the world (memo.kept): a study sends its world to Ray's workers pickled,
# and Rerun's chunks cannot be pickled. Keys hold the world's id, the world kept beside them.
_PREPARED: OrderedDict[Hashable, tuple[Any, list[Any] | None]] = OrderedDict()


def send_prepared(rr: Any, rec: Any, key: Hashable, owner: Any,
                  logged: Callable[[Any], None]) -> None:
    """Send to ``rec`` what ``logged(stream)`` logs (static only). The first time a process
    sees ``key`` for ``owner`` (the object it is made of, kept with it so that ``key`` may
    hold its ``id``), it is logged as it is; the second time it is prepared (a throwaway
    recording costs a few ms, not worth it for a one-off run) and sent as chunks from then
    on."""
    kept = _PREPARED.pop(key, None)
    seen = kept is not None and kept[0] is owner
    chunks = kept[1] if kept is not None and seen else None
    if seen and chunks is None:
        chunks = _prepare(rr, logged)
    _PREPARED[key] = (owner, chunks)
    while len(_PREPARED) > KEPT:
        _PREPARED.popitem(last=False)
    if chunks is None:
        logged(rec)
    else:
        rec.send_chunks(chunks)


def _prepare(rr: Any, logged: Callable[[Any], None]) -> list[Any] | None:
    """The chunks ``logged`` makes, read back from a throwaway recording (``None`` if it
    could not be written)."""
    from rerun.chunk import RrdReader

    try:
        with tempfile.TemporaryDirectory(prefix="astralis-prepared-") as folder:
            path = Path(folder) / "prepared.rrd"
            stream = rr.RecordingStream(APPLICATION, recording_id="prepared",
                                        send_properties=False)
            stream.set_log_time_enabled(False)
            stream.save(path)
            logged(stream)
            stream.flush()
            stream.disconnect()
            return [chunk for chunk in RrdReader(path).stream().to_chunks()
                    if not chunk.entity_path.startswith("/__")]
    except (OSError, RuntimeError) as exc:  # no temporary folder to write it to
        log.debug("not prepared (%s): logged as it is", exc)
        return None
