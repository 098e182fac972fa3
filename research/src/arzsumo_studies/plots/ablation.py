"""Figures of the ablation's mechanism (:mod:`arzsumo_studies.ablation.mechanism`): what
the green share bought, and the paired shift of speed spread against mean speed."""

from __future__ import annotations

from collections.abc import Mapping

import pandas as pd
from matplotlib.figure import Figure

from arzsumo.plots import plt


def _label(step: str, controller: str) -> str:
    return f"{step} " + ("open loop" if controller == "open" else controller)


def mechanism_map_figure(runs: pd.DataFrame, levels: Mapping[float, float]) -> Figure:
    """Section outflow (veh/h) against the mean green share, one dot per run (columns
    ``step``, ``controller``, ``green_mean``, ``section_outflow_veh_h``), with the static
    ``levels`` (green share -> veh/h) of held plans when given."""
    fig, ax = plt.subplots(figsize=(7, 4.5))
    ax.set_prop_cycle(color=plt.cm.tab20.colors)
    for (step, ctrl), g in runs.groupby(["step", "controller"]):
        ax.scatter(g["green_mean"], g["section_outflow_veh_h"], s=14, label=_label(step, ctrl))
    if levels:
        shares = sorted(levels)
        ax.plot(shares, [levels[g] for g in shares], "k--", marker="s",
                label="static levels, held plans (meter-dynamics)")
    seeds = runs["seed"].nunique()
    ax.set(xlabel="mean green share over the control window", xlim=(-0.02, 1.02),
           ylabel="section outflow (veh/h)", title=f"What the green share bought ({seeds} seeds)")
    ax.legend(fontsize=7, ncol=2)
    fig.tight_layout()
    return fig


def mechanism_shift_figure(pairs: pd.DataFrame) -> Figure:
    """Per class, the paired change of speed spread against the change of mean speed
    (km/h; columns ``d_speed_mean_<c>_kmh``, ``d_speed_sd_<c>_kmh``)."""
    fig, axes = plt.subplots(1, 2, figsize=(10, 4.2))
    for ax, c, name in zip(axes, ("h", "a"), ("HV", "AV"), strict=True):
        ax.set_prop_cycle(color=plt.cm.tab20.colors)
        for (step, ctrl), g in pairs.groupby(["step", "controller"]):
            ax.scatter(g[f"d_speed_mean_{c}_kmh"], g[f"d_speed_sd_{c}_kmh"], s=14,
                       label=f"{step} {ctrl}")
        ax.axhline(0, color="k", lw=0.6)
        ax.axvline(0, color="k", lw=0.6)
        ax.set(xlabel=f"{name} mean speed minus open loop (km/h)",
               ylabel=f"{name} speed spread minus open loop (km/h)",
               title=f"{name}, paired by seed")
    axes[0].legend(fontsize=7)
    fig.tight_layout()
    return fig
