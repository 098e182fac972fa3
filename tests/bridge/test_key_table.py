"""``arzsumo run``'s printed result: the key columns in 100 characters, the rest named
in summary.csv (no SUMO)."""

from __future__ import annotations

import pytest

from arzsumo.bridge.compare import COLUMNS, KEY_COLUMNS, key_table, updates_line


def _summary(controller: str, seed: int) -> dict:
    return {"kind": "run", "scenario": "a_scenario_with_a_long_name", "horizon": 450.0,
            "warmup": {"duration_s": 600.0}, "controller": controller, "seed": seed,
            "plan_changes": 12345, "light_changes": 67890, "triggers": 449,
            "release_time": 1.0, "TTT": {"total": 123456.0},
            "total_delay": {"total": -36000.0}, "J_fuel": {"total": 1357.9},
            "J_discom": {"total": 6461.0}, "speed_variance": {"h": 4.0, "a": 1.0},
            "max_ramp_queue": 37, "network": {"time_loss_s": {"total": 86400.0}},
            "rmse_blocks": {"replay": {"rho_h": {"relative": 0.1641}}},
            "network_whole_demand": {"complete": True, "time_spent_s": {"total": 453600.0},
                                     "ramp_wait_s": {"p95": 134.25}}}


@pytest.mark.parametrize(("controller", "seed"), [("etc", 42), ("observer-etc", 2**31 - 1)])
def test_every_printed_line_fits_100_columns(controller: str, seed: int) -> None:
    text = key_table(_summary(controller, seed), "results/some-run/summary.csv")
    lines = text.splitlines()
    assert all(len(line) <= 100 for line in lines), [len(line) for line in lines]
    assert f"{controller}, seed {seed}, scenario a_scenario_with_a_long_name" in lines[0]
    heads = lines[2]
    assert heads.split()[:6] == ["whole", "TTS", "veh.h", "ramp", "wait", "p95"]
    assert lines[3].split()[:3] == ["126", "134", "24"]
    assert " ".join(text.split()).endswith(f"every column ({len(COLUMNS)}: also light "
                                           "changes, fuel, discomfort, speed spreads, the "
                                           "twins' errors) is in "
                                           "results/some-run/summary.csv")


def test_the_legend_explains_only_the_columns_shown() -> None:
    text = " ".join(key_table(_summary("etc", 1), "x.csv").split())
    assert "whole TTS: every vehicle of the demand to its arrival" in text
    assert "J_discom SI" not in text and "light chg:" not in text
    assert set(KEY_COLUMNS) <= {c for c, _ in COLUMNS}


def test_the_updates_line_fits_100_columns() -> None:
    line = updates_line({"controller": "observer-etc", "triggers": 449, "release_time": 1.0,
                         "horizon": 450.0})
    assert line is not None
    assert max(len(part) for part in line.splitlines()) <= 100
