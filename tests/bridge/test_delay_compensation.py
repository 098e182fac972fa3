"""Delay compensation in the closed loop with real SUMO: a short run of
``scenarios/legacy_default.toml`` (30 s warm-up, 30 s of control, seed 42), backstepping
with ``delay_compensation_s = 12`` and ``u_max_fraction = 0.1`` (so the U applied differs
from the law's); every command is recomputed here from the state the controller got."""

from __future__ import annotations

from pathlib import Path

import pytest

from arzsumo.bridge.cosim import run_cosimulation
from arzsumo.bridge.delay import compensate
from arzsumo.bridge.session import prepare_run
from arzsumo.control.backstepping import Backstepping
from arzsumo.control.base import MacroState
from arzsumo.control.predictor import committed, predict_riemann
from arzsumo.errors import ScenarioError
from arzsumo.kernel_cache import cached_kernels
from arzsumo.model.characteristic import linearize
from arzsumo.outputs.bridge import actuation_summary
from arzsumo.scenario import load_scenario
from tests.runs import SMALL_GRIDS, prepared

DEFAULT = Path(__file__).resolve().parents[2] / "scenarios" / "legacy_default.toml"
THETA = 12.0
CHANGES = {"actuation.delay_compensation_s": THETA, "actuation.u_max_fraction": 0.1}


@pytest.fixture(scope="module")
def cache(tmp_path_factory):
    with pytest.MonkeyPatch.context() as mp:
        mp.setenv("ARZSUMO_CACHE", str(tmp_path_factory.mktemp("cache")))
        yield


@pytest.fixture(scope="module")
def run(cache):
    return run_cosimulation(prepared(DEFAULT, {**CHANGES, **SMALL_GRIDS},
                                     controller="backstepping", warmup=30.0, horizon=30.0,
                                     seed=42))


def _law_on_prediction(res, k, delay, column="u_applied"):
    """U (veh/s) of control_law on the state of check k predicted ``delay`` s ahead with
    the U of ``column`` at the earlier checks, recomputed from the run's record."""
    lin = linearize(res.equilibrium)
    law = Backstepping(lin, cached_kernels(lin.system, res.settings.kernel_cells))
    sm, per, p = law.state_map, lin.u_bar_per_u, res.periods
    w_bar = sm.riemann(sm.deviations(MacroState(p["t"][k], res.x, *res.estimator.fields[k])))
    ahead = committed(p["t"][:k], p[column][:k] * per, p["t"][k], delay)
    return law.law.u_bar(predict_riemann(lin.system, sm.x, w_bar, delay, ahead)) / per


@pytest.mark.sumo
def test_command_is_the_law_on_the_predicted_state(run):
    p = run.periods
    assert p["t"].size == 30 and run.shift is None
    assert p["saturated"].sum() > 0                      # u_applied != u_raw somewhere
    checked = 0
    for k in (0, 5, 13, 20, 29):                         # k > 12: applied commands matter
        expected = _law_on_prediction(run, k, THETA)
        assert p["u_raw"][k] == pytest.approx(expected, rel=1e-9, abs=1e-12)
        if k > 0:
            plain = _law_on_prediction(run, k, 0.0)      # the law on the present state
            assert abs(p["u_raw"][k] - plain) > 1e-3 * max(abs(plain), 1e-3)
            checked += 1
        if k > 12:                                       # the meter's U, not the law's
            raw = _law_on_prediction(run, k, THETA, "u_raw")
            assert abs(p["u_raw"][k] - raw) > 1e-3 * abs(raw)
    assert checked == 4
    assert actuation_summary(run)["delay_compensation"] == THETA


def test_zero_delay_wraps_nothing_and_is_recorded_as_off():
    sc = load_scenario(DEFAULT)
    assert sc.actuation.delay_compensation == 0.0
    ctrl = object()
    assert compensate(ctrl, "backstepping", sc) is ctrl        # today's controller itself
    assert compensate(ctrl, "alinea", sc.with_(CHANGES)) is ctrl


@pytest.mark.parametrize(("changes", "message"), [
    ({"actuation.delay_compensation_s": 70},
     r"^.*legacy_default.toml: \[actuation\] delay_compensation_s = 70 is not allowed: a "
     r"dead time in \[0, 66.61\) s, shorter than L / max \|lambda\|"),
    ({"actuation.delay_compensation_s": -2},
     r"\[actuation\] delay_compensation_s = -2 is not allowed: a dead time >= 0 s"),
])
def test_bad_delay_is_refused_at_load(changes, message):
    with pytest.raises(ScenarioError, match=message) as info:
        load_scenario(DEFAULT).with_(changes)
    assert "\n" not in str(info.value)


def test_observer_etc_on_its_observer_is_refused_before_sumo():
    sc = load_scenario(DEFAULT).with_(CHANGES)
    with pytest.raises(ScenarioError, match=r"\[actuation\] delay_compensation_s = 12.0 is "
                                            r"not allowed with controller 'observer-etc'") as info:
        prepare_run(sc, controller="observer-etc")
    assert "\n" not in str(info.value)
    assert prepare_run(sc, controller="etc").scenario.actuation.delay_compensation == THETA
