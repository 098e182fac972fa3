"""The report of a reproduction: ``report.md``, CSV tables and figure data, written through
:mod:`arzsumo.outputs.reproduce` (atomically, :func:`arzsumo.io.atomic_dir`). The files
and their columns: ``docs/outputs.md``, 'arzsumo reproduce'.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from arzsumo.control.etc import PAPER_DESIGN
from arzsumo.outdir import OutputDir
from arzsumo.outputs.reproduce import ReproduceFigures, write_report
from arzsumo.workflows.paper.compare import (
    NOT_REPRODUCED,
    REPRODUCED,
    Claim,
    claims,
    delay_table,
    events_table,
    penetration_table,
    performance_table,
    sensitivity_table,
)
from arzsumo.workflows.paper.reproduce import LYAPUNOV_FRACTION, QUICK_TWIN, Reproduction, RunRecord
from arzsumo.workflows.paper.values import EVENTS, SENSITIVITY


def run_row(rec: RunRecord) -> dict[str, Any]:
    """The numbers of one run's summary as a flat CSV row (SI; relative changes in %)."""
    s = rec.summary
    row: dict[str, Any] = {"name": rec.name, "scenario": rec.scenario,
                           "controller": rec.controller, "complete": s["complete"],
                           "triggers": rec.triggers, "release_time_s": rec.release_time,
                           "lyapunov_time_s": rec.lyapunov_time,
                           "final_norm_ratio": s["final_norm_ratio"],
                           "saturation_time_s": s["saturation_time"],
                           "penetration": s["equilibrium"]["penetration"]}
    for key in ("J_fuel", "J_discom", "J_TTT", "total_delay"):
        for part in ("h", "a", "total"):
            row[f"{key}_{part}"] = s[key][part]
            row[f"{key}_{part}_rel_percent"] = rec.relative(part, key)
    return row


def _cell(v: Any) -> str:
    if isinstance(v, float):
        if math.isnan(v):
            return "-"
        if math.isinf(v):
            return "never"
        if v.is_integer():
            return str(int(v))
        return f"{v:.3g}" if abs(v) < 0.1 else f"{v:.2f}"
    if v == REPRODUCED:
        return "yes"
    if v == NOT_REPRODUCED:
        return "**no**"
    return "-" if v is None else str(v)


def markdown_table(rows: Sequence[dict[str, Any]], columns: Sequence[str],
                   headers: Sequence[str] | None = None) -> str:
    """A GitHub markdown table of ``columns`` of ``rows``."""
    head = list(headers or columns)
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    lines += ["| " + " | ".join(_cell(r.get(c)) for c in columns) + " |" for r in rows]
    return "\n".join(lines)


def _reasons(rows: Sequence[dict[str, Any]]) -> str:
    """Group the per-cell notes ("column: reason") by reason."""
    by_reason: dict[str, list[str]] = {}
    for r in rows:
        for note in filter(None, r["notes"].split(" | ")):
            column, reason = note.split(": ", 1)
            by_reason.setdefault(reason, []).append(
                f"{r['label']} {column.removesuffix('_percent')}")
    return "\n".join(f"- {reason} ({', '.join(cells)})." for reason, cells in by_reason.items())


def _section(title: str, *blocks: str) -> list[str]:
    """A markdown section: its title and blocks, each followed by a blank line."""
    return [title, ""] + [line for block in blocks for line in (block, "")]


def _cells(rep: Reproduction) -> str:
    """The runs' grid as they ran it ("200"; a quick run's 40; "40-200" when mixed)."""
    cells = sorted({int(r.summary["config"]["cells"]) for r in rep.records})
    return "?" if not cells else str(cells[0]) if len(cells) == 1 else \
        f"{cells[0]}-{cells[-1]}"


