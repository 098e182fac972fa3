"""``arzsumo premise``: its refusals of bad input (no SUMO), and one short real run."""

from __future__ import annotations

import contextlib
import io
import json
import math
import re

import pandas as pd
import pytest
from arzsumo_studies.cli.premise import EXIT_PREMISE_FAILS, FLOORS
from arzsumo_studies.premise import floors as premise_floors

from arzsumo.cli import main

#: a run of legacy_default short enough for a test: 60 s warm-up, 120 s windows, a 40 s
#: round trip, a 20 s pulse and a staircase of four 30 s levels after a 30 s lead-in
SHORT = ["--seeds", "1", "--warmup", "60", "--window", "120", "--round-trip", "40",
         "--pulse-s", "20", "--level-s", "30", "--levels", "4", "--workers", "1",
         "--quiet"]


def cli(*args: str) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main(list(args))
    return code, out.getvalue(), err.getvalue()


def test_the_cli_offers_the_floors_the_study_knows():
    assert FLOORS == premise_floors.FLOORS


@pytest.mark.parametrize(("args", "message"), [
    (["nope"], r"scenario = 'nope' does not exist"),
    (["legacy_default", "--window", "60", "--round-trip", "40"],
     r"--window = 60 is not allowed: the count trend needs 3 blocks of 30 s; allowed: at "
     r"least 90 s$"),
    (["legacy_default", "--window", "90", "--round-trip", "50"],
     r"--window = 90 is not allowed: .*2 x 50 s \(T: --round-trip\); allowed: at least "
     r"100 s"),
    (["legacy_default", "--window", "100"],
     r"--window = 100 is not allowed: .*2 round trips .*the model's .*at least 691\.\d+ s"),
    (["legacy_default", "--window", "120", "--round-trip", "30", "--level-s", "0.5"],
     r"--level-s = 0.5 is not allowed: a whole number of control periods"),
    (["legacy_default", "--window", "120", "--round-trip", "30", "--pulse-s", "120"],
     r"--pulse-s = 120 is not allowed: shorter than the window"),
    (["legacy_default", "--window", "120", "--round-trip", "30", "--levels", "1"],
     r"--levels = 1 is not allowed: at least 2"),
    (["legacy_default", "--window", "120", "--round-trip", "30", "--step-veh-h", "5000"],
     r"--step-veh-h = 5000 is not allowed: the fixed-cycle meter cannot move"),
    (["default", "--step-veh-h", "400"],
     r"--step-veh-h = 400 is not allowed: the release rate 600 \+ 400 veh/h lies outside "
     r"the meter's \[240, 900\] veh/h"),
    (["default", "--warmup", "100"], r"--warmup = 100 is not allowed: .*fill phase"),
    (["legacy_default", "--seeds", "0"], r"--seeds = 0 is not allowed: an integer >= 1"),
    (["legacy_default", "--floor", "median"], r"argument --floor: invalid choice"),
])
def test_bad_input_is_refused_in_one_line_before_any_run(tmp_path, args, message):
    out = tmp_path / "out"
    code, stdout, err = cli("premise", *args, "--out", str(out))
    assert code == 2 and stdout == ""
    assert err.count("\n") == 1 and err.startswith("arzsumo: error: ")
    assert re.search(message, err), err
    assert not out.exists()


def _gates(doc: dict) -> dict[str, dict]:
    return {g["name"]: g for g in doc["per_seed"][0]["gates"]}


@pytest.mark.sumo
def test_a_short_run_writes_every_gate_and_a_restart_reuses_its_runs(tmp_path):
    out = tmp_path / "premise"
    code, text, err = cli("premise", "legacy_default", *SHORT, "--out", str(out))
    assert code in (0, EXIT_PREMISE_FAILS), err
    doc = json.loads((out / "premise.json").read_text())
    assert code == (0 if doc["verdict"]["passed"] else EXIT_PREMISE_FAILS)
    assert sorted(p.name for p in out.iterdir()) == [
        ".arzsumo-result", "premise.csv", "premise.json", "premise.png", "runs"]
    # the seed's three runs share one warm-up: one task, one stored file
    assert sorted(p.name for p in (out / "runs").iterdir()) == ["seed=1.json"]
    stored = json.loads((out / "runs" / "seed=1.json").read_text())
    assert [r["kind"] for r in stored["row"]["rows"]] == ["baseline", "pulse", "staircase"]
    assert (out / "premise.png").stat().st_size > 10_000
    gates = _gates(doc)
    # legacy_default's fixed cycle has no release-rate bound: no ramp_demand gate
    assert list(gates) == ["coupling[hv]", "coupling[av]", "waves[hv]", "waves[av]",
                           "model_wave[hv]", "model_wave[av]", "amplification[hv]",
                           "amplification[av]", "pulse", "actuator", "stationary",
                           "inserted", "ramp_queue"]
    for name in ("coupling[hv]", "amplification[hv]", "inserted", "ramp_queue"):
        assert math.isfinite(gates[name]["value"]), name
    assert doc["seeds"] == [1] and doc["options"]["window_s"] == 120.0
    assert doc["scenario"]["name"] == "legacy_default" and "[sumo]" in doc["scenario"]["toml"]
    # the staircase's four steps, two up and two down, of exactly 200 veh/h
    steps = gates["actuator"]["detail"]["steps"]
    assert [round(s["dr"] * 3600, 6) for s in steps] == [200, -200, -200, 200]
    assert [s["t0_s"] for s in steps] == [90.0, 120.0, 150.0, 180.0]
    pulse = gates["pulse"]["detail"]
    assert (pulse["round_trip_s"], pulse["window_s"], doc["pulse_floor"]["method"]) == \
        (40.0, 80.0, "late")
    assert pulse["total"]["peak"] > 0
    runs = doc["runs"]["1"]
    # every lateral sample is a vehicle on main at a period's end; 120 snapshots
    assert runs["lateral_samples"] == runs["main_vehicles_total"] > 120 * 50
    assert runs["lateral_samples"] == sum(runs["class_samples"].values())
    # collisions are not counted unless [sumo] collision_check (it changes no vehicle)
    assert runs["pulse_plan"] == 0.0 and runs["collisions"] is None
    table = pd.read_csv(out / "premise.csv")
    assert table["gate"].tolist() == list(gates)
    row = table.set_index("gate").loc["waves[hv]"]
    assert row["value_shown"] == pytest.approx(row["value"] * 3.6, rel=1e-5)
    assert row["unit"] == "m/s" and row["unit_shown"] == "km/h"
    assert "coupling[hv]" in text and ("premise holds" in text or "does not hold" in text)
    # a second call with the same directory runs nothing and gives the same verdict
    stored = {p.name: p.stat().st_mtime_ns for p in (out / "runs").iterdir()}
    code2, printed, _ = cli("premise", "legacy_default", *SHORT, "--out", str(out), "--json")
    assert code2 == code and json.loads(printed)["verdict"] == doc["verdict"]
    assert {p.name: p.stat().st_mtime_ns for p in (out / "runs").iterdir()} == stored
