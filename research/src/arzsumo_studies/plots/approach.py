"""The map of the approach study (:mod:`arzsumo_studies.sumo_map.approach`): stationarity,
stop-and-go and regime over mainline demand x green share.

Top: four panels of the demand x green-share grid of one group of runs (seed means):
the section-count trend (veh/min, marked where the trend test rejects stationarity), the
HV speed sd (km/h), lambda_4 of the model (km/h; < 0 congested) and the mainline inserted
fraction; a star marks the points that qualify. Bottom: every run, trend against
stop-and-go and insertion against the buffer queue.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
from matplotlib.figure import Figure

from arzsumo.plots import plt


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
        if r["qualifies"]:
            text = "*" + text
        ax.text(j, i, text, ha="center", va="center", fontsize=7)
    ax.set_xticks(range(len(d)), [f"{v:.0f}" for v in d], fontsize=7)
    ax.set_yticks(range(len(g)), [f"{v:.2f}" for v in g], fontsize=7)
    ax.set_xlabel("mainline demand (veh/h)", fontsize=8)
    ax.set_ylabel("nominal green share", fontsize=8)
    ax.set_title(title, fontsize=8)


def _tradeoff(ax, df: pd.DataFrame, sd_min: float) -> None:
    """Every run: drift of the section count against HV speed sd, coloured by lambda_4."""
    sc = ax.scatter(df["drift_rel"] * 100, df["sd_v_h_kmh"], c=df["lambda4_kmh"],
                    cmap="coolwarm", vmin=-80, vmax=80, edgecolors="k", marker="o", s=40)
    ax.figure.colorbar(sc, ax=ax, label="lambda_4 (km/h)")
    ax.axvspan(-10, 10, color="0.9", zorder=-1)
    ax.axhline(sd_min, color="0.4", ls="--", lw=0.8)
    ax.set_xlabel("section count drift over the horizon (% of mean; grey: |drift| < 10 %)",
                  fontsize=8)
    ax.set_ylabel("HV speed sd (km/h)", fontsize=8)
    ax.set_title("every run: stationary (grey band) vs stop-and-go (above dashed line)",
                 fontsize=8)


def _insertion(ax, df: pd.DataFrame, inserted_min: float) -> None:
    """Every run: inserted fraction against the buffer queue at the end."""
    ax.scatter(df["queue_m_end"] / df["approach_m"], df["inserted_main"],
               c=df["lambda4_kmh"], cmap="coolwarm", vmin=-80, vmax=80, edgecolors="k", s=40)
    ax.axhline(inserted_min, color="0.4", ls="--", lw=0.8)
    ax.set_xlabel("buffer queue at the end / buffer length", fontsize=8)
    ax.set_ylabel("mainline inserted fraction", fontsize=8)
    ax.set_title("every run: insertion fails once the buffer queue reaches its start",
                 fontsize=8)


def approach_map_figure(points: pd.DataFrame, runs: pd.DataFrame, tag: str,
                        sd_min: float, inserted_min: float) -> Figure:
    """The map: ``points`` (seed means of one group, with a boolean ``qualifies``) on the
    grid, ``runs`` (every run) below; ``tag`` describes the group."""
    fig = plt.figure(figsize=(18, 9))
    top = [fig.add_subplot(2, 4, k + 1) for k in range(4)]
    _panel(top[0], points, "slope_veh_min", "coolwarm",
           f"section count trend (veh/min), {tag}", ".2f", center=0.0)
    _panel(top[1], points, "sd_v_h_kmh", "viridis", f"HV speed sd (km/h), {tag}", ".1f",
           lims=(0.0, 30.0))
    _panel(top[2], points, "lambda4_kmh", "coolwarm", f"lambda_4 (km/h), {tag}", ".1f",
           center=0.0)
    _panel(top[3], points, "inserted_main", "Greens", f"mainline inserted fraction, {tag}",
           ".3f", lims=(0.9, 1.0))
    _tradeoff(fig.add_subplot(2, 2, 3), runs, sd_min)
    _insertion(fig.add_subplot(2, 2, 4), runs, inserted_min)
    fig.suptitle("SUMO with an approach buffer: * = stationary, congested (lambda_4 < 0), "
                 f"HV speed sd >= {sd_min:g} km/h, >= {inserted_min:.0%} inserted",
                 fontsize=10)
    fig.tight_layout()
    return fig
