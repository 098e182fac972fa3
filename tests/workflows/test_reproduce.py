"""``arzsumo reproduce``: planning, shared open loops, report and CSV, verdicts."""

from __future__ import annotations

import csv
import math
from pathlib import Path

import pytest

from arzsumo.cli import main
from arzsumo.engines.twin import run_twin
from arzsumo.errors import ScenarioError
from arzsumo.scenario import load_scenario
from arzsumo.workflows.paper.compare import (
    NOT_REPRODUCED,
    REPRODUCED,
    claims,
    direction,
    trend,
)
from arzsumo.workflows.paper.report import write_reproduction
from arzsumo.workflows.paper.reproduce import DEFAULT_DIR, load_experiments, plan, reproduce

PAPER_DIR = Path(__file__).resolve().parents[2] / "scenarios" / "paper"
SUBSET = ["base_open", "base_backstepping", "base_etc", "penetration_44_etc",
          "penetration_53_etc", "sensitivity_zeta"]


@pytest.fixture(scope="module")
def quick(tmp_path_factory):
    """A quick reproduction of a subset, written once for the module."""
    mp = pytest.MonkeyPatch()
    mp.setenv("ARZSUMO_CACHE", str(tmp_path_factory.mktemp("cache")))
    rep = reproduce(PAPER_DIR, quick=True, only=SUBSET, workers=1)
    out = write_reproduction(rep, tmp_path_factory.mktemp("rep") / "out")
    yield rep, out
    mp.undo()


def _csv(path: Path) -> list[dict[str, str]]:
    with path.open(encoding="utf-8") as fh:
        return list(csv.DictReader(fh))


def test_every_section5_experiment_has_a_scenario_file():
    names = {sc.name for sc in load_experiments(PAPER_DIR)}
    for c in ("open", "backstepping", "etc", "observer_etc"):
        assert f"base_{c}" in names
    for n in ("s12_etc", "aggressive_etc", "nonrecurrent_etc", "linear_etc",
              "demand_high_etc", "demand_medium_etc", "demand_low_etc",
              "penetration_44_etc", "penetration_47_etc", "penetration_50_etc",
              "penetration_53_etc", "sensitivity_mu", "sensitivity_sigma", "sensitivity_zeta"):
        assert n in names
    assert DEFAULT_DIR.parts == ("scenarios", "paper")


def test_penetration_scenarios_keep_the_base_inflow_on_the_congested_branch():
    from arzsumo.model import linearize

    base = load_scenario(PAPER_DIR / "base_etc.toml").equilibrium
    for pen in (44, 47, 50, 53):
        eq = load_scenario(PAPER_DIR / f"penetration_{pen}_etc.toml").equilibrium
        assert eq.q == pytest.approx(base.q, rel=1e-6)
        assert eq.penetration == pytest.approx(pen / 100)
        assert linearize(eq).regime == "congested"


def test_demand_scenarios_are_congested_and_carry_their_demands():
    from arzsumo.model import linearize

    for level, total in (("high", 6510), ("medium", 5664), ("low", 4966)):
        eq = load_scenario(PAPER_DIR / f"demand_{level}_etc.toml").equilibrium
        assert eq.q * 3600 == pytest.approx(total, rel=1e-9)
        assert linearize(eq).regime == "congested"


def test_plan_groups_controllers_that_share_an_open_loop():
    tasks = plan(load_experiments(PAPER_DIR))
    group = {t.scenario.name: t.group for t in tasks if t.sweep is None}
    assert group["base_open"] == group["base_etc"] == group["base_observer_etc"]
    assert group["base_etc"] != group["s12_etc"]
    sweeps = [t for t in tasks if t.sweep is not None]
    assert {t.group for t in sweeps} == {group["base_etc"]}
    assert {t.sweep[0] for t in sweeps} == {"mu", "sigma", "zeta"}


