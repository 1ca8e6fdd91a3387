"""A run folder read back: its ``summary.json`` (checked for what a comparison reads), its
``events.jsonl`` and, when it has one, its ``recording.rrd``. Folders written by
``astralis run -o DIR`` and by a study's ``--recordings`` (``DIR/scenarios/NNNNNN/VV_name``)
are alike. Anything else is an :class:`~astralis_des.errors.InputError` naming the file, the
line or the key."""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from pydantic import BaseModel, ConfigDict, ValidationError

from astralis_des.errors import InputError

SUMMARY, EVENTS, RECORDING = "summary.json", "events.jsonl", "recording.rrd"
Value = float | int | bool | str | None


class Match(BaseModel):
    """One pair of an assignment round's matching."""

    agent: str
    room: str
    action: str | None = None


class Round(BaseModel):
    round: int
    t: float
    segment: str | None = None
    strategy: str | None = None
    matching: list[Match]


class Robot(BaseModel):
    kind: str
    distance: float = 0.0
    tasks_failed: int = 0
    faulted: bool = False


class Summary(BaseModel):
    """What a comparison reads of ``summary.json`` (other keys are kept, not checked)."""

    model_config = ConfigDict(extra="allow")

    mission: str
    seed: int
    fidelity: str
    outcome: str
    end_time: float
    time_to_find: float | None = None
    found_by: str | None = None
    target: dict[str, Any]
    robots: dict[str, Robot]
    rounds: list[Round]
    rooms_searched: list[str]
    metrics: dict[str, Any] | None = None  # the study metrics, in runs that write them
    fork: dict[str, Any] | None = None  # a fork's point and changes (astralis run --fork-at)


@dataclass(frozen=True)
class Run:
    folder: Path
    summary: Summary
    events: list[dict[str, Any]]
    recording: Path | None  # None: the run was made without one

    @property
    def strategy(self) -> str:
        """Its rounds' strategies in order, ``mixed`` or ``mixed->cbba`` (a fork's), ``-`` for a
        run without rounds."""
        return "->".join(dict.fromkeys(r.strategy for r in self.summary.rounds
                                       if r.strategy)) or "-"

    @property
    def label(self) -> str:
        """``mixed, seed 42, kinematic``: what tells two runs of one mission apart (a fork's
        says where it forked: ``mixed->cbba, seed 42, kinematic, forked at round:3``)."""
        s = self.summary
        forked = f", forked at {s.fork['point']}" if s.fork and "point" in s.fork else ""
        return f"{self.strategy}, seed {s.seed}, {s.fidelity}{forked}"


def load_run(folder: str | Path) -> Run:
    """The run in ``folder`` (an :class:`InputError` if it is not a whole run folder)."""
    path = Path(folder)
    if not path.is_dir():
        raise InputError("no such folder" if not path.exists() else
                         "is a file: give a run's folder (what `astralis run -o DIR` wrote)",
                         file=path)
    if not (path / SUMMARY).is_file():
        raise InputError(f"not a run folder (no {SUMMARY}){_hint(path)}", file=path)
    summary = _summary(path / SUMMARY)
    events = _events(path / EVENTS)
    recording = path / RECORDING
    return Run(path, summary, events, recording if recording.is_file() else None)


def _hint(path: Path) -> str:
    """Where a run is, when ``path`` holds runs (a study's folder, a scenario's)."""
    found = sorted(path.glob(f"*/{SUMMARY}")) or sorted(path.glob(f"scenarios/*/*/{SUMMARY}")) \
        or sorted(path.glob(f"*/*/{SUMMARY}"))
    if found:
        return f": it holds runs, give one of them, e.g. {found[0].parent}"
    return ": give a folder written by `astralis run -o DIR` or by a study's --recordings"


def _text(path: Path) -> str:
    try:
        return path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise InputError("missing: diff compares the runs' event logs (was the mission's "
                         "outputs.events off?)", file=path) from None
    except UnicodeDecodeError:
        raise InputError("not UTF-8 text: is it a run's file?", file=path) from None
    except OSError as exc:
        raise InputError(f"cannot be read ({exc.strerror or exc})", file=path) from None


def _summary(path: Path) -> Summary:
    try:
        data = json.loads(_text(path))
    except json.JSONDecodeError as exc:
        raise InputError(f"not valid JSON ({exc.msg})", file=path, line=exc.lineno) from None
    if not isinstance(data, dict):
        raise InputError("not a run's summary (a JSON object)", file=path)
    try:
        return Summary.model_validate(data)
    except ValidationError as exc:
        first = exc.errors()[0]
        key = ".".join(str(p) for p in first["loc"])
        raise InputError(f"{first['msg'].lower()}: is it a run's summary?", file=path,
                         key=key) from None


def _events(path: Path) -> list[dict[str, Any]]:
    events = []
    for n, line in enumerate(_text(path).splitlines(), start=1):
        try:
            record = json.loads(line)
        except json.JSONDecodeError as exc:
            raise InputError(f"not a JSON event ({exc.msg})", file=path, line=n) from None
        if not (isinstance(record, dict) and isinstance(record.get("kind"), str)
                and isinstance(record.get("t"), int | float)):
            raise InputError("an event is an object with a time t and a kind", file=path,
                             line=n)
        events.append(record)
    if not events:
        raise InputError("empty: no events", file=path)
    return events
