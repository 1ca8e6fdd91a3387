"""``astralis tune``: a search over study parameters against target figures or objectives."""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest
import yaml

from astralis_des.cli import main
from astralis_des.studies import load_study, run_study
from astralis_des.studies.tune import run_tune
from astralis_des.studies.tune_spec import load_tune

ROOT = Path(__file__).resolve().parents[1]
STUDY = {"name": "t5", "mission": str(ROOT / "missions" / "urban_search.yaml"), "seed": 3,
         "scenarios": 300, "evaluate": "assignment",
         "draw": {"positions": "building", "segment": "random"},
         "vary": {"strategy": ["mixed"]}}


def write(folder: Path, tune: dict[str, object], study: dict[str, object] = STUDY) -> Path:
    (folder / "study.yaml").write_text(yaml.safe_dump(study), encoding="utf-8")
    path = folder / "tune.yaml"
    path.write_text(yaml.safe_dump({"name": "fit", "study": "study.yaml", **tune},
                                   sort_keys=False), encoding="utf-8")
    return path


def share(tmp_path: Path, ugv_risk: float) -> float:
    """The mixed heuristic's UGV -> high-messiness share with the UGV's risk weight."""
    (tmp_path / "study.yaml").write_text(yaml.safe_dump(STUDY), encoding="utf-8")
    study = load_study(tmp_path / "study.yaml").with_changes(set={"w1.ugv": ugv_risk})
    entry = next(e for e in run_study(study, workers=1).summary()
                 if e["metric"] == "ugv_high_mess")
    return float(entry["estimate"])


def test_a_tune_recovers_the_weight_that_made_the_figure(tmp_path: Path) -> None:
    wanted = share(tmp_path, 3.0)  # the figure computed with w1.ugv = 3
    path = write(tmp_path, {"seed": 1, "trials": 11, "sampler": "grid",
                            "params": {"w1.ugv": {"low": 0, "high": 10, "step": 1}},
                            "targets": {"mixed.ugv_high_mess": wanted}})
    result = run_tune(load_tune(path), workers=1)
    assert [r["param.w1.ugv"] for r in result.best] == [3]
    assert result.best[0]["score"] == 0.0
    fits = sorted(r["param.w1.ugv"] for r in result.fits())
    assert 3 in fits and fits == list(range(fits[0], fits[-1] + 1))  # one region round it
    assert 0 not in fits and 10 not in fits  # the bounds' ends are told apart at n = 300


def test_the_same_seed_gives_the_same_trials_and_a_resumed_tune_goes_on_as_one(
        tmp_path: Path) -> None:
    tune = {"seed": 5, "trials": 8, "sampler": "tpe",
            "params": {"w1.ugv": {"low": 0, "high": 10}, "w2.ugv": {"low": 0, "high": 10}},
            "targets": {"mixed.ugv_high_mess": 0.06, "mixed.human_high_risk": 0.0}}
    path = write(tmp_path, tune)

    def trials(out: Path) -> list[dict[str, object]]:
        return [{k: v for k, v in r.items() if k != "seconds"}
                for r in (json.loads(line)["row"] for line in
                          (out / "trials.jsonl").read_text().splitlines()[1:])]

    assert main(["tune", str(path), "--out", str(tmp_path / "a"), "--quiet"]) == 0
    assert main(["tune", str(path), "--out", str(tmp_path / "b"), "--quiet"]) == 0
    assert trials(tmp_path / "a") == trials(tmp_path / "b")
    assert len(trials(tmp_path / "a")) == 8
    assert main(["tune", str(path), "--out", str(tmp_path / "c"), "--trials", "3",
                 "--quiet"]) == 0
    assert main(["tune", str(path), "--out", str(tmp_path / "c"), "--resume", "--quiet"]) == 0
    assert trials(tmp_path / "c") == trials(tmp_path / "a")
    for name in ("trials.csv", "trials.parquet", "best.json", "report.md", "meta.json",
                 "plots/params.png"):
        assert (tmp_path / "c" / name).is_file(), name
    assert "## The weights that fit" in (tmp_path / "c" / "report.md").read_text()


