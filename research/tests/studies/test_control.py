"""``arzsumo study control``: both experiments from one scenario, the deviation measures
from the regulation open loop's stationary state, tables paired by seed.

The SUMO test runs a short version of the default (a 200 m approach, a 100 s fill, a 60 s
window, a short drain) on two seeds: the disturbance must be felt where the regulation
open loop is at its own stationary band."""

from __future__ import annotations

import tomllib

import numpy as np
import pandas as pd
import pytest
from arzsumo_studies.common import StudyError
from arzsumo_studies.control.study import DISTURBANCE, experiment_scenario

from arzsumo.io import dump_toml
from arzsumo.resources import shipped_scenarios_dir
from arzsumo.sumo.fork import can_fork

DEFAULT = shipped_scenarios_dir() / "default.toml"


def base() -> dict:
    return tomllib.loads(DEFAULT.read_text(encoding="utf-8"))


def test_the_experiments_differ_only_in_the_disturbance():
    reg, dis = (experiment_scenario(base(), e) for e in ("regulation", "disturbance"))
    assert "disturbance" not in reg and dis["disturbance"] == DISTURBANCE
    assert {k: v for k, v in dis.items() if k not in ("disturbance", "name")} == \
        {k: v for k, v in reg.items() if k != "name"}
    assert reg["name"] == "default-regulation"


def test_unknown_experiments_are_refused(run_study, tmp_path):
    with pytest.raises(StudyError, match="--experiments = 'regulation,pulse' is not allowed"):
        run_study("control", "--experiments", "regulation,pulse", "--out", tmp_path)


@pytest.fixture(scope="module")
def short_default(tmp_path_factory):
    data = base()
    data["sumo"].update(approach_length_m=200.0, fill_s=100.0, horizon_s=60.0,
                        drain_max_s=120.0)
    data["run"].update(warmup_s=100.0, kernel_cells=50, twin_cells=50)
    path = tmp_path_factory.mktemp("scenario") / "short.toml"
    path.write_text(dump_toml(data), encoding="utf-8")
    return path


