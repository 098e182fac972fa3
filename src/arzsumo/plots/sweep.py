"""Figures of a sweep: triggers, release time (and, in SUMO, meter plan changes) against
each study axis, mean over seeds with one standard deviation as error bars, the paper's
values beside them where the paper gives numbers (tables diffpene and diffdemands).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence

import numpy as np
import pandas as pd
from matplotlib.axes import Axes
from matplotlib.figure import Figure

from arzsumo.plots import plt

LABELS = {"triggers": "triggers (control updates)", "release_time": "release time (s)",
          "plan_changes": "meter plan changes", "penetration": "AV penetration",
          "demand_veh_h": "total demand (veh/h)"}


def _numeric(values: np.ndarray) -> bool:
    return pd.api.types.is_numeric_dtype(pd.Series(values).infer_objects())


def _stats(df: pd.DataFrame, x: str, metric: str) -> tuple[np.ndarray, ...]:
    # numbers in increasing order; names (controllers, ...) in the sweep file's order
    g = df.groupby(x, sort=_numeric(df[x].to_numpy()))[metric]
    mean, sd, n = g.mean(), g.std(ddof=1).fillna(0.0), g.count()
    return mean.index.to_numpy(), mean.to_numpy(float), sd.to_numpy(float), n.to_numpy()


def _label_axes(ax: Axes, x: str, metric: str) -> None:
    ax.set_xlabel(LABELS.get(x, x))
    ax.set_ylabel(LABELS.get(metric, metric))
    ax.set_ylim(bottom=0)
    ax.grid(alpha=0.3)


def _logscale(values: np.ndarray) -> bool:
    if not _numeric(values):
        return False
    v = np.asarray(values, float)
    return bool(v.size > 1 and np.all(v > 0) and v.max() / v.min() > 20)


def study_figure(df: pd.DataFrame, x: str, metrics: Sequence[str],
                 lines: Sequence[str] = (), paper: Mapping[str, Mapping[float, float]]
                 | None = None, title: str = "", label: str = "this sweep") -> Figure:
    """One panel per metric against axis ``x``; one line per combination of ``lines``
    columns (else one line called ``label``); error bars one standard deviation over the
    remaining rows (the seeds)."""
    fig, axes = plt.subplots(1, len(metrics), figsize=(4.2 * len(metrics), 3.6),
                             squeeze=False)
    groups = list(df.groupby(list(lines), sort=True)) if lines else [((), df)]
    for ax, metric in zip(axes[0], metrics, strict=True):
        for k, (key, part) in enumerate(groups):
            xs, mean, sd, _ = _stats(part, x, metric)
            label = ", ".join(f"{c}={v}" for c, v in zip(lines, np.atleast_1d(key),
                                                         strict=False)) or label
            ax.errorbar(xs, mean, yerr=sd, fmt="o-", capsize=3, color=f"C{k}", label=label)
        if paper and metric in paper and paper[metric]:
            px = np.array(sorted(paper[metric]))
            ax.plot(px, [paper[metric][v] for v in px], "k*--", ms=9, lw=1, label="paper")
        if _logscale(df[x].to_numpy()):
            ax.set_xscale("log")
        _label_axes(ax, x, metric)
        ax.legend(fontsize=8)
    if title:
        fig.suptitle(title)
    fig.tight_layout()
    return fig


def sensitivity_figure(df: pd.DataFrame, group: str, parameters: Sequence[str],
                       metrics: Sequence[str], marks: Mapping[str, float] | None = None,
                       title: str = "") -> Figure:
    """One-at-a-time study: rows are metrics, columns the varied parameters (the rows of
    ``df`` whose ``group`` column names that parameter); ``marks`` draws a reference value
    of each parameter (the paper's design) as a dotted line."""
    fig, axes = plt.subplots(len(metrics), len(parameters),
                             figsize=(4 * len(parameters), 3.0 * len(metrics)), squeeze=False)
    for j, par in enumerate(parameters):
        part = df[df[group] == par]
        for i, metric in enumerate(metrics):
            ax = axes[i, j]
            if part.empty:
                continue
            xs, mean, sd, _ = _stats(part, par, metric)
            ax.errorbar(xs.astype(float), mean, yerr=sd, fmt="o-", capsize=3)
            if _logscale(xs):
                ax.set_xscale("log")
            if marks and par in marks and math.isfinite(marks[par]):
                ax.axvline(marks[par], color="0.5", ls=":", lw=1)
            _label_axes(ax, par, metric)
    if title:
        fig.suptitle(title)
    fig.tight_layout()
    return fig
