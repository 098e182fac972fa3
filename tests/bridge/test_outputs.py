"""Results of a run: the meter counts of summary.json cover the control window only.

The light and plan changes are recomputed from ``periods.parquet`` (the green shares
commanded and running per period) with the meter's cycle rule, step by step, from
SUMO's t = 0: the warm-up's changes must appear under ``warmup`` and not in the
control window's counts.
"""

import json
from itertools import pairwise
from pathlib import Path

import numpy as np
import pyarrow.parquet as pq
import pytest

from arzsumo.bridge.cosim import run_cosimulation
from arzsumo.outputs.bridge import write_results
from arzsumo.scenario import load_scenario
from arzsumo.sumo.calibrate import run_fixed_meter
from arzsumo.sumo.green_share import plan_green_steps
from tests.runs import SMALL_GRIDS, prepared

DEFAULT = Path(__file__).resolve().parents[2] / "scenarios" / "legacy_default.toml"
WARMUP, HORIZON = 30.0, 30.0
pytestmark = pytest.mark.sumo


@pytest.fixture(scope="module")
def result(tmp_path_factory):
    with pytest.MonkeyPatch.context() as mp:
        mp.setenv("ARZSUMO_CACHE", str(tmp_path_factory.mktemp("cache")))
        run = prepared(DEFAULT, SMALL_GRIDS, controller="backstepping", warmup=WARMUP,
                       horizon=HORIZON, seed=1)
        res = run_cosimulation(run)
        path, _ = write_results(res, tmp_path_factory.mktemp("run") / "bs", "# test\n",
                                plots=False)
    summ = json.loads((path / "summary.json").read_text())
    return run.sumo, pq.read_table(path / "periods.parquet").to_pandas(), summ


def _nominal(cfg) -> int:
    """Green steps per cycle of the nominal plan (the warm-up's)."""
    dt = cfg.step_length
    return plan_green_steps(cfg.green_share, round(cfg.meter_cycle / dt),
                            round(cfg.min_green / dt), round(cfg.min_red / dt))


def _light_per_step(cfg, periods) -> tuple[np.ndarray, int]:
    """The light (True = green) at SUMO steps 0..end, rebuilt from the running plans.

    The meter refreshes its plan at steps n with n % C == 0 (C steps per cycle) and shows
    green while n % C < green steps; ``green_running`` is the plan after each period's
    last step. Returns the lights and the step at which control starts.
    """
    dt, p = cfg.step_length, cfg.steps_per_period
    c, nominal = round(cfg.meter_cycle / dt), _nominal(cfg)
    w = round(WARMUP / dt)
    ends = w + p * (np.arange(len(periods)) + 1)
    plans: dict[int, int] = {m: nominal for m in range(w // c + 1)}   # warm-up: nominal
    for end, g in zip(ends, periods["green_running"], strict=True):
        steps = round(g * c)
        assert plans.setdefault(end // c, steps) == steps     # one plan per cycle
    n = np.arange(ends[-1] + 1)
    green = np.array([k % c < plans[k // c] for k in n])
    green[0] = nominal > 0                                    # the light set at creation
    return green, w


def test_light_and_plan_changes_are_those_of_the_control_window(result):
    cfg, periods, summ = result
    assert len(periods) == HORIZON / cfg.control_period
    green, w = _light_per_step(cfg, periods)
    switches = np.flatnonzero(green[1:] != green[:-1]) + 1    # steps at which it changed
    in_window = int(np.sum(switches > w))
    in_warmup = int(np.sum(switches <= w))
    assert summ["light_changes"] == in_window
    assert summ["warmup"]["light_changes"] == in_warmup == WARMUP / cfg.meter_cycle * 2
    assert summ["light_changes"] > 0 and summ["light_changes"] != in_window + in_warmup
    assert periods["light_changes"].iloc[-1] == summ["light_changes"]   # cumulative from 0

    c = round(cfg.meter_cycle / cfg.step_length)
    pending = [_nominal(cfg)] + [round(g * c) for g in periods["green_commanded"]]
    assert summ["plan_changes"] == sum(a != b for a, b in pairwise(pending))
    assert summ["plan_changes"] > 0 and summ["warmup"]["plan_changes"] == 0
    assert periods["plan_changes"].iloc[-1] == summ["plan_changes"]
    assert periods["plan_changes"].iloc[0] == (pending[1] != pending[0])


def test_queue_maximum_of_the_window_and_the_warmup_apart(result):
    cfg, periods, summ = result
    assert summ["max_ramp_queue"] == periods["max_queue"].iloc[-1]
    assert summ["max_ramp_queue"] >= periods["queue"].max()
    assert np.all(np.diff(periods["max_queue"]) >= 0)
    warm = summ["warmup"]
    assert warm["duration_s"] == WARMUP
    # the warm-up is the nominal plan from t = 0: an open-loop run of its length, same seed
    alone = run_fixed_meter(load_scenario(DEFAULT).params, cfg.with_(horizon=WARMUP)).meter
    assert warm["max_ramp_queue"] == alone["max_queue"] > 0
    assert (warm["light_changes"], warm["plan_changes"]) == (alone["light_changes"], 0)
    assert "not in the top-level" in warm["window"]
    assert summ["kind"] == "run" and summ["horizon"] == HORIZON
