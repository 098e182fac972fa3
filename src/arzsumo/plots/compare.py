"""The bar plot of ``arzsumo compare``: one panel per metric, bars per controller or run."""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from arzsumo.plots import plt


def comparison_figure(labels: list[str],
                      bars: dict[str, tuple[np.ndarray, np.ndarray | None]],
                      title: str) -> Figure:
    """One bar chart per metric: ``bars`` maps a panel title (with its unit) to the bar
    heights and their error bars (None: no error bars), one bar per label; ``title``
    says what the bars are (means over seeds, or single runs)."""
    fig, axes = plt.subplots(1, len(bars), figsize=(4 * len(bars), 3.8),
                             layout="constrained", squeeze=False)
    for ax, (name, (height, err)) in zip(axes[0], bars.items(), strict=True):
        ax.bar(labels, height, yerr=err, capsize=3, color="C0")
        ax.set_title(name, fontsize=10)
        ax.tick_params(axis="x", rotation=30)
    fig.suptitle(title, fontsize=10)
    return fig
