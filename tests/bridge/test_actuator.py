"""limit_u and the actuator's ranges (issue 17): pure functions, known answers, properties."""

from __future__ import annotations

import math

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from arzsumo.bridge.actuator import ActuationLimits, limit_u, meter_range, ramp_floor
from arzsumo.scenario.actuation import ActuationSettings
from arzsumo.sumo.config import SumoConfig
from arzsumo.sumo.meter import DEFAULT_CURVE

FLOW = st.floats(-10.0, 10.0, allow_nan=False)
TOL = 1e-12


@settings(max_examples=400, deadline=None)
@given(u_raw=FLOW, u_prev=FLOW, lo=st.floats(0.0, 5.0), hi=st.floats(0.0, 5.0),
       rate=st.floats(1e-6, 5.0))
def test_output_lies_in_the_range_and_within_the_rate(u_raw, u_prev, lo, hi, rate):
    lower, upper = -lo, hi
    out = limit_u(u_raw, u_prev, lower, upper, rate)
    assert lower <= out.u_applied <= upper                  # the range always holds
    if lower <= u_prev <= upper:                            # the rate holds from inside it
        assert abs(out.u_applied - u_prev) <= rate + TOL
    if not lower <= u_raw <= upper:                         # the law beyond the range
        assert out.saturated
    if not out.saturated:                                   # only the rate may have acted
        assert out.u_applied == min(max(u_raw, u_prev - rate), u_prev + rate)
        assert out.rate_limited == (out.u_applied != u_raw)


@settings(max_examples=200, deadline=None)
@given(u_raw=st.floats(allow_nan=False, allow_infinity=False),
       u_prev=st.floats(allow_nan=False, allow_infinity=False))
def test_every_limit_off_is_the_identity(u_raw, u_prev):
    assert limit_u(u_raw, u_prev) == (u_raw, False, False)
    lim = ActuationLimits.of(ActuationSettings(), 1.24, DEFAULT_CURVE, SumoConfig())
    lower, upper = lim.range(queue=7)
    assert limit_u(u_raw, u_prev, lower, upper, lim.rate_step).u_applied == u_raw


@pytest.mark.parametrize(("args", "want"), [
    ((0.5, 0.0, -0.2, 0.2, 0.05), (0.05, True, True)),      # both act
    ((0.1, 0.0, -0.2, 0.2, 0.05), (0.05, False, True)),     # rate only
    ((-0.5, -0.2, -0.2, 0.2, 0.05), (-0.2, True, False)),   # range only
    ((0.0, -0.5, -0.2, 0.2, 0.05), (-0.2, True, True)),     # range moved: it wins over rate
    ((0.03, 0.0, -0.2, 0.2, 0.05), (0.03, False, False)),
])
def test_known_answers(args, want):
    got = limit_u(*args)
    assert got.u_applied == pytest.approx(want[0], abs=1e-15)
    assert (got.saturated, got.rate_limited) == want[1:]


def test_meter_range_is_the_curve_between_the_green_share_limits():
    q_nom = DEFAULT_CURVE.outflow_at(0.5)                    # 4464 veh/h
    lo, hi = meter_range(DEFAULT_CURVE, SumoConfig(), q_nom)
    assert (lo * 3600, hi * 3600) == pytest.approx((3240 - 4464, 5664 - 4464))
    cfg = SumoConfig(green_share_min=0.25, green_share_max=0.75)
    lo, hi = meter_range(DEFAULT_CURVE, cfg, q_nom)
    assert (lo * 3600, hi * 3600) == pytest.approx((3300 - 4464, 4512 - 4464))


def test_ramp_floor_allows_no_more_release_than_arrivals_and_queue():
    q_nom = DEFAULT_CURVE.outflow_at(0.5)
    # 5664 - 1200 - 4464 = 0 veh/h: with an empty queue U < 0 is not deliverable
    assert ramp_floor(DEFAULT_CURVE, SumoConfig(), q_nom, queue=0) == pytest.approx(0.0,
                                                                                   abs=1e-12)
    # 3 vehicles over one 6 s cycle: 0.5 veh/s more release, U >= -0.5 veh/s
    assert ramp_floor(DEFAULT_CURVE, SumoConfig(), q_nom, queue=3) == pytest.approx(-0.5)
    # a light ramp demand: the floor is capped at 0 (the nominal plan is always allowed)
    light = SumoConfig(ramp_demand=600 / 3600)
    assert ramp_floor(DEFAULT_CURVE, light, q_nom, queue=0) == 0.0


def test_limits_combine_fraction_meter_and_ramp():
    q_nom = DEFAULT_CURVE.outflow_at(0.5)
    cfg = SumoConfig()
    lim = ActuationLimits.of(ActuationSettings(u_max_fraction=0.5, u_rate_max=0.01,
                                               ramp_bound=True), q_nom, DEFAULT_CURVE, cfg)
    assert lim.rate_step == pytest.approx(0.01 * cfg.control_period)
    lo, hi = lim.range(queue=3)
    assert lo == pytest.approx(-(4464 - 3240) / 3600)       # meter: all green
    assert hi == pytest.approx((5664 - 4464) / 3600)        # meter: all red
    lo, hi = lim.range(queue=0)
    assert lo == pytest.approx(0.0, abs=1e-12) and math.isfinite(hi)
    tight = ActuationLimits.of(ActuationSettings(u_max_fraction=0.1), q_nom, DEFAULT_CURVE,
                               cfg)
    assert tight.range(queue=0) == pytest.approx((-0.1 * q_nom, 0.1 * q_nom))
    assert tight.rate_step == math.inf
