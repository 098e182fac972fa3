"""Write the report of ``arzsumo premise``: ``premise.json``, ``premise.csv`` and
``premise.png``, each atomically, and its table for the terminal.

The gates are :class:`~arzsumo_studies.gates.GateResult` records (SI values); the
table and the CSV also show each value in the unit a reader expects (km/h for speeds,
s, ratios as they are) through :func:`gate_unit`. The figure is drawn by
:func:`arzsumo_studies.plots.premise.premise_figure`.
"""

from __future__ import annotations

import json
import math
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import pandas as pd

from arzsumo.io import atomic_file, json_safe
from arzsumo_studies.gates import GateResult, PremiseVerdict, SeedSummary

JSON, CSV, FIGURE = "premise.json", "premise.csv", "premise.png"
#: CSV columns, in order
COLUMNS = ["seed", "gate", "value", "unit", "value_shown", "unit_shown", "threshold",
           "threshold_high", "passed"]
#: per gate (the name before "[class]"): SI unit, shown unit, factor SI -> shown, and how
#: the threshold reads ({} the threshold in the shown unit)
UNITS: dict[str, tuple[str, str, float, str]] = {
    "coupling": ("m/s", "km/h", 3.6, "<= {}"),
    "waves": ("m/s", "km/h", 3.6, "< {}, lag linear in distance"),
    "model_wave": ("1", "1", 1.0, "|ratio - 1| <= {}"),
    "amplification": ("1", "1", 1.0, ">= {}"),
    "pulse": ("s", "s", 1.0, "no decay by {}"),
    "actuator": ("1", "1", 1.0, "in {}"),
    "stationary": ("-", "-", 1.0, "= {}"),
    "inserted": ("1", "1", 1.0, ">= {}"),
    "ramp_demand": ("1", "1", 1.0, "<= {}"),
    "ramp_queue": ("1", "1", 1.0, "<= {}"),
}


def gate_unit(name: str) -> tuple[str, str, float, str]:
    """(SI unit, shown unit, factor, threshold form) of gate ``name`` (``waves[hv]``)."""
    return UNITS.get(name.split("[")[0], ("1", "1", 1.0, "{}"))


def _num(v: float, factor: float = 1.0) -> str:
    return "nan" if not math.isfinite(v) else f"{v * factor:.4g}"


def threshold_text(name: str, threshold: float | Sequence[float]) -> str:
    """The threshold of gate ``name`` in its shown unit, as the gate compares."""
    _, unit, factor, form = gate_unit(name)
    if isinstance(threshold, list | tuple):
        value = "[" + ", ".join(_num(float(v), factor) for v in threshold) + "]"
    else:
        value = _num(float(threshold), factor)
    return form.format(value if unit in ("1", "-") else f"{value} {unit}")


def csv_rows(gates: Mapping[int, Sequence[GateResult]]) -> pd.DataFrame:
    """One row per seed and gate (:data:`COLUMNS`)."""
    rows = []
    for seed, results in gates.items():
        for g in results:
            si, shown, factor, _ = gate_unit(g.name)
            lo, hi = (g.threshold if isinstance(g.threshold, tuple)
                      else (g.threshold, math.nan))
            rows.append({"seed": seed, "gate": g.name, "value": g.value, "unit": si,
                         "value_shown": g.value * factor, "unit_shown": shown,
                         "threshold": lo, "threshold_high": hi, "passed": g.passed})
    return pd.DataFrame(rows, columns=COLUMNS)


def _cell(g: GateResult | None) -> str:
    if g is None:
        return "-"
    return f"{_num(g.value, gate_unit(g.name)[2])} {'pass' if g.passed else 'FAIL'}"


def _overall(s: SeedSummary) -> str:
    return f"{s.passed_seeds}/{s.seeds} {'PASS' if s.passed else 'FAIL'}"


