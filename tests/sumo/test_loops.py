"""Loop stations and AV probes in the real SUMO, checked against vehicle positions.

Two short runs, each started congested (vehicles placed at 60 + 30 veh/km and 8 m/s on
``main``, so that loops see queues, vehicles standing on them, vehicles placed across
them and HVs passing side by side), with loops every 250 m (stations at 6, 250, 500, 750
and 999.9 m) and every AV as a probe:

* ``insert``: ``scenarios/legacy_default.toml``, 60 s: mainline vehicles inserted at
  x = 0, in front of the station at 0+;
* ``approach``: ``scenarios/lateral_files.toml`` with a 100 m approach edge, 40 s: mainline
  vehicles enter ``main`` through the junction from the approach.

The reference follows every vehicle on ``main`` after every step, and on until its back
has left ``main`` (through the junction onto ``merge``).
"""

from dataclasses import dataclass, field

import numpy as np
import pytest

from arzsumo.errors import ScenarioError
from arzsumo.scenario import load_scenario, scenario_from_dict
from arzsumo.sumo.loops import INLET_GAP, V_MIN, LoopSensor, placed_positions, speed_means
from arzsumo.sumo.network import MAIN
from arzsumo.sumo.placement import place_vehicles
from arzsumo.sumo.probes import AvProbes
from arzsumo.sumo.sensing import SensorLayout
from arzsumo.sumo.sensor import SumoSensor
from arzsumo.sumo.simulation import open_simulation
from arzsumo.sumo.vtypes import AV_TYPE, MAX_LENGTH

pytestmark = pytest.mark.sumo

SCENARIO = load_scenario("scenarios/lateral_files.toml")   # the counts were set on it
PARAMS = SCENARIO.params
LEGACY = load_scenario("scenarios/legacy_default.toml")
CASES = {"insert": (LEGACY.params, LEGACY.sumo.with_(horizon=60.0)),
         "approach": (PARAMS, SCENARIO.sumo.with_(horizon=40.0, approach_length=100.0,
                                                   fill_duration=0.0))}
LAYOUT = SensorLayout(kinds=("probe", "loops", "av_probes"), loop_spacing=250.0)


@dataclass
class Reference:
    """Per period: the loop records, and what vehicle positions say (per class, station)."""

    records: list = field(default_factory=list)
    counts: list = field(default_factory=list)       # fronts that crossed x_j
    speeds: list = field(default_factory=list)       # mean speed at the crossing step
    harmonic: list = field(default_factory=list)     # their harmonic mean (floored)
    slow: list = field(default_factory=list)         # crossings at a speed below V_MIN
    harmonic_records: list = field(default_factory=list)   # a loop_speed = "harmonic" sensor
    zone: list = field(default_factory=list)         # time front in [x_j, x_j + l) / l T
    probes: list = field(default_factory=list)       # (record, AVs on main then)
    abreast: int = 0                                 # same-step crossings of one station
    horizon: float = 0.0


class Tracks:
    """Front positions along the route from x = 0 of the vehicles on ``main`` and of those
    that left it until their back is past L (through the junction onto ``merge``)."""

    def __init__(self, lib, length: float) -> None:
        self.lib, self.length, self.front, self.lane = lib, length, {}, {}
        self.offset, self.meta = {}, {}

    def step(self) -> dict:
        """{id: (previous front or None, front m, speed m/s, length m, class, on main)}."""
        veh, out = self.lib.vehicle, {}
        for vid in self.lib.edge.getLastStepVehicleIDs(MAIN):
            if vid not in self.meta:
                self.meta[vid] = (veh.getLength(vid), int(veh.getTypeID(vid) == AV_TYPE))
                self.offset[vid], self.lane[vid] = 0.0, f"{MAIN}_0"
        for vid, (length, c) in list(self.meta.items()):
            lane = veh.getLaneID(vid)
            if lane != self.lane[vid]:
                self.offset[vid] += self.lib.lane.getLength(self.lane[vid])
                self.lane[vid] = lane
            p1 = self.offset[vid] + veh.getLanePosition(vid)
            out[vid] = (self.front.get(vid), p1, veh.getSpeed(vid), length, c,
                        lane == f"{MAIN}_0")
            self.front[vid] = p1
            if p1 - length > self.length:
                del self.meta[vid]
        return out


