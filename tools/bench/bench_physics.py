"""Physics fidelity benchmark: real-time factor, overhead over raw PyBullet, idle cost.

    python tools/bench/bench_physics.py [--mission missions/urban_search.yaml]

Measured in one run, on this machine:
- raw PyBullet: the same world (static compound), the Husky and two rigid UAV bodies, stepped
  at 240 Hz with the Husky driving and the UAVs held up, no Python around it;
- the default mission in physics at 240 Hz with recording on and each robot's default sensors
  (cameras looking 4 times a second while searching, the UGV's lidar at 10 Hz and the IMUs at
  20 Hz while moving): wall time, time inside ``stepSimulation``, their ratio (the overhead
  ratio), the real-time factor, and each sensor's share (``camera`` renders frames,
  ``camera_cull`` tests whether the target can be in view at all); the run's floor, Bullet's
  steps and the sensors alone, and what the 40x goal leaves everything else;
- the recording's share (the same run without outputs);
- the same mission after a one-hour idle wait (``assignment.start_at: 3600``);
- ``astralis run missions/urban_search.yaml --fidelity physics`` as a user runs it: the whole
  process, start-up, recording and summary included, with the package's bytecode cached (as
  Python does by default) and, where PYTHONDONTWRITEBYTECODE is set, compiled each time; and
  its floor, a process that only imports what it imports, plus the run's floor;
- a team-size curve (``--teams 4 8 16 32 64 100``): the default mission with half the team
  UAVs and half UGVs, in physics with the default sensors and no outputs, idle UGVs asleep
  in Bullet (``physics.sleep_idle``, the default; ``--awake`` keeps them awake): real-time
  factor, its share of raw PyBullet's, time inside ``stepSimulation`` and the overhead ratio
  per team size (goals: >= 10x with 32 robots, >= 3x with 100).

Goals (issue 43): >= 40x real time in the run with the default sensors; wall / time inside
``stepSimulation`` <= 1.4 leaving the sensors out; the whole ``astralis run`` process >= 25x.
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))

from astralis_des import Simulation, load_mission  # noqa: E402
from astralis_des.physics.client import PhysicsClient  # noqa: E402
from astralis_des.physics.husky import Husky  # noqa: E402


def raw_pybullet(mission, steps: int = 2400) -> float:  # type: ignore[no-untyped-def]
    """Seconds per physics step of bare PyBullet with the mission's bodies, at 240 Hz."""
    client = PhysicsClient(mission.world, 1 / 240, 1, mission.spec.physics.solver_iterations)
    husky = Husky(client, np.array([90.0, 60.0, 0.0]))
    shape = client.call("createCollisionShape", 4, radius=0.3, height=0.12)
    uavs = [client.call("createMultiBody", 1.5, shape, basePosition=[88.0 + 2 * k, 64.0, 1.5])
            for k in range(2)]
    client.step(60)
    t0 = time.perf_counter()
    for _ in range(steps):
        husky.drive(1.0, 0.3)
        for uav in uavs:
            client.call("applyExternalForce", uav, -1, [0, 0, 1.5 * 9.81], [0, 0, 0], 1)
        client.step()
    per_step = (time.perf_counter() - t0) / steps
    client.close()
    return per_step


