"""The estimation studies (estimation-layouts, loop-speed, enkf-noise) and u-estimate:
their designs, the shared record cache, and the EnKF noise calibration step."""

from __future__ import annotations

import numpy as np
import pytest
from arzsumo_studies.common import shipped_scenario
from arzsumo_studies.estimation import enkf_noise, u_estimate
from arzsumo_studies.estimation import layouts as estimation_layouts

from arzsumo.scenario import load_scenario, scenario_from_dict

DEFAULT = shipped_scenario("default.toml")


def test_the_layout_design_records_one_open_loop_per_seed():
    runs = estimation_layouts.design(DEFAULT, [1, 2], horizon=300.0)
    assert [r.run_id for r in runs] == ["seed=1", "seed=2"]
    assert runs[0].scenario["run"]["controller"] == "open"
    assert runs[0].scenario["sumo"]["horizon_s"] == 300.0
    assert runs[0].scenario["run"]["warmup_s"] == 600            # the default's fill


def test_records_are_cached_per_scenario_and_seed(monkeypatch, tmp_path):
    monkeypatch.setenv("ARZSUMO_CACHE", str(tmp_path))
    one, two = estimation_layouts.design(DEFAULT, [1, 2])
    path = estimation_layouts.cache_path(one)
    assert path.parent == tmp_path / "estimation-runs"
    assert path.name.startswith("default-seed=1-") and path.suffix == ".npz"
    assert path == estimation_layouts.cache_path(estimation_layouts.design(DEFAULT, [1])[0])
    assert path != estimation_layouts.cache_path(two)
    assert path != estimation_layouts.cache_path(
        estimation_layouts.design(DEFAULT, [1], horizon=60.0)[0])


@pytest.mark.parametrize("layout", list(estimation_layouts.LAYOUTS))
def test_every_layout_is_a_valid_sensing_table(layout):
    sc = load_scenario(DEFAULT).with_(estimation_layouts.LAYOUTS[layout])
    assert sc.name == "default"


def test_the_layout_table_gives_means_with_t_half_widths():
    rows = [{"layout": "loops 250 m", "method": "smoothing", "seed": s,
             **{f"{v}_rel": x for v in estimation_layouts.VARS}}
            for s, x in ((1, 0.1), (2, 0.2), (3, 0.3))]
    lines = estimation_layouts.table(rows).splitlines()
    assert lines[2] == "| loops 250 m | smoothing | " + " | ".join(["0.200 +- 0.248"] * 4) + " |"


def test_the_enkf_settings_are_scenario_keys_and_a_round_scales_by_the_error():
    sc = load_scenario(DEFAULT).with_(enkf_noise.settings([2.0, 1.0, 1.0, 1.0], 1.05))
    assert sc.name == "default"
    rows = [{**{f"{v}_rel": e for v, e in zip(enkf_noise.VARS, (0.4, 0.1, 0.2, 0.01),
                                               strict=True)},
             **{f"{v}_spread_rel": 0.1 for v in enkf_noise.VARS}}]
    assert enkf_noise.normalised(rows) == pytest.approx([4.0, 1.0, 2.0, 0.1])
    sd = enkf_noise.next_sd(np.array([2.0, 1.0, 1.0, 1.0]), rows, gain=1.0)
    assert sd == pytest.approx([8.0, 1.0, 2.0, 0.25])              # clipped to [1/4, 4]


def test_the_u_estimate_design_is_one_run_per_estimator_on_legacy_default():
    spec = u_estimate.design(u_estimate.UEstimateOptions(seeds=(42,)))
    runs = spec.runs()
    assert [r.run_id for r in runs] == ["estimator=none,seed=42", "estimator=smoothing,seed=42",
                                        "estimator=enkf,seed=42"]
    for r in runs:
        sc = scenario_from_dict(r.scenario)
        assert (sc.run.controller, sc.run.warmup, sc.sumo.horizon, sc.sumo.seed) == \
            ("backstepping", 150.0, 120.0, 42)
    assert runs[2].scenario["estimation"]["method"] == "enkf"
    assert runs[2].scenario["sensing"] == {"kinds": ["loops", "av_probes"],
                                           "loop_spacing_m": 250}
    assert "sensing" not in runs[0].scenario or \
        runs[0].scenario["sensing"].get("kinds") != ["loops", "av_probes"]


class FakeEngine:
    """``map_runs`` of the enkf-noise study without SUMO: the records are made-up paths,
    every score is the same row; the recording's progress label and every scoring job
    are kept."""

    def __init__(self) -> None:
        self.progress: list[str | None] = []
        self.jobs: list[tuple] = []

    def map_runs(self, fn, tasks, **kwargs):
        if fn is estimation_layouts.record:
            self.progress.append(kwargs.get("progress"))
            return [{"path": f"record-{i}.npz"} for i, _ in enumerate(tasks)]
        self.jobs += tasks
        return [{"seed": t[2], "layout": t[3],
                 **{f"{v}_rel": 0.2 for v in enkf_noise.VARS},
                 **{f"{v}_spread_rel": 0.1 for v in enkf_noise.VARS}} for t in tasks]


