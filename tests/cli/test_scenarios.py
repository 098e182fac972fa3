"""Scenario arguments by shipped name, and the checks made before any simulation: the
warm-up against the fill phase, observer-ETC's sensing in ``--dry-run`` (no SUMO)."""

from __future__ import annotations

import contextlib
import io
from pathlib import Path

import pytest

from arzsumo.api.scenarios import scenario_file, sweep_file
from arzsumo.bridge.session import check_warmup
from arzsumo.cli import main
from arzsumo.errors import ScenarioError
from arzsumo.resources import shipped_named, shipped_scenarios_dir
from arzsumo.scenario import load_scenario

SHIPPED = shipped_scenarios_dir()


def cli(*args: str) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main(list(args))
    return code, out.getvalue(), err.getvalue()


@pytest.mark.parametrize(("name", "where"), [
    ("default", "default.toml"), ("default.toml", "default.toml"),
    ("base_etc", "paper/base_etc.toml"), ("paper/base_etc", "paper/base_etc.toml")])
def test_shipped_names_resolve(name, where):
    assert shipped_named(name) == SHIPPED / where
    assert scenario_file(name) == SHIPPED / where


@pytest.mark.parametrize("name", ["sweeps/demand_sumo", "demand_sumo", "../default",
                                  "paper/../default", "./default", "nope"])
def test_other_names_are_not_scenarios(name):
    assert shipped_named(name) is None


def test_a_file_wins_over_a_name_and_sweeps_have_their_own(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "default").write_text("name = 'mine'\n")
    assert scenario_file("default") == Path("default")
    assert sweep_file("demand_sumo") == SHIPPED / "sweeps" / "demand_sumo.toml"
    with pytest.raises(ScenarioError, match=r"^sweep = 'paper_base' does not exist: .*"
                                            r"demand_sumo"):
        sweep_file("paper_base")


def test_run_twin_and_sweep_take_a_name_from_any_directory(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    code, out, err = cli("run", "default", "--dry-run")
    assert (code, err) == (0, "")
    assert out.startswith(f"scenario default ({SHIPPED / 'default.toml'}): valid")
    assert cli("run", str(SHIPPED / "default.toml"), "--dry-run")[1] == out
    code, out, _ = cli("sweep", "demand_twin", "--list")
    assert code == 0 and len(out.split()) > 1
    assert list(tmp_path.iterdir()) == []


def test_an_unknown_name_is_one_line_naming_the_shipped_ones():
    code, out, err = cli("twin", "defualt")
    assert code == 2 and out == "" and err.count("\n") == 1
    assert err.startswith("arzsumo: error: scenario = 'defualt' (did you mean 'default'?) "
                          "does not exist: neither a file nor a shipped name; allowed: a TOML "
                          "file or one of default, ")
    assert "legacy_default" in err and "'arzsumo list'" in err


def test_a_warmup_shorter_than_the_fill_is_refused_with_the_values(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)      # a dry run checks the default --out under results/
    code, out, err = cli("run", "default", "--dry-run", "--warmup", "5", "--horizon", "5")
    assert code == 2 and out == "" and err.count("\n") == 1
    assert err == ("arzsumo: error: --warmup = 5 is not allowed: the control window (5-10 s) "
                   "starts inside the fill phase of default ([sumo] fill_s = 600 s), so its "
                   "measures describe the fill; allowed: a warm-up >= 600 s, or "
                   "--allow-short-warmup\n")
    code, out, _ = cli("run", "default", "--dry-run", "--warmup", "5", "--horizon", "5",
                       "--allow-short-warmup")
    assert code == 0 and "warm-up 5 s + control horizon 5 s" in out
    assert cli("run", "default", "--dry-run", "--warmup", "600")[0] == 0
    assert cli("run", "legacy_default", "--dry-run", "--warmup", "5")[0] == 0   # no fill


def test_a_scenario_warmup_shorter_than_its_fill_names_the_key(tmp_path):
    text = (SHIPPED / "default.toml").read_text().replace("warmup_s = 600", "warmup_s = 300")
    (tmp_path / "s.toml").write_text(text)
    sc = load_scenario(tmp_path / "s.toml")
    with pytest.raises(ScenarioError, match=r"s.toml: \[run\] warmup_s = 300 is not allowed: "
                                            r"the control window \(300-750 s\)"):
        check_warmup(sc, None, None, False)
    check_warmup(sc, None, None, True)
    check_warmup(sc, 600.0, None, False)


def test_evaluate_has_warmup_and_refuses_a_short_one_before_any_run(tmp_path):
    out = tmp_path / "ev"
    code, _, err = cli("evaluate", "default", "--warmup", "120", "--seeds", "1",
                       "--out", str(out))
    assert code == 2 and err.startswith("arzsumo: error: --warmup = 120 is not allowed")
    assert "fill_s = 600 s" in err and not out.exists()
    code, _, err = cli("evaluate", "default", "--warmup", "nan", "--out", str(out))
    assert code == 2 and err.startswith("arzsumo: error: --warmup = nan is not allowed")


def test_evaluation_spec_sets_the_warmup():
    from arzsumo.sweep.evaluate import evaluation_spec

    spec = evaluation_spec(SHIPPED / "legacy_default.toml", ["open"], [1], 30.0, 45.0)
    run = next(iter(spec.runs()))
    assert run.scenario["run"]["warmup_s"] == 45.0
    assert run.scenario["sumo"]["horizon_s"] == 30.0
    plain = next(iter(evaluation_spec(SHIPPED / "legacy_default.toml", ["open"], [1]).runs()))
    assert plain.scenario["run"]["warmup_s"] == 150


def _sensing_line(*args: str) -> str:
    code, out, err = cli("run", *args, "--dry-run")
    assert code == 0, err
    return out.splitlines()[3]


def test_dry_run_says_observer_etc_reads_the_boundary_loops_only(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)      # a dry run checks the default --out under results/
    line = _sensing_line("default", "--controller", "observer-etc")
    assert line == ("  estimation smoothing from the boundary loops only (x = 0 and x = L), "
                    "the ETC acting on that estimate")
    assert _sensing_line("default") == "  estimation smoothing from sensors loops, av_probes"
    assert "inlet speeds only" in _sensing_line("legacy_default", "--controller",
                                                "observer-etc")


def test_dry_run_refuses_the_out_directory_the_run_would_refuse(tmp_path):
    """A foreign non-empty directory, or a run's result without --overwrite: exit 2 and one
    line, as the real run gives before SUMO starts; nothing is created or deleted."""
    foreign = tmp_path / "mine"
    foreign.mkdir()
    (foreign / "notes.txt").write_text("keep me", encoding="utf-8")
    code, out, err = cli("run", "default", "--dry-run", "--out", str(foreign))
    assert code == 2 and out == "" and len(err.strip().splitlines()) == 1
    assert "--out" in err and (foreign / "notes.txt").read_text(encoding="utf-8") == "keep me"
    result = tmp_path / "result"
    result.mkdir()
    from arzsumo.outdir import write_marker

    write_marker(result, "run")
    (result / "summary.json").write_text("{}", encoding="utf-8")
    code, _, err = cli("run", "default", "--dry-run", "--out", str(result))
    assert code == 2 and "--overwrite" in err
    code, out, _ = cli("run", "default", "--dry-run", "--out", str(result), "--overwrite")
    assert code == 0 and "valid" in out
    code, out, _ = cli("run", "default", "--dry-run", "--out", str(tmp_path / "new" / "run"))
    assert code == 0 and not (tmp_path / "new").exists()
