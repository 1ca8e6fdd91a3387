"""The long fuzz profile: generated mission (and study) files and API requests, by the hundred
thousand, on a few processes; prints what became of them and keeps every failing case.

    python tools/fuzz.py                                   # 100,000 missions and requests
    python tools/fuzz.py --missions 2000 --requests 2000 --studies 50 --workers 2

The missions' worlds include bad values (NaN, infinite, negative or tiny sizes and origins, rooms
smaller than a robot, buildings off the site) and their starts and move commands points inside
solids or off the site (``tests/fuzzing/strategies.py``); a quarter of the cases write to an
output path other than ``out`` (nested, a symbolic link, accents, or one that cannot be
written: under a file, a file, a name too long, ``/proc``: ``tests/fuzzing/cases.py``).

Each case runs as ``tests/test_fuzz.py`` runs it (``tests/fuzzing/``), but a failure is counted
and saved under ``--out`` (``failures/KIND-N/``, the files to re-run) instead of stopping the
run. Exit status 1 if any case failed.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from collections import Counter
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests"))

LIMIT = 30.0  # s: a case that takes longer is a hang


def _settings(examples: int, seed: int) -> Any:
    from hypothesis import HealthCheck, Phase, settings

    return settings(max_examples=examples, deadline=None, database=None,
                    phases=[Phase.generate], suppress_health_check=list(HealthCheck))


def files(kind: str, examples: int, seed: int, out: str) -> dict[str, Any]:
    """Run ``examples`` generated cases of ``kind`` (missions, studies) from ``seed``."""
    from fuzzing.cases import run_case
    from fuzzing.strategies import mission_cases, study_cases
    from hypothesis import given
    from hypothesis import seed as with_seed

    tally: Counter[str] = Counter()
    times: list[float] = []
    folder = Path(out) / f"work-{kind}-{seed}" / "case"

    @with_seed(seed)
    @_settings(examples, seed)
    @given({"missions": mission_cases, "studies": study_cases}[kind]())
    def one(case: Any) -> None:
        outcome = run_case(case, folder, LIMIT)
        tally[outcome.kind] += 1
        if outcome.seconds > max(times, default=0.0):  # keep the slowest, to look at
            case.save(Path(out) / f"slowest-{kind}-{seed}")
        times.append(outcome.seconds)
        if len(times) % 1000 == 0:  # what an interrupted run can still report
            (Path(out) / f"tally-{kind}-{seed}.json").write_text(
                json.dumps({"tally": dict(tally), "cases": len(times), "max_s": max(times)}))
        if not outcome.ok:
            where = Path(out) / "failures" / f"{kind}-{seed}-{sum(tally.values())}"
            case.save(where)
            (where / "outcome.txt").write_text(f"{outcome.kind}: {outcome.detail}\n")

    one()
    return {"tally": dict(tally), "times": times}


def api(examples: int, seed: int, out: str) -> dict[str, Any]:
    """Send ``examples`` generated requests to a server of the default mission."""
    from fuzzing.cases import dealer_to
    from fuzzing.strategies import requests
    from hypothesis import given
    from hypothesis import seed as with_seed

    from astralis_des import load_mission

    mission = load_mission(ROOT / "missions" / "urban_search.yaml")
    tally: Counter[str] = Counter()
    times: list[float] = []

    @with_seed(seed)
    @_settings(examples, seed)
    @given(requests())
    def one(frames: list[bytes]) -> None:
        t0 = time.perf_counter()
        dealer.send_multipart([b"", *frames])
        if not dealer.poll(int(LIMIT * 1000)):
            tally["hang"] += 1
            raise SystemExit(f"no reply in {LIMIT:g} s to {frames!r:.300}")
        reply = json.loads(dealer.recv_multipart()[-1])
        times.append(time.perf_counter() - t0)
        code = "ok" if reply["ok"] else reply["error"]["code"]
        if not reply["ok"] and "\n" in reply["error"]["message"]:
            code = "failure"  # an error message of more than one line
        tally[code] += 1
        if code in ("internal", "failure"):
            where = Path(out) / "failures" / f"api-{seed}-{sum(tally.values())}.json"
            where.parent.mkdir(parents=True, exist_ok=True)
            where.write_text(json.dumps({"frames": [f.decode("latin-1") for f in frames],
                                         "reply": reply}, indent=2))

    with dealer_to(mission) as dealer:
        one()
        dealer.send_multipart([b"", b'{"op": "info"}'])
        alive = bool(dealer.poll(5000)) and json.loads(dealer.recv_multipart()[-1])["ok"]
    return {"tally": dict(tally), "times": times, "alive": alive}


def _merge(parts: list[dict[str, Any]]) -> tuple[Counter[str], list[float]]:
    tally: Counter[str] = Counter()
    times: list[float] = []
    for part in parts:
        tally.update(part["tally"])
        times += part["times"]
    return tally, sorted(times)


def _report(name: str, parts: list[dict[str, Any]], wall: float) -> None:
    tally, times = _merge(parts)
    n = len(times)
    if not n:
        return

    def p(q: float) -> float:
        return times[min(n - 1, int(q * n))]

    print(f"{name}: {n:,} cases in {wall:,.0f} s ({n / wall:,.0f}/s): "
          + ", ".join(f"{k} {v:,}" for k, v in sorted(tally.items())))
    print(f"  seconds a case: median {p(0.5):.3f}, p99 {p(0.99):.3f}, max {times[-1]:.2f} "
          f"(a hang: over {LIMIT:g})")


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--missions", type=int, default=100_000)
    parser.add_argument("--requests", type=int, default=100_000)
    parser.add_argument("--studies", type=int, default=200)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--out", default="out/fuzz")
    args = parser.parse_args()
    Path(args.out).mkdir(parents=True, exist_ok=True)
    failed = 0
    with ProcessPoolExecutor(args.workers) as pool:
        for kind, total in (("missions", args.missions), ("studies", args.studies),
                            ("requests", args.requests)):
            if total <= 0:
                continue
            t0 = time.perf_counter()
            share = -(-total // args.workers)
            jobs = [pool.submit(api, share, args.seed + w, args.out) if kind == "requests"
                    else pool.submit(files, kind, share, args.seed + w, args.out)
                    for w in range(args.workers)]
            parts = [job.result() for job in jobs]
            _report(kind, parts, time.perf_counter() - t0)
            tally, _ = _merge(parts)
            bad = ("traceback", "warning", "hang", "mixed", "internal", "failure")
            failed += sum(tally.get(k, 0) for k in bad)
            if kind == "requests":
                print(f"  the servers still answered at the end: "
                      f"{all(p['alive'] for p in parts)}")
    print(f"failures: {failed} (kept under {args.out}/failures/)")
    return 1 if failed else 0


if __name__ == "__main__":
    raise SystemExit(main())
