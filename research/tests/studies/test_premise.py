"""The premise command's layout of runs, its plans and its analysis, on rows made here
(no SUMO): a wave travelling upstream at 4 m/s, a pulse that dies out, a unit-gain meter."""

from __future__ import annotations

import math

import numpy as np
import pytest
from arzsumo_studies.common import shipped_scenario
from arzsumo_studies.gates import GateResult
from arzsumo_studies.premise import floors as premise_floors
from arzsumo_studies.premise import study
from arzsumo_studies.premise.runs import (
    KINDS,
    PremiseOptions,
    PremiseRunError,
    check_options,
    grouped,
    least_plan,
    nominal_plan,
    plan_for_step,
    premise_runs,
    staircase_levels,
    ungrouped,
)

from arzsumo.scenario import load_scenario
from arzsumo.sumo.green_share import DEFAULT_CURVE

DEFAULT, LEGACY = shipped_scenario("default.toml"), shipped_scenario("legacy_default.toml")
T0, PERIODS, CELLS, DX = 100.0, 400, 20, 50.0
WAVE_MS = -4.0


def test_one_run_per_seed_and_kind_each_keyed_by_what_it_depends_on():
    opts = PremiseOptions(window=300.0)
    runs = premise_runs(LEGACY, [3, 4], 60.0, opts)
    assert [r.run_id for r in runs] == [f"seed={s},kind={k}" for s in (3, 4)
                                        for k in ("baseline", "pulse", "staircase")]
    assert runs[0].scenario["sumo"]["seed"] == 3 and runs[0].scenario["run"]["warmup_s"] == 60
    longer = premise_runs(LEGACY, [3], 60.0, PremiseOptions(window=300.0, pulse=20.0))
    # a longer pulse changes the pulse's run only
    assert [a.sha256 == b.sha256 for a, b in zip(runs, longer, strict=False)] == [
        True, False, True]
    # every kind of a seed is set up for the longest (the staircase: 9 x 120 s), so that
    # the three share their warm-up; a shorter staircase changes them all
    assert {r.options["horizon_periods"] for r in runs} == {1080}
    shorter = premise_runs(LEGACY, [3], 60.0, PremiseOptions(window=300.0, level=60.0))
    assert not any(a.sha256 == b.sha256 for a, b in zip(runs, shorter, strict=False))


def test_a_seed_s_runs_are_one_group_and_come_apart_again():
    runs = premise_runs(LEGACY, [3, 4], 60.0, PremiseOptions(window=300.0))
    groups = grouped(runs)
    assert [g.run_id for g in groups] == ["seed=3", "seed=4"]
    assert [i for i, _ in groups[0].options["group"]] == [
        "seed=3,kind=baseline", "seed=3,kind=pulse", "seed=3,kind=staircase"]
    assert groups[1].scenario == runs[3].scenario
    rows = [{"rows": [{"kind": k, "seed": s} for k in KINDS]} for s in (3, 4)]
    assert [(r["seed"], r["kind"]) for r in ungrouped(rows)] == [
        (s, k) for s in (3, 4) for k in KINDS]


def test_the_plans_of_both_meters():
    one = load_scenario(DEFAULT).sumo
    assert (nominal_plan(one), least_plan(one)) == (pytest.approx(600 / 3600),
                                                   pytest.approx(240 / 3600))
    assert plan_for_step(one, DEFAULT_CURVE, 200 / 3600) == pytest.approx(800 / 3600)
    fixed = load_scenario(LEGACY).sumo
    assert (nominal_plan(fixed), least_plan(fixed)) == (0.5, 0.0)
    # the fixed cycle: the green share whose curve outflow is q* - dr
    up = plan_for_step(fixed, DEFAULT_CURVE, 200 / 3600)
    assert DEFAULT_CURVE.outflow_at(up) == pytest.approx((4464 - 200) / 3600)
    assert plan_for_step(fixed, DEFAULT_CURVE, 0.0) == 0.5
    assert staircase_levels(6) == [0, 1, 0, -1, 0, 1, 0]


