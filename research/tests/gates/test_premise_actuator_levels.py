"""The actuator gate's level estimator on synthetic staircases (0, +1, 0, -1, ... steps of
the release rate) whose gains per side of the nominal rate are known."""

import math

import numpy as np
import pytest
from arzsumo_studies.gates import ActuatorRecord, PremiseError, actuator_gate
from arzsumo_studies.gates.actuator_levels import hold_levels, side_fit
from arzsumo_studies.measures.step_response import fopdt_response

STEP = 200.0 / 3600.0
BASE_RATE, BASE_FLOW = 600.0 / 3600.0, 1.07
PATTERN = (0, 1, 0, -1)


def _staircase(k_up: float, k_down: float, hold: float = 120.0, levels: int = 8,
               noise: float = 0.0, seed: int = 0, offset: float = 0.0,
               delay: float = 8.0, tau: float = 5.0) -> ActuatorRecord:
    """q(L) answering the premise's staircase (lead-in, then +, 0, -, 0, ...): above the
    nominal rate q = q0 + k_up (r - r0), below it q0 + k_down (r - r0), reached through
    a first order plus dead time response; per-second Gaussian counting noise."""
    sides = [0] + [PATTERN[(k + 1) % 4] for k in range(levels)]
    t = np.arange(1.0, hold * len(sides) + 1.0)
    times = tuple(hold * (i + 1) for i in range(levels))
    r = np.full(t.size, BASE_RATE)
    q = np.full(t.size, BASE_FLOW + offset)
    level_q = [(k_up if s > 0 else k_down) * s * STEP for s in sides]
    for i, t0 in enumerate(times):
        r[t > t0] += (sides[i + 1] - sides[i]) * STEP
        q += fopdt_response(t, 0.0, 1.0, level_q[i + 1] - level_q[i], t0, delay, tau,
                            bin_width=1.0)
    q += np.random.default_rng(seed).normal(0.0, noise, t.size)
    return ActuatorRecord(t, q, r, times)


def test_levels_recover_each_sides_gain_and_pass_a_unit_meter():
    g = actuator_gate(_staircase(-1.0, -1.0))
    assert g.passed and g.detail["estimator"] == "levels"
    for side in ("up", "down"):
        fit = g.detail["levels"][side]
        # the level starts 30 s after its step: the response's tail exp(-22 / 5) is left
        assert fit["gain"] == pytest.approx(-1.0, abs=2e-3)
        assert fit["levels"] == 7 and fit["passed"]        # 5 nominal + 2 on the side
        assert fit["gain_high"] - fit["gain_low"] < 1e-2
    # a longer settling time is held to half the hold (60 s): the tail exp(-52 / 5)
    settled = actuator_gate(_staircase(-1.0, -1.0), settle_s=90.0).detail["levels"]
    assert settled["up"]["gain"] == pytest.approx(-1.0, abs=1e-5)


def test_a_meter_that_moves_the_outflow_one_way_fails_on_that_side():
    g = actuator_gate(_staircase(k_up=-1.0, k_down=-0.12))
    assert not g.passed and g.value == pytest.approx(-0.12, abs=2e-3)
    assert g.detail["levels"]["up"]["passed"]
    assert not g.detail["levels"]["down"]["passed"]


def test_each_seeds_own_operating_point_is_its_own_intercept():
    recs = [_staircase(-0.9, -0.9, offset=o) for o in (-0.2, 0.0, 0.3)]
    g = actuator_gate(recs)
    assert g.detail["levels"]["up"]["records"] == 3
    assert g.detail["levels"]["up"]["gain"] == pytest.approx(-0.9, abs=2e-3)
    assert g.detail["levels"]["up"]["gain_high"] - g.detail["levels"]["up"]["gain_low"] \
        < 1e-2
    # one intercept for all reads the seeds' offsets as noise: an interval 8 wide
    q, r = (np.concatenate(a) for a in zip(*[hold_levels(x.t, x.q, x.r, x.step_times)
                                             for x in recs], strict=True))
    pooled = side_fit([(q, r)], "up")
    assert pooled.gain_high - pooled.gain_low > 1.0


def test_the_interval_covers_the_true_gain_about_95_percent_of_the_time():
    hits = []
    for s in range(200):
        fit = actuator_gate([_staircase(-1.0, -1.0, noise=0.8, seed=100 * s + k)
                             for k in range(3)]).detail["levels"]["up"]
        hits.append(fit["gain_low"] <= -1.0 <= fit["gain_high"])
    assert 0.90 <= np.mean(hits) <= 0.99


def test_levels_are_narrower_than_pooled_steps_on_the_same_counts():
    """Each level averages its hold after 30 s (210 s of a 240 s hold), each step's level
    only the hold's last 60 s: intervals about sqrt(60 / 210) as wide, less the per-step
    pooling's own gain from sharing levels."""
    widths = {"levels": [], "steps": []}
    for s in range(30):
        recs = [_staircase(-1.0, -1.0, hold=240.0, noise=0.8, seed=1000 * s + k)
                for k in range(3)]
        lv = actuator_gate(recs).detail["levels"]["up"]
        st = actuator_gate(recs, estimator="steps").detail["up"]
        widths["levels"].append(lv["gain_high"] - lv["gain_low"])
        widths["steps"].append(st["gain_high"] - st["gain_low"])
    assert np.median(widths["levels"]) < 0.7 * np.median(widths["steps"])


def test_too_few_levels_give_no_interval_and_fail():
    g = actuator_gate(_staircase(-1.0, -1.0, levels=1))     # lead-in, +: no '-' side
    assert math.isnan(g.detail["levels"]["down"]["gain"])
    up = g.detail["levels"]["up"]            # 2 levels, 1 intercept: no residual left
    assert up["gain"] == pytest.approx(-1.0, abs=2e-3) and math.isnan(up["gain_low"])
    assert not g.passed


def test_a_settling_time_longer_than_a_hold_keeps_the_holds_second_half():
    rec = _staircase(-1.0, -1.0, hold=40.0, delay=2.0, tau=1.0)
    q, _ = hold_levels(rec.t, rec.q, rec.r, rec.step_times, settle_s=200.0)
    assert len(q) == 9 and actuator_gate(rec).detail["levels"]["up"]["gain"] == \
        pytest.approx(-1.0, abs=1e-6)
    with pytest.raises(PremiseError, match="estimator = 'mean' is not allowed"):
        actuator_gate(_staircase(-1.0, -1.0), estimator="mean")


@pytest.mark.parametrize(("low", "high", "want"), [
    (-1.2, -0.8, "inside"),            # in the range and narrow enough
    (-1.25, -0.6, "unresolved"),       # straddles the range's upper end
    (-2.87, -1.66, "outside"),         # the default's up side: wide, but resolved
    (-0.5, 0.4, "outside"),            # no effect at all is outside too
    (float("nan"), -1.0, "unresolved"),
])
def test_an_interval_outside_the_range_resolves_the_gate_however_wide(low, high, want):
    from arzsumo_studies.gates.actuator import verdict
    from arzsumo_studies.gates.gates import PremiseThresholds
    assert verdict(low, high, PremiseThresholds()) == want
