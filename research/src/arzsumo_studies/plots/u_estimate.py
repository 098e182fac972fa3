"""The figure of :mod:`arzsumo_studies.estimation.u_estimate`: the control law's U over time, one
line per state it acted on."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from matplotlib.figure import Figure

from arzsumo.plots import plt


def u_series_figure(series: Sequence[tuple[str, np.ndarray, np.ndarray]], title: str
                    ) -> Figure:
    """One line per (label, t s since the control start, U veh/h)."""
    fig, ax = plt.subplots(figsize=(9, 4))
    for label, t, u in series:
        ax.plot(t, u, lw=1.0, label=label)
    ax.set_xlabel("t since control start (s)")
    ax.set_ylabel("U, continuous law (veh/h)")
    ax.set_title(title)
    ax.legend(fontsize=8)
    fig.tight_layout()
    return fig
