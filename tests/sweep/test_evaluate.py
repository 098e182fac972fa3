"""``arzsumo evaluate`` with real SUMO: 2 controllers x 3 seeds, short runs; the report's
paired differences are those of the runs' own summaries; a restart runs nothing again."""

import json
import math
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from arzsumo.cli import main
from arzsumo.evaluation.report import MEASURES

ROOT = Path(__file__).resolve().parents[2]
SEEDS = (5, 6, 7)
pytestmark = pytest.mark.sumo


def _scenario(tmp: Path) -> Path:
    text = (ROOT / "scenarios" / "legacy_default.toml").read_text(encoding="utf-8")
    text = text.replace("warmup_s = 150", "warmup_s = 30").replace(
        "kernel_cells = 100", "kernel_cells = 40").replace("twin_cells = 100", "twin_cells = 40")
    text = text.replace("[sumo]\n", "[sumo]\ndrain_max_s = 900\n")   # the whole demand
    path = tmp / "short.toml"
    path.write_text(text, encoding="utf-8")
    return path


def _evaluate(scenario: Path, out: Path, *extra: str) -> int:
    return main(["evaluate", str(scenario), "--controllers", "alinea", "--seeds", "3",
                 "--seed-start", str(SEEDS[0]), "--horizon", "30", "--workers", "2",
                 "--quiet", "--out", str(out), *extra])


