"""The paper's section 5 numbers beside the twin's, with a verdict on each claim.

Pure functions of a :class:`arzsumo.workflows.paper.reproduce.Reproduction`: they return rows
(dicts, CSV-ready); the :class:`Claim` records come from :mod:`arzsumo.workflows.paper.claims`
(re-exported here). Nothing is written here. How the verdicts are reached, and why
magnitudes are not expected to match: ``docs/twin.md``, 'Reproducing section 5'.
"""

from __future__ import annotations

import math
from typing import Any, TypeVar

from arzsumo.units import veh_m_to_veh_km

# re-exported for the CLI, the report and the tests
from arzsumo.workflows.paper.claims import (
    NOT_REPRODUCED,
    REPRODUCED,
    Claim,
    claims,
    penetration_records,
    trend,
)
from arzsumo.workflows.paper.reproduce import Reproduction, RunRecord
from arzsumo.workflows.paper.values import (
    DIFFPENE,
    DIFFPERFORMANCE,
    EVENTS,
    SENSITIVITY,
    TOTALDELAY,
    DelayRow,
    EventRow,
    PerformanceRow,
)

__all__ = ["MIN_CHANGE", "NOT_REPRODUCED", "REPRODUCED", "Claim", "claims", "delay_table",
           "direction", "events_table", "penetration_table", "performance_table",
           "sensitivity_table", "trend"]

#: Smallest |relative change| (percent) we count as a change at all.
MIN_CHANGE = 0.05

_Row = TypeVar("_Row", PerformanceRow, DelayRow, EventRow)

WHY_SMALL = ("the two-period stop-and-go wave adds no vehicles and the metering averages "
             "about q*, so vehicle-count indices (J_TTT, J_fuel, delay) move by less than "
             f"{MIN_CHANGE} % either way; the paper's changes of the same size depend on "
             "unreported details (d, amplitude, grid)")
WHY_SIGN = ("the change has the opposite sign here; at this size it is decided by the "
            "unreported details (d, amplitude, grid, outlet split between classes)")
WHY_NAN = "no baseline: the run or its open loop stopped early"

#: Reasons specific to one cell (scenario, column), where we measured the cause.
WHY_CELL = {
    ("linear_etc", "J_discom_percent"): (
        "the linear profile puts 15 % extra vehicles on the road that only the metering can "
        "remove; the held, stepwise outflow changes that drain them add accelerations near "
        "the outlet (J_discom about 650 against 300 veh m^2/s^3 in the open loop), while "
        "the paper's discomfort falls"),
}


def direction(paper: float, ours: float) -> tuple[str, str]:
    """Verdict and reason for one relative change (percent)."""
    if math.isnan(ours):
        return NOT_REPRODUCED, WHY_NAN
    if abs(ours) < MIN_CHANGE:
        return NOT_REPRODUCED, WHY_SMALL
    if (paper > 0) == (ours > 0):
        return REPRODUCED, ""
    return NOT_REPRODUCED, WHY_SIGN


def _cells(row: dict[str, Any], key: str, paper: float, ours: float) -> list[str]:
    verdict, why = direction(paper, ours)
    if why:
        why = WHY_CELL.get((row["scenario"], key), why)
    row[f"paper_{key}"] = paper
    row[f"ours_{key}"] = round(ours, 4)
    row[f"{key}_verdict"] = verdict
    return [f"{key}: {why}"] if why else []


def _compared_row(label: str, scenario: str, cells: list[tuple[str, float, float]],
                  extra: dict[str, Any] | None = None) -> dict[str, Any]:
    """One published row beside ours: per cell ``(column, paper, ours)`` both values
    (units as the column says) and a verdict, then ``extra``; ``notes`` joins the reasons
    of the cells not reproduced."""
    row: dict[str, Any] = {"label": label, "scenario": scenario}
    notes: list[str] = []
    for key, paper, ours in cells:
        notes += _cells(row, key, paper, ours)
    row.update(extra or {})
    row["notes"] = " | ".join(dict.fromkeys(notes))
    return row


def _ran(rep: Reproduction, rows: tuple[_Row, ...]) -> list[tuple[_Row, RunRecord]]:
    """The published ``rows`` whose scenario ``rep`` ran, each with its record."""
    return [(p, rec) for p in rows if (rec := rep.get(p.scenario)) is not None]


def performance_table(rep: Reproduction) -> list[dict[str, Any]]:
    """Table diffperformance: relative J_fuel, J_discom, J_TTT (%) and release time (s)."""
    return [_compared_row(p.label, p.scenario,
                          [(f"{key}_percent", getattr(p, key), rec.relative("total", key))
                           for key in ("J_fuel", "J_discom", "J_TTT")],
                          {"paper_release_time_s": p.release_time,
                           "ours_release_time_s": rec.release_time,
                           "ours_triggers": rec.triggers})
            for p, rec in _ran(rep, DIFFPERFORMANCE)]


def delay_table(rep: Reproduction) -> list[dict[str, Any]]:
    """Table totaldelay: change of TD_h, TD_a and TD_h + TD_a against the open loop (%)."""
    return [_compared_row(p.label, p.scenario,
                          [(f"{name}_delay_percent", getattr(p, part),
                            rec.relative(part, "total_delay"))
                           for part, name in (("h", "HV"), ("a", "AV"), ("total", "total"))])
            for p, rec in _ran(rep, TOTALDELAY)]


def penetration_table(rep: Reproduction) -> list[dict[str, Any]]:
    """Table diffpene: release time (s) and triggers per AV penetration rate."""
    rows = []
    for pen, rec in penetration_records(rep).items():
        release, triggers = DIFFPENE[pen]
        eq = rec.summary["equilibrium"]
        rows.append({"penetration_percent": pen, "scenario": rec.name,
                     "rho_h_veh_km": round(veh_m_to_veh_km(eq["rho_h"]), 3),
                     "rho_a_veh_km": round(veh_m_to_veh_km(eq["rho_a"]), 3),
                     "paper_release_time_s": release, "ours_release_time_s": rec.release_time,
                     "paper_triggers": triggers, "ours_triggers": rec.triggers})
    return rows


def events_table(rep: Reproduction) -> list[dict[str, Any]]:
    """Release and trigger numbers of the text and figures beside ours."""
    return [{"label": e.label, "scenario": e.scenario, "where": e.where,
             "paper_triggers": e.triggers, "ours_triggers": rec.triggers,
             "paper_release_time_s": e.release_time, "ours_release_time_s": rec.release_time,
             "ours_final_norm_ratio": rec.summary["final_norm_ratio"],
             "ours_lyapunov_time_s": rec.lyapunov_time}
            for e, rec in _ran(rep, EVENTS)]


def sensitivity_table(rep: Reproduction) -> list[dict[str, Any]]:
    """Triggers, release time and Lyapunov convergence time (s) of each sweep run."""
    return [{"parameter": par, "value": rec.sweep[1] if rec.sweep else math.nan,
             "triggers": rec.triggers, "release_time_s": rec.release_time,
             "lyapunov_time_s": rec.lyapunov_time,
             "final_norm_ratio": rec.summary["final_norm_ratio"]}
            for par in SENSITIVITY for rec in rep.sweep(par)]


