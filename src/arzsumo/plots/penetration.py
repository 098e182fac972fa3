"""The penetration study's figure: triggers, release time and the mainline demand
inserted against the AV share, per seed and on average."""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
import pandas as pd
from matplotlib.figure import Figure

from arzsumo.plots import plt

#: summary key -> axis label of the figure's panels
PANELS = {"triggers": "controller updates in 450 s",
          "release_time": "release time, s",
          "inserted_fraction_main": "mainline demand inserted"}


def penetration_figure(tables: Mapping[str, pd.DataFrame], share: str = "penetration",
                       inflow: str = "equal inflow") -> Figure:
    """One panel per :data:`PANELS` key against ``share`` (in %): each table's seeds as
    thin lines, their mean with its 95 % t interval as markers; ``tables``: label ->
    finished runs (columns ``share``, ``seed`` and the keys); ``inflow``: how the
    demand was set across shares (the title says it)."""
    from scipy import stats

    fig, axes = plt.subplots(1, len(PANELS), figsize=(4.0 * len(PANELS), 3.4))
    for (label, table), colour in zip(tables.items(), ("C0", "C3", "C2"), strict=False):
        for ax, key in zip(axes, PANELS, strict=True):
            for _, g in table.sort_values(share).groupby("seed"):
                ax.plot(100 * g[share], g[key], color=colour, alpha=0.25, lw=0.8)
            agg = table.groupby(share)[key].agg(["mean", "std", "count"])
            half = stats.t.ppf(0.975, np.maximum(agg["count"] - 1, 1)) * agg["std"] \
                / np.sqrt(agg["count"])
            ax.errorbar(100 * agg.index.to_numpy(float), agg["mean"], yerr=half,
                        color=colour, marker="o", capsize=3, label=label)
    for ax, text in zip(axes, PANELS.values(), strict=True):
        ax.set_xlabel("AV share of the mainline demand, %")
        ax.set_ylabel(text)
        ax.grid(alpha=0.3)
    axes[0].legend(fontsize=8)
    fig.suptitle(f"ETC against the AV share in SUMO ({inflow}; thin: one seed)",
                 fontsize=10)
    fig.tight_layout()
    return fig
