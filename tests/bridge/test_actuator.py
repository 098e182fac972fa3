"""limit_u, the actuator's ranges and its one saturation of the meter's plan: pure
functions, known answers, properties (no SUMO: a meter of the realisations' pure rules)."""

from __future__ import annotations

import itertools
import math

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from arzsumo.bridge.actuator import ActuationLimits, MeterActuator, command_meter, limit_u
from arzsumo.scenario.actuation import ActuationSettings
from arzsumo.sumo.config import SumoConfig
from arzsumo.sumo.green_share import DEFAULT_CURVE, fixed_cycle_ramp_floor, fixed_cycle_u_range
from arzsumo.sumo.meter_release import (
    one_per_green_ramp_floor,
    one_per_green_u_range,
    release_rate_for,
)

FLOW = st.floats(-10.0, 10.0, allow_nan=False)
TOL = 1e-12


class _Meter:
    """A meter's interface without SUMO, from the realisations' pure rules; the queue
    override as told."""

    def __init__(self, cfg: SumoConfig, override: bool = False, queue: int = 50) -> None:
        self.cfg, self.on, self.queue, self.green_share = cfg, override, queue, 0.2
        self.release_rate = cfg.release_rate if self.one else None
        self.planned: list[float] = []

    @property
    def one(self) -> bool:
        return self.cfg.meter_mode == "one_per_green"

    def override(self) -> bool:
        return self.on

    def override_u(self, q_nominal: float) -> float:
        return self.cfg.release_rate - self.cfg.release_rate_max

    def plan_for(self, u: float, q_nominal: float) -> float:
        if self.one:
            return release_rate_for(u, self.cfg)
        return DEFAULT_CURVE.green_share_for(q_nominal + u)

    @property
    def plan_bounds(self) -> tuple[float, float]:
        if self.one:
            return self.cfg.release_rate_min, self.cfg.release_rate_max
        return self.cfg.green_share_min, self.cfg.green_share_max

    def set_plan(self, plan: float) -> float:
        lo, hi = self.plan_bounds
        assert lo <= plan <= hi
        self.planned.append(plan)
        return 0.2

    def u_range(self, q_nominal: float) -> tuple[float, float]:
        if self.one:
            return one_per_green_u_range(self.cfg)
        return fixed_cycle_u_range(DEFAULT_CURVE, self.cfg, q_nominal)

    def ramp_floor(self, queue: float, q_nominal: float) -> float:
        if self.one:
            return one_per_green_ramp_floor(self.cfg, queue)
        return fixed_cycle_ramp_floor(DEFAULT_CURVE, self.cfg, q_nominal, queue)


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
    lim = ActuationLimits.of(ActuationSettings(), 1.24, SumoConfig().control_period)
    lower, upper = lim.range(_Meter(SumoConfig(), queue=7), 1.24)
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
    lo, hi = fixed_cycle_u_range(DEFAULT_CURVE, SumoConfig(), q_nom)
    assert (lo * 3600, hi * 3600) == pytest.approx((3240 - 4464, 5664 - 4464))
    cfg = SumoConfig(green_share_min=0.25, green_share_max=0.75)
    lo, hi = fixed_cycle_u_range(DEFAULT_CURVE, cfg, q_nom)
    assert (lo * 3600, hi * 3600) == pytest.approx((3300 - 4464, 4512 - 4464))


def test_ramp_floor_allows_no_more_release_than_arrivals_and_queue():
    q_nom = DEFAULT_CURVE.outflow_at(0.5)
    # 5664 - 1200 - 4464 = 0 veh/h: with an empty queue U < 0 is not deliverable
    floor = fixed_cycle_ramp_floor
    assert floor(DEFAULT_CURVE, SumoConfig(), q_nom, queue=0) == pytest.approx(0.0, abs=1e-12)
    # 3 vehicles over one 6 s cycle: 0.5 veh/s more release, U >= -0.5 veh/s
    assert floor(DEFAULT_CURVE, SumoConfig(), q_nom, queue=3) == pytest.approx(-0.5)
    # a light ramp demand: the floor is capped at 0 (the nominal plan is always allowed)
    light = SumoConfig(ramp_demand=600 / 3600)
    assert floor(DEFAULT_CURVE, light, q_nom, queue=0) == 0.0


