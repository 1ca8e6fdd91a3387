"""What a study prints and writes to ``report.md``, by registry (``report:`` picks it).

A report is plain data (titled tables of strings); the CLI draws them with rich.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

from astralis_des.registry import Registry
from astralis_des.studies import registries
from astralis_des.studies.table import format_estimate

if TYPE_CHECKING:
    from astralis_des.studies.results import StudyResult


@dataclass(frozen=True)
class TextTable:
    title: str
    headers: list[str]
    rows: list[list[str]]
    notes: list[str] = field(default_factory=list)

    def markdown(self) -> str:
        lines = [f"**{self.title}**", "", "| " + " | ".join(self.headers) + " |",
                 "|" + "|".join(" --- " for _ in self.headers) + "|"]
        lines += ["| " + " | ".join(row) + " |" for row in self.rows]
        if self.notes:
            lines += ["", *self.notes]
        return "\n".join(lines) + "\n"


Report = Callable[["StudyResult"], list[TextTable]]
REPORTS: Registry[str, Report] = registries.REPORTS


@REPORTS.register("summary")
def summary_report(result: StudyResult) -> list[TextTable]:
    """Per variant: scenarios run and failed, then each metric with its 95% interval."""
    entries = result.summary()
    metrics = list(dict.fromkeys(e["label"] for e in entries))
    rows = []
    for variant in result.study.variants:
        mine = [e for e in entries if e["variant"] == variant.name]
        ran = sum(r["variant"] == variant.name for r in result.rows)
        failed = mine[0]["failed"] if mine else 0
        rows.append([variant.name, str(ran), str(failed), *(format_estimate(e) for e in mine)])
    study = result.study
    return [TextTable(f"{study.name}: {study.scenarios:,} scenarios x {len(study.variants)} "
                      f"variants ({study.spec.evaluate}), 95% confidence intervals",
                      ["variant", "runs", "failed", *metrics], rows)]


def report(result: StudyResult) -> list[TextTable]:
    return REPORTS.get(result.study.spec.report)(result)
