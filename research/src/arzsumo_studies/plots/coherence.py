"""What a boundary can reach: the speed field's coherence with each boundary series.

One column per boundary series (q(0, t), q(L, t), U(t), as the caller names them). Top:
the magnitude-squared coherence against the place x (m) and the period (s, log scale),
the bands' edges drawn as lines. Bottom: each cell's coherent share of its band variance
against x, one line per band, with the estimator's bias floor dashed. Takes results read
by attribute (:class:`arzsumo_studies.measures.coherence.CoherentShare`: ``x`` m, ``f`` Hz,
``coherence`` (N, F), ``share`` (B, N), ``floor`` (N,), ``band_names``, ``band_s`` (B, 2)
s, ``share_section`` (B,)) and returns a Figure; nothing is converted (x in m, periods in
s, coherence and shares dimensionless).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import matplotlib.pyplot as plt
from matplotlib.figure import Figure

#: the bands' colours, in order
COLOURS = ("tab:red", "tab:blue", "tab:green")


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

