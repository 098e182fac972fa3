"""The premise report's files and table: units shown, one CSV row per seed and gate."""

from __future__ import annotations

import json
import math

import numpy as np
import pandas as pd
import pytest
from arzsumo_studies.gates import GateResult, PremiseThresholds, premise_verdict
from arzsumo_studies.outputs.premise import (
    COLUMNS,
    csv_rows,
    premise_table,
    threshold_text,
    write_premise,
)

TH = PremiseThresholds()


def _seed(coupling_ms: float, gain: float) -> list[GateResult]:
    return [GateResult("coupling[hv]", coupling_ms, TH.file_speed_gap,
                       coupling_ms <= TH.file_speed_gap),
            GateResult("pulse", math.nan, 200.0, True),
            GateResult("actuator", gain, TH.gain_range, -1.3 <= gain <= -0.7),
            GateResult("model_wave[hv]", 1.1, 0.25, True)]


@pytest.fixture
def gates() -> dict[int, list[GateResult]]:
    return {1: _seed(1.0, -1.0), 2: _seed(5.0, -0.2)}


def test_thresholds_read_in_the_shown_unit():
    assert threshold_text("coupling[av]", TH.file_speed_gap) == "<= 10 km/h"
    assert threshold_text("waves[hv]", 0.0) == "< 0 km/h, lag linear in distance"
    assert threshold_text("pulse", 1016.0) == "no decay by 1016 s"
    assert threshold_text("actuator", (-1.3, -0.7)) == "in [-1.3, -0.7]"


def test_one_csv_row_per_seed_and_gate_with_both_units(gates):
    table = csv_rows(gates)
    assert list(table.columns) == COLUMNS and len(table) == 8
    row = table.iloc[0]
    assert (row["seed"], row["gate"], row["unit"], row["unit_shown"]) == (
        1, "coupling[hv]", "m/s", "km/h")
    assert row["value_shown"] == pytest.approx(3.6)
    act = table[table["gate"] == "actuator"].iloc[0]
    assert (act["threshold"], act["threshold_high"]) == (-1.3, -0.7)


def test_the_table_shows_each_seed_and_the_verdict(gates):
    verdict = premise_verdict(list(gates.values()), TH)
    text = premise_table(gates, verdict)
    lines = text.splitlines()
    assert lines[0].split() == ["gate", "unit", "threshold", "seed", "1", "seed", "2",
                                "seeds", "passing"]
    coupling = next(line for line in lines if line.startswith("coupling[hv]"))
    assert "3.6 pass" in coupling and "18 FAIL" in coupling and "1/2 FAIL" in coupling
    assert next(line for line in lines if line.startswith("model_wave")).endswith("(model)")
    assert lines[-2] == "premise does not hold; failed: coupling[hv], actuator"


def test_the_files_are_written_with_nan_as_null(tmp_path, gates):
    t = np.arange(1.0, 301.0)
    pulses = {1: (t, np.exp(-t / 50), np.exp(-t / 50), 0.1, 200.0)}
    stairs = {1: (t, 1.2 - 0 * t, np.full(t.size, 600 / 3600), np.array([100.0, 200.0]))}
    doc = {"kind": "premise", "value": math.nan}
    written = write_premise(tmp_path, doc, gates, pulses, stairs)
    assert [p.name for p in written] == ["premise.json", "premise.csv", "premise.png"]
    assert json.loads((tmp_path / "premise.json").read_text()) == {"kind": "premise",
                                                                   "value": None}
    assert len(pd.read_csv(tmp_path / "premise.csv")) == 8
    assert (tmp_path / "premise.png").stat().st_size > 10_000
    assert [p.name for p in write_premise(tmp_path / "b", doc, gates, plots=False)] == [
        "premise.json", "premise.csv"]
