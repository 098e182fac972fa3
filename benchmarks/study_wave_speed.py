"""Which way SUMO's speed and density fluctuations travel on the section (issue 17).

The paper's actuator sits at the outlet x = L and acts on the section through the one
characteristic that travels upstream (lambda_4 < 0 in congestion, clpsys4); whatever enters
at x = 0 and travels downstream reaches the meter without the meter acting on it. This
script measures the direction: for pairs of cells 250 m apart it cross-correlates the
fluctuation of a variable (each cell's series minus its mean over the control window) in
the micro fields of an ``arzsumo run`` result (``cells.parquet``) and reports the lag of
the peak (s; > 0: the downstream cell follows) and the travel speed it implies (km/h).

    python benchmarks/study_wave_speed.py results/default-etc-seed42-h450s [more runs]
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np
import pandas as pd

#: cell pairs (indices of 50 m cells): 250 m apart, upstream, middle, downstream
PAIRS = ((2, 7), (5, 10), (10, 15))
MAX_LAG_S = 60
VARIABLES = ("rho_h", "v_h", "rho_a", "v_a")


def lagged_corr(u: np.ndarray, w: np.ndarray, lag: int) -> float:
    """Correlation of u(t) with w(t + lag) (lag in samples, either sign)."""
    if lag >= 0:
        return float(np.corrcoef(u[:len(u) - lag], w[lag:])[0, 1])
    return float(np.corrcoef(u[-lag:], w[:len(w) + lag])[0, 1])


def travel(cells: pd.DataFrame, var: str) -> list[dict[str, float]]:
    """Peak lag and implied speed of ``var``'s fluctuations for every pair of ``PAIRS``."""
    micro = cells[cells["source"] == "micro"]
    field = micro.pivot(index="t_s", columns="x_m", values=var)
    field = field.interpolate(limit_direction="both")
    dt = float(np.median(np.diff(field.index.to_numpy())))
    a = field.to_numpy() - field.to_numpy().mean(axis=0)
    xs = field.columns.to_numpy()
    lags = np.arange(-int(MAX_LAG_S / dt), int(MAX_LAG_S / dt) + 1)
    rows = []
    for i, j in PAIRS:
        corr = np.array([lagged_corr(a[:, i], a[:, j], int(k)) for k in lags])
        k = int(np.nanargmax(corr))
        lag_s = float(lags[k] * dt)
        rows.append({"variable": var, "x_up_m": float(xs[i]), "x_down_m": float(xs[j]),
                     "lag_s": lag_s, "peak_corr": float(corr[k]),
                     "speed_kmh": (xs[j] - xs[i]) / lag_s * 3.6 if lag_s else np.nan})
    return rows


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("runs", type=Path, nargs="+", help="arzsumo run result directories")
    args = ap.parse_args()
    for run in args.runs:
        cells = pd.read_parquet(run / "cells.parquet")
        rows = [r for var in VARIABLES for r in travel(cells, var)]
        print(f"== {run}")
        print(pd.DataFrame(rows).round(2).to_string(index=False))
    return 0


if __name__ == "__main__":
    sys.exit(main())