def _covered(p0: float, p1: float, x: np.ndarray, length: float) -> np.ndarray:
    """Fraction of a step in which a body of ``length`` whose front moves linearly from
    ``p0`` to ``p1`` (SUMO's Euler update) covers each x_j: front in [x_j, x_j + l)."""
    if p1 - p0 < 1e-9:
        return ((x <= p1) & (p1 < x + length)).astype(float)
    return np.clip(np.minimum(p1, x + length) - np.maximum(p0, x), 0.0, None) / (p1 - p0)


def _run(params, cfg) -> Reference:
    x_cells = np.arange(25.0, params.length, 50.0)
    ones = np.ones_like(x_cells)
    initial, _ = place_vehicles(params, cfg, x_cells, 0.06 * ones, 8 * ones, 0.03 * ones,
                                8 * ones)
    x = placed_positions(LAYOUT.loop_x(params.length), params.length)
    ref, n = Reference(), x.size
    with open_simulation(params, cfg, initial=initial,
                         loops=LAYOUT.loop_x(params.length)) as sim:
        lib = sim.lib
        sensor = SumoSensor(lib, params.length, cfg, layout=LAYOUT)
        harmonic = LoopSensor(lib, LAYOUT.loop_x(params.length), params.length,
                              cfg.step_length, cfg.steps_per_period, speed="harmonic")
        tracks = Tracks(lib, params.length)
        cnt, vsum, zone = np.zeros((2, n)), np.zeros((2, n)), np.zeros((2, n))
        vinv, slow = np.zeros((2, n)), np.zeros((2, n))
        while sim.time < cfg.horizon - 1e-9:
            t = sim.step()
            step = np.zeros((2, n))
            cur = tracks.step()
            for p0, p1, v, length, c, _ in cur.values():
                crossed = (x <= p1) & (x > (p1 - length if p0 is None else p0))
                step[c] += crossed
                vsum[c] += v * crossed
                vinv[c] += crossed / max(v, V_MIN)
                slow[c] += crossed * (v < V_MIN)
                zone[c] += cfg.step_length / length * _covered(
                    p1 if p0 is None else p0, p1, x, length)
            ref.abreast += int((step >= 2).sum())
            cnt += step
            _, m = sensor.observe(t)
            h = harmonic.observe(t)
            if m is None:
                continue
            ref.records.append(m.loops)
            ref.harmonic_records.append(h)
            ref.counts.append(cnt)
            with np.errstate(invalid="ignore", divide="ignore"):
                ref.speeds.append(vsum / cnt)
                ref.harmonic.append(np.where(cnt > 0, cnt / vinv, np.nan))
            ref.slow.append(slow)
            ref.zone.append(zone / cfg.control_period)
            av_main = {v: s[1:3] for v, s in cur.items() if s[4] and s[5]}
            ref.probes.append((m.probes, av_main))
            cnt, vsum, zone = np.zeros((2, n)), np.zeros((2, n)), np.zeros((2, n))
            vinv, slow = np.zeros((2, n)), np.zeros((2, n))
    return ref


@pytest.fixture(scope="module", params=sorted(CASES))
def run(request) -> Reference:
    ref = _run(*CASES[request.param])
    ref.horizon = CASES[request.param][1].horizon
    return ref


def test_loops_count_every_front_that_crosses_them_per_class_and_period(run):
    assert len(run.records) == round(run.horizon)
    for rec, cnt in zip(run.records, run.counts, strict=True):
        np.testing.assert_array_equal(rec.flow * rec.period, cnt)     # exact, veh
        assert rec.t_mid == pytest.approx(rec.t - 0.5)
    total = np.sum(run.counts, axis=0)
    assert total.sum() > 200 and total[1].sum() > 40       # both classes, every station
    assert np.all(total > 5)
    assert run.abreast > 0        # HVs passing side by side within one step: all counted


def test_loop_speeds_are_the_crossing_vehicles_speeds(run):
    # the same vehicles at the same step: equal up to rounding; NaN exactly where none
    # of the class crossed
    for rec, v in zip(run.records, run.speeds, strict=True):
        np.testing.assert_allclose(rec.speed, v, rtol=0, atol=1e-9, equal_nan=True)
    speeds = np.array([r.speed for r in run.records])
    assert np.nanmin(speeds) < 7.0 < 14.0 < np.nanmax(speeds)   # slow and fast passages


