"""One open-loop SUMO run on the approach network and its stationarity measures: what the
``approach`` and ``fill`` studies record per run.

The meter runs its nominal fixed-cycle plan; after the warm-up, every control period the
section's Edie cells (50 m x 1 s by default) and the vehicles on the approach are kept.
:func:`run_measures` then gives, per run (units in the names):

* stationarity: the OLS slope of the section's vehicle count over the measured window on
  :data:`BLOCK_S` block means (veh/min, with its 95 % t interval), Kendall's tau test of
  those block means against time, and the drift over the window relative to the mean
  count; ``stationary`` when Kendall's p > 0.05 and the drift is under 10 %;
* mean density (veh/km), Edie speed and speed sd over cells x periods (km/h) per class;
  the share of congested cell-periods (slower than :data:`CONGESTED_KMH`);
* section inflow and outflow (veh/h), the mainline inserted fraction, the vehicles on the
  approach and its queue length at the end (m), and the approach count's trend;
* the regime under the scenario's model: lambda_4 (km/h) of
  :func:`arzsumo.model.linearize` at the measured mean densities.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from scipy import stats

from arzsumo.units import (
    kmh_to_ms,
    ms_to_kmh,
    veh_km_to_veh_m,
    veh_m_to_veh_km,
    veh_s_to_veh_h,
)

#: block length of the trend test, s
BLOCK_S = 30.0
#: a cell-period slower than this counts as congested, km/h
CONGESTED_KMH = 40.0
#: an optional congested start (veh/km, km/h): near the merge's discharge state measured
#: at 5664 veh/h and green share 0.5; it spares the ~20 min a small demand excess needs
#: to fill the section from free flow
INIT_RHO_H, INIT_RHO_A, INIT_V_KMH = 85.0, 45.0, 20.0
#: a vehicle on the approach slower than this is queued, km/h
QUEUED_KMH = 10.0


def trend(n: np.ndarray, dt: float) -> dict[str, float]:
    """Trend of the section count ``n`` (one sample per ``dt`` s) on block means.

    Block means tame the autocorrelation of the stop-and-go waves, so the OLS interval
    and Kendall's test are not fooled by it as much as on raw 1 s samples.
    """
    per = max(1, round(BLOCK_S / dt))
    nb = len(n) // per
    blocks = n[: nb * per].reshape(nb, per).mean(axis=1)
    t_min = (np.arange(nb) + 0.5) * per * dt / 60.0
    fit = stats.linregress(t_min, blocks)
    half = stats.t.ppf(0.975, nb - 2) * fit.stderr
    tau = stats.kendalltau(t_min, blocks)
    mean = float(n.mean())
    drift = fit.slope * len(n) * dt / 60.0 / mean if mean > 0 else math.nan
    return {"n_mean": mean, "slope_veh_min": fit.slope, "slope_lo": fit.slope - half,
            "slope_hi": fit.slope + half, "kendall_p": float(tau.pvalue),
            "drift_rel": float(drift)}


def regime(params: Any, rho_h: float, rho_a: float) -> tuple[float, str]:
    """lambda_4 (km/h) and regime of the model ``params`` at densities in veh/km."""
    from arzsumo.errors import ModelError
    from arzsumo.model import Equilibrium, linearize

    try:
        eq = Equilibrium(params, veh_km_to_veh_m(rho_h), veh_km_to_veh_m(rho_a))
        lam = linearize(eq).eigenvalues
    except ModelError:  # AO beyond the model's AO_max: a state the model cannot hold
        return math.nan, "beyond AO_max"
    lam4 = ms_to_kmh(float(lam[3]))
    return lam4, "congested" if lam4 < 0 else "free"


def initial_vehicles(params: Any, cfg: Any) -> list[Any]:
    """A uniform congested section at INIT_RHO_H / INIT_RHO_A and INIT_V_KMH."""
    from arzsumo.pde.state import cell_centres
    from arzsumo.sumo.placement import place_vehicles

    x = cell_centres(params.length, 20)
    one = np.ones_like(x)
    v = kmh_to_ms(INIT_V_KMH) * one
    return place_vehicles(params, cfg, x, veh_km_to_veh_m(INIT_RHO_H) * one, v,
                          veh_km_to_veh_m(INIT_RHO_A) * one, v)[0]


def open_loop(params: Any, cfg: Any, warmup: float, initial: list[Any] | None = None
              ) -> tuple[list[Any], list[int], tuple[int, float], int, Any]:
    """One open-loop run (nominal fixed-cycle meter) to ``cfg.horizon`` s: the Edie cells
    and approach counts of every period after ``warmup`` s, the approach's vehicles and
    queue (m from x = 0 to the farthest upstream vehicle slower than :data:`QUEUED_KMH`)
    and the ramp queue at the end, and SUMO's run report."""
    from arzsumo.sumo.network import APPROACH
    from arzsumo.sumo.period_reads import OpenLoopPeriod, OpenLoopReads
    from arzsumo.sumo.plant import SumoPlant
    from arzsumo.sumo.simulation import open_simulation

    cells, n_app = [], []

    def keep(p: OpenLoopPeriod) -> None:
        if p.measurement is not None and p.t > warmup + 1e-9:
            cells.append(p.measurement.cells)
            n_app.append(p.vehicles[APPROACH])

    reads = OpenLoopReads(edges=(APPROACH,), queued_below=kmh_to_ms(QUEUED_KMH))
    with open_simulation(params, cfg, initial=initial or []) as sim:
        plant = SumoPlant(sim, params.length, cfg)     # the fixed cycle: cfg's mode
        end = plant.run_open_loop(on_period=keep, until=cfg.horizon, reads=reads)
    return cells, n_app, end.approach, end.ramp_queue, sim.report


