"""The meter as the field runs it, in the real SUMO (libsumo), 120-140 s runs.

The legacy default's traffic (SumoConfig defaults: 4104 HV/h + 1560 AV/h, ramp 1200 veh/h,
step 0.1 s): the ramp demand exceeds every release rate used here, so a queue stands at
the meter after the first half minute.
"""

import numpy as np
import pytest

from arzsumo.model import get_preset
from arzsumo.sumo.config import SumoConfig
from arzsumo.sumo.meter_release import OnePerGreenMeter
from arzsumo.sumo.plant import SumoPlant
from arzsumo.sumo.simulation import open_simulation

pytestmark = pytest.mark.sumo

PARAMS = get_preset("paper_base").params
BASE = SumoConfig()
ONE = BASE.with_(meter_mode="one_per_green", meter_clearance=2.0)


class Metered:
    """A finished run's meter, with :meth:`summary` the meter's and its stop line's."""

    def __init__(self, plant: SumoPlant) -> None:
        self.plant = plant

    def summary(self) -> dict:
        return self.plant.meter_summary()

    def __getattr__(self, name: str):
        return getattr(self.plant.meter, name)


def run_meter(cfg: SumoConfig, horizon: float, commands=()) -> tuple[Metered, set[str]]:
    """Run ``horizon`` s with the meter of ``cfg``; ``commands``: (time s, rate veh/h)
    given to a one-per-green meter. Returns the meter and the light states SUMO showed."""
    todo = sorted(commands)
    with open_simulation(PARAMS, cfg.with_(horizon=horizon)) as sim:
        plant = SumoPlant(sim, PARAMS.length, cfg, measure=False)
        meter = plant.meter
        shown = set()
        while sim.time < horizon - 1e-9:
            while todo and sim.time >= todo[0][0] - 1e-9:
                meter.set_plan(todo.pop(0)[1] / 3600)
            plant.step()
            shown.add(sim.lib.trafficlight.getRedYellowGreenState("meter"))
    return Metered(plant), shown


def test_clearance_removes_the_emergency_stops_at_the_meter():
    plain, shown_plain = run_meter(BASE, 120.0)
    clear, shown_clear = run_meter(BASE.with_(meter_clearance=2.0), 120.0)
    a, b = plain.summary(), clear.summary()
    assert shown_plain == {"G", "r"} and shown_clear == {"G", "y", "r"}
    # without clearance every red catches the head vehicle: 1 stop, 17 braking in 120 s
    assert a["emergency_stops"] + a["emergency_braking"] >= 10
    assert b["emergency_stops"] == 0
    assert b["emergency_braking"] <= a["emergency_braking"] / 2        # measured 6 vs 17
    assert a["light_changes"] == b["light_changes"] == 40              # yellow not counted
    assert (a["clearance_s"], b["clearance_s"]) == (0.0, 2.0)


def test_one_per_green_releases_one_vehicle_per_green_without_emergency():
    meter, shown = run_meter(ONE, 120.0)
    s = meter.summary()
    done = meter.greens[:-1]                       # complete green intervals
    queued = [g for g in done if g.queue > 0]
    assert shown == {"G", "y", "r"} and s["mode"] == "one_per_green"
    assert max(g.releases for g in done) == 1 == s["releases_per_green_max"]
    assert len(queued) >= 10
    assert sum(g.releases == 1 for g in queued) >= 0.8 * len(queued)   # measured all
    assert s["releases"] == sum(g.releases for g in meter.greens) >= 10
    assert s["emergency_stops"] == 0 and s["emergency_braking"] == 0
    assert s["plan_changes"] == 0 and s["release_rate"] == pytest.approx(600 / 3600)


def test_one_per_green_cycles_follow_the_commanded_rate():
    meter, _ = run_meter(ONE, 140.0, [(30.0, 900.0), (70.0, 240.0)])
    assert isinstance(meter.plant.meter, OnePerGreenMeter)
    assert meter.plan_changes == 2
    dt = ONE.step_length
    for lo, hi, rate in ((33.0, 70.0, 900.0), (72.0, 140.0, 240.0)):
        cycles = [g for g in meter.greens[:-1] if lo <= g.start * dt < hi]
        lengths = np.array([g.length * dt for g in cycles])
        assert len(cycles) >= 3
        # cycle = 3600 / r; a green extended for a late head vehicle may stretch one
        assert np.median(lengths) == pytest.approx(3600 / rate, abs=dt / 2)
        assert np.mean(np.abs(lengths - 3600 / rate) < dt / 2) >= 0.8
        assert max(g.releases for g in cycles) == 1


def test_queue_override_forces_releases_in_both_modes():
    slow = [(0.0, 240.0)]                                   # release_rate_min: 15 s cycles
    plain, _ = run_meter(ONE, 120.0, slow)
    over, _ = run_meter(ONE.with_(ramp_storage=3), 120.0, slow)
    assert plain.summary()["override_steps"] == 0 and over.summary()["override_steps"] > 0
    assert plain.releases <= 120 / 15 + 1
    assert over.releases >= plain.releases + 5
    assert over.summary()["releases_per_green_max"] == 1
    # the fixed cycle at all red releases only under the override (green forced)
    red = BASE.with_(green_share=0.0, meter_clearance=2.0)
    held, _ = run_meter(red, 90.0)
    forced, shown = run_meter(red.with_(ramp_storage=3), 90.0)
    assert held.releases == 0 and held.summary()["override_steps"] == 0
    assert forced.releases > 0 and forced.summary()["override_steps"] > 0
    assert "y" in shown and forced.summary()["emergency_stops"] == 0
