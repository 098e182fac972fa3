"""The premise map's figure: points (rows) against gates (columns), coloured by the share
of seeds each gate passed on."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import pandas as pd
from matplotlib.figure import Figure

from arzsumo.plots import plt


def premise_map_figure(wide: pd.DataFrame, gates: Sequence[str]) -> Figure:
    """Pass shares (0 red .. 1 green, grey: not measured) of ``gates`` per point of
    ``wide`` (the per-point table of :func:`arzsumo.studies.premise_map.map_tables`)."""
    share = np.array([[wide[f"{g}_passed"].iloc[i] for g in gates]
                      for i in range(len(wide))], dtype=float)
    fig, ax = plt.subplots(figsize=(1.0 + 0.75 * len(gates), 1.2 + 0.42 * len(wide)))
    cmap = plt.get_cmap("RdYlGn").with_extremes(bad="0.85")
    ax.imshow(np.ma.masked_invalid(share), cmap=cmap, vmin=0, vmax=1, aspect="auto")
    for (i, j), v in np.ndenumerate(share):
        ax.text(j, i, "-" if np.isnan(v) else f"{v:.0%}", ha="center", va="center",
                fontsize=7)
    ax.set_xticks(range(len(gates)), gates, rotation=40, ha="right", fontsize=8)
    labels = [f"{p} ({a})" for p, a in zip(wide["point"], wide["axis"], strict=True)]
    ax.set_yticks(range(len(wide)), labels, fontsize=8)
    ax.set_title("premise gates passed (share of seeds), open loop", fontsize=9)
    fig.tight_layout()
    return fig
