"""The premise map: its points, its design and its tables on a synthetic stream whose
answers are known (the premise study's rows: a wave travelling upstream at 4 m/s, a pulse
that decays in 40 s)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from arzsumo_studies.common import StudyError, shipped_scenario
from arzsumo_studies.gates import GateResult
from arzsumo_studies.premise import map_points as pmp
from arzsumo_studies.premise import map_study as pm
from arzsumo_studies.premise import map_tables as pmt
from arzsumo_studies.premise.runs import PremiseOptions

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
    return pmt.map_tables(_map_rows(), [pm.MapPoint("p", "axis", {})], 1000.0,
                         fallback_trip=100.0)


def test_every_point_but_today_leaves_the_uncoupled_files_and_names_are_unique():
    names = [p.name for p in pm.POINTS]
    assert len(names) == len(set(names)) and names[:2] == ["today", "columns-0.6"]
    assert pm.POINTS[0].set == {}
    for p in pm.POINTS[1:]:
        assert p.set["sumo.min_gap_lat_m"] >= 0.6, p.name
        if not p.mapped:                      # mapped points get theirs from the run
            assert p.set["sumo.demand_h_veh_h"] < 3750, p.name  # re-mapped demand


def test_the_mapping_rule_reproduces_the_coupled_base_mapped_by_hand():
    """The coupled base was mapped by hand: outflow 3860 veh/h, hold 3900, fill 4400."""
    d = pmp.mapped_demand(3860 / 3600, 0.18)
    assert d["demand_h_veh_h"] + d["demand_a_veh_h"] == pytest.approx(3899, abs=1)
    assert d["fill_demand_h_veh_h"] + d["fill_demand_a_veh_h"] == pytest.approx(4400, abs=1)
    assert d == pmp.demand(0.18, 1.01 * 3860, 1.14 * 3860)
    with pytest.raises(StudyError, match="cannot be mapped"):
        pmp.mapped_demand(float("nan"), 0.18)


def test_a_mapped_point_is_held_above_any_discharge_then_at_its_own():
    p = next(q for q in pm.POINTS if q.name == "idm-flow")
    assert p.mapped and "sumo.demand_h_veh_h" not in p.set
    held = pmp.discharge_point(p)
    assert held.set["sumo.demand_h_veh_h"] + held.set["sumo.demand_a_veh_h"] == 4400
    assert held.set["sumo.fill_demand_h_veh_h"] == held.set["sumo.demand_h_veh_h"]
    mapped = pm.mapped_points([p, pm.POINTS[0]], {"idm-flow": 3000 / 3600})
    assert mapped[1] is pm.POINTS[0]
    assert mapped[0].set["sumo.demand_h_veh_h"] == round(3030 * 0.82)
    assert mapped[0].set["sumo.hv_accel_m_s2"] == 1.0           # Flow's IDM kept
    for q in pmp.share_variants(p):
        assert q.mapped and q.av_share in (0.3, 0.5) and q.name.startswith("idm-flow@av")


def test_discharge_runs_use_a_seed_no_gate_reads_and_a_short_window():
    runs = pm.discharge_runs(shipped_scenario("default.toml"),
                             pm.selected_points("coupled,krauss-0.75-s1,eidm"), 600.0)
    assert [r.run_id for r in runs] == [
        f"point=krauss-0.75-s1,seed={pmp.MAPPING_SEED},kind=discharge",
        f"point=eidm,seed={pmp.MAPPING_SEED},kind=discharge"]
    sumo = runs[0].scenario["sumo"]
    assert sumo["hv_sigma_step_s"] == 1.0 and sumo["depart_pos_lat"] == "random"
    assert sumo["demand_h_veh_h"] + sumo["demand_a_veh_h"] == pmp.OVERSATURATED_VEH_H
    assert runs[0].options["window_s"] == pmp.DISCHARGE_WINDOW_S
    again = pm.discharge_runs(shipped_scenario("default.toml"),
                              pm.selected_points("krauss-0.75-s1,eidm"), 600.0,
                              first={"eidm": 3000 / 3600})
    assert [r.run_id for r in again] == [f"point=eidm,seed={pmp.MAPPING_SEED},"
                                         "kind=discharge2"]
    sumo = again[0].scenario["sumo"]
    assert sumo["demand_h_veh_h"] + sumo["demand_a_veh_h"] == pytest.approx(3030, abs=1)
    assert sumo["fill_demand_h_veh_h"] + sumo["fill_demand_a_veh_h"] == pytest.approx(
        3420, abs=1)


def test_the_demand_splits_its_totals_by_the_av_share():
    d = pmp.demand(0.25, hold=4000, fill=4800)
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
    with pytest.raises(StudyError, match=r"keys of sumo\., run\.start, .* only"):
        pm.MapPoint("x", "axis", {"run.controller": "etc"})
    placed = pm.MapPoint("x", "axis", {"run.start": "placement",
                                       "initial.amplitude": [0.0, 0.0, 0.0, 0.0]})
    assert placed.set["run.start"] == "placement"        # where vehicles start is allowed


def test_the_round_trip_is_the_measured_one():
    rows = _rows(1)
    base = rows[0]
    wave = GateResult("waves[hv]", WAVE_MS, 0.0, True)
    v = float(np.mean(base["v_hv"]))
    assert pmt.measured_round_trip(base, [wave], 1000.0) == pytest.approx(
        1000 / v + 1000 / abs(WAVE_MS))
    down = GateResult("waves[hv]", -WAVE_MS, 0.0, False)
    assert math.isnan(pmt.measured_round_trip(base, [down], 1000.0))


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
    from arzsumo_studies.plots.premise_map import premise_map_figure

    fig = premise_map_figure(tables[1], pmt.MAP_GATES)
    ax = fig.axes[0]
    assert ax.images[0].get_array().shape == (1, len(pmt.MAP_GATES))
    assert len(ax.texts) == len(pmt.MAP_GATES)


def test_the_theory_figure_puts_each_points_measurement_beside_its_prediction():
    import pandas as pd
    from arzsumo_studies.plots.premise_map import theory_figure

    wide = pd.DataFrame({"point": ["a", "b"], "amplification[hv]_value": [0.6, 1.4],
                         "amplification[av]_value": [0.5, 1.2],
                         "growth_hv": [float("nan"), 6.0], "growth_av": [16.6, 3.0]})
    ax = theory_figure(wide).axes[0]
    lines = {ln.get_label(): ln for ln in ax.lines}
    assert list(lines["HV measured amplification"].get_xdata()) == [0.6, 1.4]
    assert list(lines["AV predicted growth max|G|^N"].get_xdata()) == [16.6, 3.0]
    assert ax.get_xscale() == "log" and [t.get_text() for t in ax.get_yticklabels()] == \
        ["a", "b"]


def test_the_pulse_is_judged_within_the_round_trips_that_fit():
    rows = [r for r in _map_rows() if r["kind"] in ("baseline", "pulse")]
    long, _ = pmt.map_tables(rows, [pm.MapPoint("p", "axis", {})], 1000.0,
                            fallback_trip=100.0,
                            th=pmt.PremiseThresholds(pulse_round_trips=0.9))
    pulse = long[long.gate == "pulse"].iloc[0]
    # the pulse decays in 40 s, well within 0.9 x 375 s: a stable stream fails the gate
    assert pulse["value"] < 100.0 and not pulse["passed"]


def test_one_seed_reads_the_pulse_but_leaves_it_undecided():
    rows = [r for r in _map_rows() if r["seed"] == 1]
    long, _ = pmt.map_tables(rows, [pm.MapPoint("p", "axis", {})], 1000.0,
                            fallback_trip=100.0,
                            th=pmt.PremiseThresholds(pulse_round_trips=0.9))
    pulse = long[long.gate == "pulse"].iloc[0]
    assert math.isnan(pulse["value"]) and not pulse["passed"]
    _, wide = pmt.map_tables(rows, [pm.MapPoint("p", "axis", {})], 1000.0, fallback_trip=100.0)
    assert math.isnan(wide.iloc[0]["pulse_passed"])       # undecided: neither pass nor fail
    gates = pmt.point_gates({1: {r["kind"]: r for r in rows}}, 1000.0,
                           pmt.PremiseThresholds(pulse_round_trips=0.9), 30.0, 100.0)[1]
    detail = next(g.detail for g in gates if g.name == "pulse")
    # against its own late deviation the decayed pulse reads as decayed within 100 s
    assert detail["late_floor_value"] < 100.0 and "one seed" in detail["reason"]


def test_the_theory_columns_are_the_prediction_at_each_seeds_measured_point():
    """IDM HVs: the table's gain is the mean over seeds of
    :func:`arzsumo_studies.measures.car_following_stability.predict` at each baseline's
    densities and HV speed;
    Krauss has none (NaN)."""
    from dataclasses import replace

    from arzsumo_studies.measures.car_following_stability import predict

    from arzsumo.scenario import load_scenario

    sc = load_scenario(shipped_scenario("default.toml"))
    idm = replace(sc, sumo=sc.sumo.with_(hv_model="IDM"))
    rows = [{**r, "rho_hv_veh_m": 0.08 + 0.01 * r["seed"], "rho_av_veh_m": 0.02}
            for r in _map_rows()]
    _, wide = pmt.map_tables(rows, [pm.MapPoint("p", "axis", {})], 1000.0,
                            fallback_trip=100.0, scenarios={"p": idm})
    v = float(np.mean(np.array(rows[0]["v_hv"])))     # both seeds' fields: mean 8 m/s
    want = np.mean([predict(idm.params, idm.sumo, 0.08 + 0.01 * s, 0.02, v)["hv"].gain
                    for s in (1, 2)])
    assert wide["gain_hv"].iloc[0] == pytest.approx(want, rel=1e-3)
    assert wide["gain_hv"].iloc[0] > 1.0                      # IDM at 8 m/s: unstable
    assert wide["growth_hv"].iloc[0] > wide["gain_hv"].iloc[0]
    _, krauss = pmt.map_tables(rows, [pm.MapPoint("p", "axis", {})], 1000.0,
                              fallback_trip=100.0, scenarios={"p": sc})
    assert math.isnan(krauss["gain_hv"].iloc[0]) and krauss["gain_av"].iloc[0] > 1.0
    assert "max|G| hv" in pmt.theory_markdown(wide)


def test_a_gridlocked_discharge_run_leaves_its_point_out_and_says_so():
    def row(point, q_veh_h, inserted):
        return {"point": point, "outflow_veh_s": q_veh_h / 3600, "inserted_main": inserted,
                "requested_main": 1000}

    first = [row("a", 3000, 800), row("b", 0.0, 400), row("c", 2500, 700)]
    assert pmp.flowing(first) == {"a": 3000 / 3600, "c": 2500 / 3600}
    second = [row("a", 2950, 990), row("c", 100, 300)]
    assert pmp.flowing(second) == {"a": 2950 / 3600}
    text = pmp.mapping_lines(first, second).splitlines()
    assert text[0] == ("a: discharge 3000 veh/h (80% inserted) held above it; 2950 veh/h "
                       "(99% inserted) at the demand it maps to")
    assert text[1].startswith("b: discharge 0 veh/h") and "gridlocked" in text[1]
    assert "gridlocked" in text[2]


def test_the_fill_lacked_the_vehicles_between_the_tail_and_the_margin():
    """A tail 300 m into the section, free cells at 16 m/s, congested ones at 8 m/s,
    q = 0.7 veh/s: (300 + 200) m x 0.7 (1/8 - 1/16) veh/m = 21.9 vehicles over 600 s."""
    x = np.arange(20) * 50.0 + 25.0
    v = np.where(x < 300.0, 16.0, 8.0)[None, :].repeat(60, axis=0)
    want = 500.0 * 0.7 * (1 / 8 - 1 / 16) / 600.0
    assert pmp.fill_shortfall(x, v, 300.0, 0.7, 600.0) == pytest.approx(want)
    assert pmp.fill_shortfall(x, v, 0.0, 0.7, 600.0) == 0.0
    d = pmp.mapped_demand(0.7, 0.18, fill_extra_veh_s=want)
    base = pmp.mapped_demand(0.7, 0.18)
    assert d["demand_h_veh_h"] == base["demand_h_veh_h"]                  # hold unchanged
    fill = d["fill_demand_h_veh_h"] + d["fill_demand_a_veh_h"]
    assert fill == pytest.approx(1.14 * 2520 + want * 3600, abs=1)


def test_the_map_reports_the_queue_tail_of_its_worst_seed():
    rows = _map_rows()
    for r in rows:
        if r["kind"] == "baseline" and r["seed"] == 2:
            v = np.array(r["v_hv"], float)
            v[:, :4] = 3 * np.nanmean(v)                 # the first 4 cells ride free
            r["v_hv"] = v.tolist()
    _, wide = pmt.map_tables(rows, [pm.MapPoint("p", "axis", {})], 1000.0,
                            fallback_trip=100.0)
    dx = rows[0]["dx_m"]
    assert wide["queue_tail_m"].iloc[0] == pytest.approx(4 * dx)


def test_the_fields_figure_draws_each_points_first_seed_and_marks_a_tail():
    from arzsumo_studies.plots.premise_map import fields_figure

    fields = pmt.first_fields(_map_rows())
    assert list(fields) == ["p"]
    t, _, v = fields["p"]
    base = next(r for r in _map_rows() if r["kind"] == "baseline" and r["seed"] == 1)
    assert t[0] == pytest.approx(base["t_s"][0] - base["t0_s"])
    assert v[0, 0] == pytest.approx(base["v_hv"][0][0] * 3.6)
    fig = fields_figure(fields, {"p": 150.0})
    assert fig.axes[0].get_title() == "p (tail 150 m)" and fig.axes[0].lines


def test_the_study_runs_from_python_with_its_options_and_the_cli_maps_onto_them():
    """Library code: MapOptions in, run IDs (or a MapResult) out, no argparse; the
    command line builds the same options."""
    import argparse
    from pathlib import Path

    from arzsumo_studies.cli import premise_map as cli

    opts = pm.MapOptions(scenario=shipped_scenario("default.toml"),
                         points=("coupled", "krauss-0.75-s1"), seeds=(3,), pulses=False)
    assert pm.design(opts) == [
        f"point=krauss-0.75-s1,seed={pmp.MAPPING_SEED},kind=discharge",
        "point=coupled,seed=3,kind=baseline", "point=krauss-0.75-s1,seed=3,kind=baseline"]
    parser = argparse.ArgumentParser()
    cli.add_arguments(parser)
    args = parser.parse_args(["--scenario", str(opts.scenario), "--points",
                              "coupled,krauss-0.75-s1", "--seeds", "3", "--no-pulse",
                              "--out", "results/studies/premise-map"])
    assert cli.options(args) == opts
    assert cli.options(parser.parse_args(["--out", "x"])).out == Path("x")
    with pytest.raises(StudyError, match="at least one seed"):
        pm.MapOptions(seeds=())
    assert "argparse" not in Path(pm.__file__).read_text(encoding="utf-8")


def test_a_run_listed_twice_is_run_once_and_read_by_both(tmp_path):
    """A point and its fuller-fill variant share their discharge runs."""
    from arzsumo_studies.design import StudyRun, run_design

    calls = []

    def task(run):
        calls.append(run.run_id)
        return {"id": run.run_id}

    run = StudyRun("point=a,seed=100,kind=discharge", {"sumo": {}})
    other = StudyRun("point=b,seed=100,kind=discharge", {"sumo": {}})
    rows = run_design([run, other, run], task, tmp_path, in_process=True, progress=False)
    assert calls == [run.run_id, other.run_id]
    assert rows == [{"id": run.run_id}, {"id": other.run_id}, {"id": run.run_id}]


def test_a_placed_point_starts_uniform_at_its_equilibrium_and_others_unplaced():
    from arzsumo_studies.premise.runs import placed_fields

    from arzsumo.resources import shipped_scenarios_dir
    from arzsumo.scenario import load_scenario

    sc = load_scenario(shipped_scenarios_dir() / "default.toml")
    assert placed_fields(sc) is None
    fields = placed_fields(sc.with_(dict(pmp.PLACED)))
    eq = sc.equilibrium
    assert fields.shape == (4, 20)                         # 1000 m in 50 m cells
    np.testing.assert_allclose(fields[0], eq.rho_h, rtol=1e-12)
    np.testing.assert_allclose(fields[2], eq.rho_a, rtol=1e-12)
    np.testing.assert_allclose(fields[1], eq.v_h, rtol=1e-12)
