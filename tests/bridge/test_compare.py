"""``arzsumo compare``: one table of comparable runs; mixes refused or labelled.

Real SUMO runs (12 s of warm-up, 12 or 18 s of control) and a real twin result.
"""

import json
import os
import subprocess
import sys
from pathlib import Path

import pandas as pd
import pytest

from arzsumo.bridge.compare import bar_title, row_of
from arzsumo.bridge.cosim import run_cosimulation
from arzsumo.cli import main
from arzsumo.outputs.bridge import write_results
from arzsumo.outputs.compare import compare_runs
from arzsumo.scenario import load_scenario
from tests.runs import prepared

DEFAULT = Path(__file__).resolve().parents[2] / "scenarios" / "legacy_default.toml"
SRC = str(Path(__file__).resolve().parents[2] / "src")
pytestmark = pytest.mark.sumo

TWIN = """
name = "short"
[model]
preset = "paper_base"
[equilibrium]
rho_h_veh_km = 110
rho_a_veh_km = 95
[twin]
cells = 40
horizon_s = 12
controller = "open"
"""


@pytest.fixture(scope="module")
def dirs(tmp_path_factory):
    """Runs ``open`` and ``alinea`` on seeds 1, 2 at 12 s, ``open`` seed 1 at 18 s, a twin."""
    root = tmp_path_factory.mktemp("results")
    sc = load_scenario(DEFAULT)
    out = {}
    for name, controller, seed, horizon in (("o1", "open", 1, 12.0), ("o2", "open", 2, 12.0),
                                            ("a1", "alinea", 1, 12.0),
                                            ("a2", "alinea", 2, 12.0),
                                            ("long", "open", 1, 18.0)):
        res = run_cosimulation(prepared(sc, {"run.twin_cells": 40}, controller=controller,
                                        warmup=12.0, horizon=horizon, seed=seed))
        out[name] = write_results(res, root / name, "# test\n", plots=False)[0]
    (root / "twin.toml").write_text(TWIN)
    assert main(["twin", str(root / "twin.toml"), "--out", str(root / "twin"), "--no-plots",
                 "--no-baseline"]) == 0
    out["twin"] = root / "twin"
    return out


def compare_cli(*args) -> subprocess.CompletedProcess:
    """``arzsumo compare`` in a process of its own (exit code and stderr as a user sees)."""
    env = {**os.environ, "PYTHONPATH": SRC}
    return subprocess.run([sys.executable, "-m", "arzsumo.cli", "compare", *map(str, args)],
                          capture_output=True, text=True, timeout=120, env=env)


def compare(capsys, *args) -> subprocess.CompletedProcess:
    """``arzsumo compare`` in this process (faster), as a CompletedProcess."""
    capsys.readouterr()
    code = main(["compare", *map(str, args)])
    out, err = capsys.readouterr()
    return subprocess.CompletedProcess(args, code, out, err)


def test_comparable_runs_give_a_table_csv_with_identity_and_mean_bars(dirs, tmp_path):
    runs = [dirs[k] for k in ("o1", "o2", "a1", "a2")]
    text, csv, png = compare_runs(runs, tmp_path / "cmp")
    assert text.splitlines()[0] == ("scenario legacy_default, horizon 12 s, warm-up 12 s: arzsumo "
                                    "run result (meter counts over the control window)")
    df = pd.read_csv(csv)
    assert list(df.columns[:6]) == ["scenario", "horizon_s", "warmup_s", "controller", "seed",
                                    "kind"]
    assert df["scenario"].tolist() == ["legacy_default"] * 4 and df["kind"].tolist() == ["run"] * 4
    assert df["horizon_s"].tolist() == [12.0] * 4 and df["warmup_s"].tolist() == [12.0] * 4
    assert df["controller"].tolist() == ["open", "open", "alinea", "alinea"]
    assert df["seed"].tolist() == [1, 2, 1, 2]
    for run, (_, row) in zip(runs, df.iterrows(), strict=True):
        summ = json.loads((run / "summary.json").read_text())
        assert row["light_changes"] == summ["light_changes"]
        assert row["plan_changes"] == summ["plan_changes"]
    assert png.read_bytes()[:4] == b"\x89PNG"
    assert bar_title(df) == ("mean over 2 seeds per controller (seeds 1, 2); error bars: "
                             "standard deviation", True)
    single = bar_title(df.iloc[[0, 3]])
    assert single == ("one run per controller, no averaging (open seed 1, alinea seed 2)",
                      False)