def test_quick_reproduction_reuses_open_loops_and_writes_everything(quick):
    rep, out = quick
    assert rep.quick
    assert rep.open_loops == 3                    # base, 44 %, 53 %
    assert len(rep.records) == 5 + 5              # 5 scenarios + 5 zeta values
    for name in ("report.md", "diffperformance.csv", "totaldelay.csv", "diffpene.csv",
                 "events.csv", "sensitivity.csv", "claims.csv", "runs.csv",
                 "summaries.json", "release_instants.png", "penetration.png",
                 "sensitivity.png"):
        assert (out / name).stat().st_size > 0, name
    text = (out / "report.md").read_text()
    assert "## Table diffperformance" in text and "Quick mode" in text


def test_csv_numbers_equal_the_run_summaries(quick):
    rep, out = quick
    for row in _csv(out / "diffperformance.csv"):
        rec = rep.get(row["scenario"])
        for key in ("J_fuel", "J_discom", "J_TTT"):
            assert float(row[f"ours_{key}_percent"]) == pytest.approx(
                rec.relative("total", key), abs=1e-4)
        assert float(row["ours_release_time_s"]) == rec.summary["release_time"]
        assert int(row["ours_triggers"]) == rec.summary["triggers"]
    for row in _csv(out / "totaldelay.csv"):
        rec = rep.get(row["scenario"])
        assert float(row["ours_AV_delay_percent"]) == pytest.approx(
            rec.summary["relative_to_open_loop_percent"]["a"]["total_delay"], abs=1e-4)
    pene = _csv(out / "diffpene.csv")
    assert [int(r["penetration_percent"]) for r in pene] == [44, 53]
    for row in pene:
        rec = rep.get(row["scenario"])
        assert int(row["ours_triggers"]) == rec.summary["triggers"]
    runs = {r["name"]: r for r in _csv(out / "runs.csv")}
    for rec in rep.records:
        assert int(runs[rec.name]["triggers"]) == rec.summary["triggers"]
        assert float(runs[rec.name]["J_TTT_total"]) == pytest.approx(
            rec.summary["J_TTT"]["total"], rel=1e-12)


def test_shared_open_loop_is_the_baseline_of_each_controller(quick):
    rep, _ = quick
    opn, etc = rep.get("base_open"), rep.get("base_etc")
    expected = 100 * (etc.summary["J_TTT"]["total"] - opn.summary["J_TTT"]["total"]) \
        / opn.summary["J_TTT"]["total"]
    assert etc.relative("total", "J_TTT") == pytest.approx(expected, rel=1e-9)
    assert math.isnan(opn.relative("total", "J_TTT"))


def test_quick_numbers_are_pinned(quick):
    # recorded with `arzsumo reproduce --quick` before paper reproduction moved out of twin/
    # into studies/ and onto the sweep engine: the move must not change a number
    rep, out = quick
    etc, back, opn = rep.get("base_etc"), rep.get("base_backstepping"), rep.get("base_open")
    assert (etc.triggers, etc.release_time) == (3, 37.0)
    assert etc.summary["final_norm_ratio"] == pytest.approx(1.1636401548102235, rel=1e-12)
    assert etc.summary["J_fuel"]["total"] == pytest.approx(206.73892605824363, rel=1e-12)
    assert (back.triggers, back.release_time) == (40, 0.0)
    assert (opn.triggers, opn.release_time) == (0, 40.0)         # never updated: the horizon
    rows = {r["name"]: r for r in _csv(out / "runs.csv")}
    assert (rows["base_etc"]["triggers"], rows["base_etc"]["release_time_s"]) == ("3", "37.0")


def test_workers_do_not_change_results(quick, tmp_path, monkeypatch):
    monkeypatch.setenv("ARZSUMO_CACHE", str(tmp_path))
    rep, _ = quick
    two = reproduce(PAPER_DIR, quick=True, only=["base_etc", "penetration_44_etc"], workers=2)
    for rec in two.records:
        assert rec.summary["triggers"] == rep.get(rec.name).summary["triggers"]
        assert rec.summary["J_fuel"] == rep.get(rec.name).summary["J_fuel"]


def test_paper_base_numbers_at_two_percent():
    """Backstepping below 1 % of the initial deviation by 450 s; ETC with < 225 updates."""
    bs = run_twin(load_scenario(PAPER_DIR / "base_backstepping.toml"), baseline=False)
    etc = run_twin(load_scenario(PAPER_DIR / "base_etc.toml"), baseline=False)
    assert bs.result.complete and etc.result.complete
    assert bs.norm[-1] / bs.norm[0] < 0.01
    assert bs.triggers == 450
    assert etc.triggers < 450 / 2
    assert etc.norm[-1] / etc.norm[0] < 0.25


