"""MCAP output benchmark: what writing ``run.mcap`` costs a run, and its size.

    python tools/bench/bench_mcap.py [--fidelity physics] [--repeat 3]

Runs the default mission with the MCAP output on (and the other outputs as the mission has
them), times the MCAP writer apart (collecting events as they come and writing the file when
the run closes) and prints its share of the run's wall time, the file's size and its message
count by topic. Goal (issue 23): under 10% of the physics run's wall time.
"""

from __future__ import annotations

import argparse
import statistics
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))

from astralis_des.mission.loader import load_mission  # noqa: E402
from astralis_des.simulation import Simulation  # noqa: E402
from astralis_des.sinks import mcap_out  # noqa: E402

SPENT = [0.0]
_close, _on_event = mcap_out.McapWriter.close, mcap_out.McapWriter.on_event


def _timed(method):  # type: ignore[no-untyped-def]
    def wrapper(self, arg):  # type: ignore[no-untyped-def]
        t0 = time.perf_counter()
        method(self, arg)
        SPENT[0] += time.perf_counter() - t0
    return wrapper


mcap_out.McapWriter.close = _timed(_close)  # type: ignore[method-assign]
mcap_out.McapWriter.on_event = _timed(_on_event)  # type: ignore[method-assign]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--fidelity", default="physics")
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()
    base = load_mission(ROOT / "missions" / "urban_search.yaml")
    mission = base.with_changes(fidelity=args.fidelity, outputs={
        **base.spec.outputs.model_dump(), "mcap": True})
    shares, walls, writes = [], [], []
    for _ in range(args.repeat):
        with tempfile.TemporaryDirectory() as tmp:
            SPENT[0] = 0.0
            t0 = time.perf_counter()
            Simulation(mission, out_dir=tmp).run()
            wall = time.perf_counter() - t0
            size = (Path(tmp) / "run.mcap").stat().st_size
        walls.append(wall)
        writes.append(SPENT[0])
        shares.append(SPENT[0] / wall)
    print(f"default mission, {args.fidelity}: run {statistics.median(walls):.2f} s wall "
          f"(outputs on), MCAP writer {statistics.median(writes):.3f} s: "
          f"{statistics.median(shares):.1%} of the run (median of {args.repeat}; the first in "
          f"the process, generating the serialisers: {shares[0]:.1%}); "
          f"run.mcap {size / 1e6:.2f} MB")


if __name__ == "__main__":
    main()
