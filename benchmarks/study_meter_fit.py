"""Issue 17, point 1c: fit FOPDT models to the green-share steps of study_meter_steps.

Reads the per-second series of :mod:`study_meter_steps` and fits
y = y0 + K du (1 - exp(-(t - t0 - theta) / T)) (:func:`arzsumo.identify.step_response.fit_fopdt`,
1 s bin means) to the section's mainline outflow at x = L (HV + AV, veh/s) and to the
ramp flow past the meter:

* per step (one record from ``--pre`` s before the plan change to the next change);
* pooled per step direction (du < 0: less ramp green; du > 0: more) and per step type
  (0.5 -> 0.2, ...), over seeds and repeats (K, theta, T shared, one level per step);
* per seed, the whole staircase on one level.

Writes ``docs/results/meter_dynamics/meter_steps.csv`` (one row per fit, units in the
column names), the static levels (mean of the last ``--settled`` s of each hold) against
``meter.DEFAULT_CURVE`` and the figure ``docs/results/meter_dynamics/meter_steps.png``;
prints the tables of ``docs/results/meter_dynamics.md``.

Usage::

    PYTHONPATH=src python benchmarks/study_meter_fit.py \\
        docs/results/meter_dynamics/meter_steps_series.csv
"""

from __future__ import annotations

import argparse
import csv
import sys
from pathlib import Path
from typing import Any

import numpy as np

from arzsumo.identify.step_response import FopdtFit, StepData, fit_fopdt, fopdt_response
from arzsumo.sumo.meter import DEFAULT_CURVE

FIT_FIELDS = ["signal", "scope", "seed", "step", "du", "n_steps", "gain_veh_s",
              "sigma_gain_veh_s", "delay_s", "sigma_delay_s", "time_constant_s",
              "sigma_time_constant_s", "y0_veh_h", "residual_sd_veh_s", "samples"]


def load(path: Path) -> dict[int, dict[str, np.ndarray]]:
    """Per seed: column arrays of the series, plus ``y`` (outflow, veh/s) and ``ramp``."""
    with path.open() as f:
        rows = list(csv.DictReader(f))
    out: dict[int, dict[str, np.ndarray]] = {}
    for seed in sorted({int(r["seed"]) for r in rows}):
        mine = sorted((r for r in rows if int(r["seed"]) == seed), key=lambda r: float(r["t_s"]))
        cols = {k: np.array([float(r[k]) for r in mine]) for k in mine[0] if k != "seed"}
        cols["y"] = cols["out_h_veh"] + cols["out_a_veh"]
        cols["ramp"] = cols["ramp_veh"]
        out[seed] = cols
    return out


def plan_changes(d: dict[str, np.ndarray]) -> list[tuple[float, float, float]]:
    """(t0 s, green share before, after) of every plan change (t0: the new plan runs
    from t0; the row at t0 is the first whose running plan differs)."""
    g, t = d["g_run"], d["t_s"]
    idx = np.flatnonzero(np.diff(g) != 0) + 1
    return [(float(t[i]), float(g[i - 1]), float(g[i])) for i in idx]


def step_records(d: dict[str, np.ndarray], signal: str, pre: float
                 ) -> list[tuple[tuple[float, float], StepData]]:
    """One record per plan change: from ``pre`` s before it to the next change."""
    ch = plan_changes(d)
    out = []
    for j, (t0, g0, g1) in enumerate(ch):
        end = ch[j + 1][0] if j + 1 < len(ch) else np.inf
        keep = (d["t_s"] > t0 - pre) & (d["t_s"] <= end)
        out.append(((g0, g1), StepData(d["t_s"][keep], d[signal][keep], t0, g1 - g0)))
    return out


def staircase(d: dict[str, np.ndarray], signal: str, pre: float) -> StepData:
    """The whole run from ``pre`` s before the first change, on one level."""
    ch = plan_changes(d)
    keep = d["t_s"] > ch[0][0] - pre
    return StepData(d["t_s"][keep], d[signal][keep], tuple(c[0] for c in ch),
                    tuple(c[2] - c[1] for c in ch))


def row(signal: str, scope: str, seed: Any, step: str, du: Any, n: int, fit: FopdtFit
        ) -> dict[str, Any]:
    """One CSV row of a fit."""
    return {"signal": signal, "scope": scope, "seed": seed, "step": step, "du": du,
            "n_steps": n, "gain_veh_s": fit.gain, "sigma_gain_veh_s": fit.sigma_gain,
            "delay_s": fit.delay, "sigma_delay_s": fit.sigma_delay,
            "time_constant_s": fit.time_constant,
            "sigma_time_constant_s": fit.sigma_time_constant,
            "y0_veh_h": float(np.mean(fit.y0)) * 3600, "residual_sd_veh_s": fit.residual_sd,
            "samples": fit.n_samples}


