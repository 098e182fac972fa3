"""The one open-loop driver, :meth:`SumoPlant.run_open_loop`: periods, the plan schedule,
the reads beside the sensor, and its refusals (real SUMO, short runs)."""

from __future__ import annotations

import numpy as np
import pytest

from arzsumo.model import get_preset
from arzsumo.sumo.config import SumoConfig
from arzsumo.sumo.network import MAIN, RAMP_UP
from arzsumo.sumo.period_reads import OpenLoopPeriod, OpenLoopReads
from arzsumo.sumo.plant import SumoPlant
from arzsumo.sumo.simulation import open_simulation

pytestmark = pytest.mark.sumo

PARAMS = get_preset("paper_base").params
FAST = SumoConfig(horizon=30.0, step_length=0.2, control_period=2.0,
                  ramp_demand=1200 / 3600)
ALL = OpenLoopReads(edges=(MAIN, RAMP_UP), ramp_passed=True, downstream_loop=True,
                    lateral=True)
NONE = OpenLoopReads()


def _run(cfg: SumoConfig, reads: OpenLoopReads = NONE, measure: bool = True,
         **kw) -> tuple[list[OpenLoopPeriod], object]:
    got: list[OpenLoopPeriod] = []
    with open_simulation(PARAMS, cfg) as sim:
        plant = SumoPlant(sim, PARAMS.length, cfg, measure=measure)
        end = plant.run_open_loop(on_period=got.append, reads=reads, **kw)
    return got, end


def test_periods_and_until_step_the_same_periods_and_the_hook_sees_each_end():
    by_count, end = _run(FAST, periods=7)
    by_time, _ = _run(FAST.with_(horizon=15.0), until=15.0)   # 7.5 periods: the half is cut
    assert [p.index for p in by_count] == list(range(7)) and end.periods == 7
    assert [p.t for p in by_count] == pytest.approx([2.0 * (k + 1) for k in range(7)])
    assert all(p.measurement is not None and p.measurement.t == p.t for p in by_count)
    for a, b in zip(by_count, by_time, strict=True):
        np.testing.assert_array_equal(a.measurement.cells.rho_h, b.measurement.cells.rho_h)
    assert end.lateral is None and end.approach is None and by_count[0].loop is None


def test_the_schedule_sets_each_plan_at_the_step_it_names():
    got, _ = _run(FAST, periods=6, plans=[(4.0, 0.2), (8.0, 0.9), (-1.0, 0.0)])
    assert [p.plan for p in got] == [None, None, 0.2, 0.2, 0.9, 0.9]
    # two requests, two plan changes (the one at t = -1 s had passed and never ran)
    assert got[-1].meter.plan_changes == 2


def test_reading_more_changes_no_number_and_hands_out_what_was_read():
    cfg = FAST.with_(horizon=60.0)     # the first ramp vehicles pass the meter at ~20 s
    plain, _ = _run(cfg, periods=30)
    more, end = _run(cfg, ALL, periods=30)
    quiet, _ = _run(cfg, OpenLoopReads(downstream_loop=True), measure=False, periods=30)
    for a, b, c in zip(plain, more, quiet, strict=True):
        for field in ("rho_h", "rho_a", "v_h", "v_a"):
            np.testing.assert_array_equal(getattr(a.measurement.cells, field),
                                          getattr(b.measurement.cells, field))
        assert a.meter == b.meter == c.meter and a.releases == b.releases
        # the loop as the measuring sensor reads it, without the sensor
        assert c.measurement is None
        assert c.loop == (b.measurement.occupancy_out, b.measurement.flow_out_loop)
    assert all(p.vehicles.keys() == {MAIN, RAMP_UP} for p in more)
    assert end.lateral is not None
    assert end.lateral.counts.tolist() == [p.vehicles[MAIN] for p in more]
    # vehicles new on ramp_dn, period by period: those the stop line released, a step later
    assert 0 < sum(p.ramp_passed for p in more) <= more[-1].releases


@pytest.mark.parametrize(("kw", "match"), [
    ({}, "periods or until, one of the two"),
    ({"periods": 2, "until": 4.0}, "periods or until, one of the two"),
    ({"periods": 2, "green_shares": True}, "green_shares needs the fixed-cycle meter"),
])
def test_a_run_it_cannot_make_is_refused(kw, match):
    cfg = FAST.with_(meter_mode="one_per_green") if kw.get("green_shares") else FAST
    with open_simulation(PARAMS, cfg) as sim:
        plant = SumoPlant(sim, PARAMS.length, cfg)
        with pytest.raises(ValueError, match=match):
            plant.run_open_loop(**kw)


def test_a_run_starts_at_a_period_boundary():
    with open_simulation(PARAMS, FAST) as sim:
        plant = SumoPlant(sim, PARAMS.length, FAST)
        plant.step()
        with pytest.raises(ValueError, match="starts at a period's boundary; the plant is 1"):
            plant.run_open_loop(periods=1)
