"""Run one generated case as a user would, and judge it.

A case is the bytes of a world file, a mission file and (for studies) a study file, written to a
folder; ``astralis run`` (``validate`` for a physics mission, ``study`` for a study) runs on it
in-process, with an earlier run's files in the output folder some of the time. The property:

- the command ends in a **result** (exit 0, complete outputs) or a **one-line error** (exit 2,
  ``error: FILE...``, one line, the output folder untouched);
- never a traceback (an exception out of ``main``, another exit code, more lines), a warning
  printed on the way, a **hang** (over ``limit`` seconds), or a **mixed** folder (a file of the
  earlier run beside this run's, or a half-written one).
"""

from __future__ import annotations

import contextlib
import io
import json
import shutil
import signal
import time
import warnings
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import yaml

from astralis_des.cli import main

STALE = b'{"stale": "an earlier run"}\n'
OUTPUT_FILES = ("events.jsonl", "summary.json", "recording.rrd")
NAMES = ("mission.yaml", "world.yaml", "study.yaml")


@dataclass(frozen=True)
class Case:
    mission: bytes
    world: bytes
    study: bytes | None = None  # a study of the mission file: run ``astralis study``
    stale: bool = False  # an earlier run's files sit in the output folder
    recording: bool = False  # write the Rerun recording too (else --no-recording)
    out: str = "out"  # the output path given, relative to the case's folder (OUTPUT_PATHS)

    def out_path(self, folder: Path) -> Path:
        return folder / self.out.split("->")[0].rstrip("/")

    def save(self, folder: Path) -> None:
        folder.mkdir(parents=True, exist_ok=True)
        (folder / "mission.yaml").write_bytes(self.mission)
        (folder / "world.yaml").write_bytes(self.world)
        if self.study is not None:
            (folder / "study.yaml").write_bytes(self.study)
        if "->" in self.out:  # a symbolic link to a folder yet to be made
            link, target = self.out.split("->")
            (folder / link).symlink_to(target)


@dataclass(frozen=True)
class Outcome:
    kind: str  # result, error | traceback, warning, hang, mixed
    seconds: float
    detail: str = ""

    @property
    def ok(self) -> bool:
        return self.kind in ("result", "error")


class Hang(Exception):
    pass


@contextlib.contextmanager
def alarm(limit: float) -> Iterator[None]:
    """A :class:`Hang` raised in the main thread after ``limit`` seconds."""
    def fire(_signum: int, _frame: Any) -> None:
        raise Hang(f"no end in {limit:g} s")

    old = signal.signal(signal.SIGALRM, fire)
    signal.setitimer(signal.ITIMER_REAL, limit)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, old)


@contextlib.contextmanager
def dealer_to(mission: Any) -> Iterator[Any]:
    """A ZeroMQ DEALER connected to a server of ``mission`` that waits for commands (its clock
    paused, no automatic rounds): where generated requests go."""
    import zmq

    from astralis_des.api.local import Background

    server = Background(mission.with_changes(assignment={"auto": False, "search": ["A"]}),
                        running=False)
    server.start()
    ctx = zmq.Context()
    socket = ctx.socket(zmq.DEALER)
    socket.connect(server.address)
    try:
        yield socket
    finally:
        ctx.destroy(linger=0)
        server.stop()


def _fidelity(mission: bytes) -> Any:
    try:
        doc = yaml.load(mission, Loader=yaml.CSafeLoader)
    except Exception:  # a broken file: astralis will say what is wrong
        return None
    return doc.get("fidelity") if isinstance(doc, dict) else None


# Output paths a user gives (``Case.out``): nested folders yet to be made, a trailing slash,
# spaces and accents, the case's own folder, a symbolic link to a folder yet to be made; and
# ones that cannot be written: a path under a file, an existing file, a name too long for
# the file system, /proc. Each ends in a result or in one line naming the path, exit 2.
OUTPUT_PATHS = ("out", "deep/er/out", "out/", "dossier de sortie é", ".",
                "link->made/later", "mission.yaml/out", "world.yaml", "x" * 300,
                "/proc/astralis-out")


def command(case: Case, folder: Path) -> list[str]:
    out = case.out if case.out.startswith("/") else str(folder / case.out.split("->")[0])
    if case.study is not None:
        return ["study", str(folder / "study.yaml"), "--out", out, "--workers", "1", "--quiet"]
    if _fidelity(case.mission) == "physics":
        return ["validate", str(folder / "mission.yaml")]
    return ["run", str(folder / "mission.yaml"), "--out", out, "--quiet",
            *([] if case.recording else ["--no-recording"])]


