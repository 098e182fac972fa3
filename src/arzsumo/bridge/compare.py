"""One table across co-simulation runs (``arzsumo compare``): rows from run summaries, as
text; written with its bar plot by :func:`arzsumo.outputs.compare.compare_runs`."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pandas as pd

from arzsumo.errors import ScenarioError

#: (column, header, how to read it from summary.json, unit conversion for humans)
COLUMNS: tuple[tuple[str, str], ...] = (
    ("controller", "controller"), ("seed", "seed"), ("plan_changes", "plan chg"),
    ("light_changes", "light chg"), ("triggers", "updates"), ("release_time", "release s"),
    ("TTT_veh_h", "TTT veh.h"), ("delay_veh_h", "delay veh.h"), ("J_fuel", "J_fuel"),
    ("J_discom", "J_discom"), ("speed_sd_h_kmh", "sd v_h km/h"),
    ("speed_sd_a_kmh", "sd v_a km/h"), ("max_ramp_queue", "max queue"),
    ("rmse_rho_rel", "replay RMSE rho"), ("rmse_v_rel", "replay RMSE v"))


def _total(summ: dict[str, Any], key: str) -> float:
    value = summ.get(key)
    return float(value["total"]) if isinstance(value, dict) and value.get("total") is not None \
        else float("nan")


def row_of(summ: dict[str, Any]) -> dict[str, Any]:
    """One flat row (human units) from a run's summary."""
    rm = summ.get("rmse", {}).get("replay", {})

    def rel(*names: str) -> float:
        vals = [rm[n]["relative"] for n in names if n in rm and rm[n]["relative"] is not None]
        return sum(vals) / len(vals) if vals else float("nan")

    var = summ.get("speed_variance", {})
    return {
        "controller": summ.get("controller"), "seed": summ.get("seed"),
        "plan_changes": summ.get("plan_changes"), "light_changes": summ.get("light_changes"),
        "triggers": summ.get("triggers"), "release_time": summ.get("release_time"),
        "TTT_veh_h": _total(summ, "TTT") / 3600.0,
        "delay_veh_h": _total(summ, "total_delay") / 3600.0,
        "J_fuel": _total(summ, "J_fuel"), "J_discom": _total(summ, "J_discom"),
        "speed_sd_h_kmh": (var.get("h") or float("nan")) ** 0.5 * 3.6,
        "speed_sd_a_kmh": (var.get("a") or float("nan")) ** 0.5 * 3.6,
        "max_ramp_queue": summ.get("max_ramp_queue"),
        "rmse_rho_rel": rel("rho_h", "rho_a"), "rmse_v_rel": rel("v_h", "v_a"),
    }


def summary_table(summaries: list[dict[str, Any]]) -> str:
    """Text table of runs (one row each)."""
    df = pd.DataFrame([row_of(s) for s in summaries])
    df = df.rename(columns=dict(COLUMNS))
    return df.to_string(index=False, float_format=lambda v: f"{v:.3g}")


def load_summaries(runs: list[Path]) -> list[dict[str, Any]]:
    out = []
    for run in runs:
        path = run / "summary.json"
        if not path.is_file():
            raise ScenarioError(f"run = {str(run)!r} is not allowed: it has no summary.json "
                                "(not a complete arzsumo run directory)")
        out.append(json.loads(path.read_text(encoding="utf-8")))
    return out
