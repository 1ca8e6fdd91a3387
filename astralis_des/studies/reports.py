"""What a study prints and writes to ``report.md``, by registry (``report:`` picks it).

A report is plain data (titled tables of strings); the CLI draws them with rich. A table may
be for ``report.md`` alone: the terminal shows the headline, the file every metric.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

from astralis_des.registry import Registry
from astralis_des.studies import registries
from astralis_des.studies.scenarios import evaluation_of
from astralis_des.studies.table import format_estimate, format_quartiles, metric_values

if TYPE_CHECKING:
    from astralis_des.studies.results import StudyResult


@dataclass(frozen=True)
class TextTable:
    title: str  # "" for none
    headers: list[str]
    rows: list[list[str]]
    notes: list[str] = field(default_factory=list)
    keys: int = 1  # the leading columns that name a row (repeated when a table is split)
    shown: bool = True  # on the terminal too (else in report.md only)

    def markdown(self) -> str:
        lines = [f"**{self.title}**", ""] if self.title else []
        lines += ["| " + " | ".join(self.headers) + " |",
                  "|" + "|".join(" --- " for _ in self.headers) + "|"]
        lines += ["| " + " | ".join(row) + " |" for row in self.rows]
        if self.notes:
            lines += ["", *self.notes]
        return "\n".join(lines) + "\n"


Report = Callable[["StudyResult"], list[TextTable]]
REPORTS: Registry[str, Report] = registries.REPORTS


@REPORTS.register("summary")
def summary_report(result: StudyResult) -> list[TextTable]:
    """The headline, then every metric with its 95% interval (``report.md`` only)."""
    return [headline(result), every_metric(result)]


def headline(result: StudyResult) -> TextTable:
    """Per variant: its runs (and failures, if any), then the evaluation's headline metrics
    with their 95% intervals, a mean's median and quartiles beside it."""
    metrics = evaluation_of(result.study).headline_metrics()
    entries = {(e["variant"], e["metric"]): e for e in result.summary()}
    data = result.table.to_pydict()
    failed = result.failed > 0
    headers = ["variant", "runs", *(["failed"] if failed else [])]
    for m in metrics:
        headers += [m.label] if m.kind == "rate" else [f"{m.label}, mean", f"{m.label}, median "
                                                       "[IQR]"]
    rows = []
    for variant in result.study.variants:
        row = [variant.name, str(sum(r["variant"] == variant.name for r in result.rows))]
        if failed:
            row.append(str(sum(r["variant"] == variant.name and r["status"] == "failed"
                               for r in result.rows)))
        for m in metrics:
            row.append(format_estimate(entries[variant.name, m.column]))
            if m.kind == "mean":
                row.append(format_quartiles(metric_values(data, m.column, variant.name), m.unit))
        rows.append(row)
    study = result.study
    return TextTable(f"{study.name}: {study.scenarios:,} scenarios x {len(study.variants)} "
                     f"variants ({study.spec.evaluate}), 95% confidence intervals",
                     headers, rows)


def every_metric(result: StudyResult) -> TextTable:
    """Per variant: scenarios run and failed, then each metric with its 95% interval."""
    entries = result.summary()
    metrics = list(dict.fromkeys(e["label"] for e in entries))
    rows = []
    for variant in result.study.variants:
        mine = [e for e in entries if e["variant"] == variant.name]
        ran = sum(r["variant"] == variant.name for r in result.rows)
        failed = mine[0]["failed"] if mine else 0
        rows.append([variant.name, str(ran), str(failed), *(format_estimate(e) for e in mine)])
    return TextTable("Every metric, 95% confidence intervals",
                     ["variant", "runs", "failed", *metrics], rows, shown=False)


def report(result: StudyResult) -> list[TextTable]:
    return REPORTS.get(result.study.spec.report)(result)