STARTS = {"delay_starts": (2.0, 10.0), "tau_starts": (3.0, 15.0)}


def fits(data: dict[int, dict[str, np.ndarray]], signal: str, pre: float,
         detail: bool = True) -> list[dict[str, Any]]:
    """Per-step, pooled (direction, step type) and per-seed staircase fits of a signal
    (``detail=False``: only the pooled ones)."""
    rows, recs = [], []
    for seed, d in data.items():
        for (g0, g1), rec in step_records(d, signal, pre):
            recs.append(((g0, g1), rec))
            if detail:
                rows.append(row(signal, "step", seed, f"{g0:g}->{g1:g}", g1 - g0, 1,
                                fit_fopdt([rec], **STARTS)))
        if detail:
            rows.append(row(signal, "staircase", seed, "all", "", len(plan_changes(d)),
                            fit_fopdt([staircase(d, signal, pre)], **STARTS)))
    groups: dict[str, list[StepData]] = {"down (less ramp green)": [],
                                         "up (more ramp green)": []}
    for (g0, g1), rec in recs:
        groups["down (less ramp green)" if g1 < g0 else "up (more ramp green)"].append(rec)
        groups.setdefault(f"{g0:g}->{g1:g}", []).append(rec)
    for name, members in groups.items():
        if members:
            scope = "direction" if "ramp green" in name else "type"
            if scope == "type" and not detail:
                continue
            rows.append(row(signal, scope, "all", name, members[0].du[0]
                            if scope == "type" else "", len(members),
                            fit_fopdt(members, **STARTS)))
    both = [rec for _, rec in recs]
    rows.append(row(signal, "all steps", "all", "all", "", len(both),
                    fit_fopdt(both, **STARTS)))
    return rows


def static_levels(data: dict[int, dict[str, np.ndarray]], settled: float
                  ) -> dict[float, list[float]]:
    """Mean outflow (veh/h) over the last ``settled`` s of each hold, per green share."""
    out: dict[float, list[float]] = {}
    for d in data.values():
        ch = plan_changes(d)
        ends = [c[0] for c in ch[1:]] + [float(d["t_s"][-1])]
        for (_, _, g1), end in zip(ch, ends, strict=True):
            keep = (d["t_s"] > end - settled) & (d["t_s"] <= end)
            out.setdefault(g1, []).append(float(d["y"][keep].mean()) * 3600)
    return out


def staircase_model(d: dict[str, np.ndarray], r: dict[str, Any], pre: float
                    ) -> tuple[np.ndarray, np.ndarray]:
    """The per-seed staircase fit's model (times s, veh/s), from its CSV row."""
    rec = staircase(d, "y", pre)
    y = np.full(rec.t.size, r["y0_veh_h"] / 3600)
    for t0, du in zip(rec.t0, rec.du, strict=True):
        y += fopdt_response(rec.t, 0.0, r["gain_veh_s"], du, t0, r["delay_s"],
                            r["time_constant_s"], 1.0)
    return rec.t, y


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("series", type=Path)
    p.add_argument("--out", type=Path, default=Path("docs/results/meter_dynamics/meter_steps.csv"))
    p.add_argument("--figure", type=Path,
                   default=Path("docs/results/meter_dynamics/meter_steps.png"))
    p.add_argument("--pre", type=float, default=60.0, help="s before each change fitted")
    p.add_argument("--settled", type=float, default=60.0, help="s averaged for levels")
    args = p.parse_args(argv)
    data = load(args.series)
    rows = fits(data, "y", args.pre) + fits(data, "ramp", args.pre, detail=False)
    with args.out.open("w", newline="") as f:
        w = csv.DictWriter(f, FIT_FIELDS)
        w.writeheader()
        w.writerows({k: (f"{v:.5g}" if isinstance(v, float) else v) for k, v in r.items()}
                    for r in rows)
    from study_meter_plot import plot_steps, print_tables

    print_tables(rows, static_levels(data, args.settled), DEFAULT_CURVE)
    models = {r["seed"]: staircase_model(data[r["seed"]], r, args.pre) for r in rows
              if r["signal"] == "y" and r["scope"] == "staircase"}
    plot_steps(data, models, rows, args.figure)
    print(f"wrote {args.out} and {args.figure}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
