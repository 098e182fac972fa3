"""The inlet study: the characteristic inlet keeps what it prescribes, and the study
replays cached runs under every inlet end to end (the twin, no SUMO)."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
from arzsumo_studies.common import StudyError, shipped_scenario
from arzsumo_studies.identify import inlet

from arzsumo.identify import ReplayOptions
from arzsumo.identify.synthetic import SyntheticRun, synthetic_data
from arzsumo.model.characteristic import linearize
from arzsumo.scenario import load_scenario
from arzsumo.workflows.identify.cache import ARRAYS

DEFAULT = load_scenario(shipped_scenario("lateral_files.toml"))   # the former default


def test_the_characteristic_inlet_keeps_the_measured_densities_and_flow():
    eq = DEFAULT.equilibrium
    l4 = linearize(eq).T[3]
    v_max = (DEFAULT.params.v_free_h, DEFAULT.params.v_free_a)
    measured = np.array([eq.rho_h, eq.v_h * 1.1, eq.rho_a, eq.v_a * 0.9])
    z0 = np.array([eq.rho_h * 1.02, eq.v_h * 0.95, eq.rho_a, eq.v_a])
    z = inlet.characteristic(measured, z0, l4, v_max)
    assert (z[0], z[2]) == (measured[0], measured[2])
    assert z[0] * z[1] + z[2] * z[3] == pytest.approx(measured[0] * measured[1]
                                                      + measured[2] * measured[3])
    assert not np.allclose(z, measured)                  # the speeds come from lambda_4
    # the outgoing variable is the first cell's
    assert l4 @ (z - np.array([measured[0], 0, measured[2], 0])) == pytest.approx(
        l4 @ (z0 - np.array([measured[0], 0, measured[2], 0])))
    fast = inlet.characteristic(measured, z0 * np.array([1, 50, 1, 1]), l4, v_max)
    assert np.array_equal(fast, measured)                # not admissible: the measurement


@pytest.fixture
def cache(tmp_path):
    """Two synthetic 'identification runs' at the default's operating point."""
    eq = DEFAULT.equilibrium
    for k, wave in enumerate((0.05, 0.1)):
        data = synthetic_data(DEFAULT.params, SyntheticRun(eq.rho_h, eq.rho_a, wave=wave),
                              horizon=40.0, period=1.0, options=ReplayOptions(cells=20),
                              name=f"run{k}")
        np.savez(tmp_path / f"run{k}xxxx.npz", **{a: getattr(data, a) for a in ARRAYS})
    return tmp_path


def test_the_study_replays_every_run_under_every_inlet(run_study, cache, tmp_path):
    out = tmp_path / "out"
    assert run_study("inlet", "--runs", cache, "--out", out, "--docs", tmp_path / "docs") == 0
    df = pd.read_csv(out / "inlet.csv")
    assert df[["run", "inlet"]].values.tolist() == [
        [f"run{k}xxxx", i] for k in (0, 1) for i in inlet.INLETS]
    ghost = df[df["inlet"] == "ghost"]
    # the data come from the twin under the same parameters: the ghost replay is close
    assert (ghost[[f"{v}_grid_rel" for v in inlet.VARIABLES]] < 0.05).all(axis=None)
    assert not np.allclose(df.iloc[0, 3:].to_numpy(float), df.iloc[3, 3:].to_numpy(float))
    assert (tmp_path / "docs" / "identified_model" / "inlet.csv").is_file()
    assert "arzsumo study inlet --docs" in (tmp_path / "docs" / "identified_model.md").read_text()


def test_an_empty_cache_is_refused(run_study, tmp_path):
    with pytest.raises(StudyError, match="holds no cached identification runs"):
        run_study("inlet", "--runs", tmp_path, "--out", tmp_path / "out")


def test_the_study_runs_from_python_with_its_options(cache, tmp_path):
    """Library code: InletOptions in, InletResult out (one run x four inlets); the
    command line builds the same options, and a bad value names its field."""
    import argparse
    import os

    from arzsumo_studies.cli import inlet as cli

    os.utime(cache / "run0xxxx.npz", (2e9, 2e9))                   # now the most recent
    opts = inlet.InletOptions(runs=cache, last=1, out=tmp_path / "out")
    result = inlet.run_inlet(opts)
    assert result.runs == 1 and len(result.table) == len(inlet.INLETS) == 4
    assert result.table["run"].unique().tolist() == ["run0xxxx"]
    assert result.files == (tmp_path / "out" / "inlet.csv",)
    parser = argparse.ArgumentParser()
    cli.add_arguments(parser)
    assert cli.options(parser.parse_args(["--runs", str(cache), "--last", "1", "--out",
                                          str(tmp_path / "out")])) == opts
    with pytest.raises(StudyError, match="last = 0 is not allowed: an integer >= 1"):
        inlet.InletOptions(last=0)
