"""The [actuation] ranges of a one-per-green meter: U = r_nominal - r (no SUMO)."""

import pytest

from arzsumo.sumo.config import SumoConfig
from arzsumo.sumo.meter_release import one_per_green_ramp_floor, one_per_green_u_range

ONE = SumoConfig(meter_mode="one_per_green")      # 600 veh/h nominal, 240..900 veh/h


def test_one_per_green_range_is_the_release_rate_bounds():
    lo, hi = one_per_green_u_range(ONE)
    assert lo == pytest.approx((600 - 900) / 3600) and hi == pytest.approx((600 - 240) / 3600)


def test_one_per_green_ramp_floor_counts_arrivals_and_queue():
    # ramp demand 1200 veh/h, nominal cycle 6 s: floor = (600 - 1200) / 3600 - queue / 6
    assert one_per_green_ramp_floor(ONE, 0) == pytest.approx(-600 / 3600)
    assert one_per_green_ramp_floor(ONE, 3) == pytest.approx(-600 / 3600 - 0.5)
    assert one_per_green_ramp_floor(ONE.with_(ramp_demand=0.1), 0) == 0.0