def test_time_mean_loop_speed_is_unchanged_and_kept_beside_the_harmonic(run):
    # loop_speed = "time_mean" (the default): speed is the arithmetic mean, bit for bit the
    # time_mean kept on the record; a "harmonic" sensor on the same run differs only in speed
    for rec, h in zip(run.records, run.harmonic_records, strict=True):
        np.testing.assert_array_equal(rec.speed, rec.time_mean)
        np.testing.assert_array_equal(h.time_mean, rec.speed)
        np.testing.assert_array_equal(h.harmonic, rec.harmonic)
        np.testing.assert_array_equal(h.speed, h.harmonic)
        for name in ("flow", "density"):
            np.testing.assert_array_equal(getattr(h, name), getattr(rec, name))


def test_harmonic_loop_speed_is_the_floored_harmonic_mean_below_the_time_mean(run):
    # N / sum 1/max(v_k, V_MIN) of the crossing vehicles, against vehicle positions
    hm = np.array([h.speed for h in run.harmonic_records])
    tm = np.array([r.speed for r in run.records])
    cnt, slow = np.array(run.counts), np.array(run.slow)
    np.testing.assert_allclose(hm, np.array(run.harmonic), rtol=0, atol=1e-9, equal_nan=True)
    np.testing.assert_array_equal(np.isfinite(hm), cnt > 0)          # NaN: no vehicle
    clean = (cnt > 0) & (slow == 0)                                  # no floored speed
    assert np.all(hm[clean] <= tm[clean] + 1e-9)                     # AM-HM inequality
    np.testing.assert_allclose(hm[clean & (cnt == 1)], tm[clean & (cnt == 1)], rtol=1e-12)
    assert np.all(hm[cnt > 0] >= V_MIN - 1e-12)
    assert (clean & (cnt == 1)).sum() > 50 and (clean & (cnt >= 2)).sum() > 20
    two = clean & (cnt >= 2)
    assert (tm[two] - hm[two] > 1e-3).sum() > 5 and np.max(tm[two] - hm[two]) > 0.2   # m/s


def test_loop_density_is_edie_density_over_one_vehicle_length(run):
    # summed occupancy time / vehicle length per period, against the time each body covers
    # x_j with fronts moving linearly within a step (SUMO's update): equal up to rounding
    for rec, zone in zip(run.records, run.zone, strict=True):
        np.testing.assert_allclose(rec.density, zone, rtol=0, atol=1e-9)
    loop = np.mean([r.density for r in run.records], axis=0)
    assert loop.min() > 0.015 and loop[0].max() > 0.06     # veh/m: every station, queues
    assert np.array([r.density.sum(axis=0) for r in run.records]).max() > 0.2   # > 1 / l


def test_speed_means_of_known_spot_speeds():
    # 10 and 30 m/s: arithmetic 20, harmonic 2 / (1/10 + 1/30) = 15; a stopped vehicle
    # counts at V_MIN in the harmonic mean only; no vehicle: NaN
    v = [np.array([10.0, 30.0]), np.array([0.0, 5.0]), np.array([7.0]), np.array([])]
    entered = np.array([s.size for s in v], float)
    tm, hm = speed_means(entered, np.array([s.sum() for s in v]),
                         np.array([(1.0 / np.maximum(s, V_MIN)).sum() for s in v]))
    np.testing.assert_allclose(tm[:3], [20.0, 2.5, 7.0], rtol=1e-15)
    np.testing.assert_allclose(hm[:3], [15.0, 2.0 / (1 / V_MIN + 1 / 5.0), 7.0],
                               rtol=1e-15)
    assert np.isnan(tm[3]) and np.isnan(hm[3])


def test_av_probes_hold_every_av_on_main_and_nothing_else(run):
    for probes, av_main in run.probes:
        assert probes.cls == "a" and probes.share == 1.0
        assert probes.x.size == len(av_main)
        assert np.all((probes.x >= 0) & (probes.x <= 1000.0))
        np.testing.assert_array_equal(np.sort(probes.x),
                                      np.sort([p for p, _ in av_main.values()]))
        np.testing.assert_array_equal(np.sort(probes.v),
                                      np.sort([v for _, v in av_main.values()]))
    assert min(len(a) for _, a in run.probes) > 10


