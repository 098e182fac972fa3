"""The wave-speed study finds the direction and speed of a travelling wave, from arrays
and from the cells of a run directory."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
from arzsumo_studies.sumo_map import wave_speed

X = np.arange(20) * 50.0 + 25.0          # the section's 50 m cells
T = np.arange(600.0)


def wave(c: float) -> np.ndarray:
    """A wave travelling at c m/s (< 0: upstream), T x X."""
    rng = np.random.default_rng(1)
    signal = np.convolve(rng.normal(size=T.size + 400), np.ones(8) / 8, mode="same")
    t_src = np.arange(-200.0, T.size + 200.0)
    return np.stack([np.interp(T - x / c, t_src, signal) for x in X], axis=1)


@pytest.mark.parametrize(("c", "lag"), [(20.0, 12.5), (-50 / 3.6, -18.0)])
def test_the_peak_lag_gives_the_travel_speed(c, lag):
    rows = wave_speed.travel(T, X, wave(c), "v_h")
    assert [(r["x_up_m"], r["x_down_m"]) for r in rows] == [(125.0, 375.0), (275.0, 525.0),
                                                            (525.0, 775.0)]
    for r in rows:
        assert r["lag_s"] == pytest.approx(lag, abs=0.6)
        assert r["speed_kmh"] == pytest.approx(c * 3.6, rel=0.05)
        assert r["peak_corr"] > 0.9


def _run_dir(tmp_path):
    """An ``arzsumo run`` result directory whose cells carry a wave at 20 m/s."""
    run = tmp_path / "default-etc-seed42"
    run.mkdir()
    f = wave(20.0)
    cells = pd.concat([pd.DataFrame({"source": src, "t_s": np.repeat(T, X.size),
                                     "x_m": np.tile(X, T.size),
                                     **{v: f.ravel() * (k + 1) for k, v in
                                        enumerate(wave_speed.VARIABLES)}})
                       for src in ("micro", "replay")])
    cells.to_parquet(run / "cells.parquet")
    return run


def test_the_study_reads_the_cells_of_run_directories(run_study, tmp_path):
    run = _run_dir(tmp_path)
    assert run_study("wave-speed", "--from", run, "--out", tmp_path / "out") == 0
    df = pd.read_csv(tmp_path / "out" / "wave_speed.csv")
    assert len(df) == 4 * 3 and set(df["run"]) == {"default-etc-seed42"}
    assert df["speed_kmh"].between(68.0, 76.0).all()


def test_the_design_is_controllers_x_seeds():
    runs = wave_speed.design(wave_speed.WaveSpeedOptions(
        scenario=wave_speed.shipped_scenario("default.toml"), controllers=("open", "etc"),
        seeds=(42,)))
    assert [r.run_id for r in runs] == ["controller=open,seed=42", "controller=etc,seed=42"]
    assert runs[1].scenario["run"]["controller"] == "etc"


def test_list_with_run_directories_lists_no_runs_and_reads_nothing(run_study, tmp_path,
                                                                   capsys):
    one, two = tmp_path / "a", tmp_path / "b"
    assert run_study("wave-speed", "--from", one, two, "--list",
                     "--out", tmp_path / "out") == 0
    assert capsys.readouterr().out == f"no runs: --from {one} {two} is read instead\n"
    assert not (tmp_path / "out").exists()


def test_the_study_runs_from_python_with_its_options(tmp_path):
    """Library code: WaveSpeedOptions in, WaveSpeedResult out; the command line builds
    the same options, and a bad value names its field."""
    import argparse

    from arzsumo_studies.cli import wave_speed as cli
    from arzsumo_studies.common import StudyError

    run = _run_dir(tmp_path)
    opts = wave_speed.WaveSpeedOptions(source=(run,), out=tmp_path / "out")
    result = wave_speed.run_wave_speed(opts)
    assert len(result.table) == 4 * 3
    assert result.table["speed_kmh"].between(68.0, 76.0).all()
    assert result.files == (tmp_path / "out" / "wave_speed.csv",)
    parser = argparse.ArgumentParser()
    cli.add_arguments(parser)
    assert cli.options(parser.parse_args(["--from", str(run), "--out",
                                          str(tmp_path / "out")])) == opts
    with pytest.raises(StudyError, match="workers = 0 is not allowed: an integer >= 1"):
        wave_speed.WaveSpeedOptions(workers=0)
