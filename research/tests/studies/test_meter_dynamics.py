"""The meter-dynamics study: its design (the documented staircase) and the FOPDT fits,
which recover the gain, dead time and time constant of a known step response."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
from arzsumo_studies.sumo_map import meter_dynamics, meter_fit

#: the response of the made-up series: veh/s per unit of green share, s, s
GAIN, DELAY, TAU = -0.56, 10.0, 5.0


def test_the_schedule_holds_each_green_share_for_the_hold():
    assert meter_dynamics.schedule(600.0, 60.0, [0.2, 0.8], 102.0) == \
        [(0.0, 0.5), (660.0, 0.2), (762.0, 0.8)]


def test_the_design_is_one_fixed_cycle_run_per_seed_of_the_documented_length():
    runs = meter_dynamics.design(meter_dynamics.MeterDynamicsOptions(seeds=(1, 2, 3)))
    assert [r.run_id for r in runs] == ["seed=1", "seed=2", "seed=3"]
    sumo, run = runs[2].scenario["sumo"], runs[2].scenario["run"]
    assert (sumo["seed"], sumo["control_period_s"], run["warmup_s"]) == (3, 1.0, 600.0)
    assert sumo["horizon_s"] == 60.0 + 8 * 102.0          # base + 8 steps of 17 cycles
    assert "meter_mode" not in sumo and "meter_clearance_s" not in sumo
    assert runs[0].options["greens"] == [0.2, 0.5, 0.8, 0.5, 0.2, 0.5, 0.8, 0.5]


def series(seed: int = 1, greens=(0.2, 0.5, 0.8, 0.5), hold: float = 102.0,
           noise: float = 0.02) -> pd.DataFrame:
    """A per-second series whose outflow follows a FOPDT response to the plan."""
    rng = np.random.default_rng(seed)
    t = np.arange(481.0, 660.0 + hold * len(greens) + 1)
    g = np.full(t.size, 0.5)
    y = np.full(t.size, 1.2)
    prev = 0.5
    for k, share in enumerate(greens):
        t0 = 660.0 + k * hold
        g[t >= t0] = share
        late = t > t0 + DELAY
        y[late] += GAIN * (share - prev) * (1 - np.exp(-(t[late] - t0 - DELAY) / TAU))
        prev = share
    y += rng.normal(0.0, noise, t.size)
    return pd.DataFrame({"seed": seed, "t_s": t, "g_req": g, "g_run": g, "out_h_veh": 0.8 * y,
                         "out_a_veh": 0.2 * y, "in_h_veh": 1.0, "in_a_veh": 0.3,
                         "ramp_veh": 0.1 + 0.2 * g, "n_main_veh": 140, "ramp_queue_veh": 5})


def test_the_pooled_fit_recovers_the_step_response():
    data = meter_fit.by_seed(series())
    assert [round(c[0]) for c in meter_fit.plan_changes(data[1])] == [660, 762, 864, 966]
    rows = meter_fit.fits(data, "y", pre=60.0, detail=False)
    assert [r["step"] for r in rows] == [meter_fit.DOWN, meter_fit.UP, "all"]
    pooled = rows[-1]
    assert pooled["n_steps"] == 4
    assert pooled["gain_veh_s"] == pytest.approx(GAIN, rel=0.05)
    assert pooled["delay_s"] == pytest.approx(DELAY, abs=1.5)
    assert pooled["time_constant_s"] == pytest.approx(TAU, abs=1.5)


def test_the_figure_ensembles_leave_out_a_direction_without_steps():
    data = meter_fit.by_seed(series(greens=(0.8,)))         # one step, upwards only
    rows = meter_fit.fits(data, "y", pre=60.0, detail=False)
    assert meter_fit.DOWN not in [r["step"] for r in rows]
    found = meter_fit.ensembles(data, rows)
    assert [name for name, *_ in found] == [meter_fit.UP]
    _, lag, mean, fit, label = found[0]
    assert lag.shape == mean.shape == fit.shape and "theta=" in label


def test_the_static_levels_are_the_settled_outflow_per_green_share():
    data = meter_fit.by_seed(series(noise=0.0))
    levels = meter_fit.static_levels(data, settled=60.0)
    assert sorted(levels) == [0.2, 0.5, 0.8]
    # y0 + K (g - 0.5), veh/h, fully settled after 102 s
    assert np.mean(levels[0.2]) == pytest.approx((1.2 + GAIN * -0.3) * 3600, rel=1e-3)
    assert np.mean(levels[0.8]) == pytest.approx((1.2 + GAIN * 0.3) * 3600, rel=1e-3)


def test_the_study_fits_a_recorded_series_and_publishes_it(run_study, tmp_path):
    path = tmp_path / "series.csv"
    series().to_csv(path, index=False)
    out = tmp_path / "out"
    assert run_study("meter-dynamics", "--series", path, "--out", out,
                     "--docs", tmp_path / "docs") == 0
    fits = pd.read_csv(out / "fits.csv")
    assert set(fits["scope"]) == {"step", "staircase", "direction", "type", "all steps"}
    levels = pd.read_csv(out / "levels.csv")
    assert levels["green_share"].tolist() == [0.2, 0.5, 0.8]
    assert (out / "steps.png").stat().st_size > 10_000
    page = (tmp_path / "docs" / "meter_dynamics.md").read_text()
    assert "![steps](meter_dynamics/meter_steps.png)" in page
    assert sorted(p.name for p in (tmp_path / "docs" / "meter_dynamics").iterdir()) == [
        "meter_levels.csv", "meter_steps.csv", "meter_steps.png", "meter_steps_series.csv",
        "meter_tables.md"]


@pytest.mark.sumo
def test_one_short_run_in_sumo_records_the_running_plan_every_second():
    run = meter_dynamics.design(meter_dynamics.MeterDynamicsOptions(
        seeds=(1,), warmup_s=30.0, base_s=6.0, greens=(0.8, 0.5), hold_s=18.0))[0]
    got = meter_dynamics.run_steps(run)
    rows = pd.DataFrame(got["series"])
    assert rows["t_s"].tolist() == list(range(1, 73))         # 30 + 6 + 2 x 18 s
    changes = meter_fit.plan_changes(meter_fit.by_seed(rows)[1])
    # asked half a cycle early, each plan runs from the next cycle start
    assert [(g0, g1) for _, g0, g1 in changes] == [(0.5, 0.8), (0.8, 0.5)]
    assert 36.0 <= changes[0][0] <= 42.0 and 54.0 <= changes[1][0] <= 60.0
    assert got["info"]["collisions"] is None        # not counted: collision_check is off


@pytest.mark.parametrize("greens", ["0.2,1.5", "-0.1", "0.5,nan"])
def test_green_shares_the_meter_cannot_run_are_refused_in_one_line(greens, capsys, tmp_path):
    from arzsumo.cli import main

    assert main(["study", "meter-dynamics", "--greens", greens, "--out",
                 str(tmp_path / "out"), "--list"]) == 2
    err = capsys.readouterr().err
    assert err == (f"arzsumo: error: --greens = {greens} is not allowed: comma-separated "
                   "numbers in [0, 1] (see 'arzsumo study meter-dynamics --help')\n")
    assert not (tmp_path / "out").exists()


def test_list_with_a_series_lists_no_runs_and_fits_nothing(run_study, tmp_path, capsys):
    path = tmp_path / "series.csv"
    series().to_csv(path, index=False)
    assert run_study("meter-dynamics", "--series", path, "--list",
                     "--out", tmp_path / "out") == 0
    assert capsys.readouterr().out == f"no runs: --series {path} is read instead\n"
    assert not (tmp_path / "out").exists()


def test_a_rerun_without_plots_removes_its_earlier_figure_and_nothing_else(run_study,
                                                                           tmp_path):
    path = tmp_path / "series.csv"
    series().to_csv(path, index=False)
    out = tmp_path / "out"
    assert run_study("meter-dynamics", "--series", path, "--out", out) == 0
    assert (out / "steps.png").is_file()
    (out / "mine.png").write_bytes(b"the user's")
    assert run_study("meter-dynamics", "--series", path, "--out", out, "--no-plots") == 0
    assert not (out / "steps.png").exists()
    assert (out / "mine.png").read_bytes() == b"the user's"
    assert (out / "fits.csv").is_file()


def test_the_study_fits_a_series_from_python_with_its_options(tmp_path):
    """Library code: MeterDynamicsOptions in (a series read instead of SUMO),
    MeterDynamicsResult out; the command line builds the same options, and a green share
    the meter cannot run is refused naming the field."""
    import argparse

    from arzsumo_studies.cli import meter_dynamics as cli
    from arzsumo_studies.common import StudyError

    path = tmp_path / "series.csv"
    series().to_csv(path, index=False)
    opts = meter_dynamics.MeterDynamicsOptions(series=path, out=tmp_path / "out",
                                               plots=False)
    result = meter_dynamics.run_meter_dynamics(opts)
    assert len(result.series) == len(series())
    assert [p.name for p in result.files] == ["series.csv", "fits.csv", "levels.csv",
                                              "tables.md"]
    assert pd.read_csv(tmp_path / "out" / "levels.csv")["green_share"].tolist() == \
        [0.2, 0.5, 0.8]
    parser = argparse.ArgumentParser()
    cli.add_arguments(parser)
    assert cli.options(parser.parse_args(["--series", str(path), "--out",
                                          str(tmp_path / "out"), "--no-plots"])) == opts
    with pytest.raises(StudyError, match=r"greens = \(0\.2, 1\.5\) is not allowed"):
        meter_dynamics.MeterDynamicsOptions(greens=(0.2, 1.5))