def test_mixed_horizons_refused_in_one_line_then_labelled_with_the_flag(dirs, tmp_path,
                                                                      capsys):
    out = tmp_path / "mixed"
    proc = compare_cli(dirs["o1"], dirs["long"], "--out", out)
    assert proc.returncode == 2 and "Traceback" not in proc.stderr
    assert len(proc.stderr.strip().splitlines()) == 1
    assert proc.stderr.startswith("arzsumo: error: horizon_s differs between the runs: 12 s (")
    assert "18 s (" in proc.stderr and "--allow-mixed" in proc.stderr
    assert not out.exists()

    proc = compare(capsys, dirs["o1"], dirs["long"], "--out", out, "--allow-mixed")
    assert proc.returncode == 0, proc.stderr
    first = proc.stdout.splitlines()[0]
    assert first == "MIXED RESULTS (--allow-mixed), not comparable row to row: horizon_s 12, 18"
    assert "horizon s" in proc.stdout.splitlines()[1]          # the mixed column is shown
    df = pd.read_csv(out / "comparison.csv")
    assert df["horizon_s"].tolist() == [12.0, 18.0] and df["seed"].tolist() == [1, 1]
    assert bar_title(df)[0] == "one bar per run, MIXED results: horizon_s 12, 18"


def test_twin_result_refused_then_labelled_as_twin(dirs, tmp_path, capsys):
    out = tmp_path / "twin"
    proc = compare(capsys, dirs["o1"], dirs["twin"], "--out", out)
    assert proc.returncode == 2 and len(proc.stderr.strip().splitlines()) == 1
    assert f"run = '{dirs['twin']}' is not allowed: its summary.json is a twin result" \
        in proc.stderr
    assert not out.exists()
    proc = compare(capsys, dirs["o1"], dirs["twin"], "--out", out, "--allow-mixed")
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.startswith("MIXED RESULTS (--allow-mixed), not comparable row to "
                                  "row: kind run, twin; scenario legacy_default, short; "
                                  "warmup_s 12, none")
    df = pd.read_csv(out / "comparison.csv")
    assert df["kind"].tolist() == ["run", "twin"]
    assert df["horizon_s"].tolist() == [12.0, 12.0]
    assert df["controller"].tolist() == ["open", "open"]
    assert pd.isna(df["warmup_s"].iloc[1]) and pd.isna(df["light_changes"].iloc[1])
    assert df["TTT_veh_h"].iloc[1] > 0                       # the twin's J_TTT, in veh h


def test_old_layout_and_unknown_results(dirs, tmp_path, capsys):
    old = tmp_path / "old"
    old.mkdir()
    summ = json.loads((dirs["o1"] / "summary.json").read_text())
    del summ["kind"]
    summ["warmup"] = 12.0                    # before: counts from t = 0, warm-up a number
    (old / "summary.json").write_text(json.dumps(summ))
    assert row_of(summ)["kind"] == "run-v0" and row_of(summ)["warmup_s"] == 12.0
    proc = compare(capsys, dirs["o1"], old, "--out", tmp_path / "o")
    assert proc.returncode == 2 and "older arzsumo run result" in proc.stderr
    other = tmp_path / "other"
    other.mkdir()
    (other / "summary.json").write_text('{"name": "x"}')
    proc = compare(capsys, dirs["o1"], other, "--out", tmp_path / "o", "--allow-mixed")
    assert proc.returncode == 2 and len(proc.stderr.strip().splitlines()) == 1
    assert f"{other / 'summary.json'}: not a summary of arzsumo run" in proc.stderr
    proc = compare(capsys, dirs["o1"], tmp_path / "missing", "--out", tmp_path / "o")
    assert proc.returncode == 2 and "it has no summary.json" in proc.stderr
    assert not (tmp_path / "o").exists()