def summarise(cells: list[Any], dx: float) -> dict[str, float]:
    """Per-class density, Edie speed, speed sd and flows over the measured periods."""
    rho = {c: np.array([getattr(d, f"rho_{c}") for d in cells]) for c in "ha"}
    q = {c: np.array([getattr(d, f"q_{c}") for d in cells]) for c in "ha"}
    v = {c: np.array([getattr(d, f"v_{c}") for d in cells]) for c in "ha"}
    n = ((rho["h"] + rho["a"]) * dx).sum(axis=1)
    out = trend(n, cells[0].window)
    for c in "ha":
        out[f"rho_{c}_veh_km"] = veh_m_to_veh_km(float(rho[c].mean()))
        out[f"v_{c}_kmh"] = ms_to_kmh(float(q[c].sum() / rho[c].sum()))
        out[f"sd_v_{c}_kmh"] = ms_to_kmh(float(np.nanstd(v[c])))
    total = rho["h"] + rho["a"]
    vmix = (q["h"] + q["a"]) / np.where(total > 0, total, np.nan)
    out["congested_share"] = float(np.nanmean(ms_to_kmh(vmix) < CONGESTED_KMH))
    inflow = np.mean([d.inflow_h + d.inflow_a for d in cells])
    out["inflow_veh_h"] = veh_s_to_veh_h(float(inflow))
    out["outflow_veh_h"] = veh_s_to_veh_h(float(np.mean([d.outflow_h + d.outflow_a
                                                         for d in cells])))
    for c in "ha":
        out[f"outflow_{c}_veh_h"] = veh_s_to_veh_h(float(np.mean(
            [getattr(d, f"outflow_{c}") for d in cells])))
    return out


def run_measures(params: Any, cfg: Any, warmup: float, initial: list[Any] | None = None
                 ) -> dict[str, Any]:
    """Run :func:`open_loop` and return its measures (the module docstring)."""
    cells, n_app, (app_veh, queue_m), ramp_q, rep = open_loop(params, cfg, warmup, initial)
    row = summarise(cells, cfg.cell_length)
    row["inserted_main"] = rep.delivered_main
    row["approach_veh_end"], row["queue_m_end"] = app_veh, queue_m
    row["approach_slope_veh_min"] = trend(np.asarray(n_app, float),
                                          cfg.control_period)["slope_veh_min"]
    row["ramp_queue_end"] = ramp_q
    row["lambda4_kmh"], row["regime"] = regime(params, row["rho_h_veh_km"],
                                               row["rho_a_veh_km"])
    row["collisions"], row["emergency_stops"] = rep.collisions, rep.emergency_stops
    row["stationary"] = int(row["kendall_p"] > 0.05 and abs(row["drift_rel"]) < 0.1)
    return row