@pytest.fixture(scope="module")
def evaluation(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("evaluate")
    scenario, out = _scenario(tmp), tmp / "out"
    assert _evaluate(scenario, out) == 0           # open is added as the baseline
    return scenario, out


def _value(summary: dict, dotted: str) -> float:
    for part in dotted.split("."):
        summary = summary[part]
    return math.nan if summary is None else float(summary)


def test_paired_differences_are_those_of_the_runs(evaluation):
    _, out = evaluation
    csv = pd.read_csv(out / "evaluation.csv")
    assert set(csv["controller"]) == {"open", "alinea"}
    assert len(csv) == 2 * len(MEASURES)
    runs = {(c, s): json.loads((out / "runs" / f"controller={c},seed={s}" /
                                "summary.json").read_text())
            for c in ("open", "alinea") for s in SEEDS}
    for m in MEASURES:
        row = csv[(csv.measure == m.key) & (csv.controller == "alinea")].iloc[0]
        d = np.array([_value(runs["alinea", s], m.key) - _value(runs["open", s], m.key)
                      for s in SEEDS]) * m.scale
        mean = np.array([_value(runs["alinea", s], m.key) for s in SEEDS]) * m.scale
        if np.isnan(mean).all():    # 30 s resolve neither the 1-10 min band nor a growth
            assert row["n"] == 0 and m.key.startswith("section.waves."), m.key
            continue
        assert row["n"] == 3, m.key
        assert row["diff_mean"] == pytest.approx(d.mean(), abs=1e-9), m.key
        assert row["mean"] == pytest.approx(mean.mean(), abs=1e-9), m.key
        better = -d if m.lower_is_better else d
        assert row["wins"] == int((better > 0).sum()), m.key
        assert row["wins"] + row["losses"] + row["ties"] == 3
        if np.ptp(d) > 1e-9 * max(1.0, np.abs(d).max()):
            half = 4.302652729911275 * d.std(ddof=1) / np.sqrt(3)   # t(0.975, 2)
            assert row["diff_ci_high"] - row["diff_mean"] == pytest.approx(half, rel=1e-6)
    # the open loop against itself: 0 with a zero-width interval, all ties
    base = csv[(csv.controller == "open") & (csv.n > 0)]
    assert (base["diff_mean"] == 0).all() and (base["diff_ci_low"] == 0).all()
    assert (base["diff_ci_high"] == 0).all() and (base["ties"] == 3).all()
    assert (out / "paired_differences.png").stat().st_size > 10_000
    text = (out / "evaluation.md").read_text()
    assert "| window time loss, total (lower is better) | veh h | alinea | 3 |" in text


def test_a_restart_runs_nothing_again(evaluation, capsys):
    scenario, out = evaluation
    before = (out / "executions.jsonl").read_text().splitlines()
    assert len(before) == 6
    csv = (out / "evaluation.csv").read_text()
    capsys.readouterr()
    assert _evaluate(scenario, out) == 0
    assert "6 runs, 6 already finished, 0 executed" in capsys.readouterr().out
    assert (out / "executions.jsonl").read_text().splitlines() == before
    assert (out / "evaluation.csv").read_text() == csv


def test_user_mistakes_are_one_line_and_start_nothing(evaluation, tmp_path, capsys):
    scenario, _ = evaluation
    assert main(["evaluate", str(scenario), "--controllers", "open,pid", "--quiet",
                 "--out", str(tmp_path / "x")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--controllers = 'open,pid' is not allowed" in err
    assert not (tmp_path / "x").exists()
    (tmp_path / "mine").mkdir()
    (tmp_path / "mine" / "notes.txt").write_text("keep")
    assert main(["evaluate", str(scenario), "--controllers", "open", "--seeds", "1",
                 "--quiet", "--out", str(tmp_path / "mine"), "--overwrite"]) == 2
    assert "not an arzsumo result" in capsys.readouterr().err
    assert (tmp_path / "mine" / "notes.txt").read_text() == "keep"


def test_a_borrowed_baseline_is_the_same_open_loop(evaluation, tmp_path, capsys):
    """An evaluation whose scenario differs only in [sensing], [estimation] takes the open-loop runs
    of the first one (none run again) and pairs against them; sensors that only read do
    not change the open loop (a fresh open run with them gives the same SUMO numbers)."""
    scenario, out = evaluation
    step = tmp_path / "step.toml"
    step.write_text(scenario.read_text() + '\n[sensing]\nkinds = ["loops", "av_probes"]\n'
                    '[estimation]\nmethod = "smoothing"\n')
    out2 = tmp_path / "out2"
    assert _evaluate(step, out2, "--baseline-from", str(out)) == 0
    assert "3 runs, 0 already finished, 3 executed" in capsys.readouterr().out
    assert not (out2 / "runs" / "controller=open,seed=5").exists()
    csv = pd.read_csv(out2 / "evaluation.csv")
    first = pd.read_csv(out / "evaluation.csv")
    key = "network.time_loss_s.total"
    for c in ("open", "alinea"):
        a = csv[(csv.measure == key) & (csv.controller == c)].iloc[0]
        b = first[(first.measure == key) & (first.controller == c)].iloc[0]
        assert a["mean"] == pytest.approx(b["mean"], abs=1e-9)    # estimation is inert
    # the premise: an open loop with the estimator gives the same SUMO numbers
    assert main(["evaluate", str(step), "--controllers", "open", "--seeds", "1",
                 "--seed-start", str(SEEDS[0]), "--horizon", "30", "--workers", "1",
                 "--quiet", "--no-plots", "--out", str(tmp_path / "fresh")]) == 0
    fresh = json.loads((tmp_path / "fresh" / "runs" / f"controller=open,seed={SEEDS[0]}" /
                        "summary.json").read_text())
    old = json.loads((out / "runs" / f"controller=open,seed={SEEDS[0]}" /
                      "summary.json").read_text())
    assert fresh["network"] == old["network"]
    assert fresh["speed_variance"] == old["speed_variance"]


def test_a_baseline_that_differs_in_sumo_is_refused(evaluation, tmp_path, capsys):
    scenario, out = evaluation
    step = tmp_path / "step.toml"
    step.write_text(scenario.read_text().replace("ramp_demand_veh_h = 1200",
                                                 "ramp_demand_veh_h = 900"))
    assert _evaluate(step, tmp_path / "o", "--baseline-from", str(out)) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "differs in sumo.ramp_demand_veh_h" in err
    assert not (tmp_path / "o").exists()


def test_a_borrowed_baseline_needs_a_controller_to_run(evaluation, tmp_path, capsys):
    scenario, out = evaluation
    assert main(["evaluate", str(scenario), "--controllers", "open", "--quiet",
                 "--out", str(tmp_path / "o"), "--baseline-from", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--controllers = 'open' is not allowed with" in err
    assert not (tmp_path / "o").exists()


def test_a_baseline_under_another_model_is_borrowed_when_sumo_is_given_the_same(
        evaluation, tmp_path, capsys):
    """With [run] start = "warmup", a model that changes neither the vehicle types nor the
    insertion columns of SUMO's route file reaches the open loop nowhere (it drives the
    twins), so the step borrows the baseline; the premise: a fresh open run under the other
    model gives the same SUMO numbers. The section delay, computed with the model's free
    speeds, is blanked in the borrowed baseline rather than paired across two models."""
    scenario, out = evaluation
    step = tmp_path / "model.toml"
    text = scenario.read_text().replace("tau_h_s = 30", "tau_h_s = 20").replace(
        "rho_a_veh_km = 41.2363", "rho_a_veh_km = 38")
    assert "tau_h_s = 20" in text and "rho_a_veh_km = 38" in text
    step.write_text(text)
    assert _evaluate(step, tmp_path / "o", "--baseline-from", str(out)) == 0
    assert "3 runs, 0 already finished, 3 executed" in capsys.readouterr().out
    csv = pd.read_csv(tmp_path / "o" / "evaluation.csv").set_index(["measure", "controller"])
    assert csv.loc[("section.total_delay.total", "open"), "n"] == 0
    assert csv.loc[("section.total_delay.total", "alinea"), "diff_mean"] != \
        csv.loc[("section.total_delay.total", "alinea"), "diff_mean"]          # NaN
    assert csv.loc[("network.time_loss_s.total", "open"), "n"] == 3
    assert main(["evaluate", str(step), "--controllers", "open", "--seeds", "1",
                 "--seed-start", str(SEEDS[0]), "--horizon", "30", "--workers", "1",
                 "--quiet", "--no-plots", "--out", str(tmp_path / "fresh")]) == 0
    run = f"controller=open,seed={SEEDS[0]}"
    fresh = json.loads((tmp_path / "fresh" / "runs" / run / "summary.json").read_text())
    old = json.loads((out / "runs" / run / "summary.json").read_text())
    assert fresh["network"] == old["network"]
    for key in ("speed_sd_kmh", "speed_mean_kmh", "speed_oscillation_kmh"):
        assert fresh["section"][key] == old["section"][key]
    assert fresh["equilibrium"] != old["equilibrium"]      # the twins did see the model


def test_a_model_that_changes_the_vehicles_is_not_borrowed(evaluation, tmp_path, capsys):
    scenario, out = evaluation
    step = tmp_path / "longer.toml"
    step.write_text(scenario.read_text().replace("spacing_h_m = 8", "spacing_h_m = 9"))
    assert _evaluate(step, tmp_path / "o", "--baseline-from", str(out)) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "differs in model.spacing_h_m" in err
    assert not (tmp_path / "o").exists()


def test_the_model_is_not_inert_when_vehicles_are_placed_from_it():
    import tomllib

    from arzsumo.sweep.evaluate import _model_inert

    base = tomllib.loads((ROOT / "scenarios" / "legacy_default.toml").read_text())
    other = {**base, "model": {**base["model"], "tau_h_s": 20}}
    assert _model_inert(base, other)
    placed = {**other, "run": {**base["run"], "start": "placement"}}
    assert not _model_inert(base, placed)
    wider = {**base, "model": {**base["model"], "vehicle_width_m": 1.8}}
    assert not _model_inert(base, wider)


def test_runs_of_every_controller_are_taken_from_earlier_evaluations(evaluation, tmp_path,
                                                                      capsys):
    """A scenario that gains an [alinea] table changes the runs of ALINEA only: the open
    loop is taken from the first evaluation, ALINEA is run again; a third evaluation takes
    both from the two before and runs nothing, with the same report."""
    scenario, out = evaluation
    step = tmp_path / "step.toml"
    step.write_text(scenario.read_text() + "\n[alinea]\nperiod_s = 20\n")
    out2, out3 = tmp_path / "out2", tmp_path / "out3"
    assert _evaluate(step, out2, "--runs-from", str(out)) == 0
    assert "3 runs, 0 already finished, 3 executed" in capsys.readouterr().out
    assert not (out2 / "runs" / "controller=open,seed=5").exists()
    assert (out2 / "runs" / "controller=alinea,seed=5" / "summary.json").is_file()
    assert _evaluate(step, out3, "--runs-from", str(out), "--runs-from", str(out2)) == 0
    assert "every run taken from --runs-from, none executed" in capsys.readouterr().out
    second, third = (pd.read_csv(d / "evaluation.csv") for d in (out2, out3))
    pd.testing.assert_frame_equal(second, third)
    assert "Runs of `alinea` taken from" in (out3 / "evaluation.md").read_text()


def test_runs_that_differ_in_what_the_controller_reads_are_not_taken(evaluation, tmp_path):
    from arzsumo.sweep.evaluate import borrowed_controller, evaluation_spec

    scenario, out = evaluation
    step = tmp_path / "step.toml"
    step.write_text(scenario.read_text() + "\n[alinea]\nperiod_s = 20\n")
    spec = evaluation_spec(step, ["alinea"], SEEDS, 30.0)
    assert borrowed_controller(spec, out) is None                   # ALINEA reads [alinea]
    taken = borrowed_controller(evaluation_spec(step, ["open"], SEEDS, 30.0), out)
    assert taken is not None and list(taken["seed"]) == list(SEEDS)  # the open loop not
    other = tmp_path / "other.toml"
    other.write_text(scenario.read_text().replace("ramp_demand_veh_h = 1200",
                                                  "ramp_demand_veh_h = 900"))
    assert borrowed_controller(evaluation_spec(other, ["open"], SEEDS, 30.0), out) is None
