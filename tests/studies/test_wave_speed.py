"""The wave-speed study finds the direction and speed of a travelling wave, from arrays
and from the cells of a run directory."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from arzsumo.studies import wave_speed

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


def test_the_study_reads_the_cells_of_run_directories(run_study, tmp_path):
    run = tmp_path / "default-etc-seed42"
    run.mkdir()
    f = wave(20.0)
    cells = pd.concat([pd.DataFrame({"source": src, "t_s": np.repeat(T, X.size),
                                     "x_m": np.tile(X, T.size),
                                     **{v: f.ravel() * (k + 1) for k, v in
                                        enumerate(wave_speed.VARIABLES)}})
                       for src in ("micro", "replay")])
    cells.to_parquet(run / "cells.parquet")
    assert run_study("wave-speed", "--from", run, "--out", tmp_path / "out") == 0
    df = pd.read_csv(tmp_path / "out" / "wave_speed.csv")
    assert len(df) == 4 * 3 and set(df["run"]) == {"default-etc-seed42"}
    assert df["speed_kmh"].between(68.0, 76.0).all()


def test_the_design_is_controllers_x_seeds():
    runs = wave_speed.design(wave_speed.shipped_scenario("default.toml"), ["open", "etc"],
                             [42])
    assert [r.run_id for r in runs] == ["controller=open,seed=42", "controller=etc,seed=42"]
    assert runs[1].scenario["run"]["controller"] == "etc"


def test_list_with_run_directories_lists_no_runs_and_reads_nothing(run_study, tmp_path,
                                                                   capsys):
    one, two = tmp_path / "a", tmp_path / "b"
    assert run_study("wave-speed", "--from", one, two, "--list",
                     "--out", tmp_path / "out") == 0
    assert capsys.readouterr().out == f"no runs: --from {one} {two} is read instead\n"
    assert not (tmp_path / "out").exists()
