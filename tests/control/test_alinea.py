"""ALINEA and PI-ALINEA arithmetic: known rates, anti-windup by clamping, one change per period."""

from __future__ import annotations

import math

import numpy as np
import pytest

from arzsumo.control.alinea import (
    GAIN_70,
    Alinea,
    AlineaSettings,
    HeldMeter,
    PiAlinea,
    ReleaseRates,
    alinea_step,
    pi_alinea_step,
)
from arzsumo.control.base import MacroState
from arzsumo.errors import ScenarioError

H = 3600.0
RATES = ReleaseRates(600 / H, 240 / H, 900 / H)
X, ONE = np.array([25.0]), np.ones(1)


def _state(t: float, occ: float) -> MacroState:
    return MacroState(t, X, ONE, ONE, ONE, ONE, occupancy_out=occ)


def _feed(ctrl: Alinea, occupancies: list[float], start: float = 0.0) -> list[float]:
    """U after each 1 s check, occupancy ``occupancies[k]`` at check k."""
    return [ctrl.check(_state(start + k, o)) for k, o in enumerate(occupancies)]


def test_gain_is_scaled_with_the_period():
    s = AlineaSettings(period=40.0)
    assert pytest.approx(70 * 100 / H) == GAIN_70                   # veh/s per unit occ.
    assert s.scaled(s.gain) * H / 100 == pytest.approx(70 * 40 / 60)  # 46.7 veh/h per %
    assert AlineaSettings(period=60.0).scaled(GAIN_70) == pytest.approx(GAIN_70)


def test_alinea_known_sequence_gives_known_rates():
    s = AlineaSettings(period=20.0, target=0.20, gain=GAIN_70, gain_period=20.0)
    ctrl = Alinea(s, RATES, check_period=1.0)
    # three periods of 20 checks: mean occupancies 0.25, 0.22, 0.16
    occ = [0.25] * 20 + [0.20, 0.24] * 10 + [0.16] * 20
    u = np.array(_feed(ctrl, occ))
    r = RATES.nominal - u
    # r(1) = 600 + 70 (20 - 25) = 250; r(2) = 250 + 70 (20 - 22) = 110 -> 240 (clamped);
    # r(3) = 240 + 70 (20 - 16) = 520
    assert np.allclose(r[:19] * H, 600)
    assert np.allclose(r[19:39] * H, 250)
    assert np.allclose(r[39:59] * H, 240)
    assert r[59] * H == pytest.approx(520)
    assert ctrl.log.extra["occupancy_mean"][19] == pytest.approx(0.25)
    assert ctrl.log.extra["occupancy_mean"][39] == pytest.approx(0.22)


def test_pi_alinea_known_sequence_gives_known_rates():
    kp, ki = 60 * 100 / H, 5 * 100 / H                    # 60 and 5 veh/h per %
    s = AlineaSettings(period=20.0, target=0.20, kp=kp, ki=ki, gain_period=20.0)
    ctrl = PiAlinea(s, RATES, check_period=1.0)
    r = RATES.nominal - np.array(_feed(ctrl, [0.25] * 20 + [0.30] * 20 + [0.28] * 20))
    # first update: o(k-1) = o(k): r = 600 + 5 (20 - 25) = 575
    # then r = 575 - 60 (30 - 25) + 5 (20 - 30) = 225 -> 240; then 240 - 60 (28 - 30) +
    # 5 (20 - 28) = 320
    assert r[19] * H == pytest.approx(575)
    assert r[39] * H == pytest.approx(240)
    assert r[59] * H == pytest.approx(320)
    assert pi_alinea_step(0.1, 0.3, 0.25, 0.2, kp, ki, 0.0, 1.0) == pytest.approx(
        0.1 - kp * 0.05 + ki * (-0.1))


def test_clamping_the_state_is_anti_windup():
    lo, hi = RATES.low, RATES.high
    r = RATES.nominal
    rates = []
    errors = [-0.1] * 5 + [0.01, 0.01]        # o above target for five periods, then below
    for e in errors:
        r = alinea_step(r, 0.2 - e, 0.2, GAIN_70, lo, hi)
        rates.append(r)
    assert rates[1:5] == [lo] * 4              # held at the bound, not wound below it
    # the first update after the error changes sign leaves the bound at once
    assert rates[5] == pytest.approx(lo + GAIN_70 * 0.01) and rates[5] > lo
    # the same with a range the actuator imposed (anti-windup on the applied U)
    s = AlineaSettings(period=20.0, target=0.2, gain_period=20.0)
    ctrl = Alinea(s, RATES)
    _feed(ctrl, [0.1] * 20)                    # too free: r rises
    ctrl.applied(0.0, RATES.nominal - 700 / H, math.inf)       # meter can give <= 700
    _feed(ctrl, [0.1] * 20, start=20)
    assert ctrl.rate * H == pytest.approx(700)
    _feed(ctrl, [0.21] * 20, start=40)          # error changes sign: leaves the cap
    assert ctrl.rate * H == pytest.approx(700 - 70 * 1)


def test_command_changes_at_most_once_per_period_with_1s_checks():
    rng = np.random.default_rng(3)
    s = AlineaSettings(period=40.0, target=0.2)
    for cls in (Alinea, PiAlinea):
        ctrl = cls(s, RATES, check_period=1.0)
        u = np.array(_feed(ctrl, list(0.2 + 0.1 * rng.standard_normal(200))))
        changes = np.flatnonzero(np.diff(u) != 0) + 1
        assert changes.size >= 3
        assert np.all(np.diff(changes) >= 40)          # at most once per 40 s
        assert np.all((changes + 1) % 40 == 0)          # at the period's last check
        assert sum(ctrl.log.triggered) == changes.size


def test_missing_samples_are_skipped_and_a_silent_period_holds():
    s = AlineaSettings(period=20.0, target=0.2, gain_period=20.0)
    ctrl = Alinea(s, RATES)
    u = _feed(ctrl, [math.nan] * 20 + [math.nan] * 10 + [0.22] * 10)
    assert u[19] == 0.0                                   # no sample: rate kept
    assert (RATES.nominal - u[39]) * H == pytest.approx(600 - 70 * 2)   # mean of 10


def test_held_meter_and_settings_validation():
    held = HeldMeter(RATES)
    assert [held.check(_state(k, 0.3)) for k in range(3)] == [pytest.approx(360 / H)] * 3
    with pytest.raises(ScenarioError, match="period"):
        AlineaSettings(period=10.0)
    with pytest.raises(ScenarioError, match="loop_distance"):
        AlineaSettings(loop_distance=350.0)
    with pytest.raises(ScenarioError, match="whole multiple"):
        Alinea(AlineaSettings(period=20.5), RATES, check_period=1.0)