def premise_table(gates: Mapping[int, Sequence[GateResult]], verdict: PremiseVerdict,
                  pooled: GateResult | None = None,
                  pulse_mean: GateResult | None = None) -> str:
    """The gates per seed and over seeds as an aligned text table, with the verdict and
    the readings pooled over the seeds (the actuator, the pulse's mean response)."""
    seeds = list(gates)
    by = {s: {g.name: g for g in gates[s]} for s in seeds}
    head = ["gate", "unit", "threshold", *[f"seed {s}" for s in seeds], "seeds passing"]
    rows = []
    for part, summaries in (("premise", verdict.premise), ("model", verdict.model)):
        for s in summaries:
            first = next(by[k][s.name] for k in seeds if s.name in by[k])
            rows.append([s.name, gate_unit(s.name)[1], threshold_text(s.name, first.threshold),
                         *[_cell(by[k].get(s.name)) for k in seeds],
                         _overall(s) + (" (model)" if part == "model" else "")])
    widths = [max(len(str(r[i])) for r in [head, *rows]) for i in range(len(head))]
    lines = ["  ".join(str(c).ljust(w) for c, w in zip(r, widths, strict=True)).rstrip()
             for r in [head, *rows]]
    lines.insert(1, "  ".join("-" * w for w in widths))
    if pooled is not None:
        used = pooled.detail.get("seed_list")
        over = f"seeds {', '.join(map(str, used))}" if used else "the seeds"
        lines.append(f"actuator pooled over {over}: gain {_num(pooled.value)} "
                     f"({'pass' if pooled.passed else 'FAIL'}; reported, not in the verdict)")
        lines += [f"  {side}: {_num(f['gain'])} [{_num(f['gain_low'])}, "
                  f"{_num(f['gain_high'])}], {VERDICT_TEXT[f['verdict']]}"
                  for side, f in pooled.detail.get("levels", {}).items() if "verdict" in f]
    if pulse_mean is not None:
        lines.append(pulse_mean_line(pulse_mean))
    holds = "holds" if verdict.passed else "does not hold"
    failed = f"; failed: {', '.join(verdict.failed)}" if verdict.failed else ""
    lines += [f"premise {holds}{failed}", f"rule: {verdict.rule}"]
    return "\n".join(lines)


#: the actuator interval's verdict (:func:`arzsumo_studies.gates.actuator.verdict`)
VERDICT_TEXT = {"inside": "inside the range: resolved, passes",
                "outside": "outside the range: resolved, fails",
                "unresolved": "overlaps the range's edge: not resolved"}


def theory_lines(theory: Mapping[int, Mapping[str, Any]]) -> str:
    """Per seed the linear string-stability prediction of each class's model at the
    baseline's operating point: the theory beside the amplification and the pulse."""
    lines = ["linear string stability at each seed's operating point (theory; beside "
             "amplification and pulse):"]
    for seed, by_class in theory.items():
        parts = []
        for cls, p in by_class.items():
            if math.isnan(p.gain):
                parts.append(f"{cls} {p.model}: none ({p.reason})")
            else:
                parts.append(f"{cls} {p.model}: max|G| {p.gain:.4f}, x {p.growth:.3g} over "
                             f"{p.vehicles:.0f} vehicles")
        lines.append(f"  seed {seed}: " + "; ".join(parts))
    return "\n".join(lines) if theory else ""


def write_premise(out: Path, document: Mapping[str, Any],
                  gates: Mapping[int, Sequence[GateResult]],
                  pulses: Mapping[int, tuple[Any, ...]] | None = None,
                  stairs: Mapping[int, tuple[Any, ...]] | None = None,
                  plots: bool = True) -> list[Path]:
    """Write ``document`` as ``premise.json``, the gates as ``premise.csv`` and, with
    ``plots``, the figure of ``pulses`` and ``stairs`` as ``premise.png`` into ``out``;
    return the paths written."""
    out = Path(out)
    with atomic_file(out / JSON) as tmp:
        tmp.write_text(json.dumps(json_safe(dict(document)), indent=2) + "\n",
                       encoding="utf-8")
    with atomic_file(out / CSV) as tmp:
        csv_rows(gates).to_csv(tmp, index=False, float_format="%.6g")
    written = [out / JSON, out / CSV]
    if plots and pulses and stairs:
        from arzsumo.outputs.figures import save_png
        from arzsumo_studies.plots.premise import premise_figure

        written.append(save_png(premise_figure(pulses, stairs), out / FIGURE, dpi=100))
    return written


def pulse_mean_line(g: GateResult) -> str:
    """One line on the pulse's mean response over the seeds (s, m/s m^(1/2))."""
    d = g.detail
    if "total" not in d:
        head = f"pulse, mean response over {d.get('seeds', '?')} seeds: "
        return head + f"not measured ({d.get('reason', 'no reading')})"
    tot, floor = d["total"], d.get("floor", {}).get("total", math.nan)
    head = f"pulse, mean response over seeds {', '.join(map(str, d.get('seed_list', [])))}: "
    if not tot["detectable"]:
        return head + (f"peak {_num(tot['peak'])} at {_num(tot['peak_time_s'])} s, not above "
                       f"its floor {_num(floor)}: not read (reported, not in the verdict)")
    when = (f"decays {_num(tot['decay_time_s'])} s after the pulse"
            if tot["decayed"] else f"no decay by {_num(g.threshold)} s")
    return (head + f"peak {_num(tot['peak'])} at {_num(tot['peak_time_s'])} s over a floor "
            f"{_num(floor)}, {when} ({'pass' if g.passed else 'FAIL'}; reported, not in "
            "the verdict)")