def _overview(rep: Reproduction) -> list[str]:
    """Title, what was run, how to read the verdicts, and the runs without a baseline."""
    stopped = [f"{r.name}: {r.summary['open_loop_baseline']}" for r in rep.records
               if not r.summary["complete"]
               or str(r.summary["open_loop_baseline"]).startswith("no comparison")]
    runs = (f"{len(rep.records)} runs ({rep.open_loops} open loops shared by the controllers "
            f"of each scenario) from `{rep.source}`, {rep.wall_time:.0f} s wall time on "
            f"{rep.workers} process(es)."
            + (f" **Quick mode** ({QUICK_TWIN}): the numbers are not meaningful." if rep.quick
               else "")
            + (f" Overrides of every `[twin]`: {rep.overrides}." if rep.overrides else ""))
    reading = (
        "Relative changes are against the open loop of the same scenario, in percent "
        "(negative = better). *yes* = reproduced in direction (same sign, at least "
        "0.05 % in size), **no** = not reproduced. Magnitudes are not expected to match: "
        "the paper does not give the vehicle width d (2.0 m here), the initial amplitude "
        "(2 % stop-and-go here), the aggressive case's speeds and maximum AOs; its 1/4 "
        f"profile fraction is infeasible (0.15 here); the grid is {_cells(rep)} cells (first "
        "order unless overridden).")
    baseline = ("Runs without a baseline because they or their open loop left the physical "
                "domain (kept, marked incomplete): " + "; ".join(stopped) + "." if stopped
                else "All runs and their open loops completed.")
    return _section("# Reproduction of section 5 on the nonlinear PDE twin", runs, reading,
                    baseline)


def _claims_section(cl: Sequence[Claim]) -> list[str]:
    """Every claim with its verdict, and how many are reproduced."""
    n_ok = sum(c.verdict == REPRODUCED for c in cl)
    return _section(f"## Claims ({n_ok} of {len(cl)} reproduced in direction)", "\n".join(
        f"- **{c.verdict}** - {c.claim}. Paper: {c.paper}. Twin: {c.ours}."
        + (f" *{'Why' if c.verdict != REPRODUCED else 'Note'}:* {c.why}." if c.why else "")
        for c in cl))


def _performance_section(perf: Sequence[dict[str, Any]]) -> list[str]:
    """Table diffperformance: relative J_fuel, J_discom, J_TTT (%) and release time (s)."""
    return _section("## Table diffperformance", markdown_table(
        perf, ["label", "paper_J_fuel_percent", "ours_J_fuel_percent",
               "J_fuel_percent_verdict", "paper_J_discom_percent", "ours_J_discom_percent",
               "J_discom_percent_verdict", "paper_J_TTT_percent", "ours_J_TTT_percent",
               "J_TTT_percent_verdict", "paper_release_time_s", "ours_release_time_s"],
        ["scenario", "J_fuel paper", "ours", "", "J_discom paper", "ours", "",
         "J_TTT paper", "ours", "", "release paper (s)", "ours (s)"]))


def _delay_section(perf: Sequence[dict[str, Any]],
                   delay: Sequence[dict[str, Any]]) -> list[str]:
    """Table totaldelay (%), then the reasons of the cells of both tables not reproduced."""
    table = markdown_table(
        delay, ["label", "paper_HV_delay_percent", "ours_HV_delay_percent",
                "HV_delay_percent_verdict", "paper_AV_delay_percent", "ours_AV_delay_percent",
                "AV_delay_percent_verdict", "paper_total_delay_percent",
                "ours_total_delay_percent", "total_delay_percent_verdict"],
        ["scenario", "HV paper", "ours", "", "AV paper", "ours", "", "total paper", "ours",
         ""])
    return _section("## Table totaldelay", table, "Reasons where a cell is not reproduced:",
                    _reasons([*perf, *delay]))


def _penetration_section(pen: Sequence[dict[str, Any]]) -> list[str]:
    """Table diffpene: densities (veh/km), release time (s) and triggers per AV share."""
    return _section("## Table diffpene (equal inflow 5680 veh/h, congested branch)",
                    markdown_table(pen, ["penetration_percent", "rho_h_veh_km", "rho_a_veh_km",
                                         "paper_release_time_s", "ours_release_time_s",
                                         "paper_triggers", "ours_triggers"],
                                   ["AV %", "rho_h (veh/km)", "rho_a (veh/km)",
                                    "release paper (s)", "ours (s)", "triggers paper", "ours"]))


