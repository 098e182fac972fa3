"""ALINEA's loop: flow against occupancy, the triangular fit, the critical occupancy and
the target (``arzsumo alinea-target``). Occupancy in %, flow in veh/h (a report)."""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.figure import Figure

from arzsumo.units import veh_s_to_veh_h


def loop_curve_figure(occupancy: np.ndarray, flow: np.ndarray, centres: np.ndarray,
                      mean: np.ndarray, fit: tuple[np.ndarray, np.ndarray], critical: float,
                      target: float, title: str, lower_bound: bool = False) -> Figure:
    """Period means (occupancy fraction, flow veh/s), the binned mean, the fitted curve
    ``fit`` (occupancies, flows) and the critical occupancy and target (fractions);
    ``lower_bound``: the critical occupancy is only a lower bound (no peak in the data)."""
    fig, ax = plt.subplots(figsize=(7, 4.6), layout="constrained")
    ax.plot(100 * occupancy, veh_s_to_veh_h(flow), ".", ms=4, alpha=0.4, color="0.45",
            label="period means")
    ax.plot(100 * centres, veh_s_to_veh_h(mean), "C0o-", ms=3, lw=1, label="bin mean")
    ax.plot(100 * fit[0], veh_s_to_veh_h(fit[1]), "C3", lw=2, label="triangular fit")
    what = "critical >=" if lower_bound else "critical"
    ax.axvline(100 * critical, color="C3", ls="--", label=f"{what} {100 * critical:.1f} %")
    ax.axvline(100 * target, color="C2", ls="-.", label=f"target {100 * target:.1f} %")
    ax.set_xlabel("loop occupancy (%)")
    ax.set_ylabel("loop flow (veh/h)")
    ax.set_title(title)
    ax.legend(fontsize=8)
    return fig
