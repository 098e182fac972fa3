"""``arzsumo alinea-target`` on run directories (no SUMO): files, printed target, refusals."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
import pytest

from arzsumo.cli import main

SCENARIO = Path(__file__).resolve().parents[2] / "scenarios" / "default.toml"


def _run_dir(path: Path, seed: int) -> Path:
    """A fake run: 1 s loop samples of a triangular curve (critical occupancy 0.25)."""
    rng = np.random.default_rng(seed)
    occ = np.repeat(rng.uniform(0.02, 0.5, 100), 40) + rng.normal(0, 0.01, 4000)
    flow = np.where(occ < 0.25, 0.6 * occ / 0.25, 0.6 * (0.8 - occ) / 0.55)
    path.mkdir()
    pq.write_table(pa.table({"t_s": np.arange(4000.0), "occupancy_out": occ,
                             "flow_out_loop": flow + rng.normal(0, 0.02, 4000)}),
                   path / "periods.parquet")
    (path / "summary.json").write_text(json.dumps({"seed": seed}))
    return path


def test_alinea_target_from_run_directories(tmp_path, capsys):
    runs = [str(_run_dir(tmp_path / f"r{s}", s)) for s in (1, 2)]
    out = tmp_path / "target"
    assert main(["alinea-target", str(SCENARIO), "--runs", *runs, "--out", str(out)]) == 0
    text = capsys.readouterr().out
    assert "[alinea] target_pct = " in text
    doc = json.loads((out / "target.json").read_text())
    assert doc["critical_occupancy_pct"] == pytest.approx(25, abs=1.5)
    assert doc["target_pct"] == pytest.approx(0.9 * doc["critical_occupancy_pct"])
    assert doc["seeds"] == [1, 2] and doc["period_s"] == 40 and doc["samples"] == 200
    for name in ("samples.csv", "curve.csv", "curve.png"):
        assert (out / name).is_file(), name


def test_alinea_target_refusals(tmp_path, capsys):
    assert main(["alinea-target", str(SCENARIO), "--out", str(tmp_path / "o")]) == 2
    assert "--seeds or --runs is needed" in capsys.readouterr().err
    assert main(["alinea-target", str(SCENARIO), "--runs", str(tmp_path),
                 "--out", str(tmp_path / "o")]) == 2
    assert "no periods.parquet there" in capsys.readouterr().err