@pytest.mark.parametrize(("paper", "ours", "verdict"), [
    (-0.5, -0.2, REPRODUCED), (-0.5, 0.2, NOT_REPRODUCED), (-0.5, -0.01, NOT_REPRODUCED),
    (2.0, 1.0, REPRODUCED), (-1.0, math.nan, NOT_REPRODUCED)])
def test_direction(paper, ours, verdict):
    assert direction(paper, ours)[0] == verdict


def test_trend():
    assert trend(80, 82) == "longer"
    assert trend(82, 80) == "shorter"
    assert trend(82, 82.5) == "flat"
    assert trend(82, math.inf) == "longer"


def test_claims_cover_the_headlines(quick):
    rep, _ = quick
    text = " ".join(c.claim for c in claims(rep))
    assert "ETC performance close to backstepping" in text
    assert "More AVs" in text
    assert "Backstepping brings the deviation norm below 1 %" in text
    assert "Sensitivity to zeta" in text


@pytest.mark.parametrize(("sweep", "match"), [
    ({"parameter": "nu", "values": [1.0]}, r'parameter = "nu" is not allowed: one of'),
    ({"parameter": "mu", "values": []}, r"values = \[\] is not allowed"),
    ({"parameter": "mu"}, r"exactly the keys parameter and values"),
])
def test_bad_sweeps_are_refused(tmp_path, sweep, match):
    lines = ['name = "bad"', "[model]", 'preset = "paper_base"', "[sweep]"]
    lines += [f"{k} = {v!r}".replace("'", '"') for k, v in sweep.items()]
    (tmp_path / "bad.toml").write_text("\n".join(lines) + "\n")
    with pytest.raises(ScenarioError, match=match):
        plan(load_experiments(tmp_path))


def test_unknown_names_and_directories_are_refused(tmp_path):
    with pytest.raises(ScenarioError, match=r"only = \['nope'\] is not allowed"):
        plan(load_experiments(PAPER_DIR), only=["nope"])
    with pytest.raises(ScenarioError, match="is not a directory"):
        load_experiments(tmp_path / "missing")
    with pytest.raises(ScenarioError, match="holds no"):
        load_experiments(tmp_path)


def test_cli_reproduce_quick(tmp_path, monkeypatch, capsys):
    monkeypatch.setenv("ARZSUMO_CACHE", str(tmp_path / "cache"))
    out = tmp_path / "rep"
    code = main(["reproduce", "--quick", "--scenarios", str(PAPER_DIR), "--only", "base_open",
                 "base_etc", "--out", str(out), "--no-plots"])
    assert code == 0
    assert (out / "report.md").exists() and not (out / "sensitivity.png").exists()
    captured = capsys.readouterr()
    assert "claims reproduced in direction in the smoke test" in captured.out
    verdicts = [line for line in captured.out.splitlines() if line.startswith("  [")]
    assert verdicts and all(line.startswith(("  [smoke yes]", "  [smoke NO ]"))
                            for line in verdicts)
    assert "quick: a smoke test" in captured.out.splitlines()[0]
    assert "open loops for" not in captured.err          # no stray log line
    # the claims quote the run's own horizon, the report its own grid
    assert "at 40 s:" in captured.out and "450 s" not in captured.out
    assert "the grid is 40 cells" in (out / "report.md").read_text(encoding="utf-8")


def test_twin_overrides_reach_every_scenario_and_are_validated():
    tasks = plan(load_experiments(PAPER_DIR), only=["base_etc", "linear_etc"],
                 twin={"scheme": "muscl"})
    for t in tasks:
        assert t.scenario.twin.solver.scheme == "muscl"
    with pytest.raises(ScenarioError, match=r'\[twin\] scheme = "third" is not allowed'):
        plan(load_experiments(PAPER_DIR), only=["base_etc"], twin={"scheme": "third"})
