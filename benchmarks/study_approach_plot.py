"""The map of ``study_approach.py``: stationarity, stop-and-go and regime over demand x green.

One row of panels per (Krauss sigma, step length); seeds are averaged per point. Panels:
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


def qualifies(df: pd.DataFrame) -> pd.Series:
    """Stationary, congested under the model, visible stop-and-go, demand inserted."""
    return ((df["stationary"] >= 0.5) & (df["lambda4_kmh"] < 0)
            & (df["sd_v_h_kmh"] >= SD_MIN_KMH) & (df["inserted_main"] >= INSERTED_MIN))


def point_means(df: pd.DataFrame) -> pd.DataFrame:
    """Seed means per (step, sigma, demand, green share); ``stationary`` becomes the share
    of seeds that passed, ``seeds`` the count."""
    keys = ["step_s", "hv_sigma", "demand_veh_h", "green_share"]
    num = df.select_dtypes("number").columns.difference(keys)
    out = df.groupby(keys)[list(num)].mean()
    out["seeds"] = df.groupby(keys).size()
    return out.reset_index()


def _panel(ax, sub: pd.DataFrame, col: str, cmap: str, title: str, fmt: str,
           center: float | None = None) -> None:
    d = sorted(sub["demand_veh_h"].unique())
    g = sorted(sub["green_share"].unique())
    z = np.full((len(g), len(d)), np.nan)
    for _, r in sub.iterrows():
        z[g.index(r["green_share"]), d.index(r["demand_veh_h"])] = r[col]
    kw = {}
    if center is not None:
        lim = np.nanmax(np.abs(z - center)) or 1.0
        kw = {"vmin": center - lim, "vmax": center + lim}
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
    """The map as a Figure (seed means per point)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    pts = point_means(df)
    groups = list(pts.groupby(["step_s", "hv_sigma"]))
    fig, axes = plt.subplots(len(groups), 4, figsize=(17, 3.6 * len(groups)), squeeze=False)
    for row, ((step, sigma), sub) in zip(axes, groups, strict=True):
        tag = f"sigma {sigma:g}, step {step:g} s"
        _panel(row[0], sub, "slope_veh_min", "coolwarm",
               f"section count trend (veh/min), {tag}", ".2f", center=0.0)
        _panel(row[1], sub, "sd_v_h_kmh", "viridis", f"HV speed sd (km/h), {tag}", ".1f")
        _panel(row[2], sub, "lambda4_kmh", "coolwarm", f"lambda_4 (km/h), {tag}", ".1f",
               center=0.0)
        _panel(row[3], sub, "inserted_main", "Greens", f"mainline inserted fraction, {tag}",
               ".3f")
    fig.suptitle("SUMO with an approach buffer: * = stationary, congested (lambda_4 < 0), "
                 f"HV speed sd >= {SD_MIN_KMH:g} km/h, >= {INSERTED_MIN:.0%} inserted",
                 fontsize=10)
    fig.tight_layout()
    return fig


def plot_map(csv: Path) -> Path:
    """Write ``<csv stem>.png`` beside ``csv``; return its path."""
    import matplotlib.pyplot as plt

    fig = map_figure(pd.read_csv(csv))
    out = csv.with_suffix(".png")
    fig.savefig(out, dpi=110)
    plt.close(fig)
    return out
