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
#: panels drawn when every table has them (records made before them lack them)
WAVE_PANELS = {"section.waves.h.growth_per_km": "HV wave growth upstream, 1/km",
               "section.speed_oscillation_kmh.h": "HV speed oscillation, km/h"}


def penetration_figure(tables: Mapping[str, pd.DataFrame], share: str = "penetration",
                       inflow: str = "equal inflow") -> Figure:
    """One panel per :data:`PANELS` key against ``share`` (in %): each table's seeds as
    thin lines, their mean with its 95 % t interval as markers; ``tables``: label ->
    finished runs (columns ``share``, ``seed`` and the keys); ``inflow``: how the
    demand was set across shares (the title says it)."""
    from scipy import stats

    panels = PANELS | {k: v for k, v in WAVE_PANELS.items()
                       if all(k in t.columns for t in tables.values())}
    fig, axes = plt.subplots(1, len(panels), figsize=(3.5 * len(panels), 3.4))
    for (label, table), colour in zip(tables.items(), ("C0", "C3", "C2"), strict=False):
        for ax, key in zip(axes, panels, strict=True):
            for _, g in table.sort_values(share).groupby("seed"):
                ax.plot(100 * g[share], g[key], color=colour, alpha=0.25, lw=0.8)
            agg = table.groupby(share)[key].agg(["mean", "std", "count"])
            half = stats.t.ppf(0.975, np.maximum(agg["count"] - 1, 1)) * agg["std"] \
                / np.sqrt(agg["count"])
            ax.errorbar(100 * agg.index.to_numpy(float), agg["mean"], yerr=half,
                        color=colour, marker="o", capsize=3, label=label)
    for ax, text in zip(axes, panels.values(), strict=True):
        ax.set_xlabel("AV share of the mainline demand, %")
        ax.set_ylabel(text)
        ax.grid(alpha=0.3)
    fig.legend(*axes[0].get_legend_handles_labels(), loc="lower center",
               ncol=len(tables), fontsize=8, frameon=False)
    fig.suptitle(f"ETC against the AV share in SUMO ({inflow}; thin: one seed)",
                 fontsize=10)
    fig.tight_layout(rect=(0, 0.08, 1, 1))      # room for the legend below
    return fig
