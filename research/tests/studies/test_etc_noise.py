"""The etc-noise study: the twin's ETC against a noisy state, and SUMO's point."""

import numpy as np
import pandas as pd
import pytest
from arzsumo_studies.common import StudyError
from arzsumo_studies.control import etc_noise

from arzsumo.resources import shipped_scenarios_dir

#: the power-law model the twin measurements of research/readings/etc_remedies.md ran on
POWER_LAW = shipped_scenarios_dir() / "default_power_law.toml"


def test_the_output_noise_is_the_sd_of_the_change_between_checks_in_veh_h():
    u = 0.01 * (-1.0) ** np.arange(11)               # +-0.01 veh/s: changes of +-0.02
    assert etc_noise.output_noise_veh_h(u) == pytest.approx(0.02 * 3600)
    assert etc_noise.output_noise_veh_h(np.linspace(0, 1, 50)) == pytest.approx(0, abs=1e-9)
    assert np.isnan(etc_noise.output_noise_veh_h(np.array([1.0, np.nan])))


def test_on_the_power_law_the_etc_samples_a_fifth_of_the_checks_without_noise_and_all_with_1_pct():
    clean = etc_noise.twin_row((POWER_LAW, "etc", 0.0, 1))
    noisy = etc_noise.twin_row((POWER_LAW, "etc", 1.0, 1))
    law = etc_noise.twin_row((POWER_LAW, "backstepping", 1.0, 1))
    assert clean["checks"] == noisy["checks"] == 450
    assert 0.1 < clean["event_share"] < 0.33                      # the design's events
    assert noisy["event_share"] > 0.95                             # the trigger sees noise
    assert law["events"] == 450
    # the same noise seed: the ETC's law output carries the backstepping law's noise
    assert noisy["output_noise_veh_h"] == pytest.approx(law["output_noise_veh_h"], rel=0.05)
    assert 80 < law["output_noise_veh_h"] < 140 and clean["output_noise_veh_h"] < 3


def write_periods(path, u, triggered):
    path.mkdir(parents=True)
    pd.DataFrame({"u_continuous": u, "triggered": triggered}).to_parquet(
        path / "periods.parquet")


def test_sumo_rows_read_the_laws_runs_of_a_control_study_and_skip_the_others(tmp_path):
    u = 0.01 * (-1.0) ** np.arange(11)               # changes of +-0.02 veh/s, mean 0
    write_periods(tmp_path / "regulation/runs/controller=etc,seed=3", u, [True] + [True, False] * 5)
    write_periods(tmp_path / "disturbance/runs/controller=backstepping,seed=3", u, [True] * 11)
    write_periods(tmp_path / "regulation/runs/controller=open,seed=3", u, [False] * 11)
    rows = etc_noise.sumo_rows(tmp_path).sort_values("experiment")
    assert rows[["experiment", "law", "seed", "events"]].values.tolist() == [
        ["disturbance", "backstepping", 3, 11], ["regulation", "etc", 3, 6]]
    assert rows["output_noise_veh_h"].tolist() == pytest.approx([72.0, 72.0])
    table = etc_noise.summary(rows, ["law"])
    assert table["event_share"].tolist() == pytest.approx([1.0, 6 / 11])


def test_a_directory_without_the_laws_runs_is_refused(tmp_path):
    with pytest.raises(StudyError, match=r"--sumo .* holds no runs"):
        etc_noise.sumo_rows(tmp_path)


def test_the_study_writes_its_tables(run_study, tmp_path, capsys):
    assert run_study("etc-noise", "--levels", "0", "--seeds", "1", "--workers", "1",
                     "--quiet", "--out", tmp_path / "out") == 0
    twin = pd.read_csv(tmp_path / "out" / "twin.csv")
    assert twin["law"].tolist() == ["backstepping", "etc", "observer-etc"]
    assert twin["n"].tolist() == [1, 1, 1]
    # the default's Newell design: 4 events in 450 noise-free checks (the power law's: 93)
    assert "| etc | 0 | 1 | 4 |" in capsys.readouterr().out


def test_a_negative_noise_level_is_refused(run_study, tmp_path):
    with pytest.raises(StudyError, match="--levels"):
        run_study("etc-noise", "--levels", "-1", "--out", tmp_path / "out")
    assert not (tmp_path / "out").exists()


def test_the_options_from_python_give_the_design_and_refuse_a_negative_level(tmp_path):
    """Library code: EtcNoiseOptions in, the design out (level x law x seed); the command
    line builds the same options."""
    import argparse

    from arzsumo_studies.cli import etc_noise as cli

    assert len(etc_noise.design(etc_noise.EtcNoiseOptions())) == 8 * 3 * 10
    opts = etc_noise.EtcNoiseOptions(levels=(0.0, 1.0), seeds=(4, 5), out=tmp_path / "o")
    lines = etc_noise.design(opts)
    assert len(lines) == 2 * 3 * 2
    assert lines[:2] == ["backstepping, noise 0 %, seed 4", "backstepping, noise 0 %, seed 5"]
    parser = argparse.ArgumentParser()
    cli.add_arguments(parser)
    assert cli.options(parser.parse_args(["--levels", "0,1", "--seeds", "4,5", "--out",
                                          str(tmp_path / "o")])) == opts
    with pytest.raises(StudyError, match=r"--levels \[0\.5, -1\.0\] is not allowed"):
        etc_noise.EtcNoiseOptions(levels=(0.5, -1.0))
