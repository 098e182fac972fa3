"""The outlet's speed limit as the actuator: the pure map from U to a limit, and a short
closed loop in real SUMO (``scenarios/legacy_default.toml``, 60 s warm-up, 60 s of
control, seed 42)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from arzsumo.bridge.cosim import run_cosimulation
from arzsumo.bridge.speed_actuator import limit_for, u_range
from arzsumo.outputs.bridge import write_results
from arzsumo.scenario.actuation import ActuationSettings
from tests.runs import SMALL_GRIDS, prepared

DEFAULT = Path(__file__).resolve().parents[2] / "scenarios" / "legacy_default.toml"
KMH = 1 / 3.6
#: 40 veh/h per km/h, 10-60 km/h in 1 km/h steps
SETTINGS = ActuationSettings(actuator="speed_limit", speed_limit_gain=0.04,
                             speed_limit_min=10 * KMH, speed_limit_max=60 * KMH,
                             speed_limit_step=1 * KMH)


@pytest.mark.parametrize(("u_veh_h", "limit_kmh"), [
    (0, 50), (400, 60), (-400, 40), (419, 60), (-419, 40), (61, 52), (-59, 49),
    (10_000, 60), (-10_000, 10)])
def test_limit_is_the_nominal_plus_u_over_the_gain_on_the_step_grid(u_veh_h, limit_kmh):
    assert limit_for(u_veh_h / 3600, 50 * KMH, SETTINGS) == pytest.approx(limit_kmh * KMH)


def test_continuous_limit_and_the_range_of_u():
    cont = ActuationSettings(actuator="speed_limit", speed_limit_gain=0.04,
                             speed_limit_min=10 * KMH, speed_limit_max=60 * KMH)
    assert limit_for(61 / 3600, 50 * KMH, cont) == pytest.approx((50 + 61 / 40) * KMH)
    lo, hi = u_range(50 * KMH, SETTINGS)
    assert (lo * 3600, hi * 3600) == pytest.approx((-1600, 400))
    lo, hi = u_range(50 * KMH, SETTINGS, u_max=300 / 3600)
    assert (lo * 3600, hi * 3600) == pytest.approx((-300, 300))


SPEED_LIMIT = {"actuation.actuator": "speed_limit",
               "actuation.speed_limit_gain_veh_h_per_kmh": 40,
               "actuation.speed_limit_min_kmh": 10, "actuation.speed_limit_max_kmh": 60,
               "actuation.speed_limit_step_kmh": 1, "actuation.u_rate_max_veh_h_s": 180}


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    with pytest.MonkeyPatch.context() as mp:
        mp.setenv("ARZSUMO_CACHE", str(tmp_path_factory.mktemp("cache")))
        return run_cosimulation(prepared(DEFAULT, {**SPEED_LIMIT, **SMALL_GRIDS},
                                         controller="backstepping", warmup=60.0,
                                         horizon=60.0, seed=42))


@pytest.mark.sumo
def test_the_law_drives_the_outlet_and_leaves_the_meter(run):
    p, nominal = run.periods, run.meter["speed_limit_nominal_m_s"]
    assert nominal == pytest.approx(50 * KMH, abs=2e-3)    # as the network file holds it
    v = p["speed_limit"]
    assert v.size == 60 and np.isfinite(v).all()
    # every limit on the 1 km/h grid about the nominal or at a bound of the range
    steps = (v - nominal) / KMH
    inside = (v > 10 * KMH) & (v < 60 * KMH)
    np.testing.assert_allclose(steps[inside], np.round(steps[inside]), atol=1e-9)
    assert v.min() >= 10 * KMH - 1e-9 and v.max() <= 60 * KMH + 1e-9
    # the U applied is what the limit realises on the linear map: anti-windup sees it
    np.testing.assert_allclose(p["u_applied"], 0.04 * (v - nominal), atol=1e-12)
    assert np.abs(np.diff(np.r_[0.0, p["u_applied"]])).max() <= 180 / 3600 + 1e-12
    # the law moved the limit, and the meter held its nominal plan
    changes = int(np.count_nonzero(np.diff(np.r_[nominal, v])))
    assert changes >= 5
    assert run.meter["plan_changes"] == 0
    assert run.meter["speed_limit_changes"] == changes


@pytest.mark.sumo
def test_summary_and_periods_carry_the_limit(run, tmp_path):
    path, _ = write_results(run, tmp_path / "run", "# test\n", plots=False)
    meter = json.loads((path / "summary.json").read_text())["meter"]
    assert meter["speed_limit_nominal_m_s"] == pytest.approx(50 * KMH, abs=2e-3)
    assert meter["speed_limit_changes"] == run.meter["speed_limit_changes"]
    import pyarrow.parquet as pq
    table = pq.read_table(path / "periods.parquet")
    np.testing.assert_array_equal(table.column("speed_limit").to_numpy(),
                                  run.periods["speed_limit"])
