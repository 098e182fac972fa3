"""First-order-plus-dead-time fits to the green-share steps of
:mod:`arzsumo_studies.sumo_map.meter_dynamics`, the static levels, and their tables.

The model y = y0 + K du (1 - exp(-(t - t0 - theta) / T))
(:func:`arzsumo_studies.measures.step_response.fit_fopdt`, 1 s bin means) is fitted to the
section's mainline outflow at x = L (HV + AV, veh/s; signal ``y``) and to the ramp flow
past the meter (signal ``ramp``):

* per step (one record from ``pre`` s before the plan change to the next change);
* pooled per step direction (du < 0: less ramp green; du > 0: more) and per step type
  (0.5 -> 0.2, ...), over seeds and repeats (K, theta, T shared, one level per step);
* per seed, the whole staircase on one level.

Pure: series in, rows and text out (the study writes them).
"""

from __future__ import annotations

from typing import Any

import numpy as np
import pandas as pd

from arzsumo.sumo.green_share import GreenShareCurve
from arzsumo.units import VEH_H_PER_VEH_S, veh_h_to_veh_s, veh_s_to_veh_h
from arzsumo_studies.measures.step_response import FopdtFit, StepData, fit_fopdt, fopdt_response

#: columns of the fit table (units in the names; gains per unit of green share)
FIT_FIELDS = ["signal", "scope", "seed", "step", "du", "n_steps", "gain_veh_s",
              "sigma_gain_veh_s", "delay_s", "sigma_delay_s", "time_constant_s",
              "sigma_time_constant_s", "y0_veh_h", "residual_sd_veh_s", "samples"]
#: starting values of the fits' dead time and time constant, s
STARTS = {"delay_starts": (2.0, 10.0), "tau_starts": (3.0, 15.0)}
DOWN, UP = "down (less ramp green)", "up (more ramp green)"
Series = dict[int, dict[str, np.ndarray]]


def by_seed(series: pd.DataFrame) -> Series:
    """Per seed: column arrays of the series (time order), plus ``y`` (outflow, veh/s)
    and ``ramp`` (ramp vehicles past the meter per s)."""
    out: Series = {}
    for seed, g in series.groupby("seed"):
        g = g.sort_values("t_s")
        cols = {k: g[k].to_numpy(float) for k in g.columns if k != "seed"}
        cols["y"] = cols["out_h_veh"] + cols["out_a_veh"]
        cols["ramp"] = cols["ramp_veh"]
        out[int(seed)] = cols
    return out


def plan_changes(d: dict[str, np.ndarray]) -> list[tuple[float, float, float]]:
    """(t0 s, green share before, after) of every plan change (the row at t0 is the
    first whose running plan differs)."""
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
    """One row of the fit table."""
    return {"signal": signal, "scope": scope, "seed": seed, "step": step, "du": du,
            "n_steps": n, "gain_veh_s": fit.gain, "sigma_gain_veh_s": fit.sigma_gain,
            "delay_s": fit.delay, "sigma_delay_s": fit.sigma_delay,
            "time_constant_s": fit.time_constant,
            "sigma_time_constant_s": fit.sigma_time_constant,
            "y0_veh_h": veh_s_to_veh_h(float(np.mean(fit.y0))),
            "residual_sd_veh_s": fit.residual_sd,
            "samples": fit.n_samples}


def _pooled(recs: list[tuple[tuple[float, float], StepData]], signal: str, detail: bool
            ) -> list[dict[str, Any]]:
    """Fits pooled per direction, per step type (with ``detail``) and over all steps."""
    groups: dict[str, list[StepData]] = {DOWN: [], UP: []}
    for (g0, g1), rec in recs:
        groups[DOWN if g1 < g0 else UP].append(rec)
        groups.setdefault(f"{g0:g}->{g1:g}", []).append(rec)
    rows = []
    for name, members in groups.items():
        scope = "direction" if name in (DOWN, UP) else "type"
        if members and (detail or scope == "direction"):
            rows.append(row(signal, scope, "all", name, members[0].du[0]
                            if scope == "type" else "", len(members),
                            fit_fopdt(members, **STARTS)))
    both = [rec for _, rec in recs]
    return [*rows, row(signal, "all steps", "all", "all", "", len(both),
                       fit_fopdt(both, **STARTS))]


