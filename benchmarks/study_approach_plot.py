"""The map of ``study_approach.py``: stationarity, stop-and-go and regime over demand x green.

Top: the demand x green-share grid of the largest group of runs (same step, Krauss sigma,
warm-up, buffer length and AV share; seeds averaged per point). Bottom: every run, trend
against stop-and-go and insertion against the buffer queue. Grid panels:
section-count trend (veh/min, hatched where the trend test rejects stationarity), HV
speed sd (km/h), lambda_4 of the calibrated model (km/h; < 0 congested), mainline
inserted fraction. A star marks points meeting every criterion of :func:`qualifies`.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

#: visible stop-and-go: HV speed sd over cells x periods at least this, km/h (free flow
#: on main today: 5.5 km/h)
SD_MIN_KMH = 10.0
INSERTED_MIN = 0.98
#: one row of panels per combination of these
GROUP = ["step_s", "hv_sigma", "warmup_s", "approach_m", "av_share"]
#: the default scenario's mainline AV share (rows written before the column existed)
AV_SHARE = 1560.0 / 5664.0


def qualifies(df: pd.DataFrame) -> pd.Series:
    """Stationary, congested under the model, visible stop-and-go, demand inserted."""
    return ((df["stationary"] >= 0.5) & (df["lambda4_kmh"] < 0)
            & (df["sd_v_h_kmh"] >= SD_MIN_KMH) & (df["inserted_main"] >= INSERTED_MIN))


def point_means(df: pd.DataFrame) -> pd.DataFrame:
    """Seed means per (step, sigma, demand, green share); ``stationary`` becomes the share
    of seeds that passed, ``seeds`` the count."""
    keys = [*GROUP, "demand_veh_h", "green_share"]
    num = df.select_dtypes("number").columns.difference(keys)
    out = df.groupby(keys)[list(num)].mean()
    out["seeds"] = df.groupby(keys).size()
    return out.reset_index()


def _panel(ax, sub: pd.DataFrame, col: str, cmap: str, title: str, fmt: str,
           center: float | None = None, lims: tuple[float, float] | None = None) -> None:
    d = sorted(sub["demand_veh_h"].unique())
    g = sorted(sub["green_share"].unique())
    z = np.full((len(g), len(d)), np.nan)
    for _, r in sub.iterrows():
        z[g.index(r["green_share"]), d.index(r["demand_veh_h"])] = r[col]
    kw = {}
    if center is not None:
        lim = np.nanmax(np.abs(z - center)) or 1.0
        kw = {"vmin": center - lim, "vmax": center + lim}
    if lims is not None:
        kw = {"vmin": lims[0], "vmax": lims[1]}
    im = ax.imshow(z, origin="lower", aspect="auto", cmap=cmap, **kw)
    ax.figure.colorbar(im, ax=ax, shrink=0.8)
    for _, r in sub.iterrows():
        i, j = g.index(r["green_share"]), d.index(r["demand_veh_h"])
        text = format(r[col], fmt)
        if col == "slope_veh_min" and r["stationary"] < 0.5:
            text += "\n(trend)"
        if qualifies(pd.DataFrame([r])).iloc[0]:
            text = "*" + text
        ax.text(j, i, text, ha="center", va="center", fontsize=7)
    ax.set_xticks(range(len(d)), [f"{v:.0f}" for v in d], fontsize=7)
    ax.set_yticks(range(len(g)), [f"{v:.2f}" for v in g], fontsize=7)
    ax.set_xlabel("mainline demand (veh/h)", fontsize=8)
    ax.set_ylabel("nominal green share", fontsize=8)
    ax.set_title(title, fontsize=8)


def map_figure(df: pd.DataFrame):
    """The map as a Figure: the grid of the largest run group (top), every run (bottom)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    df = df.assign(av_share=df.get("av_share", pd.Series(index=df.index, dtype=float))
                   .fillna(AV_SHARE).round(3))
    pts = point_means(df)
    (step, sigma, warm, app, av), sub = max(pts.groupby(GROUP), key=lambda kv: len(kv[1]))
    fig = plt.figure(figsize=(18, 9))
    top = [fig.add_subplot(2, 4, k + 1) for k in range(4)]
    tag = (f"sigma {sigma:g}, step {step:g} s\nwarm-up {warm:g} s, buffer {app:g} m, "
           f"AV share {av:.2f}")
    _panel(top[0], sub, "slope_veh_min", "coolwarm", f"section count trend (veh/min), {tag}",
           ".2f", center=0.0)
    _panel(top[1], sub, "sd_v_h_kmh", "viridis", f"HV speed sd (km/h), {tag}", ".1f",
           lims=(0.0, 30.0))
    _panel(top[2], sub, "lambda4_kmh", "coolwarm", f"lambda_4 (km/h), {tag}", ".1f",
           center=0.0)
    _panel(top[3], sub, "inserted_main", "Greens", f"mainline inserted fraction, {tag}",
           ".3f", lims=(0.9, 1.0))
    _tradeoff(fig.add_subplot(2, 2, 3), df)
    _insertion(fig.add_subplot(2, 2, 4), df)
    fig.suptitle("SUMO with an approach buffer: * = stationary, congested (lambda_4 < 0), "
                 f"HV speed sd >= {SD_MIN_KMH:g} km/h, >= {INSERTED_MIN:.0%} inserted",
                 fontsize=10)
    fig.tight_layout()
    return fig


