"""limit_u and the actuator's ranges: pure functions, known answers, properties."""

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


class _Meter:
    """A one-per-green meter's interface without SUMO: the override as told."""

    def __init__(self, cfg: SumoConfig, override: bool) -> None:
        self.cfg, self.on, self.queue, self.green_share = cfg, override, 50, 0.2
        self.commanded: list[float] = []

    def override(self) -> bool:
        return self.on

    def override_u(self, q_nominal: float) -> float:
        return self.cfg.release_rate - self.cfg.release_rate_max

    def command(self, u: float, q_nominal: float) -> float:
        self.commanded.append(u)
        return 0.2


def test_the_queue_override_is_a_saturation_the_law_sees():
    from arzsumo.bridge.actuator import MeterActuator

    cfg = SumoConfig(meter_mode="one_per_green")
    limits = ActuationLimits.of(ActuationSettings(u_max_fraction=0.2, u_rate_max=0.01,
                                                  ramp_bound=True), 1.2, DEFAULT_CURVE, cfg)
    forced = MeterActuator(_Meter(cfg, override=True), 1.2, False, limits)
    act = forced.apply(0.05)                 # the law asks for less release
    assert act.u_applied == pytest.approx((600 - 900) / 3600)   # the largest release
    assert act.saturated and act.lower == act.upper == act.u_applied
    assert not act.rate_limited             # the override is not slowed by the rate limit
    free = MeterActuator(_Meter(cfg, override=False), 1.2, False, limits)
    act = free.apply(0.05)
    assert act.u_applied == pytest.approx(0.01) and act.rate_limited   # rate from U = 0
