"""``astralis study``: the folder it writes, the report it prints, replays."""

from __future__ import annotations

import contextlib
import io
import json
import re
from pathlib import Path

import pyarrow.parquet as pq
import pytest

import astralis_des
from astralis_des.cli import main
from astralis_des.studies import load_study
from astralis_des.studies.eval_mission import METRICS
from astralis_des.studies.reports import headline
from astralis_des.studies.results import StudyResult

ROOT = Path(__file__).parents[1]
TABLE5 = ROOT / "studies" / "table5.yaml"


def run_cli(*argv: str) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main(list(argv))
    return code, out.getvalue(), err.getvalue()


@pytest.fixture(scope="module")
def table5_run(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, int, str, str]:
    """``astralis study studies/table5.yaml --scenarios 200 --workers 1 --out DIR``."""
    out = tmp_path_factory.mktemp("t5") / "table5"
    code, stdout, stderr = run_cli("study", str(TABLE5), "--scenarios", "200", "--workers",
                                   "1", "--out", str(out))
    return out, code, stdout, stderr


def test_study_writes_one_folder(table5_run: tuple[Path, int, str, str]) -> None:
    """The folder holds the table (CSV, Parquet), summary, report, plots, study file, meta."""
    out, code, _, stderr = table5_run
    assert code == 0, stderr
    assert sorted(p.name for p in out.iterdir()) == [
        "meta.json", "plots", "report.md", "study.yaml", "summary.csv", "summary.parquet",
        "table.csv", "table.parquet"]
    assert sorted(p.name for p in (out / "plots").iterdir()) == [
        "metrics.png", "metrics.svg", "tradeoff.png", "tradeoff.svg"]
    assert [p.name for p in out.parent.iterdir()] == ["table5"]  # no staging folder left
    meta = json.loads((out / "meta.json").read_text())
    assert (meta["astralis_des"], meta["scenarios"], meta["rows"], meta["failed"]) == (
        astralis_des.__version__, 200, 400, 0)
    assert (out / "study.yaml").read_text().startswith(TABLE5.read_text())
    assert "# changed for this run: scenarios: 200" in (out / "study.yaml").read_text()


def test_table_files_agree(table5_run: tuple[Path, int, str, str]) -> None:
    """CSV and Parquet hold the same 400 rows: scenario, seed, variant, inputs, outcomes."""
    out = table5_run[0]
    table = pq.read_table(out / "table.parquet")
    assert table.num_rows == 400
    assert table.column_names[:6] == ["scenario", "seed", "variant", "strategy", "status",
                                      "error"]
    lines = (out / "table.csv").read_text().splitlines()
    assert len(lines) == 401
    assert lines[0].startswith('"scenario","seed","variant","strategy","status","error"')


def test_report_printed_and_written(table5_run: tuple[Path, int, str, str]) -> None:
    """The Table V comparison is printed and kept in report.md."""
    out, _, stdout, _ = table5_run
    assert "Table V: results for randomly initialized assignments" in stdout
    assert "400 runs in" in stdout
    report = (out / "report.md").read_text()
    assert "| Human assigned to high-risk area | mixed | 0.0% [0.0, 1.9] | 0.0% |" in report


def test_replay_prints_the_scenario_rows(table5_run: tuple[Path, int, str, str]) -> None:
    """``--replay N`` runs scenario N alone and shows the same values as the table's rows."""
    out = table5_run[0]
    code, stdout, _ = run_cli("study", str(TABLE5), "--replay", "7", "--variant", "mixed")
    assert code == 0
    row = next(r for r in pq.read_table(out / "table.parquet").to_pylist()
           if r["scenario"] == 7 and r["variant"] == "mixed")
    assert f"{row['seed']}" in stdout
    assert row["assignment"].split()[0] in stdout


@pytest.mark.parametrize(("argv", "says"), [
    (["--replay", "1000"], "error: --replay: scenario 1000 is not in the study (0 to 999)"),
    (["--replay", "1", "--variant", "mixd"],
     "error: --variant: no variant 'mixd'; did you mean 'mixed'?"),
    (["--variant", "mixed"],
     "error: --variant: --variant picks a variant to replay: use it with --replay"),
    (["--backend", "rey"], "error: --backend: unknown study backend 'rey'; did you mean 'ray'?"),
])
def test_bad_arguments(tmp_path: Path, argv: list[str], says: str) -> None:
    """Bad options are one line on stderr, exit code 2, nothing written."""
    code, _, stderr = run_cli("study", str(TABLE5), "--out", str(tmp_path / "o"), *argv)
    assert (code, stderr) == (2, says + "\n")
    assert not any(tmp_path.iterdir())


def test_help_lists_study() -> None:
    """``astralis --help`` names the study command."""
    with pytest.raises(SystemExit):
        run_cli("--help")
    code, stdout, _ = run_cli()
    assert code == 0 and "study" in stdout


OUTCOMES = ROOT / "studies" / "outcomes.yaml"


@pytest.mark.parametrize("width", [100, 80])
def test_the_summary_fits_the_terminal(tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
                                       width: int) -> None:
    """A mission study has 14 metrics: the terminal gets the headline (found, time to find
    with its median and quartiles) within its width, no value cut to "…", and a line naming
    the files with the rest; report.md has every metric. (Before: 17 columns of "…".)"""
    monkeypatch.setenv("COLUMNS", str(width))
    out = tmp_path / "outcomes"
    code, stdout, stderr = run_cli("study", str(OUTCOMES), "--scenarios", "3", "--workers",
                                   "1", "--out", str(out))
    assert code == 0, stderr
    lines = stdout.splitlines()
    assert max(len(line) for line in lines) <= width
    assert "…" not in stdout and "..." not in stdout
    assert [v for v in ("naive", "mixed", "greedy") if re.search(rf"│ {v} +│", stdout)] == [
        "naive", "mixed", "greedy"]
    for word in ("variant", "runs", "found", "time", "mean", "median", "[IQR]"):
        assert f" {word} " in stdout, word  # headers wrap at words, as the width allows
    assert re.search(r"│ +\d+\.\d% ", stdout)  # a share, whole
    assert "9 runs in " in stdout
    assert lines[-1] == "also there: report.md (every metric), table.csv (every run)"
    report = (out / "report.md").read_text()
    for metric in METRICS:
        assert f"| {metric.label} |" in report, metric.label
    assert "| time to find, median [IQR] |" in report


def test_a_failed_run_shows_in_the_headline(tmp_path: Path) -> None:
    """The headline counts failed runs only when there are some."""
    study = load_study(OUTCOMES).with_changes(scenarios=2)
    rows = [{"scenario": 0, "seed": 1, "variant": "naive", "status": "failed", "error": "x"}]
    rows += [{"scenario": i, "seed": i, "variant": v, "status": "ok", "found": True,
              "time_to_find": 10.0 * (i + 1)} for i in range(2) for v in ("mixed", "greedy")]
    table = headline(StudyResult(study, rows))
    assert table.headers[:3] == ["variant", "runs", "failed"]
    assert [row[:3] for row in table.rows] == [["naive", "1", "1"], ["mixed", "2", "0"],
                                               ["greedy", "2", "0"]]
    assert table.rows[1][-1] == "15.0 s [12.5, 17.5]"  # median [first, third quartile]
    assert table.rows[0][3:] == ["-", "-", "-"]