def test_options_the_meter_cannot_run_are_refused():
    sc = load_scenario(DEFAULT)
    check_options(sc, PremiseOptions(window=300.0), DEFAULT_CURVE)
    with pytest.raises(PremiseRunError, match=r"^--step-veh-h = 400 is not allowed"):
        check_options(sc, PremiseOptions(window=300.0, step=400 / 3600), DEFAULT_CURVE)
    with pytest.raises(PremiseRunError, match=r"^--window = 300.5 is not allowed: a whole"):
        check_options(sc, PremiseOptions(window=300.5), DEFAULT_CURVE)


def _wave(t: np.ndarray, x: np.ndarray, seed: int) -> np.ndarray:
    """8 m/s plus A(x) g(t - x / c): fluctuations travelling at c, their amplitude A
    growing upstream from 1 at x = L to 2 at x = 0 (g: three incommensurate sines)."""
    s = t[:, None] - x[None, :] / WAVE_MS + 0.5 * seed     # seeds: nearly alike
    g = sum(np.sin(2 * np.pi * s / p + k) for k, p in enumerate((61.0, 97.0, 173.0)))
    return 8.0 + (2.0 - x[None, :] / 1000.0) * g


def _rows(seed: int) -> list[dict]:
    """A baseline (a wave at -4 m/s), a pulse (+3 m/s decaying in 40 s) and a staircase
    (q = q0 - (r - r0) exactly) of one seed, as the worker returns them."""
    t = T0 + np.arange(1, PERIODS + 1, dtype=float)
    x = (np.arange(CELLS) + 0.5) * DX
    v = _wave(t, x, seed)
    grid = {"seed": seed, "t0_s": T0, "t_s": t.tolist(), "x_m": x.tolist(), "dx_m": DX,
            "period_s": 1.0, "wall_s": 1.0}
    lateral = GateResult("coupling[hv]", 0.0, 10 / 3.6, True, {}).as_dict()
    base = {**grid, "kind": "baseline", "v_hv": v.tolist(), "v_av": v.tolist(),
            "count_veh": (100 + np.sin(t / 7.0)).tolist(), "main_vehicles": [100] * PERIODS,
            "lateral_counts": [100] * PERIODS, "lateral_samples": 100 * PERIODS,
            "class_samples": {"hv": 80 * PERIODS, "av": 20 * PERIODS},
            "coupling": [lateral, {**lateral, "name": "coupling[av]"}],
            "inserted_main": 990, "requested_main": 1000, "collisions": 0,
            "ramp_demand_veh_s": 800 / 3600, "max_release_veh_s": 900 / 3600,
            "meter_mode": "one_per_green", "max_queue_veh": 20, "ramp_storage_veh": 37}
    bump = 3.0 * np.exp(-(t - T0) / 40.0)[:, None] * np.ones(CELLS)
    pulse = {**grid, "kind": "pulse", "v_hv": (v + bump).tolist(), "v_av": v.tolist(),
             "pulse_plan": 240 / 3600}
    r = np.repeat(np.array([0, 1, 0, -1, 0]) * 200 / 3600 + 600 / 3600, 80)
    stair = {**grid, "kind": "staircase", "q_veh_s": (1.2 - (r - 600 / 3600)).tolist(),
             "r_veh_s": r.tolist(), "step_times_s": [T0 + 80 * k for k in range(1, 5)],
             "released_veh_s": r.tolist()}
    return [base, pulse, stair]


@pytest.fixture(scope="module")
def report() -> study.PremiseReport:
    rows = _rows(1) + _rows(2)
    return study.analyse(rows, load_scenario(LEGACY), study.AnalysisOptions(round_trip=100.0))