def test_a_mission_tune_on_two_workers_gives_the_trials_of_one(tmp_path: Path) -> None:
    """The workers hold the study for every trial and keep what they furnished and swept on
    its world: the trials are those of a run on one process, number for number."""
    study = {"name": "m", "mission": str(ROOT / "missions" / "urban_search.yaml"), "seed": 4,
             "scenarios": 6, "evaluate": "mission",
             "draw": {"positions": {"type": "outdoor", "radius": 20}},
             "set": {"fidelity": "kinematic", "strategy": "mixed"}}
    path = write(tmp_path, {"seed": 1, "trials": 3, "sampler": "random",
                            "params": {"w1.ugv": {"low": 0, "high": 10},
                                       "w2.human": {"low": 0, "high": 10}},
                            "objectives": [{"metric": "time_to_find"},
                                           {"metric": "ugv_high_mess_s"}]}, study)
    tune = load_tune(path)
    one, two = run_tune(tune, workers=1), run_tune(tune, workers=2)
    drop = ("seconds",)
    assert [{k: v for k, v in r.items() if k not in drop} for r in two.rows] == \
        [{k: v for k, v in r.items() if k not in drop} for r in one.rows]
    assert len({r["time_to_find"] for r in one.rows}) > 1  # the weights changed the missions


def test_ctrl_c_keeps_the_trials_done(tmp_path: Path) -> None:
    path = write(tmp_path, {"seed": 1, "trials": 10, "sampler": "random",
                            "params": {"w1.ugv": {"low": 0, "high": 10}},
                            "targets": {"mixed.ugv_high_mess": 0.06}})

    def interrupt_after_two(done: int, _total: int) -> None:
        if done == 2:
            raise KeyboardInterrupt  # as Ctrl-C (or SIGTERM, made one) would, between trials

    result = run_tune(load_tune(path), workers=1, out=tmp_path / "out",
                      progress=interrupt_after_two)
    assert result.interrupted and len(result.rows) == 2
    meta = json.loads((tmp_path / "out" / "meta.json").read_text())
    assert (meta["trials"], meta["interrupted"]) == (2, True)
    assert len((tmp_path / "out" / "trials.csv").read_text().splitlines()) == 3  # header + 2


def test_two_objectives_give_a_front_and_a_constraint_holds_on_it(tmp_path: Path) -> None:
    path = write(tmp_path, {"seed": 2, "trials": 12, "sampler": "nsga2",
                            "params": {"w1.ugv": {"low": 0, "high": 10},
                                       "w2.ugv": {"low": 0, "high": 10}},
                            "objectives": [
                                {"metric": "mixed.ugv_high_mess", "direction": "minimize"},
                                {"metric": "mixed.ugv_unassigned", "direction": "minimize"}],
                            "constraints": [{"metric": "mixed.human_high_risk", "max": 0.0}]})
    result = run_tune(load_tune(path), workers=1, out=tmp_path / "out")
    front = result.best
    assert front and all(r["feasible"] for r in front)
    xs = [r["mixed.ugv_high_mess"] for r in front]
    ys = [r["mixed.ugv_unassigned"] for r in front]
    assert xs == sorted(xs) and ys == sorted(ys, reverse=True)  # a trade-off, not one point
    assert (tmp_path / "out" / "plots" / "front.png").is_file()


