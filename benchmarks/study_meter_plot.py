"""Tables and figure of :mod:`study_meter_fit` (green-share steps in SUMO)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from arzsumo.identify.step_response import fopdt_response
from arzsumo.sumo.meter import GreenShareCurve


def _fmt(r: dict[str, Any]) -> str:
    return (f"{r['gain_veh_s'] * 3600:+.0f} +- {r['sigma_gain_veh_s'] * 3600:.0f} | "
            f"{r['delay_s']:.1f} +- {r['sigma_delay_s']:.1f} | "
            f"{r['time_constant_s']:.1f} +- {r['sigma_time_constant_s']:.1f} | "
            f"{r['residual_sd_veh_s']:.2f}")


def _spread(rows: list[dict[str, Any]], key: str, scale: float = 1.0) -> str:
    v = np.array([r[key] for r in rows]) * scale
    return f"{np.median(v):.3g} [{v.min():.3g}, {v.max():.3g}]"


def print_tables(rows: list[dict[str, Any]], levels: dict[float, list[float]],
                 curve: GreenShareCurve) -> None:
    """The markdown tables of docs/results/meter_dynamics.md."""
    print("| signal | scope | seed | step | n | K veh/h per unit | theta s | T s | "
          "resid sd veh/s |\n|---|---|---|---|---|---|---|---|---|")
    for r in rows:
        if r["scope"] != "step":
            print(f"| {r['signal']} | {r['scope']} | {r['seed']} | {r['step']} | "
                  f"{r['n_steps']} | {_fmt(r)} |")
    print("\nper-step fits: median [min, max] over seeds and steps")
    for signal in ("y", "ramp"):
        for sign, name in ((-1, "down"), (1, "up")):
            sel = [r for r in rows if r["signal"] == signal and r["scope"] == "step"
                   and np.sign(r["du"]) == sign]
            if sel:
                print(f"| {signal} | {name} | {len(sel)} | "
                      f"{_spread(sel, 'gain_veh_s', 3600)} | {_spread(sel, 'delay_s')} | "
                      f"{_spread(sel, 'time_constant_s')} |")
    print("\nstatic levels (mean of the settled part of each hold), veh/h")
    print("| green share | holds | outflow mean | sd | DEFAULT_CURVE |\n|---|---|---|---|---|")
    for g in sorted(levels):
        v = np.array(levels[g])
        print(f"| {g:g} | {v.size} | {v.mean():.0f} | {v.std(ddof=1) if v.size > 1 else 0:.0f}"
              f" | {curve.outflow_at(g) * 3600:.0f} |")
    for lo, hi in ((0.2, 0.5), (0.5, 0.8), (0.2, 0.8)):
        if lo in levels and hi in levels:
            s = (np.mean(levels[hi]) - np.mean(levels[lo])) / (hi - lo)
            c = (curve.outflow_at(hi) - curve.outflow_at(lo)) * 3600 / (hi - lo)
            print(f"slope {lo:g}-{hi:g}: measured {s:+.0f}, DEFAULT_CURVE {c:+.0f} veh/h per unit")


def _ensemble(data: dict[int, dict[str, np.ndarray]], sign: int, span: float
              ) -> tuple[np.ndarray, np.ndarray]:
    """Mean of (y - level before) / du over the steps of one sign, against time since
    the change (s), as a trailing 6 s (one cycle) mean."""
    from study_meter_fit import plan_changes

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
    smooth = np.convolve(mean, np.ones(6) / 6, mode="full")[: mean.size]   # trailing 6 s
    return lag, smooth


def plot_steps(data: dict[int, dict[str, np.ndarray]],
               models: dict[Any, tuple[np.ndarray, np.ndarray]],
               rows: list[dict[str, Any]], path: Path) -> None:
    """Per seed: outflow per second, 10 s means, the staircase fit and the green share;
    last panel: the mean normalised response per direction with the pooled fit."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    seeds = sorted(data)
    fig, axes = plt.subplots(len(seeds) + 1, 1, figsize=(10, 2.6 * (len(seeds) + 1)))
    for ax, seed in zip(axes, seeds, strict=False):
        d = data[seed]
        t = d["t_s"]
        ax.plot(t, d["y"] * 3600, ".", ms=2, color="0.7", label="outflow per 1 s")
        n = t.size // 10
        tb = t[: n * 10].reshape(n, 10)[:, -1]
        yb = d["y"][: n * 10].reshape(n, 10).mean(axis=1) * 3600
        ax.step(tb, yb, where="post", color="C0", label="10 s mean")
        tm, ym = models[seed]
        ax.plot(tm, ym * 3600, color="C3", lw=1.5, label="FOPDT fit (staircase)")
        ax.set_ylim(0, 9000)
        ax.set_ylabel("q(L) veh/h")
        ax.set_title(f"seed {seed}", fontsize=9)
        tw = ax.twinx()
        tw.plot(t, d["g_run"], color="k", lw=0.8, drawstyle="steps-pre")
        tw.set_ylim(0, 2)
        tw.set_yticks([0.2, 0.5, 0.8])
        tw.set_ylabel("green share")
    axes[0].legend(loc="upper left", fontsize=7, ncol=3)
    axes[-2].set_xlabel("t s")
    ax = axes[-1]
    for sign, color, name in ((-1, "C0", "down (less ramp green)"),
                              (1, "C2", "up (more ramp green)")):
        lag, mean = _ensemble(data, sign, 90)
        ax.plot(lag, mean * 3600, ".-", ms=3, color=color, lw=0.6, label=f"mean {name}, 6 s means")
        r = next(r for r in rows if r["signal"] == "y" and r["step"] == name)
        fit = fopdt_response(lag, 0.0, r["gain_veh_s"], 1.0, 0.0, r["delay_s"],
                             r["time_constant_s"], 6.0)
        ax.plot(lag, fit * 3600, color=color, lw=2, alpha=0.6,
                label=f"fit K={r['gain_veh_s'] * 3600:.0f} veh/h, theta={r['delay_s']:.1f} s,"
                      f" T={r['time_constant_s']:.1f} s")
    ax.axvline(0, color="k", lw=0.5)
    ax.set_xlabel("s since the plan change")
    ax.set_ylabel("(q - q before) / du, veh/h")
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
