"""Where a speed field's fluctuations lie in time scale: the places' mean periodogram.

One panel per class, one curve per run, the caller's bands of periods shaded; arrays in
SI, power drawn in (km/h)^2 s.
"""

from __future__ import annotations

from collections.abc import Mapping

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.figure import Figure

from arzsumo.units import ms2_to_kmh2

NAMES = {"h": "HV", "a": "AV"}
#: the shading of the bands, in order
COLOURS = ("tab:red", "tab:blue", "tab:green")


def spectrum_figure(curves: Mapping[str, Mapping[str, tuple[np.ndarray, np.ndarray]]],
                    bands: Mapping[str, tuple[float, float]], title: str = "") -> Figure:
    """The figure (module docstring): ``curves`` maps a run label and a class to (periods s,
    mean periodogram density (m/s)^2 s) as :func:`arzsumo.evaluation.waves.mean_periodogram`
    gives them; ``bands`` a label to the (shortest, longest) period (s) of a band to shade."""
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.2), layout="constrained", sharey=True)
    for ax, cls in zip(axes, NAMES, strict=True):
        for (name, (lo, hi)), colour in zip(bands.items(), COLOURS, strict=False):
            ax.axvspan(lo, hi, color=colour, alpha=0.12, label=name)
        for label, per_class in curves.items():
            periods, psd = per_class[cls]
            if periods.size:
                ax.loglog(periods, ms2_to_kmh2(psd), lw=1.0, label=label)
        ax.set_xlabel("period (s)")
        ax.set_title(f"{NAMES[cls]} speed: places' mean periodogram", fontsize=10)
        ax.grid(True, which="both", alpha=0.3)
    axes[0].set_ylabel("power density ((km/h)^2 s)")
    axes[1].legend(fontsize=7, loc="lower right")
    if title:
        fig.suptitle(title)
    return fig