def run(mission, out: Path | None):  # type: ignore[no-untyped-def]
    t0 = time.perf_counter()
    sim = Simulation(mission, out_dir=out)
    result = sim.run()
    return (time.perf_counter() - t0, result, sim.cosim.step_time, sim.cosim.client.steps,
            sim.outputs_time, sim.navigator)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--mission", default=str(ROOT / "missions" / "urban_search.yaml"))
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--teams", type=int, nargs="*", default=[4, 8, 16, 32, 64, 100],
                        help="team sizes of the scaling curve (none: skip it)")
    parser.add_argument("--awake", action="store_true",
                        help="the curve with idle UGVs awake (physics.sleep_idle off)")
    args = parser.parse_args()
    mission = load_mission(args.mission).with_changes(fidelity="physics")
    raw = raw_pybullet(mission)
    print(f"raw PyBullet (Husky + 2 UAV bodies + world, 240 Hz): {raw * 1e6:.0f} us/step, "
          f"{1 / 240 / raw:.1f}x real time")
    raw_rate = 1 / 240 / raw
    runs = []
    import rerun  # noqa: F401  (imported once per process, not per run: not the run's cost)

    with tempfile.TemporaryDirectory() as tmp:
        for i in range(args.repeat):
            runs.append(run(mission, Path(tmp) / str(i)))
        rrd = Path(tmp) / "0" / "recording.rrd"
        size = rrd.stat().st_size
    wall, result, stepping, steps, writing, nav = sorted(runs, key=lambda r: r[0])[len(runs) // 2]
    bare = statistics.median(run(mission, None)[0] for _ in range(args.repeat))
    print(f"default mission, physics, recording on ({result.end_time:.1f} s simulated, "
          f"outcome {result.outcome}):")
    sensing = sum(result.sensor_time.values())
    print(f"  wall {wall:.2f} s, real-time factor {result.end_time / wall:.1f}x with the default "
          f"sensors (goal >= 40x; {result.end_time / wall / raw_rate:.0%} of raw PyBullet's); "
          f"{result.end_time / (wall - sensing):.1f}x without their time")
    print(f"  inside stepSimulation {stepping:.2f} s: overhead ratio "
          f"{(wall - sensing) / stepping:.2f} leaving the sensors out (goal <= 1.4), "
          f"{wall / stepping:.2f} with them")
    floor = stepping + sensing
    print(f"  the run's floor, Bullet's steps and the sensors alone: {floor:.2f} s, at most "
          f"{result.end_time / floor:.1f}x if nothing else cost a thing; 40x leaves "
          f"{result.end_time / 40 - floor:.2f} s for everything else, against "
          f"{wall - floor:.2f} s now")
    for name, seconds in result.sensor_time.items():
        calls = result.sensor_calls[name]
        print(f"  sensor {name:<12} {seconds * 1e3:6.0f} ms, {seconds / wall:5.1%} of the run, "
              f"{calls:5d} calls, {seconds / calls * 1e3:.2f} ms each")
    print(f"  physics steps taken: {steps} for {result.end_time * 240:.0f} at 240 Hz "
          f"({steps / (result.end_time * 240):.0%}; nothing is stepped while nothing moves), "
          f"{stepping / steps * 1e6:.0f} us each")
    print(f"  outputs (recording, event log, summary): {writing * 1e3:.0f} ms, "
          f"{writing / wall:.1%} of the run (goal < 10%); recording {size / 1024:.0f} KiB, "
          f"{size / 1024 / (result.end_time / 60):.0f} KiB per simulated minute")
    print(f"  planning ({nav.method} mode): {nav.seconds * 1e3:.0f} ms, {nav.seconds / wall:.1%} "
          f"of the run; {nav.plans} legs planned around furniture")
    print(f"  the same run without outputs: {bare:.2f} s")
    waited = mission.with_changes(assignment={**mission.spec.assignment.model_dump(),
                                              "start_at": 3600.0},
                                  time_limit=mission.spec.time_limit + 3600.0)
    idle = statistics.median(run(waited, None)[0] for _ in range(args.repeat))
    print(f"  the same after a one-hour idle wait: {idle:.2f} s against {bare:.2f} s "
          f"({(idle - bare) / bare:+.1%}; goal < +5%)")
    with tempfile.TemporaryDirectory() as cache:
        cached = whole_process(args.mission, args.repeat, user_env(cache), warm=True)
        imports = imports_only(args.repeat, user_env(cache))
    print(f"astralis run {Path(args.mission).name} --fidelity physics, the whole process with "
          f"the recording (bytecode cached, as Python does by default): median {cached:.2f} s "
          f"of {args.repeat}, {result.end_time / cached:.1f}x real time (goal >= 25x; "
          f"{result.end_time / cached / raw_rate:.0%} of raw PyBullet's)")
    print(f"  its floor: a process that only imports what it imports ({imports:.2f} s) and the "
          f"run's floor above: {imports + floor:.2f} s, at most "
          f"{result.end_time / (imports + floor):.1f}x")
    if os.environ.get("PYTHONDONTWRITEBYTECODE"):
        env = {**os.environ, "PYTHONPATH": str(ROOT)}
        compiled = whole_process(args.mission, args.repeat, env, warm=False)
        print(f"  the same with PYTHONDONTWRITEBYTECODE=1 (set here: each process compiles the "
              f"package): {compiled:.2f} s, {result.end_time / compiled:.1f}x")
    if args.teams:
        team_curve(mission, args.teams, raw_rate, sleep=not args.awake)


def user_env(cache: str) -> dict[str, str]:
    """A user's process running this checkout's code: Python writes and reads the bytecode
    (in ``cache``; this machine may set PYTHONDONTWRITEBYTECODE)."""
    env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
    return {**env, "PYTHONPYCACHEPREFIX": cache, "PYTHONPATH": str(ROOT)}


def whole_process(mission: str, repeat: int, env: dict[str, str], warm: bool) -> float:
    """Median wall seconds of ``astralis run MISSION --fidelity physics`` with the recording,
    after one run that writes the bytecode when ``warm``."""
    with tempfile.TemporaryDirectory() as tmp:
        return processes(["astralis", "run", mission, "--fidelity", "physics", "--out", tmp],
                         repeat, env, warm)


IMPORTS = ("import astralis_des.cli, astralis_des.simulation, astralis_des.cosim.physics, "
           "astralis_des.sinks.files, astralis_des.sinks.recording, pybullet, rerun; "
           "astralis_des.cli.end_process(0)")  # and ends as `astralis` does


def imports_only(repeat: int, env: dict[str, str]) -> float:
    """Median wall seconds of a Python process that only imports what ``astralis run
    --fidelity physics`` imports and ends as it does (the bytecode written first, as by
    ``whole_process``)."""
    return processes([sys.executable, "-c", IMPORTS], repeat, env, warm=True)


def processes(cmd: list[str], repeat: int, env: dict[str, str], warm: bool) -> float:
    """Median wall seconds of ``repeat`` runs of ``cmd``, after one that writes the bytecode
    when ``warm``."""
    times = []
    for k in range(repeat + warm):
        t0 = time.perf_counter()
        subprocess.run(cmd, capture_output=True, check=True, env=env)
        if k >= warm:
            times.append(time.perf_counter() - t0)
    return statistics.median(times)


ROW = 40  # robots of a kind in one row; more start in the next row, on the road before it
ROWS_Y = {"uav": (60.0, 49.0), "ugv": (66.0, 52.0)}
GOALS = {32: " (goal >= 10x)", 100: " (goal >= 3x)"}


def team(size: int) -> list[dict[str, object]]:
    """``size`` robots in the street before building A: UAVs in a row 2 m apart, UGVs in a
    row 3 m apart behind them (half each; one more UAV when ``size`` is odd); past ``ROW`` of
    a kind, the next ones in a second row on the road."""
    uavs, ugvs = (size + 1) // 2, size // 2

    def start(kind: str, k: int, spacing: float) -> list[float]:
        return [84.0 + spacing * (k % ROW), ROWS_Y[kind][k // ROW], 0.0]

    return ([{"id": f"uav{k + 1}", "kind": "uav", "start": start("uav", k, 2.0)}
             for k in range(uavs)]
            + [{"id": f"ugv{k + 1}", "kind": "ugv", "start": start("ugv", k, 3.0)}
               for k in range(ugvs)])


def team_curve(mission, sizes: list[int], raw_rate: float,  # type: ignore[no-untyped-def]
               sleep: bool) -> None:
    physics = {**mission.spec.physics.model_dump(), "sleep_idle": sleep}
    print("team-size curve: the default mission with n robots (half UAVs, half UGVs), physics, "
          f"default sensors, no outputs, idle UGVs {'asleep' if sleep else 'awake'} in Bullet:")
    print("  robots  simulated      wall  real-time  of raw  in stepSimulation  overhead  outcome")
    for size in sizes:
        team_mission = mission.with_changes(team=team(size), physics=physics)
        wall, result, stepping, steps, _, _ = run(team_mission, None)
        print(f"  {size:6d}  {result.end_time:7.1f} s  {wall:6.2f} s  "
              f"{result.end_time / wall:8.1f}x  {result.end_time / wall / raw_rate:5.0%}"
              f"  {stepping:7.2f} s ({stepping / steps * 1e6:4.0f} us/step)  "
              f"{wall / stepping:7.2f}  {result.outcome} by {result.found_by}"
              f"{GOALS.get(size, '')}")


if __name__ == "__main__":
    main()
