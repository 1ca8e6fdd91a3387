"""The study folder, written all or nothing: into a hidden sibling, renamed when complete.

    table.csv  table.parquet   one row per scenario and variant
    summary.csv                per variant and metric, with 95% intervals
    report.md                  the headline the CLI prints, then every metric
    plots/*.png  plots/*.svg
    study.yaml                 the study file as run
    meta.json                  package version, seed, scenarios, backend, workers, wall time
    failures.txt               the traceback of each failed row (if any)
    scenarios/                 each mission's outputs (with recordings on)
"""

from __future__ import annotations

import platform
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import TYPE_CHECKING

import pyarrow as pa

from astralis_des.outdir import Staging, dumps, result_files
from astralis_des.studies.results import WRITERS
from astralis_des.studies.table import write_table

if TYPE_CHECKING:
    from astralis_des.studies.results import StudyResult


STUDY_FILES = result_files("table.csv", "table.parquet", "summary.csv", "summary.parquet",
                           "report.md", "plots", "study.yaml", "meta.json", "failures.txt",
                           "scenarios", key="meta.json")


@contextmanager
def staging(folder: Path | None) -> Iterator[Path | None]:
    """The study folder's staging (:class:`~astralis_des.outdir.Staging`): a hidden folder
    beside ``folder``, locked against a second writer, put in place on success (``meta.json``
    last), removed otherwise."""
    if folder is None:
        yield None
        return
    with Staging(folder, owned=STUDY_FILES, last="meta.json") as tmp:
        yield tmp


@WRITERS.register("folder")
def write_folder(result: StudyResult, folder: Path) -> Path:
    with staging(folder) as tmp:
        assert tmp is not None
        fill_folder(result, tmp)
    return folder


def fill_folder(result: StudyResult, folder: Path) -> None:
    from astralis_des.studies.reports import report
    from astralis_des.version import __version__

    study = result.study
    write_table(result.table, folder)
    summary = result.summary()
    write_table(pa.Table.from_pylist(summary), folder, "summary")
    (folder / "report.md").write_text("\n".join(t.markdown() for t in report(result)),
                                      encoding="utf-8")
    (folder / "study.yaml").write_text(study.text, encoding="utf-8")
    meta = {"astralis_des": __version__, "study": study.name, "seed": study.spec.seed,
            "scenarios": study.scenarios, "variants": [v.name for v in study.variants],
            "evaluate": study.spec.evaluate, "rows": len(result.rows), "failed": result.failed,
            "interrupted": result.interrupted,
            "backend": result.backend, "workers": result.workers,
            "wall_time_s": round(result.wall_time, 3), "python": platform.python_version(),
            "mission": str(study.mission.path) if study.mission.path else None}
    (folder / "meta.json").write_text(dumps(meta, indent=2) + "\n", encoding="utf-8")
    if result.failures:
        (folder / "failures.txt").write_text("\n".join(result.failures), encoding="utf-8")
    if study.spec.outputs.plots:
        from astralis_des.studies.plots import write_plots

        write_plots(result, summary, folder / "plots")