@pytest.fixture
def engine(monkeypatch):
    fake = FakeEngine()
    monkeypatch.setattr("arzsumo.sweep.driver.map_runs", fake.map_runs)
    monkeypatch.setattr(enkf_noise, "map_runs", fake.map_runs)
    return fake


ENKF_QUICK = ("--tune-seeds", "1", "--report-seeds", "2", "--rounds", "0",
              "--inflation-only", "1.05", "--workers", "1")


@pytest.mark.parametrize(("quiet", "progress"), [((), "estimation-layouts: recording"),
                                                  (("--quiet",), None)])
def test_enkf_noise_records_with_a_progress_bar_unless_quiet(run_study, engine, tmp_path,
                                                             quiet, progress):
    assert run_study("enkf-noise", *ENKF_QUICK, *quiet, "--out", tmp_path / "out") == 0
    assert engine.progress == [progress]


def test_enkf_noise_reports_the_perfect_model_at_the_inflation_asked_for(run_study, engine,
                                                                         tmp_path):
    assert run_study("enkf-noise", *ENKF_QUICK, "--inflation", "1.3",
                     "--out", tmp_path / "out") == 0
    reported = [extra for _, _, seed, _, extra in engine.jobs if seed == 2]
    perfect = [e for e in reported if all(e[k] == 0.0 for k in enkf_noise.KEYS)]
    noisy = [e for e in reported if e not in perfect]
    assert perfect and noisy
    assert {e["estimation.inflation"] for e in perfect + noisy} == {1.3}


def test_loop_speed_station_means_leave_out_a_period_without_a_harmonic_speed():
    from types import SimpleNamespace

    from arzsumo_studies.estimation import loop_speed

    periods, stations = 2, 5                  # the first period (start) is the warm-up's
    speed = np.full((periods + 1, 2, stations), 10.0)
    harmonic = np.full((periods + 1, 2, stations), 8.0)
    harmonic[1, 0, 2] = np.nan                # no harmonic mean there (say, a stopped car)
    truth = np.zeros((periods, 4, stations))
    truth[:, 1], truth[:, 3] = 9.0, 9.0
    rec = SimpleNamespace(start=0, x=np.arange(stations) * 100.0,
                          loop_x=np.arange(stations) * 100.0, speed=speed,
                          speed_harmonic=harmonic, truth=lambda: truth)
    assert loop_speed.station_speeds(rec) == [
        "v_h at the stations, km/h: time-mean 36.00, harmonic 28.80, probe cells 32.40 "
        "(5 station-periods)",
        "v_a at the stations, km/h: time-mean 36.00, harmonic 28.80, probe cells 32.40 "
        "(6 station-periods)"]


def test_loop_speed_runs_from_python_with_its_options_and_the_cli_maps_onto_them():
    """Library code: LoopSpeedOptions in, its design out, no argparse in the study."""
    import argparse
    from pathlib import Path

    from arzsumo_studies.cli import loop_speed as cli
    from arzsumo_studies.common import StudyError
    from arzsumo_studies.estimation import loop_speed

    opts = loop_speed.LoopSpeedOptions(scenario=DEFAULT, seeds=(3, 4), horizon_s=120.0,
                                       method="enkf")
    runs = loop_speed.design(opts)
    assert [r.run_id for r in runs] == ["seed=3", "seed=4"]
    assert runs[0].scenario["sumo"]["horizon_s"] == 120.0
    parser = argparse.ArgumentParser()
    cli.add_arguments(parser)
    args = parser.parse_args(["--scenario", str(DEFAULT), "--seeds", "3,4", "--horizon",
                              "120", "--method", "enkf"])
    assert cli.options(args) == opts
    with pytest.raises(StudyError, match=r"horizon_s = -1\.0 is not allowed"):
        loop_speed.LoopSpeedOptions(horizon_s=-1.0)
    with pytest.raises(StudyError, match="method = 'kalman' is not allowed"):
        loop_speed.LoopSpeedOptions(method="kalman")
    assert "argparse" not in Path(loop_speed.__file__).read_text(encoding="utf-8")


