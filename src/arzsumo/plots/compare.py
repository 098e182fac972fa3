"""The bar plot of ``arzsumo compare``: mean over seeds per controller, sd as error bars."""

from __future__ import annotations

import pandas as pd
from matplotlib.figure import Figure

from arzsumo.plots import plt


def comparison_figure(df: pd.DataFrame) -> Figure:
    """One panel per metric; ``df`` has one row per run with a ``controller`` column and
    the columns of :data:`arzsumo.bridge.compare.COLUMNS` (human units)."""
    grouped = df.groupby("controller", sort=False)
    metrics = [("plan_changes", "meter plan changes"), ("TTT_veh_h", "TTT (veh h)"),
               ("delay_veh_h", "total delay (veh h)"), ("speed_sd_h_kmh", "sd of HV speed (km/h)")]
    fig, axes = plt.subplots(1, len(metrics), figsize=(4 * len(metrics), 3.6),
                             layout="constrained")
    for ax, (col, label) in zip(axes, metrics, strict=True):
        mean, sd = grouped[col].mean(), grouped[col].std().fillna(0.0)
        ax.bar(mean.index, mean.values, yerr=sd.values, capsize=3, color="C0")
        ax.set_title(label, fontsize=10)
        ax.tick_params(axis="x", rotation=30)
    fig.suptitle("mean over seeds (error bars: standard deviation)")
    return fig
