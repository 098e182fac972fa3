"""The options every study shares and the resumable execution of a design."""

from __future__ import annotations

import argparse
import json

import pytest
from arzsumo_studies import design as design_module
from arzsumo_studies.common import (
    METER_KEYS,
    fixed_cycle,
    number_list,
    scenario_data,
    seed_list,
    seed_text,
    shipped_scenario,
    study_spec,
)
from arzsumo_studies.design import StudyRun, design_runs, run_design


@pytest.mark.parametrize(("text", "seeds"), [("1-3,7", [1, 2, 3, 7]), ("42", [42]),
                                             ("0,2", [0, 2])])
def test_seed_lists_take_ranges_and_lists(text, seeds):
    assert seed_list(text) == seeds


@pytest.mark.parametrize("text", ["3-1", "a", "1,1", "-2", "2147483648"])
def test_bad_seed_lists_are_refused(text):
    with pytest.raises(argparse.ArgumentTypeError, match="is not allowed"):
        seed_list(text)


def test_seed_text_and_number_lists():
    assert (seed_text([3, 1, 2]), seed_text([1, 2]), seed_text([1, 5, 7])) == \
        ("1-3", "1,2", "1,5,7")
    assert number_list("0.2,0.5") == [0.2, 0.5]
    with pytest.raises(argparse.ArgumentTypeError):
        number_list("0.2,inf")


def test_the_fixed_cycle_base_drops_the_defaults_meter_realisation():
    data = scenario_data(shipped_scenario("default.toml"))
    assert all(k in data["sumo"] for k in METER_KEYS)
    base = fixed_cycle(data)
    assert not any(k in base["sumo"] for k in METER_KEYS)
    assert base["sumo"]["demand_h_veh_h"] == data["sumo"]["demand_h_veh_h"] == 3198
    assert all(k in data["sumo"] for k in METER_KEYS)          # the input is left alone


CALLS: list[str] = []


def _worker(run: StudyRun) -> dict:
    CALLS.append(run.run_id)
    return {"seed": run.scenario["sumo"]["seed"], "scale": run.options["scale"]}


def _runs(scale: float) -> list[StudyRun]:
    spec = study_spec("toy", shipped_scenario("default.toml"), seeds=[1, 2])
    return design_runs(spec, {"scale": scale})


def test_a_design_runs_once_and_a_changed_option_runs_again(tmp_path):
    CALLS.clear()
    rows = run_design(_runs(1.0), _worker, tmp_path, in_process=True, progress=False)
    assert rows == [{"seed": 1, "scale": 1.0}, {"seed": 2, "scale": 1.0}]
    assert run_design(_runs(1.0), _worker, tmp_path, in_process=True) == rows
    assert CALLS == ["seed=1", "seed=2"]                     # the second call ran nothing
    doc = json.loads((tmp_path / "runs" / "seed=2.json").read_text())
    assert doc["sha256"] == _runs(1.0)[1].sha256 != _runs(2.0)[1].sha256
    assert run_design(_runs(2.0), _worker, tmp_path, in_process=True)[0]["scale"] == 2.0
    assert CALLS == ["seed=1", "seed=2", "seed=1", "seed=2"]


def test_a_design_runs_on_the_sweep_engines_process_pool(tmp_path):
    rows = run_design(_runs(3.0), design_module_worker, tmp_path, workers=2, progress=False)
    assert [r["seed"] for r in rows] == [1, 2]


def design_module_worker(run: StudyRun) -> dict:
    """A module-level worker the spawned processes can import."""
    return {"seed": run.scenario["sumo"]["seed"], "module": design_module.__name__}


def test_a_design_on_a_relative_scenario_path_reads_that_file(monkeypatch):
    root = shipped_scenario("default.toml").parent
    monkeypatch.chdir(root.parent)
    spec = study_spec("toy", root.relative_to(root.parent) / "legacy_default.toml", seeds=[1])
    assert spec.base == root / "legacy_default.toml"


def test_a_scenario_name_cannot_lead_outside_the_directory_of_its_file():
    from arzsumo_studies.common import file_stem

    assert file_stem("default") == "default"
    assert file_stem("../../etc/x y") == "_.._etc_x_y"
    assert "/" not in file_stem("a/b") and file_stem("...") == "scenario"