@pytest.mark.sumo
@pytest.mark.slow
@pytest.mark.skipif(not can_fork(), reason="needs fork and /proc")
def test_the_study_pairs_both_experiments_and_measures_the_decay(run_study, short_default,
                                                                 tmp_path, monkeypatch):
    monkeypatch.setenv("ARZSUMO_CACHE", str(tmp_path / "cache"))
    out = tmp_path / "control"
    store = tmp_path / "records"
    common = ("--scenario", short_default, "--controllers", "open,etc", "--seeds", "1,2",
              "--workers", "1", "--quiet", "--records", store)
    args = (*common, "--out", out)
    assert run_study("control", *args) == 0
    reg = pd.read_csv(out / "regulation" / "control.csv")
    dis = pd.read_csv(out / "disturbance" / "control.csv")
    excess = "section.deviation.deviation_excess_s"

    def value(long, controller):
        row = long[(long["measure"] == excess) & (long["controller"] == controller)]
        return float(row["mean"].iloc[0])
    # the slowdown is felt: the open loop leaves its stationary band far more
    assert value(dis, "open") > value(reg, "open") + 1.0
    runs = pd.read_parquet(out / "disturbance" / "summaries.parquet")
    assert np.allclose(runs["disturbance.began_s"], 100.0)
    assert np.allclose(runs["disturbance.ended_s"], 130.0)
    assert "disturbance.began_s" not in pd.read_parquet(
        out / "regulation" / "summaries.parquet") or pd.read_parquet(
        out / "regulation" / "summaries.parquet")["disturbance.began_s"].isna().all()
    # one table row per (measure, controller), the paired difference of etc in both
    text = (out / "control.md").read_text(encoding="utf-8")
    rows = [x for x in text.splitlines() if x.startswith("| integrated deviation above")]
    assert [r.split(" | ")[2] for r in rows] == ["open", "etc"]
    assert rows[0].count("(its mean of 2)") == 2 and rows[1].count(" of 2") >= 2
    # each experiment's figure of the paired differences is a PNG
    for e in ("regulation", "disturbance"):
        assert (out / e / "control.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    # --report reads the same runs back and gives the same numbers, writing no run
    runs_before = {p: p.stat().st_mtime_ns for p in out.glob("*/runs/**/*")}
    assert run_study("control", *args, "--report") == 0
    assert pd.read_csv(out / "disturbance" / "control.csv").equals(dis)
    assert runs_before == {p: p.stat().st_mtime_ns for p in out.glob("*/runs/**/*")}
    # the record store holds every run, and carries the study to a new directory: the
    # tables come back from it alone, and a continued study runs nothing it holds
    tables = sorted(p.relative_to(store).as_posix() for p in store.rglob("*") if p.is_file())
    assert tables == ["disturbance/records.jsonl", "regulation/records.jsonl"]
    assert [len((store / t).read_text().splitlines()) for t in tables] == [5, 5]
    for flags in (("--report",), ()):
        elsewhere = tmp_path / f"elsewhere{len(flags)}"
        assert run_study("control", *common, "--out", elsewhere, *flags) == 0
        assert pd.read_csv(elsewhere / "disturbance" / "control.csv").equals(dis)
    assert not (elsewhere / "disturbance" / "runs" / "controller=open,seed=1"
                / "periods.parquet").exists()


def test_the_headline_gives_the_open_loops_mean_and_the_paired_differences():
    from arzsumo_studies.control.study import MEASURES, headline

    from arzsumo.evaluation.report import evaluate

    key = "network_whole_demand.time_spent_s.total"
    open_s = np.array([100.0, 110.0, 120.0]) * 3600
    runs = pd.DataFrame({"controller": ["open"] * 3 + ["held"] * 3, "seed": [1, 2, 3] * 2,
                         key: np.r_[open_s, open_s - 3600 * np.array([1.0, 2.0, 3.0])]})
    long = evaluate(runs, ["open", "held"], "open", [m for m in MEASURES if m.key == key])
    rows = [r for r in headline({"regulation": long}).splitlines()
            if r.startswith("| whole-demand time spent, total")]
    # open: mean 110 veh h with its t interval (sd 10, n 3: half-width 24.84)
    assert rows[0] == ("| whole-demand time spent, total | veh h | open | "
                       "110 [85.16, 134.8] (its mean of 3) |")
    # held minus open: -2 veh h, t interval -2 -+ 4.303 * 1 / sqrt(3), three wins
    assert rows[1].startswith("| whole-demand time spent, total | veh h | held | "
                              "-2 [-4.48, +0.484] {")
    assert rows[1].endswith(" 3/0 of 3 |")


def test_a_report_without_any_finished_run_is_refused(run_study, tmp_path):
    with pytest.raises(StudyError, match="has no finished runs yet; allowed: a run without"):
        run_study("control", "--report", "--seeds", "1,2", "--out", tmp_path / "none")


@pytest.mark.parametrize("flags, message", [
    (("--records", "FILE"), "--records = .*FILE is a file; allowed: a directory"),
    (("--records", "DIR", "--runs-from", "DIR"),
     "--runs-from = .*DIR is not allowed with --records; allowed: one of them"),
    (("--report", "--runs-from", "DIR"),
     "--runs-from = .*DIR is not allowed with --report; allowed: one of them"),
])
def test_unusable_record_options_are_refused(run_study, tmp_path, flags, message):
    (tmp_path / "FILE").write_text("mine")
    (tmp_path / "DIR").mkdir()
    args = [str(tmp_path / f) if f in ("FILE", "DIR") else f for f in flags]
    with pytest.raises(StudyError, match=message):
        run_study("control", *args, "--seeds", "1", "--out", tmp_path / "out")
    assert (tmp_path / "FILE").read_text() == "mine" and not (tmp_path / "out").exists()


def test_a_study_whose_runs_all_failed_exits_with_some_failed(run_study, tmp_path,
                                                             monkeypatch):
    from types import SimpleNamespace

    import arzsumo_studies.recorded as recorded
    from arzsumo_studies.common import EXIT_SOME_FAILED

    failed = SimpleNamespace(runs=pd.DataFrame(), sweep=SimpleNamespace(
        table=pd.DataFrame({"status": ["failed", "crashed"]})))
    monkeypatch.setattr(recorded, "run_evaluation", lambda *a, **k: failed)
    assert run_study("control", "--seeds", "1", "--out", tmp_path / "out") == \
        EXIT_SOME_FAILED
    assert not (tmp_path / "out" / "control.md").exists()


def test_the_study_is_called_from_python_with_its_options(tmp_path):
    from arzsumo_studies.control.study import ControlOptions, design, run_control
    from arzsumo_studies.recorded import RecordedRuns

    opts = ControlOptions(RecordedRuns((1, 2, 3), report=True), controllers=("etc",),
                          experiments=("regulation",), out=tmp_path / "none")
    assert opts.controllers == ("open", "etc")            # the baseline comes first
    assert design(opts) == ["regulation: open, etc on seeds 1-3"]
    with pytest.raises(StudyError, match="has no finished runs yet"):
        run_control(opts)
    with pytest.raises(StudyError, match="experiments"):
        ControlOptions(RecordedRuns((1,)), experiments=("rush-hour",))
    with pytest.raises(StudyError, match="seeds"):
        RecordedRuns((2, 2))
