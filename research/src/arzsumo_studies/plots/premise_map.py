"""The premise map's figure: points (rows) against gates (columns), coloured by the share
of seeds each gate passed on."""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np
import pandas as pd
from matplotlib.figure import Figure

from arzsumo.plots import plt


def premise_map_figure(wide: pd.DataFrame, gates: Sequence[str]) -> Figure:
    """Pass shares (0 red .. 1 green, grey: not measured) of ``gates`` per point of
    ``wide`` (the per-point table of :func:`arzsumo_studies.premise.map_study.map_tables`)."""
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


def theory_figure(wide: pd.DataFrame) -> Figure:
    """Theory beside measurement per point of ``wide``: the measured amplification
    (upstream over downstream amplitude, filled markers) and the linear prediction of the
    same ratio, the growth max|G|^N over the section's N vehicles (open markers; none
    for Krauss), per class, on a log scale with the line of no growth."""
    y = np.arange(len(wide))
    fig, ax = plt.subplots(figsize=(7.0, 1.4 + 0.36 * len(wide)))
    for k, (cls, colour) in enumerate((("hv", "tab:blue"), ("av", "tab:orange"))):
        dy = (k - 0.5) * 0.25
        measured = wide.get(f"amplification[{cls}]_value", pd.Series(np.nan, wide.index))
        theory = wide.get(f"growth_{cls}", pd.Series(np.nan, wide.index))
        ax.plot(measured.to_numpy(float), y + dy, "o", color=colour,
                label=f"{cls.upper()} measured amplification")
        ax.plot(theory.to_numpy(float), y + dy, "o", mfc="none", color=colour,
                label=f"{cls.upper()} predicted growth max|G|^N")
    ax.axvline(1.0, color="0.3", lw=0.8, ls="--")
    ax.set_xscale("log")
    ax.set_yticks(y, list(wide["point"]), fontsize=8)
    ax.invert_yaxis()
    ax.set_xlabel("upstream amplitude / downstream amplitude (> 1: grows upstream)")
    ax.set_title("theory beside measurement: linear string stability at the measured "
                 "operating point", fontsize=9)
    ax.legend(fontsize=7, loc="best")
    fig.tight_layout()
    return fig


def fields_figure(fields: Mapping[str, tuple[np.ndarray, np.ndarray, np.ndarray]],
                  tails: Mapping[str, float] | None = None) -> Figure:
    """Per point the HV speed field of its first seed's baseline (``fields``: point ->
    (t after the warm-up, s; cell centres, m; speeds, periods x cells, km/h)), with the
    queue's tail (``tails``, m) marked: stop-and-go shows as red stripes running down
    and to the right in x against t, i.e. upstream; a tail inside the section as a
    green band at x = 0."""
    names = list(fields)
    cols = min(4, max(1, len(names)))
    rows = int(np.ceil(len(names) / cols))
    fig, axes = plt.subplots(rows, cols, figsize=(3.4 * cols, 2.6 * rows), sharex=True,
                             sharey=True, squeeze=False)
    image = None
    for ax, name in zip(axes.flat, names, strict=False):
        t, x, v = fields[name]
        image = ax.pcolormesh(t, x, np.asarray(v, float).T, cmap="RdYlGn", vmin=0,
                              vmax=70, shading="auto")
        tail = (tails or {}).get(name, 0.0)
        if tail > 0:
            ax.axhline(tail, color="k", lw=0.8, ls="--")
        ax.set_title(name + (f" (tail {tail:.0f} m)" if tail > 0 else ""), fontsize=8)
    for ax in axes.flat[len(names):]:
        ax.set_visible(False)
    for ax in axes[-1]:
        ax.set_xlabel("t after the warm-up (s)", fontsize=8)
    for ax in axes[:, 0]:
        ax.set_ylabel("x (m)", fontsize=8)
    if image is not None:
        fig.colorbar(image, ax=axes, shrink=0.8, label="HV speed (km/h)")
    fig.suptitle("the HVs' speeds on the section, first seed, open loop", fontsize=9)
    return fig
