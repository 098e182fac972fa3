"""Figures of ``arzsumo reproduce``: release instants, penetration, sensitivity."""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.figure import Figure


def release_instants_figure(names: Sequence[str], event_times: Sequence[np.ndarray],
                            release: Sequence[float], horizon: float,
                            paper: Mapping[str, str] | None = None) -> Figure:
    """One row per run (``names`` top to bottom): a tick at each of its ``event_times``
    (control updates, s) up to ``horizon`` (s); the label gives the count and the total
    ``release`` time (s), and ``paper``'s numbers for that row label where given."""
    fig, ax = plt.subplots(figsize=(9, 0.45 * len(names) + 1.2))
    for k, times in enumerate(event_times):
        y = len(names) - 1 - k
        ax.vlines(times, y - 0.35, y + 0.35, lw=0.6, color="C0")
    labels = [f"{name}: {times.size} / {rel:.0f} s"
              + (f"  (paper {paper[name]})" if paper and name in paper else "")
              for name, times, rel in zip(names, event_times, release, strict=True)]
    ax.set_yticks(range(len(names)))
    ax.set_yticklabels(labels[::-1], fontsize=8)
    ax.set_xlim(0, horizon)
    ax.set_ylim(-0.6, len(names) - 0.4)
    ax.set_xlabel("time (s)")
    ax.set_title("Release instants: control updates (triggers / release time)")
    fig.tight_layout()
    return fig


def penetration_figure(pen: Sequence[float], ours_trig: Sequence[float],
                       ours_rel: Sequence[float], paper_trig: Sequence[float],
                       paper_rel: Sequence[float]) -> Figure:
    """Triggers and release time (s) against the AV penetration rate (percent)."""
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(9, 3.6))
    for ax, ours, paper, label in ((a1, ours_trig, paper_trig, "triggers"),
                                   (a2, ours_rel, paper_rel, "total release time (s)")):
        ax.plot(pen, ours, "o-", label="twin")
        ax.plot(pen, paper, "s--", label="paper (table diffpene)")
        ax.set_xlabel("AV penetration (%)")
        ax.set_ylabel(label)
        ax.grid(alpha=0.3)
    a1.legend()
    fig.suptitle("ETC at equal inflow, varying AV penetration")
    fig.tight_layout()
    return fig


def sensitivity_figure(sweeps: Mapping[str, tuple[np.ndarray, np.ndarray, np.ndarray]],
                       paper_values: Mapping[str, float] | None = None) -> Figure:
    """Release time and Lyapunov convergence time (s) per design parameter value.

    ``sweeps`` maps a parameter name to (values, release times, Lyapunov times); an
    infinite Lyapunov time (never converged) is left out. ``paper_values`` marks the
    paper's value of each parameter with a dotted line.
    """
    fig, axes = plt.subplots(1, max(1, len(sweeps)), figsize=(4 * max(1, len(sweeps)), 3.6),
                             squeeze=False)
    for ax, (par, (vals, rel, lyap)) in zip(axes[0], sweeps.items(), strict=False):
        ax.semilogx(vals, rel, "o-", color="C0", label="release time")
        ax.set_xlabel(par)
        ax.set_ylabel("total release time (s)", color="C0")
        ax2 = ax.twinx()
        finite = np.where(np.isfinite(lyap), lyap, np.nan)
        ax2.semilogx(vals, finite, "s--", color="C3", label="Lyapunov time")
        ax2.set_ylabel("Lyapunov convergence time (s)", color="C3")
        top = max([v for v in lyap if math.isfinite(v)] + [1.0])
        ax2.set_ylim(0, 1.3 * top)
        ax.set_ylim(0, 1.15 * max(max(rel), 1.0))
        if paper_values and par in paper_values:
            ax.axvline(paper_values[par], color="0.5", ls=":", lw=1)
            ax.text(paper_values[par], 5, " paper", color="0.4", fontsize=8)
        ax.grid(alpha=0.3)
    fig.suptitle("Sensitivity of the ETC to its design parameters")
    fig.tight_layout()
    return fig
