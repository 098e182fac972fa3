"""The held-ramp study: its scenario (the meter step at the least release rate) and the
paired table against the meter step."""

from __future__ import annotations

import pandas as pd
import pytest
from arzsumo_studies.ablation import held_ramp
from arzsumo_studies.ablation import study as ablation
from arzsumo_studies.common import StudyError


def test_the_held_ramp_is_the_meter_step_at_its_least_release_rate():
    held = held_ramp.held_scenario()
    meter, _ = ablation.step_scenario("meter")
    assert held["sumo"]["meter_mode"] == "one_per_green"
    assert held["sumo"]["release_rate_veh_h"] == \
        meter["sumo"].get("release_rate_min_veh_h", 240.0) == 240.0
    del held["sumo"]["release_rate_veh_h"]
    assert {k: v for k, v in held.items() if k != "name"} == \
        {k: v for k, v in meter.items() if k != "name"}


def test_the_measures_use_the_evaluations_labels():
    labels = [f"{m.label} ({m.unit})" for m in held_ramp.measures()]
    assert labels[0] == "window time loss, total (veh h)"
    assert labels[-1] == "max ramp queue (veh)" and len(labels) == 7


def _table(controller_loss):
    rows = []
    for controller, loss in controller_loss.items():
        for seed in (1, 2, 3):
            rows.append({"controller": controller, "seed": seed,
                         "network.time_loss_s.total": loss + 3600.0 * seed,
                         "max_ramp_queue": 30.0 + seed})
    return pd.DataFrame(rows)


def test_the_report_pairs_each_run_set_with_the_held_ramp():
    meter = _table({"open": 40000.0, "backstepping": 32800.0, "etc": 36000.0})
    held = _table({"open": 36000.0})
    lines = held_ramp.report(meter, held, [1, 2, 3]).splitlines()
    loss = next(x for x in lines if x.startswith("| window time loss, total"))
    # held: 11, 12, 13 veh h; open +1.11, backstepping -0.889, etc 0 on every seed
    assert "| 12 | +1.11 [+1.11, +1.11] (0/3) | -0.889 [-0.889, -0.889] (3/0) |" in loss
    queue = next(x for x in lines if x.startswith("| max ramp queue"))
    assert queue.startswith("| max ramp queue (veh) | 32 | +0 [")


def test_without_the_meter_step_the_study_refuses_to_run(run_study, tmp_path):
    with pytest.raises(StudyError, match="has no finished 'meter' step"):
        run_study("held-ramp", "--ablation", tmp_path, "--out", tmp_path / "h")


def test_the_study_reports_from_python_with_its_options(tmp_path):
    """Library code: HeldRampOptions(report=True) reads the two evaluations already there
    and runs nothing; the command line builds the same options."""
    import argparse

    from arzsumo_studies.cli import held_ramp as cli

    from arzsumo.outdir import write_marker

    (tmp_path / "abl" / "meter").mkdir(parents=True)
    (tmp_path / "out" / "held").mkdir(parents=True)
    _table({"open": 40000.0, "backstepping": 32800.0, "etc": 36000.0}).to_parquet(
        tmp_path / "abl" / "meter" / "summaries.parquet")
    _table({"open": 36000.0}).to_parquet(tmp_path / "out" / "held" / "summaries.parquet")
    write_marker(tmp_path / "out", "study-held-ramp")          # a held ramp evaluated before
    opts = held_ramp.HeldRampOptions(ablation=tmp_path / "abl", seeds=(1, 2, 3),
                                     report=True, out=tmp_path / "out")
    assert held_ramp.design(opts) == ["held: open on seeds 1-3"]
    result = held_ramp.run_held_ramp(opts)
    assert result.code == 0
    assert "| 12 | +1.11 [+1.11, +1.11] (0/3) |" in result.text
    assert [p.name for p in result.files] == ["held_comparison.md", "held.toml"]
    parser = argparse.ArgumentParser()
    cli.add_arguments(parser)
    assert cli.options(parser.parse_args(["--ablation", str(tmp_path / "abl"), "--seeds",
                                          "1-3", "--report", "--out",
                                          str(tmp_path / "out")])) == opts
    with pytest.raises(StudyError, match=r"seeds = \(1, 1\) is not allowed"):
        held_ramp.HeldRampOptions(seeds=(1, 1))