@pytest.mark.parametrize(("tune", "message"), [
    ({"trials": 5, "params": {"w1.ugb": {"low": 0, "high": 1}},
      "targets": {"mixed.ugv_high_mess": 0.1}},
     r"tune.yaml:\d+: params.w1.ugb: unknown parameter 'w1.ugb'; did you mean 'w1.ugv'\?"),
    ({"trials": 5, "params": {"w1.ugv": {"low": 3, "high": 1}},
      "targets": {"mixed.ugv_high_mess": 0.1}},
     r"tune.yaml:\d+: params.w1.ugv: empty or inverted bounds: low 3 must be below high 1"),
    ({"trials": 5, "params": {"w1.ugv": {"low": 0, "high": 1}},
      "targets": {"mixed.ugv_hi_mess": 0.1}},
     r"tune.yaml:\d+: targets.mixed.ugv_hi_mess: 'mixed.ugv_hi_mess': unknown metric "
     r"'ugv_hi_mess'; did you mean 'ugv_high_mess'\?"),
    ({"trials": 5, "params": {"w1.ugv": {"low": 0, "high": 1}},
      "targets": {"greedy.ugv_high_mess": 0.1}},
     r"tune.yaml:\d+: targets.greedy.ugv_high_mess: 'greedy.ugv_high_mess': no variant "
     r"'greedy' in the study"),
    ({"trials": 0, "params": {"w1.ugv": {"low": 0, "high": 1}},
      "targets": {"mixed.ugv_high_mess": 0.1}},
     r"tune.yaml:\d+: trials: Input should be greater than or equal to 1 \(got 0\)"),
    ({"trials": 5, "params": {"w1.ugv": {"low": 0, "high": 1}}},
     r"tune.yaml:\d+: give targets \(figures to reproduce\) or objectives"),
    ({"trials": 5, "params": {"strategy": ["mixed"]}, "targets": {"mixed.ugv_high_mess": 0.1}},
     r"tune.yaml:\d+: params.strategy: the study varies 'strategy' already"),
])
def test_bad_tune_files_are_one_line_and_write_nothing(
        tmp_path: Path, capsys: pytest.CaptureFixture[str], tune: dict[str, object],
        message: str) -> None:
    path = write(tmp_path, tune)
    assert main(["tune", str(path), "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err
    assert len(err.splitlines()) == 1
    assert re.search(message, err), err
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize("path", sorted((ROOT / "tunes").glob("*.yaml")), ids=lambda p: p.stem)
def test_each_tune_file_of_the_repository_loads(path: Path) -> None:
    tune = load_tune(path)
    assert tune.metrics() and tune.spec.trials >= 1


SIX = {f"w{w}.{kind}": {"low": 0, "high": 10} for w in (1, 2) for kind in ("human", "uav", "ugv")}


@pytest.mark.parametrize("width", [100, 80])
@pytest.mark.parametrize("aim", ["front", "targets"])
def test_the_report_fits_the_terminal(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                      monkeypatch: pytest.MonkeyPatch, width: int,
                                      aim: str) -> None:
    """Six weights: the front (a column each, and the two aims) or the best trial's tables
    within the terminal's width, no value cut to "…"; then where the files are."""
    monkeypatch.setenv("COLUMNS", str(width))
    goal: dict[str, object] = (
        {"objectives": [{"metric": "mixed.ugv_high_mess"}, {"metric": "mixed.human_high_risk"}]}
        if aim == "front" else {"targets": {"mixed.ugv_high_mess": 0.06}})
    path = write(tmp_path, {"seed": 1, "trials": 4, "sampler": "random", "params": SIX,
                            **goal})
    assert main(["tune", str(path), "-o", str(tmp_path / "out")]) == 0
    out = capsys.readouterr().out
    assert max(len(line) for line in out.splitlines()) <= width
    assert "…" not in out
    best = json.loads((tmp_path / "out" / "best.json").read_text())
    shown = [f"param.{p}" for p in SIX] + ["mixed.ugv_high_mess"]
    for row in best:  # every weight and figure of the best trial (or the front), whole
        for key in shown:
            assert f" {row[key]:.4g} " in out, key
    assert out.splitlines()[-1] == ("also there: report.md (this report), trials.csv (every "
                                    "trial), plots/")