def test_limits_combine_fraction_meter_and_ramp():
    q_nom = DEFAULT_CURVE.outflow_at(0.5)
    cfg = SumoConfig()
    lim = ActuationLimits.of(ActuationSettings(u_max_fraction=0.5, u_rate_max=0.01,
                                               ramp_bound=True), q_nom, cfg.control_period)
    assert lim.rate_step == pytest.approx(0.01 * cfg.control_period)
    lo, hi = lim.range(_Meter(cfg, queue=3), q_nom)
    assert lo == pytest.approx(-(4464 - 3240) / 3600)       # meter: all green
    assert hi == pytest.approx((5664 - 4464) / 3600)        # meter: all red
    lo, hi = lim.range(_Meter(cfg, queue=0), q_nom)
    assert lo == pytest.approx(0.0, abs=1e-12) and math.isfinite(hi)
    tight = ActuationLimits.of(ActuationSettings(u_max_fraction=0.1), q_nom,
                               cfg.control_period)
    assert tight.range(_Meter(cfg, queue=0), q_nom) == pytest.approx((-0.1 * q_nom,
                                                                      0.1 * q_nom))
    assert tight.rate_step == math.inf


def test_the_queue_override_is_a_saturation_the_law_sees():
    cfg = SumoConfig(meter_mode="one_per_green")
    limits = ActuationLimits.of(ActuationSettings(u_max_fraction=0.2, u_rate_max=0.01,
                                                  ramp_bound=True), 1.2, cfg.control_period)
    forced = MeterActuator(_Meter(cfg, override=True), 1.2, False, limits)
    act = forced.apply(0.05)                 # the law asks for less release
    assert act.u_applied == pytest.approx((600 - 900) / 3600)   # the largest release
    assert act.saturated and act.lower == act.upper == act.u_applied
    assert not act.rate_limited             # the override is not slowed by the rate limit
    free = MeterActuator(_Meter(cfg, override=False), 1.2, False, limits)
    act = free.apply(0.05)
    assert act.u_applied == pytest.approx(0.01) and act.rate_limited   # rate from U = 0


@pytest.mark.parametrize(("mode", "u", "plan"), [
    ("one_per_green", 0.0, 600 / 3600),
    ("one_per_green", -1.0, 900 / 3600),        # more release than the meter has: its max
    ("one_per_green", 1.0, 240 / 3600),         # less: its least rate
    ("fixed_cycle", 0.0, 0.5),
    ("fixed_cycle", 10.0, 0.25),                # more outflow than the curve: least green
    ("fixed_cycle", -10.0, 0.75),
])
def test_the_meter_plan_is_saturated_once_to_its_bounds(mode, u, plan):
    cfg = SumoConfig(meter_mode=mode, green_share_min=0.25, green_share_max=0.75)
    meter = _Meter(cfg)
    command_meter(meter, u, DEFAULT_CURVE.outflow_at(0.5))
    assert meter.planned == [pytest.approx(plan)]


def test_a_held_u_keeps_its_plan_until_the_moving_range_leaves_it():
    # one per green with the ramp bound: the floor moves with the queue (one vehicle is
    # 1/30 veh/s over a 30 s period). A law holds U = -0.08 veh/s; where the floor is
    # above it the plan is clipped to the floor. With hold_plan_in_range the plan stays
    # while it lies in the range and moves only when the floor passes it; without, every
    # move of the floor moves the plan.
    cfg = SumoConfig(meter_mode="one_per_green", ramp_demand=500 / 3600, control_period=30)
    queues = [4, 3, 4, 4, 2, 1, 3]
    plans = {}
    for hold in (False, True):
        meter = _Meter(cfg, queue=queues[0])
        limits = ActuationLimits.of(ActuationSettings(ramp_bound=True,
                                                      hold_plan_in_range=hold), 1.0, 30.0)
        act = MeterActuator(meter, 1.0, False, limits)
        applied = []
        for q in queues:
            meter.queue = q
            applied.append(act.apply(-0.08).u_applied)
        plans[hold] = applied
    lower = [max(one_per_green_u_range(cfg)[0], one_per_green_ramp_floor(cfg, q))
             for q in queues]
    assert plans[False] == pytest.approx([max(-0.08, f) for f in lower])
    want = [-0.08, lower[1], lower[1], lower[1], lower[4], lower[5], lower[5]]
    assert plans[True] == pytest.approx(want)
    changes = {h: sum(a != b for a, b in itertools.pairwise(p)) for h, p in plans.items()}
    assert changes == {False: 5, True: 3}


def test_a_held_u_still_completes_its_rate_limited_approach():
    cfg = SumoConfig(meter_mode="one_per_green")
    limits = ActuationLimits.of(ActuationSettings(u_rate_max=0.05, hold_plan_in_range=True),
                                1.0, 1.0)
    act = MeterActuator(_Meter(cfg), 1.0, False, limits)
    got = [act.apply(0.12).u_applied for _ in range(4)]
    assert got == pytest.approx([0.05, 0.10, 0.12, 0.12])