def test_av_probe_share_is_reproducible_by_seed():
    ids = [f"av_0.{k}" for k in range(4000)]
    x, v = np.linspace(0, 1000, 4000), np.full(4000, 10.0)
    av = np.ones(4000, bool)
    a = AvProbes(0.3, seed=7).observe(0.0, ids, x, v, av)
    b = AvProbes(0.3, seed=7).observe(0.0, ids[::-1], x[::-1], v, av)
    c = AvProbes(0.3, seed=8).observe(0.0, ids, x, v, av)
    np.testing.assert_array_equal(a.x, np.sort(b.x))          # same vehicles, any order
    assert abs(a.x.size / 4000 - 0.3) < 0.03                   # binomial sd 0.007
    assert not np.array_equal(a.x, c.x)
    assert abs(np.intersect1d(a.x, c.x).size / a.x.size - 0.3) < 0.05   # independent draws
    hv = AvProbes(1.0).observe(0.0, ["hv_0.1", "av_0.1"], np.array([5.0, 7.0]),
                               np.array([1.0, 2.0]), np.array([False, True]))
    assert hv.x.tolist() == [7.0] and hv.v.tolist() == [2.0]


def test_inlet_station_lies_beyond_every_inserted_vehicle():
    # SUMO inserts at x = 0 with the front at length + 0.1 m
    assert INLET_GAP > MAX_LENGTH + 0.1
    np.testing.assert_allclose(placed_positions([0, 500, 1000], 1000.0), [6.0, 500, 999.9])


def test_default_scenario_senses_loops_every_250_m_and_av_probes():
    # the scenario's layout (loops and AV probes); the built-in layout stays the probe alone
    assert SensorLayout().kinds == ("probe",) and SensorLayout().loop_x(1000.0) == ()
    assert SCENARIO.sensing.kinds == ("loops", "av_probes")
    np.testing.assert_allclose(SCENARIO.sensing.loop_x(1000.0), [0, 250, 500, 750, 1000])
    assert SCENARIO.sensing.loop_speed == "time_mean"
    sc = scenario_from_dict({"sensing": {"kinds": ["loops"], "loop_speed": "harmonic"}},
                            "s.toml")
    assert sc.sensing.loop_speed == "harmonic"
    lay = SensorLayout(kinds=("loops",))
    assert lay.loop_x(1000.0) == (0.0, 1000.0)
    assert SensorLayout(kinds=("loops",), loop_spacing=300.0).loop_x(1000.0) == (
        0.0, 300.0, 600.0, 900.0, 1000.0)


@pytest.mark.parametrize(("table", "message"), [
    ({"kinds": ["loops"], "loop_positions_m": [0, 1200]},
     "loop_positions_m = [0, 1200] is not allowed: positions in [0, 1000] m"),
    ({"kinds": ["loops"], "loop_positions_m": [-1, 500]}, "loop_positions_m = [-1, 500]"),
    ({"kinds": ["loops"], "loop_spacing_m": 0}, "loop_spacing_m = 0 is not allowed: a "
                                                "distance > 0 m"),
    ({"kinds": ["loops"], "loop_spacing_m": -250}, "loop_spacing_m = -250 is not allowed"),
    ({"kinds": ["radar"]}, "kinds = [\"radar\"] is not allowed: a list of probe, loops, "
                           "av_probes"),
    ({"kinds": []}, "kinds = [] is not allowed"),
    ({"kinds": ["loops", "loops"]}, "each kind once"),
    ({"loop_spacing_m": 250}, "only with kinds including \"loops\""),
    ({"kinds": ["loops"], "loop_positions_m": [0, 2]}, "distinct positions"),
    ({"kinds": ["av_probes"], "av_probe_share": 1.5}, "av_probe_share = 1.5 is not allowed"),
    ({"kinds": ["loops"], "av_probe_share": 0.5}, "without \"av_probes\" in kinds"),
    ({"kinds": ["av_probes"], "unknown": 1}, "unknown key 'unknown'"),
    ({"kinds": ["loops"], "loop_speed": "space_mean"},
     "loop_speed = \"space_mean\" is not allowed: one of time_mean, harmonic"),
    ({"kinds": ["loops"], "loop_speed": 1}, "loop_speed = 1 is not allowed"),
    ({"kinds": ["av_probes"], "loop_speed": "harmonic"}, "without \"loops\" in kinds"),
])
def test_bad_layouts_are_refused_in_one_line(table, message):
    with pytest.raises(ScenarioError) as err:
        scenario_from_dict({"sensing": table}, "s.toml")
    text = str(err.value)
    assert text.startswith("s.toml: [sensing] ") and message in text
    assert "\n" not in text and text.count("[sensing]") == 1