def _label(r: pd.Series) -> str:
    return (f"{r['demand_veh_h']:.0f}/{r['green_share']:g} s{r['hv_sigma']:g} "
            f"dt{r['step_s']:g} w{r['warmup_s']:.0f}"
            + (f" av{r['av_share']:.2f}" if abs(r["av_share"] - AV_SHARE) > 1e-3 else ""))


def _tradeoff(ax, df: pd.DataFrame) -> None:
    """Every run: drift of the section count against HV speed sd, coloured by lambda_4."""
    sc = ax.scatter(df["drift_rel"] * 100, df["sd_v_h_kmh"], c=df["lambda4_kmh"],
                    cmap="coolwarm", vmin=-80, vmax=80, edgecolors="k",
                    marker="o", s=40)
    ax.figure.colorbar(sc, ax=ax, label="lambda_4 (km/h)")
    for _, r in df.iterrows():
        if r["warmup_s"] > 150 or r["step_s"] < 0.2:
            ax.annotate(_label(r), (r["drift_rel"] * 100, r["sd_v_h_kmh"]), fontsize=6,
                        xytext=(3, 3), textcoords="offset points")
    ax.axvspan(-10, 10, color="0.9", zorder=-1)
    ax.axhline(SD_MIN_KMH, color="0.4", ls="--", lw=0.8)
    ax.set_xlabel("section count drift over the horizon (% of mean; grey: |drift| < 10 %)",
                  fontsize=8)
    ax.set_ylabel("HV speed sd (km/h)", fontsize=8)
    ax.set_title("every run: stationary (grey band) vs stop-and-go (above dashed line); "
                 "labels demand/green, sigma, step, warm-up", fontsize=8)


def _insertion(ax, df: pd.DataFrame) -> None:
    """Every run: inserted fraction against the buffer queue at the end."""
    ax.scatter(df["queue_m_end"] / df["approach_m"], df["inserted_main"],
               c=df["lambda4_kmh"], cmap="coolwarm", vmin=-80, vmax=80, edgecolors="k", s=40)
    ax.axhline(INSERTED_MIN, color="0.4", ls="--", lw=0.8)
    ax.set_xlabel("buffer queue at the end / buffer length", fontsize=8)
    ax.set_ylabel("mainline inserted fraction", fontsize=8)
    ax.set_title("every run: insertion fails once the buffer queue reaches its start",
                 fontsize=8)


def plot_map(csv: Path) -> Path:
    """Write ``<csv stem>.png`` beside ``csv``; return its path."""
    import matplotlib.pyplot as plt

    fig = map_figure(pd.read_csv(csv))
    out = csv.with_suffix(".png")
    fig.savefig(out, dpi=110)
    plt.close(fig)
    return out
