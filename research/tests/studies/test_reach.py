"""What a boundary can reach, read off run directories: a synthetic run whose field is the
outlet's flow travelling upstream plus independent noise gives back the known share."""

from __future__ import annotations

import json

import numpy as np
import pandas as pd
import pytest
from arzsumo_studies.common import StudyError
from arzsumo_studies.control.reach import reach, reach_table, read_run

L, C, V_STAR = 1000.0, -8.0, 4.5                 # m, m/s (lambda_4), m/s
X = np.arange(25.0, 1000.0, 50.0)


def _write_run(path, seed, noise_sd, t_end=3600, empty=()):
    """A run directory: v(t, x) = 5 m/s + 2 qL(t - (L - x)/|C|) + noise, qL an AR(1)
    series (veh/s), q0 and U independent of the field."""
    rng = np.random.default_rng(seed)
    t = np.arange(t_end + 200, dtype=float)
    ql = np.zeros(t.size)
    for k in range(1, t.size):
        ql[k] = 0.97 * ql[k - 1] + rng.normal(0.0, 0.05)
    lag = np.rint((L - X) / abs(C)).astype(int)
    keep = slice(200, None)
    v = np.stack([5.0 + 2.0 * np.roll(ql, lag_k) for lag_k in lag], axis=1)[keep]
    v = v + rng.normal(0.0, noise_sd, v.shape)
    for j in empty:
        v[:, j] = np.nan
    n = v.shape[0]
    path.mkdir()
    # as a run writes them: the cells at the start of control (t = 0), then at the end of
    # each period; the periods at their check times 0 .. n - 1
    v = np.vstack([np.full((1, X.size), 99.0), v])
    cells = pd.DataFrame({"source": "micro",
                          "t_s": np.repeat(np.arange(n + 1, dtype=float), X.size),
                          "x_m": np.tile(X, n + 1), "rho_h": 0.1, "v_h": v.ravel(),
                          "rho_a": 0.02, "v_a": v.ravel()})
    cells.to_parquet(path / "cells.parquet")
    periods = pd.DataFrame({"t_s": np.arange(n, dtype=float),
                            "inflow_h": rng.normal(0.5, 0.1, n), "inflow_a": 0.1,
                            "outflow_h": ql[keep] + 0.5, "outflow_a": 0.0,
                            "u_applied": rng.normal(0.0, 0.05, n)})
    periods.to_parquet(path / "periods.parquet")
    (path / "summary.json").write_text(json.dumps({"lambda_4": C,
                                                   "equilibrium": {"v_h": V_STAR}}))
    return path


def test_the_outlets_share_is_the_signals_and_the_others_sit_on_the_floor(tmp_path):
    runs = [_write_run(tmp_path / f"run{s}", s, noise_sd=0.0) for s in range(3)]
    table = reach_table({"synthetic": runs})
    row = table.set_index(["boundary", "band"])
    # a field that is the outlet's flow delayed, nothing else: all of it is coherent
    assert row.loc[("qL", "stop_and_go"), "share"] == pytest.approx(1.0, abs=0.03)
    assert row.loc[("qL", "short_waves"), "share"] == pytest.approx(1.0, abs=0.03)
    for b in ("q0", "U"):
        for band in ("short_waves", "stop_and_go"):
            r = row.loc[(b, band)]
            assert r["share"] < 3 * r["floor"] + 0.02, (b, band)
    assert set(table["runs"]) == {3} and set(table["condition"]) == {"synthetic"}


def test_independent_noise_of_equal_power_halves_the_share_in_each_band(tmp_path):
    # the AR(1) series' power in a band, against white noise of the same total power
    # there: the known share is the signal's fraction of each band's power
    runs = [read_run(_write_run(tmp_path / f"run{s}", 10 + s, noise_sd=0.6), 5.0)
            for s in range(4)]
    res = reach(runs).results["qL"]
    known = []
    rng = np.random.default_rng(0)
    from scipy.signal import welch
    ql = np.zeros(200_000)
    for k in range(1, ql.size):
        ql[k] = 0.97 * ql[k - 1] + rng.normal(0.0, 0.05)
    f, p_sig = welch(2.0 * ql, fs=1.0, nperseg=4096)
    p_noise = 2 * 0.6 ** 2                           # one-sided white noise, per Hz
    for lo, hi in res.band_s:
        band = (f >= 1 / hi) & (f <= 1 / lo)
        known.append(p_sig[band].mean() / (p_sig[band].mean() + p_noise))
    assert res.beyond_floor == pytest.approx(known, abs=0.08)


def test_a_cell_empty_in_a_run_is_left_out_and_a_run_without_two_cells_refused(tmp_path):
    runs = [read_run(_write_run(tmp_path / "a", 1, 0.1, empty=(3,)), 5.0),
            read_run(_write_run(tmp_path / "b", 2, 0.1), 5.0)]
    res = reach(runs).results["qL"]
    assert res.x.size == X.size - 1 and 175.0 not in res.x
    with pytest.raises(StudyError, match="runs = 0 is not allowed"):
        reach([])