def fits(data: Series, signal: str, pre: float, detail: bool = True) -> list[dict[str, Any]]:
    """Per-step, pooled (direction, step type) and per-seed staircase fits of a signal
    (``detail=False``: only the pooled ones by direction and over all steps)."""
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
    return rows + _pooled(recs, signal, detail)


def static_levels(data: Series, settled: float) -> dict[float, list[float]]:
    """Mean outflow (veh/h) over the last ``settled`` s of each hold, per green share."""
    out: dict[float, list[float]] = {}
    for d in data.values():
        ch = plan_changes(d)
        ends = [c[0] for c in ch[1:]] + [float(d["t_s"][-1])]
        for (_, _, g1), end in zip(ch, ends, strict=True):
            keep = (d["t_s"] > end - settled) & (d["t_s"] <= end)
            out.setdefault(g1, []).append(veh_s_to_veh_h(float(d["y"][keep].mean())))
    return out


def levels_table(levels: dict[float, list[float]], curve: GreenShareCurve) -> pd.DataFrame:
    """Per green share: holds, mean and sd of the settled outflow and the curve's, veh/h."""
    rows = []
    for g in sorted(levels):
        v = np.array(levels[g])
        rows.append({"green_share": g, "holds": v.size, "outflow_mean_veh_h": v.mean(),
                     "outflow_sd_veh_h": v.std(ddof=1) if v.size > 1 else 0.0,
                     "curve_veh_h": veh_s_to_veh_h(curve.outflow_at(g))})
    return pd.DataFrame(rows)


def staircase_model(d: dict[str, np.ndarray], r: dict[str, Any], pre: float
                    ) -> tuple[np.ndarray, np.ndarray]:
    """The per-seed staircase fit's model (times s, veh/s), from its table row."""
    rec = staircase(d, "y", pre)
    y = np.full(rec.t.size, veh_h_to_veh_s(r["y0_veh_h"]))
    for t0, du in zip(rec.t0, rec.du, strict=True):
        y += fopdt_response(rec.t, 0.0, r["gain_veh_s"], du, t0, r["delay_s"],
                            r["time_constant_s"], 1.0)
    return rec.t, y


def ensemble(data: Series, sign: int, span: float) -> tuple[np.ndarray, np.ndarray]:
    """Mean of (y - level before) / du over the steps of one sign, against time since
    the change (s), as a trailing 6 s (one cycle) mean."""
    lag = np.arange(-20.0, span + 1)
    acc = []
    for d in data.values():
        for t0, g0, g1 in plan_changes(d):
            if np.sign(g1 - g0) != sign:
                continue
            base = d["y"][(d["t_s"] > t0 - 30) & (d["t_s"] <= t0)].mean()
            y = np.interp(t0 + lag, d["t_s"], d["y"], left=np.nan, right=np.nan)
            acc.append((y - base) / (g1 - g0))
    mean = np.nanmean(acc, axis=0)
    smooth = np.convolve(mean, np.ones(6) / 6, mode="full")[: mean.size]
    return lag, smooth


