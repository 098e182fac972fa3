"""The SUMO-options study: its design, and its paired comparison on a known table."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
from arzsumo_studies.common import StudyError
from arzsumo_studies.sumo_map.sumo_options import (
    MEASURES,
    OPTION,
    SumoOptionsOptions,
    compare,
    markdown,
    options_spec,
    signature_markdown,
)

from arzsumo.errors import ScenarioError
from arzsumo.resources import shipped_scenarios_dir
from arzsumo.scenario import load_scenario
from arzsumo.sumo.simulation import SumoSimulation

TTS = "network_whole_demand.time_spent_s.total"


def test_the_design_changes_one_option_at_a_time_on_the_same_seeds():
    spec = options_spec([1, 2, 3])
    runs = spec.runs()
    assert len(runs) == 10 * 3
    base = [r for r in runs if r.run_id.startswith("lateral_resolution_m=0.5,")]
    assert [r.scenario["sumo"]["seed"] for r in base] == [1, 2, 3]
    eager = next(r for r in runs if r.run_id == "eager_insert=false,seed=2")
    assert eager.scenario["sumo"]["eager_insert"] is False
    assert eager.scenario["sumo"]["lateral_resolution_m"] == 0.5      # the rest shipped
    assert all(r.scenario["run"]["controller"] == "open" for r in runs)


def test_the_approach_in_pieces_is_a_variant_of_its_own_against_one_edge():
    runs = options_spec([1], vary=("approach_piece_m",)).runs()
    assert [r.scenario["sumo"]["approach_piece_m"] for r in runs] == [0.0, 250.0]
    assert runs[1].scenario["sumo"]["approach_length_m"] == 2500


def test_one_value_of_a_key_is_a_variant_of_its_own_after_the_baseline_asked_first():
    """``KEY=VALUE`` picks that value alone; the first entry leads with the shipped value,
    so a later study reuses the runs of an earlier one with the same first entry."""
    runs = options_spec([1], vary=("approach_piece_m", "lateral_resolution_m=3.25")).runs()
    assert [r.run_id for r in runs] == ["approach_piece_m=0,seed=1",
                                        "approach_piece_m=250,seed=1",
                                        "lateral_resolution_m=3.25,seed=1"]
    assert runs[2].scenario["sumo"]["lateral_resolution_m"] == 3.25
    assert "approach_piece_m" not in runs[2].scenario["sumo"]          # the rest shipped
    with pytest.raises(StudyError, match=r"lateral_resolution_m=3\.3 is not allowed"):
        SumoOptionsOptions(vary=("lateral_resolution_m=3.3",))


def test_vary_runs_the_shipped_approach_once_then_each_shorter_one():
    runs = options_spec([1, 2], vary=("approach_length_m",)).runs()
    lengths = [r.scenario["sumo"]["approach_length_m"] for r in runs]
    assert lengths == [2500.0, 2500.0, 1500.0, 1500.0, 1000.0, 1000.0]
    assert runs[0].run_id == "approach_length_m=2500,seed=1"     # the shipped baseline
    assert {r.scenario["sumo"]["lateral_resolution_m"] for r in runs} == {0.5}


def _table(shift: float, noise: float, n: int = 10) -> pd.DataFrame:
    """Base runs and a 1.3 m variant whose time spent is ``shift`` s higher, +- noise."""
    rng = np.random.default_rng(0)
    rows = []
    for seed in range(1, n + 1):
        level = 400_000.0 + 10_000.0 * rng.standard_normal()
        for res, extra, wall in ((0.5, 0.0, 100.0), (1.3, shift, 80.0)):
            rows.append({OPTION: "lateral_resolution_m", "lateral_resolution_m": res,
                         "seed": seed, "status": "ok", "execution.wall_s": wall,
                         "execution.cpu_s": wall / 2, "teleports": 0,
                         "network_whole_demand.vehicles.loaded.total": 1000,
                         TTS: level + extra + noise * rng.standard_normal()})
    return pd.DataFrame(rows)


def test_a_shift_beyond_seed_noise_moves_and_one_within_does_not():
    moved = compare(_table(shift=3600.0, noise=360.0))
    row = moved[(moved["variant"] == "lateral_resolution_m=1.3")].iloc[0]
    assert row["measure"] == MEASURES[TTS][0] and row["unit"] == "veh h"
    assert row["diff_mean"] == pytest.approx(1.0, abs=0.15)          # 3600 s = 1 veh h
    assert row["diff_low"] < 1.0 < row["diff_high"] and row["moves"]
    assert row["wall_ratio"] == pytest.approx(0.8)
    still = compare(_table(shift=0.0, noise=360.0))
    assert not still[still["variant"] == "lateral_resolution_m=1.3"].iloc[0]["moves"]
    text = markdown(moved)
    assert "| lateral_resolution_m=1.3 | 10 | 80 | 0.80 | 0.80 |" in text and "**moves**" in text


def test_a_lever_keeps_the_signature_only_when_every_interval_lies_inside_its_margin():
    """Time per vehicle: 400 s a vehicle, margin 10 % = 40 s. A shift of 0 with a little
    noise lies inside; a shift of 0 with noise so large that the interval reaches past 40 s
    is outside although it contains 0; a teleport count of 0 on both is an exact 0."""
    def row(table, measure):
        t = compare(table)
        return t[(t["variant"] == "lateral_resolution_m=1.3")
                 & (t["measure"] == measure)].iloc[0]

    per_vehicle = "whole-demand time per vehicle"
    quiet = row(_table(shift=0.0, noise=2_000.0), per_vehicle)
    assert quiet["margin"] == pytest.approx(40.0, rel=0.05) and quiet["inside"]
    noisy = row(_table(shift=0.0, noise=60_000.0), per_vehicle)
    assert noisy["diff_low"] < 0 < noisy["diff_high"] and not noisy["inside"]
    teleports = row(_table(shift=0.0, noise=2_000.0), "teleports")
    assert (teleports["diff_low"], teleports["diff_high"], teleports["inside"]) == (0, 0, True)
    assert "inside +-" in markdown(compare(_table(shift=0.0, noise=2_000.0)))
    kept = signature_markdown(compare(_table(shift=0.0, noise=2_000.0)))
    assert "the signature is kept: every interval inside its margin" in kept
    moved = signature_markdown(compare(_table(shift=0.0, noise=60_000.0)))
    assert "moved: whole-demand time per vehicle outside" in moved and "| **no** |" in moved


def test_eager_insertion_is_a_scenario_key_that_reaches_sumo():
    sc = load_scenario(shipped_scenarios_dir() / "default.toml")
    for cfg, flag in ((sc.with_({"sumo.eager_insert": False}).sumo, "false"),
                      (sc.sumo, "true")):
        sim = SumoSimulation("net.xml", "rou.xml", cfg)
        cmd = sim.command()
        sim.close()                  # never started: removes its temporary directory
        assert cmd[cmd.index("--eager-insert") + 1] == flag
    with pytest.raises(ScenarioError, match="eager_insert"):
        sc.with_({"sumo.eager_insert": "no"})


def test_the_study_runs_from_python_with_its_options(monkeypatch, tmp_path):
    """Library code: SumoOptionsOptions in (the design: 6 variants per seed), and without
    SUMO a sweep with a failed run gives exit code 4 and the comparison of the rest."""
    from types import SimpleNamespace

    from arzsumo_studies.common import StudyError
    from arzsumo_studies.sumo_map import sumo_options

    opts = sumo_options.SumoOptionsOptions(seeds=(1, 2), out=tmp_path / "out")
    assert len(sumo_options.design(opts)) == 10 * 2
    asked = {}

    def fake_sweep(spec, out, **kwargs):
        asked["runs"] = len(spec.runs())
        return SimpleNamespace(table=_table(shift=3600.0, noise=360.0),
                               statuses={"ok": 20, "failed": 1})

    monkeypatch.setattr("arzsumo.sweep.driver.run_sweep", fake_sweep)
    result = sumo_options.run_sumo_options(opts, progress=False)
    assert (result.code, result.statuses["failed"], asked["runs"]) == (4, 1, 10 * 2)
    row = result.table[result.table["variant"] == "lateral_resolution_m=1.3"].iloc[0]
    assert row["diff_mean"] == pytest.approx(1.0, abs=0.15)
    assert result.files == (tmp_path / "out" / "sumo_options.csv",)
    with pytest.raises(StudyError, match=r"seeds = \(\) is not allowed"):
        sumo_options.SumoOptionsOptions(seeds=())
    with pytest.raises(StudyError, match=r"--vary = approach is not allowed: distinct"):
        sumo_options.SumoOptionsOptions(seeds=(1,), vary=("approach",))
