"""What a boundary can reach: the speed field's coherence with each boundary series.

One column per boundary series (q(0, t), q(L, t), U(t), as the caller names them). Top:
the magnitude-squared coherence against the place x (m) and the period (s, log scale),
the bands' edges drawn as lines. Bottom: each cell's coherent share of its band variance
against x, one line per band, with the estimator's bias floor dashed. Takes results read
by attribute (:class:`arzsumo_studies.measures.coherence.CoherentShare`: ``x`` m, ``f`` Hz,
``coherence`` (N, F), ``share`` (B, N), ``floor`` (N,), ``band_names``, ``band_s`` (B, 2)
s, ``share_section`` (B,)) and returns a Figure; nothing is converted (x in m, periods in
s, coherence and shares dimensionless).

:func:`reach_figure`: the coherence maps alone, a row of panels per condition (``arzsumo
study reach``), on one colour scale.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np
from matplotlib.figure import Figure

from arzsumo.plots import plt  # matplotlib's Agg backend, selected there

#: the bands' colours, in order
COLOURS = ("tab:red", "tab:blue", "tab:green")
#: the boundary series' names in a title
LABELS = {"q0": "q(0, t)", "qL": "q(L, t)", "U": "U(t)"}
#: the periods marked on a log axis, s
PERIOD_TICKS_S = (10.0, 20.0, 30.0, 60.0, 100.0, 200.0, 300.0, 600.0, 1200.0)


def _map(ax: Any, res: Any, name: str) -> Any:
    keep = res.f > 0
    periods = 1.0 / res.f[keep]
    mesh = ax.pcolormesh(res.x, periods, res.coherence[:, keep].T, vmin=0.0, vmax=1.0,
                         cmap="viridis", shading="nearest")
    ax.set_yscale("log")
    for (lo, hi), colour in zip(res.band_s, COLOURS, strict=False):
        for edge in (lo, hi):
            ax.axhline(edge, color=colour, lw=0.8, ls=":")
    ax.set_title(f"coherence with {name}", fontsize=10)
    ax.set_ylabel("period (s)")
    return mesh


def _shares(ax: Any, res: Any) -> None:
    for k, (band, colour) in enumerate(zip(res.band_names, COLOURS, strict=False)):
        lo, hi = res.band_s[k]
        ax.plot(res.x, res.share[k], "o-", ms=3, lw=1.0, color=colour,
                label=f"{band} ({lo:g}-{hi:g} s): {res.share_section[k]:.2f}")
    ax.plot(res.x, res.floor, "k--", lw=0.8, label="bias floor 1/n_eff")
    ax.set_ylim(0.0, 1.0)
    ax.set_xlabel("x (m)")
    ax.set_ylabel("coherent share of the band variance")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=7, loc="upper right")


def coherence_figure(results: Mapping[str, Any], title: str = "") -> Figure:
    """The figure (module docstring).

    Parameters
    ----------
    results : mapping
        Boundary label (e.g. ``q(0,t)``, ``q(L,t)``, ``U(t)``) -> its result, read by
        attribute (module docstring; e.g. ``BoundaryShares.results``).
    title : str, optional
        The figure's title.
    """
    n = len(results)
    if not n:
        raise ValueError("results = {} is not allowed: at least one boundary series")
    fig, axes = plt.subplots(2, n, figsize=(4.6 * n, 7.0), layout="constrained",
                             sharex=True, squeeze=False)
    mesh = None
    for j, (name, res) in enumerate(results.items()):
        mesh = _map(axes[0, j], res, name)
        _shares(axes[1, j], res)
    fig.colorbar(mesh, ax=axes[0, :].tolist(), label="magnitude-squared coherence")
    if title:
        fig.suptitle(title)
    return fig



def _reach_panel(ax: Any, res: Any, limits: tuple[float, float]) -> Any:
    """One condition's coherence with one boundary over x (m) and period (s, log)."""
    keep = res.f > 0
    mesh = ax.pcolormesh(res.x, 1.0 / res.f[keep], res.coherence[:, keep].T, vmin=0.0,
                         vmax=1.0, cmap="viridis", shading="nearest")
    ax.set_yscale("log")
    ax.set_ylim(*limits)
    ticks = [t for t in PERIOD_TICKS_S if limits[0] <= t <= limits[1]]
    ax.set_yticks(ticks, [f"{t:g}" for t in ticks])
    ax.minorticks_off()
    for (lo, hi), colour in zip(res.band_s, COLOURS, strict=False):
        for edge in (lo, hi):
            ax.axhline(edge, color=colour, lw=0.8, ls=":")
    return mesh


def reach_figure(conditions: Mapping[str, Mapping[str, Any]]) -> Figure:
    """The coherence against x and period: a row per condition, a column per boundary.

    Parameters
    ----------
    conditions : mapping
        Condition name -> (boundary name, e.g. ``q0``, ``qL``, ``U`` -> its result, read
        by attribute as in the module docstring; e.g. ``BoundaryShares.results``). Every
        condition has the same boundaries, in the columns' order.

    Returns
    -------
    Figure
        Each panel: the magnitude-squared coherence (1, colour 0..1, shared) over x (m,
        horizontal) and the period (s, vertical, log scale, from the bands' shortest to
        their longest period), the bands' edges dotted; the title gives the section's
        share per band.
    """
    if not conditions or not all(conditions.values()):
        raise ValueError("conditions = {} is not allowed: at least one condition with "
                         "at least one boundary series")
    names = list(next(iter(conditions.values())))
    band_s = np.vstack([r.band_s for c in conditions.values() for r in c.values()])
    limits = (float(band_s[:, 0].min()), float(band_s[:, 1].max()))
    rows, cols = len(conditions), len(names)
    fig, axes = plt.subplots(rows, cols, figsize=(4.2 * cols, 3.0 * rows + 0.6),
                             layout="constrained", sharex=True, sharey=True, squeeze=False)
    mesh = None
    for i, (condition, results) in enumerate(conditions.items()):
        for j, name in enumerate(names):
            res, ax = results[name], axes[i, j]
            mesh = _reach_panel(ax, res, limits)
            shares = ", ".join(f"{s:.2f}" for s in res.share_section)
            ax.set_title(f"{condition}: {LABELS.get(name, name)} ({shares})", fontsize=9)
        axes[i, 0].set_ylabel("period (s)")
    for ax in axes[-1]:
        ax.set_xlabel("x (m)")
    fig.colorbar(mesh, ax=axes.ravel().tolist(), label="magnitude-squared coherence")
    fig.suptitle("Coherence with each boundary series against x and period (in "
                 "parentheses: the section's share per band, shortest periods first)",
                 fontsize=10)
    return fig
