"""The premise map: its points, its design and its tables on a synthetic stream whose
answers are known (the premise study's rows: a wave travelling upstream at 4 m/s, a pulse
that decays in 40 s)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from arzsumo.evaluation.premise import GateResult
from arzsumo.studies import premise_map as pm
from arzsumo.studies.common import StudyError, shipped_scenario
from arzsumo.studies.premise_runs import PremiseOptions

from .test_premise import WAVE_MS, _rows


def _map_rows() -> list[dict]:
    rows = []
    for seed in (1, 2):
        for r in _rows(seed):
            if r["kind"] == "baseline" or (r["kind"] == "pulse" and seed == 1):
                rows.append({"point": "p", **r})
    return rows


@pytest.fixture(scope="module")
def tables():
    return pm.map_tables(_map_rows(), [pm.MapPoint("p", "axis", {})], 1000.0,
                         fallback_trip=100.0)


def test_every_point_but_today_leaves_the_uncoupled_files_and_names_are_unique():
    names = [p.name for p in pm.POINTS]
    assert len(names) == len(set(names)) and names[:2] == ["today", "columns-0.6"]
    assert pm.POINTS[0].set == {}
    for p in pm.POINTS[1:]:
        assert p.set["sumo.min_gap_lat_m"] >= 0.6, p.name
        assert p.set["sumo.demand_h_veh_h"] < 3750, p.name      # re-mapped demand


def test_the_demand_splits_its_totals_by_the_av_share():
    d = pm.demand(0.25, hold=4000, fill=4800)
    assert d == {"demand_h_veh_h": 3000, "demand_a_veh_h": 1000,
                 "fill_demand_h_veh_h": 3600, "fill_demand_a_veh_h": 1200}


def test_the_design_pulses_the_first_seed_only():
    runs = pm.map_runs(shipped_scenario("lateral_files.toml"), pm.selected_points("today,idm"),
                       [3, 4], 600.0, PremiseOptions(window=540.0))
    assert [r.run_id for r in runs] == [
        "point=today,seed=3,kind=baseline", "point=today,seed=3,kind=pulse",
        "point=today,seed=4,kind=baseline", "point=idm,seed=3,kind=baseline",
        "point=idm,seed=3,kind=pulse", "point=idm,seed=4,kind=baseline"]
    assert runs[3].scenario["sumo"]["hv_model"] == "IDM"
    assert runs[3].scenario["sumo"]["min_gap_lat_m"] == 0.6
    assert runs[3].scenario["sumo"]["depart_pos_lat"] == "random_free"
    assert "hv_model" not in runs[0].scenario["sumo"]


def test_bad_points_are_refused():
    with pytest.raises(StudyError, match="--points = 'today,nope' is not allowed: names"):
        pm.selected_points("today,nope")
    with pytest.raises(StudyError, match="\\[sumo\\] keys only"):
        pm.MapPoint("x", "axis", {"run.controller": "etc"})


def test_the_round_trip_is_the_measured_one():
    rows = _rows(1)
    base = rows[0]
    wave = GateResult("waves[hv]", WAVE_MS, 0.0, True)
    v = float(np.mean(base["v_hv"]))
    assert pm.measured_round_trip(base, [wave], 1000.0) == pytest.approx(
        1000 / v + 1000 / abs(WAVE_MS))
    down = GateResult("waves[hv]", -WAVE_MS, 0.0, False)
    assert math.isnan(pm.measured_round_trip(base, [down], 1000.0))


def test_the_tables_read_the_synthetic_stream(tables):
    long, wide = tables
    assert set(long["seed"]) == {1, 2}
    assert "pulse" in set(long[long.seed == 1].gate)
    assert "pulse" not in set(long[long.seed == 2].gate)
    assert not any(long.gate.str.startswith("model_wave"))
    row = wide.iloc[0]
    assert row["waves[hv]_passed"] == 1.0
    assert row["waves[hv]_value"] == pytest.approx(WAVE_MS, rel=0.05)
    # two measured round trips (2 x 375 s) outlast the 400 s record: not measured
    assert row["pulse_passed"] == 0.0 and math.isnan(row["pulse_value"])
    assert row["inserted_value"] == pytest.approx(0.99)
    assert row["v_hv_kmh"] == pytest.approx(8.0 * 3.6, rel=0.01)
    assert math.isnan(row["q_out_veh_h"])      # the synthetic rows carry no outflow


def test_the_figure_has_a_cell_per_point_and_gate(tables):
    from arzsumo.plots.premise_map import premise_map_figure

    fig = premise_map_figure(tables[1], pm.MAP_GATES)
    ax = fig.axes[0]
    assert ax.images[0].get_array().shape == (1, len(pm.MAP_GATES))
    assert len(ax.texts) == len(pm.MAP_GATES)


def test_the_pulse_is_judged_within_the_round_trips_that_fit():
    rows = [r for r in _map_rows() if r["kind"] in ("baseline", "pulse")]
    long, _ = pm.map_tables(rows, [pm.MapPoint("p", "axis", {})], 1000.0,
                            fallback_trip=100.0,
                            th=pm.PremiseThresholds(pulse_round_trips=0.9))
    pulse = long[long.gate == "pulse"].iloc[0]
    # the pulse decays in 40 s, well within 0.9 x 375 s: a stable stream fails the gate
    assert pulse["value"] < 100.0 and not pulse["passed"]


def test_one_seed_reads_the_pulse_but_leaves_it_undecided():
    rows = [r for r in _map_rows() if r["seed"] == 1]
    long, _ = pm.map_tables(rows, [pm.MapPoint("p", "axis", {})], 1000.0,
                            fallback_trip=100.0,
                            th=pm.PremiseThresholds(pulse_round_trips=0.9))
    pulse = long[long.gate == "pulse"].iloc[0]
    assert math.isnan(pulse["value"]) and not pulse["passed"]
    _, wide = pm.map_tables(rows, [pm.MapPoint("p", "axis", {})], 1000.0, fallback_trip=100.0)
    assert math.isnan(wide.iloc[0]["pulse_passed"])       # undecided: neither pass nor fail
    gates = pm.point_gates({1: {r["kind"]: r for r in rows}}, 1000.0,
                           pm.PremiseThresholds(pulse_round_trips=0.9), 30.0, 100.0)[1]
    detail = next(g.detail for g in gates if g.name == "pulse")
    # against its own late deviation the decayed pulse reads as decayed within 100 s
    assert detail["late_floor_value"] < 100.0 and "one seed" in detail["reason"]
