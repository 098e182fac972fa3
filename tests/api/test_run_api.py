"""``arzsumo.run`` in real SUMO: the typed result equals what ``arzsumo run`` writes, its
``save`` writes the same files under the same output safety, and the README's example
runs as printed."""

from __future__ import annotations

import json
import re
import subprocess
import sys

import pandas as pd
import pytest

import arzsumo
from arzsumo.cli import main
from tests.runs import LEGACY, ROOT

pytestmark = pytest.mark.sumo
SHORT = {"seed": 8, "horizon_s": 30.0, "warmup_s": 40.0}
WALL = ("wall_time", "timings", "controller_time_per_period")


def _summary(path):
    data = json.loads((path / "summary.json").read_text())
    return {k: v for k, v in data.items() if k not in WALL}


@pytest.fixture(scope="module")
def result():
    return arzsumo.run(LEGACY, controller="etc", **SHORT)


def test_the_result_is_typed_frozen_and_carries_scenario_and_version(result):
    assert isinstance(result, arzsumo.RunResult) and result.version == arzsumo.__version__
    assert result.summary.identity.controller == "etc" and result.summary.identity.seed == 8
    assert result.scenario.sumo.seed == 8 and result.scenario.run.controller == "etc"
    assert len(result.periods) == 30 and set(result.cells["source"]) == {
        "micro", "replay", "reference"}
    with pytest.raises(AttributeError):
        result.summary = None                    # frozen


def test_the_api_and_the_cli_give_the_same_run(result, tmp_path):
    assert main(["run", str(LEGACY), "--controller", "etc", "--seed", "8", "--horizon", "30",
                 "--warmup", "40", "--no-plots", "--quiet", "--out",
                 str(tmp_path / "cli")]) == 0
    path = result.save(tmp_path / "api", plots=False)
    assert _summary(path) == _summary(tmp_path / "cli")
    for name in ("periods", "cells"):
        cli = pd.read_parquet(tmp_path / "cli" / f"{name}.parquet").drop(
            columns=["controller_s"], errors="ignore")
        api = pd.read_parquet(path / f"{name}.parquet").drop(columns=["controller_s"],
                                                             errors="ignore")
        pd.testing.assert_frame_equal(cli, api)
        pd.testing.assert_frame_equal(getattr(result, name).drop(
            columns=["controller_s"], errors="ignore"), api)
    assert (path / "scenario.toml").read_text() == (tmp_path / "cli" / "scenario.toml").read_text()


def test_save_refuses_a_directory_it_did_not_write(result, tmp_path):
    mine = tmp_path / "mine"
    mine.mkdir()
    (mine / "notes.txt").write_text("keep me")
    with pytest.raises(arzsumo.ArzsumoError, match="is a non-empty directory that is not an "
                                                   "arzsumo result"):
        result.save(mine)
    assert (mine / "notes.txt").read_text() == "keep me"
    assert sorted(p.name for p in mine.iterdir()) == ["notes.txt"]


def test_the_readmes_python_example_runs_as_printed(tmp_path):
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    code = re.search(r"```python\n(.*?)```", readme, flags=re.DOTALL).group(1)
    assert len(code.strip().splitlines()) <= 15
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          cwd=tmp_path, timeout=1500)
    assert proc.returncode == 0, proc.stderr[-2000:]
    ratio, plan_changes = proc.stdout.split()
    assert float(ratio) == pytest.approx(0.179, abs=0.002)
    assert int(plan_changes) >= 0
    summary = json.loads((tmp_path / "results" / "drain-excess-seed1" / "summary.json")
                         .read_text())
    assert summary["controller"] == "drain-excess" and summary["plan_changes"] == int(
        plan_changes)
    printed = re.search(r"It prints `([0-9.]+) (\d+)`", readme)
    assert printed and (printed.group(1), printed.group(2)) == (ratio, plan_changes)