def test_every_gate_is_measured_per_seed_in_order(report):
    assert report.seeds == (1, 2)
    assert [g.name for g in report.gates[1]] == [
        "coupling[hv]", "coupling[av]", "waves[hv]", "waves[av]", "model_wave[hv]",
        "model_wave[av]", "amplification[hv]", "amplification[av]", "pulse", "actuator",
        "stationary", "inserted", "ramp_demand", "ramp_queue"]


def test_the_gates_read_the_synthetic_stream(report):
    g = {r.name: r for r in report.gates[1]}
    assert g["waves[hv]"].value == pytest.approx(WAVE_MS, rel=0.05) and g["waves[hv]"].passed
    # the pulse dies out within the first round trip: a stable stream fails the gate
    assert g["pulse"].passed is False and g["pulse"].value < 100.0
    assert g["actuator"].value == pytest.approx(-1.0) and g["actuator"].passed
    assert report.pooled_actuator.detail["up"]["steps"] == 4
    assert g["inserted"].value == pytest.approx(0.99) and g["inserted"].passed
    assert g["ramp_demand"].value == pytest.approx(800 / 900)
    assert g["ramp_queue"].value == pytest.approx(20 / 37)
    # the amplitude at 50 and 150 m over that at 850 and 950 m: 1.9 / 1.1
    assert g["amplification[hv]"].value == pytest.approx(1.9 / 1.1, rel=0.03)
    assert g["amplification[hv]"].passed
    # the model's lambda_4 of legacy_default (-17.9 km/h) against the measured 4 m/s
    assert g["model_wave[hv]"].value == pytest.approx(4.9777 / 4.0, rel=0.05)


def test_the_floor_of_two_seeds_is_the_distance_of_their_baselines(report):
    assert report.floor_method == "seeds"
    assert report.floors[1]["hv"] > 1.0 and report.floors[1]["total"] > report.floors[1]["hv"]
    assert report.verdict.passed is False and "pulse" in report.verdict.failed


def test_one_seed_falls_back_to_the_late_floor():
    method, floors = premise_floors.floors({1: {r["kind"]: r for r in _rows(1)}}, "auto")
    # the median of the bump's D = 3 exp(-t / 40 s) sqrt(L) over t = 301..400 s
    assert method == "late" and floors[1]["av"] == 0.0
    assert floors[1]["hv"] == pytest.approx(3.0 * math.exp(-350.5 / 40.0) * math.sqrt(1000),
                                            rel=0.01)


def test_the_window_refusals_name_the_bound():
    study.check_window(200.0, 100.0, True)
    with pytest.raises(PremiseRunError, match=r"2 x 100 s \(T: --round-trip\); allowed: "
                                              r"at least 200 s"):
        study.check_window(199.0, 100.0, True)
    sc = load_scenario(LEGACY)
    trip = study.model_speeds(sc).round_trip
    assert trip == pytest.approx(1000 / 6.9083 + 1000 / 4.9777, rel=1e-3)
    assert study.default_window(sc, trip) == math.ceil(2 * trip + 60)


def test_a_pulse_with_no_deviation_to_read_is_unmeasured_not_a_crash():
    rows = _rows(1) + _rows(2)
    for r in rows:
        if r["kind"] == "pulse":      # the AVs left the section during the pulse
            r["v_av"] = [[None] * CELLS] * PERIODS
    rep = study.analyse(rows, load_scenario(LEGACY), study.AnalysisOptions(round_trip=100.0))
    pulse = next(g for g in rep.gates[1] if g.name == "pulse")
    assert math.isnan(pulse.value) and not pulse.passed
    assert "norm" in pulse.detail["reason"]


