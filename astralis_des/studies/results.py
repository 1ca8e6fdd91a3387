"""The result of a study run: its rows, with how it was run."""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property
from pathlib import Path
from typing import TYPE_CHECKING, Any

from astralis_des.registry import Registry
from astralis_des.studies.scenarios import evaluation_of
from astralis_des.studies.table import summarize, to_table

if TYPE_CHECKING:
    import pyarrow as pa

    from astralis_des.studies.spec import Study

# how a result is written (``astralis_des.studies.output`` registers ``folder``): found by
# name, as the writer needs the reports and plots, which read results
WRITERS: Registry[str, Any] = Registry("study writer", plugins=("astralis_des.studies.output",))

@dataclass
class StudyResult:
    """The rows of a study run, with how it was run."""

    study: Study
    rows: list[dict[str, Any]]
    failures: list[str] = field(default_factory=list)
    wall_time: float = 0.0
    backend: str = "local"
    workers: int = 1
    interrupted: bool = False  # Ctrl-C, SIGTERM or SIGHUP: the rows of the scenarios done

    @cached_property
    def table(self) -> pa.Table:
        """One row per scenario and variant: its inputs and outcomes (a pyarrow Table)."""
        return to_table(self.rows)

    @property
    def failed(self) -> int:
        return sum(r["status"] == "failed" for r in self.rows)

    def summary(self) -> list[dict[str, Any]]:
        """Per variant and metric: the estimate and its 95% confidence interval."""
        return summarize(self.table, evaluation_of(self.study).metrics,
                         [v.name for v in self.study.variants])

    def write(self, folder: str | Path) -> Path:
        """Write the folder (table, summary, plots, study file, version) all at once."""
        return WRITERS.get("folder")(self, Path(folder))
