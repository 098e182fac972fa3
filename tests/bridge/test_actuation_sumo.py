"""Actuation limits in the closed loop with real SUMO: short runs of
``scenarios/legacy_default.toml`` (60 s warm-up, 60 s of control, seed 42)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pyarrow.parquet as pq
import pytest

from arzsumo.bridge.cosim import run_cosimulation
from arzsumo.outputs.bridge import write_results
from arzsumo.sumo.green_share import DEFAULT_CURVE, fixed_cycle_ramp_floor, fixed_cycle_u_range
from tests.runs import SMALL_GRIDS, prepared

pytestmark = pytest.mark.sumo
DEFAULT = Path(__file__).resolve().parents[2] / "scenarios" / "legacy_default.toml"
TIGHT = {"actuation.u_max_fraction": 0.1, "actuation.u_rate_max_veh_h_s": 180}
TOL = 1e-9


def _run(controller, changes):
    return run_cosimulation(prepared(DEFAULT, {**changes, **SMALL_GRIDS},
                                     controller=controller, warmup=60.0, horizon=60.0,
                                     seed=42))


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    with pytest.MonkeyPatch.context() as mp:
        mp.setenv("ARZSUMO_CACHE", str(tmp_path_factory.mktemp("cache")))
        return {"backstepping": _run("backstepping", TIGHT),
                "etc": _run("etc", TIGHT),
                "etc-windup": _run("etc", {**TIGHT, "actuation.anti_windup": False}),
                "ramp": _run("backstepping", {"actuation.ramp_bound": True})}


@pytest.mark.parametrize("name", ["backstepping", "etc", "etc-windup"])
def test_saturation_and_rate_hold_at_every_period(runs, name):
    res = runs[name]
    p, u_max = res.periods, 0.1 * res.q_nominal
    rate_step = 180 / 3600 * res.sumo.control_period
    assert p["u_applied"].size == 60
    assert np.all(np.abs(p["u_applied"]) <= u_max + TOL)
    assert np.all(np.abs(np.diff(np.r_[0.0, p["u_applied"]])) <= rate_step + TOL)
    np.testing.assert_array_equal(p["u"], p["u_applied"])
    # the limits had work to do: the law asked for more, so a run ignoring them would fail
    assert np.abs(p["u_raw"]).max() > u_max + 0.01
    assert p["saturated"].sum() > 0
    np.testing.assert_array_equal(p["saturated"] > 0, np.abs(p["u_raw"]) > u_max)


def test_backstepping_is_rate_limited(runs):
    p = runs["backstepping"].periods
    assert p["rate_limited"].sum() >= 10
    assert np.abs(np.diff(p["u_raw"])).max() > 180 / 3600 + 0.01


def test_saturated_etc_does_not_trigger_on_every_period(runs):
    on, off = runs["etc"].periods, runs["etc-windup"].periods
    assert on["saturated"].mean() > 0.5                      # saturated most of the time
    assert on["triggered"].sum() <= 60 / 4
    assert on["triggered"].sum() < off["triggered"].sum()


def test_ramp_bound_keeps_u_within_meter_and_ramp(runs):
    res = runs["ramp"]
    p, q_nom, cfg = res.periods, res.q_nominal, res.sumo
    lo, hi = fixed_cycle_u_range(DEFAULT_CURVE, cfg, q_nom)
    assert np.all((p["u_applied"] >= lo - TOL) & (p["u_applied"] <= hi + TOL))
    # the meter's queue at check k is the queue at the end of period k - 1
    floor = [fixed_cycle_ramp_floor(DEFAULT_CURVE, cfg, q_nom, q) for q in p["queue"][:-1]]
    assert np.all(p["u_applied"][1:] >= np.asarray(floor) - TOL)
    assert p["saturated"].sum() > 0 and p["rate_limited"].sum() == 0


def test_records_and_summary_report_the_limits(runs, tmp_path):
    res = runs["backstepping"]
    path, summ = write_results(res, tmp_path / "run", "# test\n", plots=False)
    table = pq.read_table(path / "periods.parquet").to_pydict()
    for col in ("u_raw", "u_applied", "saturated", "rate_limited"):
        assert len(table[col]) == 60
    assert all(isinstance(v, bool) for v in table["saturated"])
    act = summ["actuation"]
    assert act["u_max"] == pytest.approx(0.1 * res.q_nominal)
    assert act["rate_step"] == pytest.approx(0.05)
    assert act["saturated_share"] == pytest.approx(np.mean(res.periods["saturated"]))
    assert act["rate_limited_periods"] == int(res.periods["rate_limited"].sum())
    assert summ["units_by_key"]["actuation.u_rate_max"] == "veh/s^2"
