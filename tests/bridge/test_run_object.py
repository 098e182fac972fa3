"""One run object: the engine runs what ``prepare_run`` made of a scenario, and nothing
else; every run in the tests (and the package, and the benchmarks) is made as users' runs
are, through ``prepare_run`` (``tests/runs.py`` changes scenario keys first)."""

from __future__ import annotations

import ast
import inspect
import typing
from pathlib import Path

import pytest

from arzsumo.bridge import cosim
from arzsumo.bridge.session import PreparedRun
from arzsumo.control.etc import EtcDesign
from arzsumo.scenario import Scenario
from arzsumo.scenario.run import RunSettings
from arzsumo.sumo.config import SumoConfig
from arzsumo.sumo.green_share import GreenShareCurve

ROOT = Path(__file__).resolve().parents[2]
#: what a caller may add to the run object: how the run is watched and what it keeps
RUN_TIME = {"progress", "keep_measurements", "frontend"}
#: the configuration a run object carries; no stage takes it alongside
CONFIG = (Scenario, RunSettings, SumoConfig, EtcDesign, GreenShareCurve)
STAGES = [cosim.open_run, cosim.warm_start, cosim.finish_run, cosim.control]


def _calls(name: str, folder: str) -> list[tuple[Path, ast.Call]]:
    """Every call of ``name`` (as a name or an attribute) in the Python files of
    ``folder``."""
    out = []
    for path in sorted((ROOT / folder).rglob("*.py")):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.Call) and name in (getattr(node.func, "id", None),
                                                       getattr(node.func, "attr", None)):
                out.append((path, node))
    return out


def test_run_cosimulation_takes_the_run_object_and_run_time_extras_only():
    first, *rest = inspect.signature(cosim.run_cosimulation).parameters.values()
    assert typing.get_type_hints(cosim.run_cosimulation)[first.name] is PreparedRun
    assert first.kind is inspect.Parameter.POSITIONAL_OR_KEYWORD
    assert all(p.kind is inspect.Parameter.KEYWORD_ONLY for p in rest)
    assert {p.name for p in rest} <= RUN_TIME


@pytest.mark.parametrize("stage", STAGES, ids=lambda f: f.__name__)
def test_every_stage_reads_its_configuration_from_the_run_object(stage):
    hints = typing.get_type_hints(stage)
    assert PreparedRun in hints.values()
    assert [name for name, hint in hints.items() if hint in CONFIG] == []


@pytest.mark.parametrize("folder", ["tests", "src", "benchmarks"])
def test_run_cosimulation_is_called_with_the_prepared_run_alone(folder):
    calls = _calls("run_cosimulation", folder)
    assert calls, f"no run_cosimulation call in {folder}/"
    wrong = [f"{path.relative_to(ROOT)}:{call.lineno}" for path, call in calls
             if len(call.args) != 1 or isinstance(call.args[0], ast.Starred)
             or {k.arg for k in call.keywords} - RUN_TIME]
    assert wrong == [], "run_cosimulation(prepared, *, progress, keep_measurements, frontend)"


def test_no_test_assembles_a_run_object_by_hand():
    assert [f"{p.relative_to(ROOT)}:{c.lineno}" for p, c in _calls("PreparedRun", "tests")
            ] == []
