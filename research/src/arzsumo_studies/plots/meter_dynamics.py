"""The figure of the meter-dynamics study (:mod:`arzsumo_studies.sumo_map.meter_dynamics`): the
green-share staircase per seed and the mean normalised step response per direction."""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np
from matplotlib.figure import Figure

from arzsumo.plots import plt
from arzsumo.units import veh_s_to_veh_h

#: (name, lag s, mean response veh/h, fitted response veh/h, fit label)
Ensemble = tuple[str, np.ndarray, np.ndarray, np.ndarray, str]


def _seed_panel(ax, d: Mapping[str, np.ndarray], model: tuple[np.ndarray, np.ndarray],
                seed: int) -> None:
    t = d["t_s"]
    ax.plot(t, veh_s_to_veh_h(d["y"]), ".", ms=2, color="0.7", label="outflow per 1 s")
    n = t.size // 10
    tb = t[: n * 10].reshape(n, 10)[:, -1]
    yb = veh_s_to_veh_h(d["y"][: n * 10].reshape(n, 10).mean(axis=1))
    ax.step(tb, yb, where="post", color="C0", label="10 s mean")
    ax.plot(model[0], veh_s_to_veh_h(model[1]), color="C3", lw=1.5, label="FOPDT fit (staircase)")
    ax.set_ylim(0, 9000)
    ax.set_ylabel("q(L) veh/h")
    ax.set_title(f"seed {seed}", fontsize=9)
    tw = ax.twinx()
    tw.plot(t, d["g_run"], color="k", lw=0.8, drawstyle="steps-pre")
    tw.set_ylim(0, 2)
    tw.set_yticks([0.2, 0.5, 0.8])
    tw.set_ylabel("green share")


def steps_figure(data: Mapping[int, Mapping[str, np.ndarray]],
                 models: Mapping[int, tuple[np.ndarray, np.ndarray]],
                 ensembles: Sequence[Ensemble]) -> Figure:
    """Per seed: outflow per second (``y`` veh/s against ``t_s`` s), 10 s means, the
    staircase fit (``models``: seed -> (t s, veh/s)) and the running green share
    (``g_run``); last panel: the mean normalised response per direction with its fit."""
    seeds = sorted(data)
    fig, axes = plt.subplots(len(seeds) + 1, 1, figsize=(10, 2.6 * (len(seeds) + 1)),
                             squeeze=False)
    axes = axes[:, 0]
    for ax, seed in zip(axes, seeds, strict=False):
        _seed_panel(ax, data[seed], models[seed], seed)
    axes[0].legend(loc="upper left", fontsize=7, ncol=3)
    axes[-2].set_xlabel("t s")
    ax = axes[-1]
    for k, (name, lag, mean, fit, label) in enumerate(ensembles):
        color = ("C0", "C2")[k % 2]
        ax.plot(lag, mean, ".-", ms=3, color=color, lw=0.6, label=f"mean {name}, 6 s means")
        ax.plot(lag, fit, color=color, lw=2, alpha=0.6, label=label)
    ax.axvline(0, color="k", lw=0.5)
    ax.set_xlabel("s since the plan change")
    ax.set_ylabel("(q - q before) / du, veh/h")
    ax.legend(fontsize=7)
    fig.tight_layout()
    return fig