def ensembles(data: Series, rows: list[dict[str, Any]], span: float = 90.0
              ) -> list[tuple[str, np.ndarray, np.ndarray, np.ndarray, str]]:
    """Per direction with a pooled fit in ``rows``: (name, lag s, mean normalised
    response veh/h, the pooled fit's response veh/h, the fit's label) for the figure's
    last panel. A direction without a fit (no steps that way) is left out."""
    out = []
    for sign, name in ((-1, DOWN), (1, UP)):
        r = next((r for r in rows if r["signal"] == "y" and r["step"] == name), None)
        if r is None:
            continue
        lag, mean = ensemble(data, sign, span)
        fit = fopdt_response(lag, 0.0, r["gain_veh_s"], 1.0, 0.0, r["delay_s"],
                             r["time_constant_s"], 6.0)
        label = (f"fit K={veh_s_to_veh_h(r['gain_veh_s']):.0f} veh/h, theta={r['delay_s']:.1f} s, "
                 f"T={r['time_constant_s']:.1f} s")
        out.append((name, lag, veh_s_to_veh_h(mean), veh_s_to_veh_h(fit), label))
    return out


def _fmt(r: dict[str, Any]) -> str:
    return (f"{veh_s_to_veh_h(r['gain_veh_s']):+.0f} +- "
            f"{veh_s_to_veh_h(r['sigma_gain_veh_s']):.0f} | "
            f"{r['delay_s']:.1f} +- {r['sigma_delay_s']:.1f} | "
            f"{r['time_constant_s']:.1f} +- {r['sigma_time_constant_s']:.1f} | "
            f"{r['residual_sd_veh_s']:.2f}")


def _spread(rows: list[dict[str, Any]], key: str, scale: float = 1.0) -> str:
    v = np.array([r[key] for r in rows]) * scale
    return f"{np.median(v):.3g} [{v.min():.3g}, {v.max():.3g}]"


def tables(rows: list[dict[str, Any]], levels: pd.DataFrame) -> str:
    """The Markdown tables: pooled and staircase fits, the spread of the per-step fits,
    the static levels against the meter curve and the slopes between them."""
    out = ["| signal | scope | seed | step | n | K veh/h per unit | theta s | T s | "
           "resid sd veh/s |", "|---|---|---|---|---|---|---|---|---|"]
    out += [f"| {r['signal']} | {r['scope']} | {r['seed']} | {r['step']} | {r['n_steps']} "
            f"| {_fmt(r)} |" for r in rows if r["scope"] != "step"]
    out += ["", "Per-step fits, median [min, max] over seeds and steps:", "",
            "| signal | direction | n | K veh/h per unit | theta s | T s |",
            "|---|---|---|---|---|---|"]
    for signal in ("y", "ramp"):
        for sign, name in ((-1, "down"), (1, "up")):
            sel = [r for r in rows if r["signal"] == signal and r["scope"] == "step"
                   and np.sign(r["du"]) == sign]
            if sel:
                out.append(f"| {signal} | {name} | {len(sel)} | "
                           f"{_spread(sel, 'gain_veh_s', VEH_H_PER_VEH_S)} | "
                           f"{_spread(sel, 'delay_s')} "
                           f"| {_spread(sel, 'time_constant_s')} |")
    out += ["", "Static levels (mean of the settled part of each hold), veh/h:", "",
            "| green share | holds | outflow mean | sd | meter curve |", "|---|---|---|---|---|"]
    out += [f"| {r.green_share:g} | {r.holds} | {r.outflow_mean_veh_h:.0f} | "
            f"{r.outflow_sd_veh_h:.0f} | {r.curve_veh_h:.0f} |" for r in levels.itertuples()]
    lv = levels.set_index("green_share")
    for lo, hi in ((0.2, 0.5), (0.5, 0.8), (0.2, 0.8)):
        if lo in lv.index and hi in lv.index:
            s = (lv.loc[hi, "outflow_mean_veh_h"] - lv.loc[lo, "outflow_mean_veh_h"]) / (hi - lo)
            c = (lv.loc[hi, "curve_veh_h"] - lv.loc[lo, "curve_veh_h"]) / (hi - lo)
            out.append(f"\nslope {lo:g}-{hi:g}: measured {s:+.0f}, meter curve {c:+.0f} "
                       "veh/h per unit")
    return "\n".join(out)