def test_the_theory_is_predicted_at_each_seeds_baseline_operating_point():
    """The prediction uses the baseline's mean densities and HV speed; a row without the
    densities (an older record) has none."""
    from arzsumo_studies.measures.car_following_stability import predict

    sc = load_scenario(LEGACY)
    rows = _rows(1)
    rows[0] = {**rows[0], "rho_hv_veh_m": 0.1, "rho_av_veh_m": 0.02}
    rep = study.analyse(rows + _rows(2), sc, study.AnalysisOptions(round_trip=100.0))
    speed = float(np.nanmean(np.array(rows[0]["v_hv"])))
    expected = predict(sc.params, sc.sumo, 0.1, 0.02, speed)
    assert rep.theory[1]["av"] == expected["av"] and rep.theory[1]["av"].gain > 1.0
    assert math.isnan(rep.theory[1]["hv"].gain)            # the legacy HVs drive Krauss
    assert rep.theory[2] == {}
    from arzsumo_studies.outputs.premise import theory_lines

    text = theory_lines(rep.theory)
    assert "seed 1: hv Krauss: none (Krauss is not smooth" in text
    assert f"av ACC: max|G| {expected['av'].gain:.4f}" in text


def test_a_deadlocked_seed_has_no_theory_and_the_report_still_reads_every_seed():
    """A seed whose HVs stood still for the whole window (a merge deadlock) has no
    operating point to linearise about; the other seeds keep theirs."""
    sc = load_scenario(LEGACY)
    moving, stuck = _rows(1), _rows(2)
    moving[0] = {**moving[0], "rho_hv_veh_m": 0.1, "rho_av_veh_m": 0.02}
    zero = np.zeros_like(np.array(stuck[0]["v_hv"])).tolist()
    stuck[0] = {**stuck[0], "rho_hv_veh_m": 0.18, "rho_av_veh_m": 0.033, "v_hv": zero}
    rep = study.analyse(moving + stuck, sc, study.AnalysisOptions(round_trip=100.0))
    assert rep.theory[2] == {} and set(rep.theory[1]) == {"hv", "av"}
    assert rep.seeds == (1, 2)


def test_the_pooled_readings_leave_out_a_seed_that_did_not_hold_the_operating_point(report):
    # both synthetic seeds hold it: the pulse's mean response reads them both (the bump
    # decays in 40 s: the mean response decays too)
    assert report.pooled_pulse is not None and report.pooled_pulse.detail["seeds"] == 2
    assert report.pooled_pulse.detail["total"]["decayed"]
    assert report.pooled_actuator.detail["levels"]["up"]["records"] == 2
    stuck = _rows(2)
    stuck[0] = {**stuck[0], "inserted_main": 500}          # half the demand inserted
    rep = study.analyse(_rows(1) + stuck, load_scenario(LEGACY),
                        study.AnalysisOptions(round_trip=100.0))
    assert rep.pooled_actuator.detail["levels"]["up"]["records"] == 1
    assert math.isnan(rep.pooled_pulse.value) and "1 seed(s)" in rep.pooled_pulse.detail["reason"]


def test_the_floors_pair_the_held_seeds_and_a_deadlocked_seed_inflates_none():
    """Seed 2 stood still (speeds 0, half its demand not inserted): the floors pair
    seeds 1 and 3, and seed 2 gets their median instead of a distance to a standstill."""
    from arzsumo_studies.premise.pooled import held_seeds

    rows = {s: {r["kind"]: r for r in _rows(s)} for s in (1, 2, 3)}
    stuck = rows[2]["baseline"]
    rows[2]["baseline"] = {**stuck, "inserted_main": 500,
                           "v_hv": np.zeros_like(np.array(stuck["v_hv"])).tolist(),
                           "v_av": np.zeros_like(np.array(stuck["v_av"])).tolist()}
    assert held_seeds(rows) == (1, 3)
    _, paired = premise_floors.floors(rows, "seeds", (1, 3))
    _, naive = premise_floors.floors(rows, "seeds")
    assert paired[1] == paired[3]                       # 1 -> 3 and 3 -> 1: one distance
    assert paired[2]["total"] == pytest.approx(paired[1]["total"])
    assert naive[1]["total"] > 5 * paired[1]["total"]   # 1 -> 2: the distance to a standstill