def _events_section(ev: Sequence[dict[str, Any]]) -> list[str]:
    """Triggers and release times (s) stated in the text and figures, and the Lyapunov time."""
    table = markdown_table(ev, ["label", "paper_triggers", "ours_triggers",
                                "paper_release_time_s", "ours_release_time_s",
                                "ours_final_norm_ratio", "ours_lyapunov_time_s", "where"],
                           ["run", "triggers paper", "ours", "release paper (s)", "ours (s)",
                            "norm ratio at end", "Lyapunov time (s)", "paper source"])
    lyapunov = (f"Lyapunov time: first time after which V (label lyapunov, evaluated by the "
                f"controller on the linearised Riemann state of the twin) stays below "
                f"{LYAPUNOV_FRACTION:g} V(0).")
    return _section("## Triggers and release times in the text and figures", table, lyapunov)


def _sensitivity_section(sens: Sequence[dict[str, Any]]) -> list[str]:
    """The sweeps over mu, sigma, zeta: triggers, release and Lyapunov times (s)."""
    return _section("## Sensitivity (figure sensitive_analysis)",
                    markdown_table(sens, ["parameter", "value", "triggers", "release_time_s",
                                          "lyapunov_time_s", "final_norm_ratio"],
                                   ["parameter", "value", "triggers", "release (s)",
                                    "Lyapunov time (s)", "norm ratio at end"]))


def _figures_section() -> list[str]:
    """Links to the three figures written beside ``report.md``."""
    return _section("## Figures", "![release instants](release_instants.png)",
                    "![penetration](penetration.png)", "![sensitivity](sensitivity.png)")


def report_markdown(rep: Reproduction) -> str:
    """The text of ``report.md``, assembled section by section."""
    perf, delay = performance_table(rep), delay_table(rep)
    sections = [_overview(rep), _claims_section(claims(rep)), _performance_section(perf),
                _delay_section(perf, delay), _penetration_section(penetration_table(rep)),
                _events_section(events_table(rep)), _sensitivity_section(sensitivity_table(rep)),
                _figures_section()]
    return "\n".join(line for section in sections for line in section)


def figure_data(rep: Reproduction) -> ReproduceFigures:
    """The arrays behind the reproduction's figures (release instants of the ETC runs,
    penetration table, sensitivity sweeps), with the paper's numbers beside them."""
    runs = [r for r in rep.records if r.sweep is None and r.controller in ("etc",
                                                                           "observer-etc")]
    release = None
    if runs:
        paper = {e.scenario: f"{e.triggers if e.triggers is not None else '-'} / "
                             f"{e.release_time:.0f} s" for e in EVENTS
                 if e.release_time is not None}
        release = ([r.name for r in runs], [r.event_times for r in runs],
                   [r.release_time for r in runs], float(runs[0].summary["final_time"]), paper)
    pen, penetration = penetration_table(rep), None
    if pen:
        col = {k: [row[k] for row in pen] for k in pen[0]}
        penetration = (col["penetration_percent"], col["ours_triggers"],
                       col["ours_release_time_s"], col["paper_triggers"],
                       col["paper_release_time_s"])
    sens, sweeps = sensitivity_table(rep), {}
    for par in SENSITIVITY:
        rows = [r for r in sens if r["parameter"] == par]
        if rows:
            sweeps[par] = tuple(np.array([r[k] for r in rows], float)
                                for k in ("value", "release_time_s", "lyapunov_time_s"))
    return ReproduceFigures(release, penetration, sweeps,
                            {p: float(getattr(PAPER_DESIGN, p)) for p in sweeps})


def write_reproduction(rep: Reproduction, out: str | Path | OutputDir, plots: bool = True,
                       overwrite: bool = False) -> Path:
    """Write ``rep`` into directory ``out`` atomically (a previous ``reproduce`` result is
    replaced only with ``overwrite``, see :mod:`arzsumo.outdir`); return its path."""
    tables = {"diffperformance": performance_table(rep), "totaldelay": delay_table(rep),
              "diffpene": penetration_table(rep), "events": events_table(rep),
              "sensitivity": sensitivity_table(rep),
              "claims": [c.as_dict() for c in claims(rep)],
              "runs": [run_row(r) for r in rep.records]}
    return write_report(out, report_markdown(rep), tables,
                        {r.name: r.summary for r in rep.records},
                        figure_data(rep) if plots else None, overwrite=overwrite)