def test_u_estimate_runs_from_python_and_counts_the_runs_that_did_not_finish(monkeypatch,
                                                                             tmp_path):
    """run_u_estimate(UEstimateOptions) without SUMO: a failed run of the three gives
    exit code 4; the command line builds the same options."""
    import argparse
    from types import SimpleNamespace

    import pandas as pd
    from arzsumo_studies.cli import u_estimate as cli
    from arzsumo_studies.common import StudyError

    table = pd.DataFrame({"estimator": ["none", "smoothing", "enkf"], "seed": [7] * 3,
                          "status": ["ok", "failed", "incomplete"], "plan_changes": [1] * 3})
    asked = {}

    def fake_sweep(spec, out, **kwargs):
        asked.update(kwargs, runs=len(spec.runs()))
        return SimpleNamespace(out=out, table=table)

    monkeypatch.setattr("arzsumo.sweep.driver.run_sweep", fake_sweep)
    opts = u_estimate.UEstimateOptions(seeds=(7,), out=tmp_path / "out", plots=False)
    result = u_estimate.run_u_estimate(opts, progress=False)
    assert (result.code, result.finished, result.runs) == (4, 2, 3)
    assert (asked["runs"], asked["progress"]) == (3, False)
    assert [p.name for p in result.files] == ["u_estimate.csv", "u_series.csv"]
    parser = argparse.ArgumentParser()
    cli.add_arguments(parser)
    assert cli.options(parser.parse_args(["--seeds", "7", "--out", str(tmp_path / "out"),
                                          "--no-plots"])) == opts
    with pytest.raises(StudyError, match=r"warmup_s = 0\.0 is not allowed"):
        u_estimate.UEstimateOptions(warmup_s=0.0)


def test_enkf_noise_tunes_from_python_with_its_options(engine, tmp_path):
    """Library code: EnkfNoiseOptions in, EnkfNoiseResult out. Every fake score has
    RMSE / spread 2, so one round at gain 1.5 scales each sd by 2 ** 1.5 (2 significant
    digits); the command line builds the same options."""
    import argparse

    from arzsumo_studies.cli import enkf_noise as cli
    from arzsumo_studies.common import StudyError

    opts = enkf_noise.EnkfNoiseOptions(tune_seeds=(1,), report_seeds=(2,), rounds=1,
                                       inflation_only=(1.05,), workers=1,
                                       out=tmp_path / "out")
    result = enkf_noise.run_enkf_noise(opts, progress=False)
    assert result.sd == (5.7, 2.8, 2.8, 2.8)
    assert len(result.rows) == 2 * len(enkf_noise.ENKF_LAYOUTS)     # two settings each
    assert [p.name for p in result.files] == ["enkf_noise.md", "enkf_noise.csv"]
    parser = argparse.ArgumentParser()
    cli.add_arguments(parser)
    assert cli.options(parser.parse_args([*ENKF_QUICK[:4], "--rounds", "1",
                                          "--inflation-only", "1.05", "--workers", "1",
                                          "--out", str(tmp_path / "out")])) == opts
    with pytest.raises(StudyError, match=r"--start = \[1\.0\] is not allowed: 4 sd"):
        enkf_noise.EnkfNoiseOptions(start=(1.0,))
    with pytest.raises(StudyError, match="layout = 'full probe' is not allowed"):
        enkf_noise.EnkfNoiseOptions(layout="full probe")


def test_estimation_layouts_scores_from_python_with_its_options(monkeypatch, tmp_path):
    """Library code: LayoutsOptions in, LayoutsResult out, without SUMO (records and
    scores made up: every layout and method of seed s scores s / 10); the command line
    builds the same options."""
    import argparse

    from arzsumo_studies.cli import estimation_layouts as cli
    from arzsumo_studies.common import StudyError

    def fake(fn, tasks, **kwargs):
        if fn is estimation_layouts.record:
            return [{"path": f"record-{i}.npz"} for i, _ in enumerate(tasks)]
        return [[{"layout": layout, "method": "enkf", "seed": t[2],
                  **{f"{v}_rel": t[2] / 10 for v in estimation_layouts.VARS}}
                 for layout in estimation_layouts.LAYOUTS] for t in tasks]

    monkeypatch.setattr("arzsumo.sweep.driver.map_runs", fake)
    opts = estimation_layouts.LayoutsOptions(scenario=DEFAULT, seeds=(1, 2, 3),
                                             horizon_s=300.0, out=tmp_path / "out")
    assert [r.run_id for r in estimation_layouts.study_runs(opts)] == [
        "seed=1", "seed=2", "seed=3"]
    result = estimation_layouts.run_layouts(opts, progress=False)
    assert len(result.table) == 3 * len(estimation_layouts.LAYOUTS)
    assert "| loops 250 m | enkf | 0.200 +- 0.248 |" in result.text
    parser = argparse.ArgumentParser()
    cli.add_arguments(parser)
    assert cli.options(parser.parse_args(["--scenario", str(DEFAULT), "--seeds", "1-3",
                                          "--horizon", "300", "--out",
                                          str(tmp_path / "out")])) == opts
    with pytest.raises(StudyError, match="warmup_s = 0 is not allowed"):
        estimation_layouts.LayoutsOptions(warmup_s=0)