def run_case(case: Case, folder: Path, limit: float = 30.0) -> Outcome:
    """Write ``case`` into the empty ``folder``, run it, and judge what it printed and wrote."""
    if folder.exists():
        shutil.rmtree(folder)
    case.save(folder)
    out = case.out_path(folder)
    if case.stale and case.out in ("out", "out/", "deep/er/out"):
        out.mkdir(parents=True)
        for name in OUTPUT_FILES:
            (out / name).write_bytes(STALE)
    before = _snapshot(out)
    stdout, stderr = io.StringIO(), io.StringIO()
    t0 = time.perf_counter()
    try:
        with (alarm(limit), warnings.catch_warnings(record=True) as caught,
              contextlib.redirect_stdout(stdout), contextlib.redirect_stderr(stderr)):
            warnings.simplefilter("always")
            code = main(command(case, folder))
    except Hang as exc:
        return Outcome("hang", time.perf_counter() - t0, str(exc))
    except BaseException as exc:  # what a user would see as a traceback
        return Outcome("traceback", time.perf_counter() - t0, f"{type(exc).__name__}: {exc}")
    seconds = time.perf_counter() - t0
    if seconds > limit:  # the alarm fired where it could not stop the case (a GC callback)
        return Outcome("hang", seconds, f"{seconds:.1f} s")
    text = stderr.getvalue()
    if caught:
        w = caught[0]
        return Outcome("warning", seconds, f"{w.category.__name__}: {w.message} ({w.filename})")
    if code == 2:
        return _judge_error(text, before, _snapshot(out), seconds,
                            (*NAMES, case.out.split("->")[0].rstrip("/")[:40]))
    if code != 0:
        return Outcome("traceback", seconds, f"exit {code}: {text[-400:]}")
    try:
        problem = (_study_folder(out) if case.study is not None
                   else _run_folder(out, case) if "run" in command(case, folder)[:1] else "")
    except (ValueError, KeyError, IndexError, TypeError) as exc:  # an unreadable output file
        problem = f"{type(exc).__name__}: {exc}"
    return Outcome("mixed", seconds, problem) if problem else Outcome("result", seconds)


def _snapshot(folder: Path) -> dict[str, bytes]:
    try:
        if not folder.is_dir():
            return {}
    except OSError:  # a name too long
        return {}
    return {p.relative_to(folder).as_posix(): p.read_bytes()
            for p in sorted(folder.rglob("*")) if p.is_file()}


def _judge_error(text: str, before: dict[str, bytes], after: dict[str, bytes],
                 seconds: float, names: tuple[str, ...] = NAMES) -> Outcome:
    lines = text.splitlines()
    if len(lines) != 1 or not lines[0].startswith("error: "):
        return Outcome("traceback", seconds, f"not one line: {text[:600]!r}")
    if not any(name in lines[0] for name in names):
        return Outcome("traceback", seconds, f"names no file: {lines[0][:300]}")
    if after != before:
        changed = sorted(set(before) ^ set(after) | {k for k in before if
                                                      after.get(k) != before[k]})
        return Outcome("mixed", seconds, f"an error, but the output folder changed: {changed}")
    return Outcome("error", seconds, lines[0])


def _run_folder(out: Path, case: Case) -> str:
    """What is wrong with a finished run's folder ('' if nothing)."""
    files = _snapshot(out)
    stale = [name for name, data in files.items() if data == STALE]
    if stale:
        return f"files of an earlier run remain: {stale}"
    if case.recording and "recording.rrd" not in files:
        return "no recording.rrd"
    if "events.jsonl" not in files or "summary.json" not in files:
        return f"missing outputs: {sorted(files)}"
    events = [json.loads(line) for line in files["events.jsonl"].decode().splitlines()]
    summary = json.loads(files["summary.json"])
    if events[0]["kind"] != "mission_start" or events[-1]["kind"] != "mission_end":
        return f"the event log runs from {events[0]['kind']} to {events[-1]['kind']}"
    if (summary["mission"], summary["seed"]) != (events[0]["mission"], events[0]["seed"]):
        return "summary.json and events.jsonl are of different runs"
    if summary["outcome"] != events[-1]["outcome"]:
        return f"summary says {summary['outcome']}, the log {events[-1]['outcome']}"
    return ""


def _study_folder(out: Path) -> str:
    files = _snapshot(out)
    if any(data == STALE for data in files.values()):
        return "files of an earlier run remain"
    meta = json.loads(files.get("meta.json", b"{}"))
    if meta.get("interrupted") or "table.csv" not in files:
        return f"an incomplete study folder: {sorted(files)}"
    if meta.get("failed"):
        return f"{meta['failed']} runs failed: {files.get('failures.txt', b'')[:400]!r}"
    return ""
