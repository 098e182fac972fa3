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


# ``arzsumo study reach``: the same synthetic runs through the study and its command line

@pytest.fixture(scope="module")
def synthetic(tmp_path_factory):
    """Three noiseless synthetic runs (``run0`` .. ``run2``) in one directory."""
    root = tmp_path_factory.mktemp("reach_runs")
    for s in range(3):
        _write_run(root / f"run{s}", s, noise_sd=0.0)
    return root


def test_run_dirs_sort_by_seed_keep_the_first_and_refuse_what_is_not_a_run(tmp_path):
    from arzsumo_studies.control.reach import RUN_FILES, run_dirs

    for seed in (10, 2, 1):
        d = tmp_path / f"controller=open,seed={seed}"
        d.mkdir()
        for f in RUN_FILES:
            (d / f).write_text("{}")
    pattern = f"{tmp_path}/controller=open,seed=*"
    assert [d.name for d in run_dirs("open", pattern)] == [
        "controller=open,seed=1", "controller=open,seed=2", "controller=open,seed=10"]
    assert [d.name for d in run_dirs("open", pattern, 2)] == [
        "controller=open,seed=1", "controller=open,seed=2"]
    (tmp_path / "controller=open,seed=2" / "summary.json").unlink()
    with pytest.raises(StudyError, match=r"--runs = .*seed=2 has no summary.json"):
        run_dirs("open", pattern)
    with pytest.raises(StudyError, match=r"--runs = 'none=.*/nothing\*'.*matches none"):
        run_dirs("none", f"{tmp_path}/nothing*")


def test_a_run_deadlocked_before_control_is_left_out_with_a_warning(tmp_path):
    """Standing since before the window (842 s >= 450 s window + 300 s drain - 1): out; a
    gridlock that came later (standstill 200 s) stays in."""
    from arzsumo_studies.control.reach import run_dirs

    for seed, standstill in ((1, 842.3), (2, 200.0), (3, None)):
        d = _write_run(tmp_path / f"controller=open,seed={seed}", seed, 0.1)
        summary = json.loads((d / "summary.json").read_text())
        summary |= {"horizon": 450.0, "longest_standstill_main": standstill,
                    "network_whole_demand": {"drain": {"gridlock": standstill is not None,
                                                       "duration_s": 300.0}}}
        (d / "summary.json").write_text(json.dumps(summary))
    with pytest.warns(UserWarning, match=r"open: 1 run\(s\) left out.*seed=1"):
        kept = run_dirs("open", f"{tmp_path}/controller=open,seed=*")
    assert [d.name for d in kept] == ["controller=open,seed=2", "controller=open,seed=3"]


def test_the_study_writes_the_table_its_page_and_the_figure(synthetic, tmp_path):
    from arzsumo_studies.control.reach import ReachOptions, run_reach

    opts = ReachOptions(runs=(("syn", f"{synthetic}/run*"),), out=tmp_path / "out")
    res = run_reach(opts)
    assert [p.name for p in res.files] == ["reach.csv", "reach.md", "reach.png"]
    assert [d.name for d in res.dirs["syn"]] == ["run0", "run1", "run2"]
    assert list(res.table.columns[:7]) == ["condition", "boundary", "band", "share",
                                           "floor", "beyond_floor", "runs"]
    assert res.text.startswith(f"`{opts.command()}`")
    assert "| syn | qL | 3 | 1.00 [0.0" in res.text
    no_plots = run_reach(ReachOptions(runs=opts.runs, out=opts.out, plots=False))
    assert not (opts.out / "reach.png").exists() and len(no_plots.files) == 2


def test_the_command_writes_the_shares_the_library_reads(synthetic, tmp_path, capsys):
    from arzsumo.cli import main

    out = tmp_path / "out"
    assert main(["study", "reach", "--runs", f"syn={synthetic}/run*", "--out",
                 str(out)]) == 0
    table = pd.read_csv(out / "reach.csv")
    row = table.set_index(["boundary", "band"])
    assert set(table["condition"]) == {"syn"} and set(table["runs"]) == {3}
    for band in ("short_waves", "stop_and_go"):
        assert row.loc[("qL", band), "share"] == pytest.approx(1.0, abs=0.03)
        for b in ("q0", "U"):
            r = row.loc[(b, band)]
            assert r["share"] < 3 * r["floor"] + 0.02, (b, band)
    png = (out / "reach.png").read_bytes()
    assert png.startswith(b"\x89PNG\r\n\x1a\n") and len(png) > 1000
    text = (out / "reach.md").read_text(encoding="utf-8")
    assert text.startswith("`arzsumo study reach --runs") and "| syn | q0 | 3 |" in text
    assert text.strip() in capsys.readouterr().out


def test_a_glob_matching_nothing_is_refused_in_one_line(tmp_path, capsys):
    from arzsumo.cli import main

    out = tmp_path / "out"
    pattern = f"{tmp_path}/nothing=*"
    assert main(["study", "reach", "--runs", f"none={pattern}", "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("arzsumo: error: --runs = ")
    assert pattern in err and not out.exists()
    assert main(["study", "reach", "--out", str(out)]) == 2
    assert "--runs" in capsys.readouterr().err
    assert main(["study", "reach", "--runs", "no-glob", "--out", str(out)]) == 2
    assert "--runs = no-glob is not allowed: NAME=GLOB" in capsys.readouterr().err
