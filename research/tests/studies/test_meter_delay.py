"""The meter's dead time read off paired runs: synthetic periods with known parting times."""

import numpy as np
import pandas as pd
import pytest
from arzsumo_studies.common import StudyError
from arzsumo_studies.control import meter_delay
from arzsumo_studies.control.meter_delay import delay_rows, delay_summary, first_difference


def _periods(n: int = 120, seed: int = 0, command: int | None = None,
             light: int | None = None, outflow: int | None = None) -> pd.DataFrame:
    """An open loop's periods (seeded counts); with ``command``/``light``/``outflow`` the
    paired run, parting from it at those rows."""
    rng = np.random.default_rng(seed)
    p = pd.DataFrame({"t_s": np.arange(n, dtype=float),
                      "release_rate": np.full(n, 600 / 3600),
                      "green_running": np.tile([1.0, 0, 0, 0, 0, 0], n // 6 + 1)[:n],
                      "outflow_h": rng.poisson(0.9, n).astype(float),
                      "outflow_a": rng.poisson(0.2, n).astype(float)})
    if command is not None:
        p.loc[command:, "release_rate"] = 240 / 3600
    if light is not None:
        p.loc[light, "green_running"] = 1.0 - p.loc[light, "green_running"]
    if outflow is not None:
        p.loc[outflow, "outflow_a"] += 1.0
    return p


def test_first_difference_finds_the_first_parting_row_or_none():
    a = np.arange(10.0)
    b = a.copy()
    assert first_difference(a, b) is None
    b[7] += 1e-12                          # exact: the runs are bit-identical until then
    assert first_difference(a, b) == 7
    two_a, two_b = np.c_[a, a], np.c_[a, a]
    two_b[3, 1] = -1.0                     # a row differs when any of its columns does
    assert first_difference(two_a, two_b) == 3
    assert first_difference(a[:5], b) is None      # over the common length only


def test_paired_events_time_the_command_light_and_outflow_at_the_periods_end():
    ev = meter_delay.paired_events(_periods(command=0, light=5, outflow=26), _periods())
    assert ev == {"command_s": 1.0, "light_s": 6.0, "outflow_s": 27.0, "dead_time_s": 26.0,
                  "light_to_outflow_s": 21.0}
    never = meter_delay.paired_events(_periods(command=39), _periods())
    assert never["command_s"] == 40.0 and np.isnan(never["outflow_s"])
    assert np.isnan(never["dead_time_s"])


def _write(root, ctrl: str, seed: int, frame: pd.DataFrame) -> None:
    d = root / "regulation" / "runs" / f"controller={ctrl},seed={seed}"
    d.mkdir(parents=True)
    frame.to_parquet(d / "periods.parquet")


def test_rows_pair_each_seed_with_its_open_loop_and_the_summary_takes_medians(tmp_path):
    for seed, parting in ((1, 26), (2, 28), (3, 27)):
        _write(tmp_path, "open", seed, _periods(seed=seed))
        _write(tmp_path, "held", seed, _periods(seed=seed, command=0, light=5,
                                                outflow=parting))
    _write(tmp_path, "alinea", 4, _periods(seed=4, command=39))   # no open loop of seed 4
    rows = delay_rows([tmp_path], "regulation", ("held", "alinea"))
    assert sorted(rows["seed"]) == [1, 2, 3] and set(rows["controller"]) == {"held"}
    assert sorted(rows["dead_time_s"]) == [26.0, 27.0, 28.0]
    (row,) = delay_summary(rows).to_dict("records")
    assert row["n"] == 3 and row["dead time median, s"] == 27.0
    assert row["dead time range, s"] == "26-28" and row["light range, s"] == "6-6"


def test_a_directory_without_paired_runs_is_refused_naming_it(tmp_path):
    _write(tmp_path, "open", 1, _periods())
    with pytest.raises(StudyError, match=f"--sumo {tmp_path} holds no paired runs"):
        delay_rows([tmp_path], "regulation", ("held",))


def test_runs_spread_over_two_outputs_are_paired_across_them(tmp_path):
    first, second = tmp_path / "a", tmp_path / "b"
    _write(first, "open", 5, _periods(seed=5))
    _write(second, "held", 5, _periods(seed=5, command=0, outflow=30))
    _write(second, "open", 5, _periods(seed=99))          # the first directory's counts
    rows = delay_rows([first, second], "regulation", ("held",))
    assert rows["dead_time_s"].tolist() == [30.0]


def test_the_study_runs_from_python_with_its_options(tmp_path):
    """Library code: MeterDelayOptions in, MeterDelayResult out; the command line builds
    the same options, and a controller the study does not pair is refused by name."""
    import argparse

    from arzsumo_studies.cli import meter_delay as cli

    runs = tmp_path / "control"
    for seed, parting in ((1, 26), (2, 28)):
        _write(runs, "open", seed, _periods(seed=seed))
        _write(runs, "held", seed, _periods(seed=seed, command=0, outflow=parting))
    opts = meter_delay.MeterDelayOptions(sumo=(runs,), controllers=("held",),
                                         out=tmp_path / "out")
    result = meter_delay.run_meter_delay(opts)
    assert result.summary["dead time median, s"].tolist() == [27.0]
    assert [p.name for p in result.files] == ["paired_events.csv", "meter_delay.csv",
                                              "meter_delay.md"]
    parser = argparse.ArgumentParser()
    cli.add_arguments(parser)
    assert cli.options(parser.parse_args(["--sumo", str(runs), "--controllers", "held",
                                          "--out", str(tmp_path / "out")])) == opts
    with pytest.raises(StudyError, match=r"controllers = \('etc',\) is not allowed"):
        meter_delay.MeterDelayOptions(controllers=("etc",))
