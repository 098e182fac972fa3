"""Figures of ``arzsumo reproduce``: release instants, penetration, sensitivity.

Two layers: the ``*_figure`` functions take arrays and return a Figure; the writer
:func:`write_reproduce_plots` takes a reproduction and writes PNG files.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
from matplotlib.figure import Figure

from arzsumo.plots import save_png


def release_instants_figure(names: Sequence[str], event_times: Sequence[np.ndarray],
                            release: Sequence[float], horizon: float,
                            paper: Mapping[str, str] | None = None) -> Figure:
    """One row per run: a tick at each control update (s); the label gives the counts.

    Parameters
    ----------
    names : sequence of str
        Row labels (top to bottom).
    event_times : sequence of ndarray
        Update times of each run, s.
    release : sequence of float
        Total release time of each run, s (time without an update).
    horizon : float
        Simulated time, s.
    paper : mapping, optional
        Row label -> the paper's numbers, appended to the label.
    """
    fig, ax = plt.subplots(figsize=(9, 0.45 * len(names) + 1.2))
    for k, times in enumerate(event_times):
        y = len(names) - 1 - k
        ax.vlines(times, y - 0.35, y + 0.35, lw=0.6, color="C0")
    labels = []
    for name, times, rel in zip(names, event_times, release, strict=True):
        text = f"{name}: {times.size} / {rel:.0f} s"
        if paper and name in paper:
            text += f"  (paper {paper[name]})"
        labels.append(text)
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


def _save(fig: Figure, path: Path) -> Path:
    return save_png(fig, path, dpi=120)


def write_reproduce_plots(rep, out: str | Path) -> list[Path]:
    """Write release_instants.png, penetration.png and sensitivity.png into ``out``."""
    from arzsumo.twin.compare import penetration_table, sensitivity_table
    from arzsumo.twin.paper_values import EVENTS, SENSITIVITY

    out = Path(out)
    written = []
    runs = [r for r in rep.records if r.sweep is None and r.controller in ("etc",
                                                                           "observer-etc")]
    if runs:
        paper = {e.scenario: f"{e.triggers if e.triggers is not None else '-'} / "
                             f"{e.release_time:.0f} s" for e in EVENTS
                 if e.release_time is not None}
        horizon = float(runs[0].summary["final_time"])
        written.append(_save(release_instants_figure(
            [r.name for r in runs], [r.event_times for r in runs],
            [r.release_time for r in runs], horizon, paper),
            out / "release_instants.png"))
    pen = penetration_table(rep)
    if pen:
        col = {k: [row[k] for row in pen] for k in pen[0]}
        written.append(_save(penetration_figure(
            col["penetration_percent"], col["ours_triggers"], col["ours_release_time_s"],
            col["paper_triggers"], col["paper_release_time_s"]), out / "penetration.png"))
    sens = sensitivity_table(rep)
    if sens:
        sweeps = {}
        for par in SENSITIVITY:
            rows = [r for r in sens if r["parameter"] == par]
            if rows:
                sweeps[par] = tuple(np.array([r[k] for r in rows], float)
                                    for k in ("value", "release_time_s", "lyapunov_time_s"))
        from arzsumo.control.etc import PAPER_DESIGN

        written.append(_save(sensitivity_figure(
            sweeps, {p: float(getattr(PAPER_DESIGN, p)) for p in sweeps}),
            out / "sensitivity.png"))
    return written
