"""The figures that set controllers or runs side by side: ``arzsumo evaluate``'s per-seed
paired differences against the baseline and ``arzsumo compare``'s bars."""

from __future__ import annotations

import math
import textwrap
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np
from matplotlib.figure import Figure

from arzsumo.plots import plt


@dataclass(frozen=True)
class DiffPanel:
    """One measure: its title (with unit) and, per controller, the per-seed differences
    and the mean difference with its 95 % CI (low, high), in the measure's unit."""

    title: str
    diffs: Mapping[str, np.ndarray]
    ci: Mapping[str, tuple[float, float, float]]


def paired_differences_figure(panels: Sequence[DiffPanel], title: str,
                              columns: int = 4) -> Figure:
    """A grid of panels: per controller, dots for the seeds' differences (slightly spread
    sideways), a bar for the mean and its CI, and a line at 0 (no difference)."""
    rows = max(1, math.ceil(len(panels) / columns))
    fig, axes = plt.subplots(rows, columns, figsize=(3.4 * columns, 2.6 * rows),
                             layout="constrained", squeeze=False)
    rng = np.random.default_rng(0)           # the same jitter every time
    for ax, panel in zip(axes.flat, panels, strict=False):
        names = list(panel.diffs)
        for k, name in enumerate(names):
            d = np.asarray(panel.diffs[name], float)
            ax.plot(k + rng.uniform(-0.12, 0.12, d.size), d, "o", ms=3, alpha=0.6,
                    color=f"C{k}")
            mean, low, high = panel.ci[name]
            if math.isfinite(mean):
                err = [[mean - low], [high - mean]] if math.isfinite(low) else None
                ax.errorbar(k + 0.3, mean, yerr=err, fmt="s", color="k", ms=4, capsize=3)
        ax.axhline(0.0, color="0.5", lw=0.8)
        ax.set_xticks(range(len(names)), names, rotation=30, fontsize=8)
        ax.set_xlim(-0.6, len(names) - 0.2)
        ax.set_title(textwrap.fill(panel.title, 46), fontsize=8)   # long labels wrap
        ax.tick_params(axis="y", labelsize=7)
    for ax in axes.flat[len(panels):]:
        ax.set_visible(False)
    fig.suptitle(title, fontsize=10)
    return fig


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
