"""Issue 15, point 1: map where SUMO holds a stationary congested section (approach edge).

Each point is one open-loop SUMO run (fixed meter plan) on the network with an ``approach``
buffer edge before x = 0: mainline demand (HV + AV at the default AV share) x nominal
green share x Krauss sigma x seed. After ``--warmup`` s, ``--measured`` s are measured on
``main`` (Edie, 50 m x 1 s cells) and every point records

* stationarity: the OLS slope of the section's vehicle count over the measured window
  (on 30 s block means, veh/min, with its 95 % t-interval), Kendall's tau test of those
  block means against time, and the drift over the window relative to the mean count;
* mean density (veh/km), Edie speed (km/h) and speed sd over cells x periods (km/h) per
  class; the share of congested cell-periods (speed below 40 km/h);
* section inflow and outflow (veh/h), the mainline inserted fraction at the end, the
  vehicles on the approach and its queue length (m) at the end, and the approach count's
  growth rate (veh/min);
* the regime under the calibrated model of ``scenarios/default.toml``: lambda_4 (km/h) of
  :func:`arzsumo.model.linearize` at the measured mean densities.

Usage (one CSV row per run, appended as runs finish; existing rows are skipped)::

    PYTHONPATH=src python benchmarks/study_approach.py \\
        --out docs/results/sumo_map/sumo_map.csv --jobs 2 \\
        --demands 4400 4800 5200 5664 6000 --greens 0.3 0.5 0.7 0.9 --sigmas 0.5 0.8
    PYTHONPATH=src python benchmarks/study_approach.py --plot docs/results/sumo_map/sumo_map.csv
"""

from __future__ import annotations

import argparse
import csv
import math
import multiprocessing as mp
import sys
import time
from concurrent.futures import ProcessPoolExecutor, as_completed
from pathlib import Path
from typing import Any

import numpy as np
from scipy import stats

ROOT = Path(__file__).resolve().parents[1]
SCENARIO = ROOT / "scenarios" / "default.toml"
AV_SHARE = 1560.0 / 5664.0          # the default scenario's mainline AV share (0.275)
BLOCK_S = 30.0                      # block length for the trend test, s
CONGESTED_KMH = 40.0                # a cell-period slower than this counts as congested
#: initial congested section (veh/km, km/h): near the merge's discharge state measured at
#: 5664 veh/h, green share 0.5 (85 / 46 veh/km); it spares the ~20 min a small demand
#: excess needs to fill the section from free flow
INIT_RHO_H, INIT_RHO_A, INIT_V_KMH = 85.0, 45.0, 20.0
FIELDS = ["demand_veh_h", "green_share", "hv_sigma", "seed", "approach_m", "step_s",
          "initial", "av_share", "warmup_s", "measured_s", "wall_s", "n_mean",
          "slope_veh_min", "slope_lo",
          "slope_hi", "kendall_p", "drift_rel", "stationary", "rho_h_veh_km",
          "rho_a_veh_km", "v_h_kmh", "v_a_kmh", "sd_v_h_kmh", "sd_v_a_kmh",
          "congested_share", "inflow_veh_h", "outflow_veh_h", "inserted_main",
          "approach_veh_end", "queue_m_end", "approach_slope_veh_min", "ramp_queue_end",
          "lambda4_kmh", "regime", "collisions", "emergency_stops"]


def trend(n: np.ndarray, dt: float) -> dict[str, float]:
    """Trend of the section count ``n`` (one sample per ``dt`` s) on BLOCK_S block means.

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


def regime(rho_h: float, rho_a: float) -> tuple[float, str]:
    """lambda_4 (km/h) and regime of the calibrated model at densities in veh/km."""
    from arzsumo.model import Equilibrium, linearize
    from arzsumo.scenario import load_scenario

    params = load_scenario(SCENARIO).params
    try:
        lam = linearize(Equilibrium(params, rho_h / 1000.0, rho_a / 1000.0)).eigenvalues
    except Exception:  # AO beyond the model's AO_max: a state the model cannot hold
        return math.nan, "beyond AO_max"
    lam4 = float(lam[3]) * 3.6
    return lam4, "congested" if lam4 < 0 else "free"


def queue_end(lib: Any, length: float) -> tuple[int, float]:
    """Vehicles on the approach and its queue length (m from x = 0 to the farthest
    upstream vehicle slower than 10 km/h)."""
    ids = lib.edge.getLastStepVehicleIDs("approach")
    slow = [lib.vehicle.getLanePosition(v) for v in ids if lib.vehicle.getSpeed(v) < 10 / 3.6]
    return len(ids), (length - min(slow)) if slow else 0.0


def initial_vehicles(params: Any, cfg: Any) -> list[Any]:
    """A uniform congested section at INIT_RHO_H / INIT_RHO_A, INIT_V_KMH."""
    from arzsumo.sumo.placement import place_vehicles

    x = (np.arange(20) + 0.5) * params.length / 20
    one = np.ones_like(x)
    v = INIT_V_KMH / 3.6 * one
    return place_vehicles(params, cfg, x, INIT_RHO_H / 1000 * one, v,
                          INIT_RHO_A / 1000 * one, v)[0]


def open_loop(params: Any, cfg: Any, warmup: float, initial: list[Any] | None = None
              ) -> tuple[list[Any], list[int], tuple[int, float], int, Any]:
    """One open-loop run (nominal meter): the Edie cells and approach counts of every period
    after ``warmup`` s, the approach's vehicles and queue (m) and the ramp queue at the end,
    and SUMO's run report."""
    from arzsumo.sumo.meter import RampMeter
    from arzsumo.sumo.sensor import SumoSensor
    from arzsumo.sumo.simulation import open_simulation

    cells, n_app = [], []
    with open_simulation(params, cfg, initial=initial or []) as sim:
        meter = RampMeter(sim.lib, cfg)
        sensor = SumoSensor(sim.lib, params.length, cfg)
        while sim.time < cfg.horizon - 1e-9:
            got = sensor.observe(sim.step())
            meter.step(sensor.queue)
            if got is not None and got.t > warmup + 1e-9:
                cells.append(got.cells)
                n_app.append(sim.lib.edge.getLastStepVehicleNumber("approach"))
        end = queue_end(sim.lib, cfg.approach_length)
        ramp_q = sensor.queue
    return cells, n_app, end, ramp_q, sim.report


def run_point(demand: float, green: float, sigma: float, seed: int, approach: float,
              warmup: float, measured: float, step: float, initial: bool,
              av_share: float = AV_SHARE) -> dict[str, Any]:
    """One open-loop run; returns the CSV row (units in the column names)."""
    from arzsumo.scenario import load_scenario

    t0 = time.perf_counter()
    sc = load_scenario(SCENARIO)
    cfg = sc.sumo.with_(
        demand_h=demand * (1 - av_share) / 3600, demand_a=demand * av_share / 3600,
        green_share=green, hv_sigma=sigma, seed=seed, approach_length=approach,
        horizon=warmup + measured, step_length=step)
    init = initial_vehicles(sc.params, cfg) if initial else []
    cells, n_app, (app_veh, queue_m), ramp_q, rep = open_loop(sc.params, cfg, warmup, init)
    row = {"demand_veh_h": demand, "green_share": green, "hv_sigma": sigma, "seed": seed,
           "approach_m": approach, "step_s": step, "initial": int(initial),
           "av_share": av_share,
           "warmup_s": warmup, "measured_s": measured}
    row.update(run_measures(cfg, cells, n_app, (app_veh, queue_m), ramp_q, rep))
    row["wall_s"] = time.perf_counter() - t0
    return row


def run_measures(cfg: Any, cells: list[Any], n_app: list[int], end: tuple[int, float],
                 ramp_q: int, rep: Any) -> dict[str, Any]:
    """The CSV columns of one run from :func:`open_loop`'s results (units in the names)."""
    row = summarise(cells, cfg.cell_length)
    row["inserted_main"] = rep.delivered_main
    row["approach_veh_end"], row["queue_m_end"] = end
    row["approach_slope_veh_min"] = trend(np.asarray(n_app, float),
                                          cfg.control_period)["slope_veh_min"]
    row["ramp_queue_end"] = ramp_q
    row["lambda4_kmh"], row["regime"] = regime(row["rho_h_veh_km"], row["rho_a_veh_km"])
    row["collisions"], row["emergency_stops"] = rep.collisions, rep.emergency_stops
    row["stationary"] = int(row["kendall_p"] > 0.05 and abs(row["drift_rel"]) < 0.1)
    return row


def summarise(cells: list[Any], dx: float) -> dict[str, float]:
    """Per-class density, Edie speed, speed sd and flows over the measured periods."""
    rho = {c: np.array([getattr(d, f"rho_{c}") for d in cells]) for c in "ha"}
    q = {c: np.array([getattr(d, f"q_{c}") for d in cells]) for c in "ha"}
    v = {c: np.array([getattr(d, f"v_{c}") for d in cells]) for c in "ha"}
    n = ((rho["h"] + rho["a"]) * dx).sum(axis=1)
    out = trend(n, cells[0].window)
    for c in "ha":
        out[f"rho_{c}_veh_km"] = float(rho[c].mean() * 1000)
        out[f"v_{c}_kmh"] = float(q[c].sum() / rho[c].sum() * 3.6)
        out[f"sd_v_{c}_kmh"] = float(np.nanstd(v[c]) * 3.6)
    vmix = (q["h"] + q["a"]) / np.where(rho["h"] + rho["a"] > 0, rho["h"] + rho["a"], np.nan)
    out["congested_share"] = float(np.nanmean(vmix * 3.6 < CONGESTED_KMH))
    out["inflow_veh_h"] = float(np.mean([d.inflow_h + d.inflow_a for d in cells]) * 3600)
    out["outflow_veh_h"] = float(np.mean([d.outflow_h + d.outflow_a for d in cells]) * 3600)
    return out


def _key(row: dict[str, Any]) -> tuple:
    return (float(row["demand_veh_h"]), float(row["green_share"]), float(row["hv_sigma"]),
            int(row["seed"]), float(row["approach_m"]), float(row["step_s"]),
            int(row["initial"]), float(row["warmup_s"]), float(row["measured_s"]),
            round(float(row.get("av_share") or AV_SHARE), 6))


def sweep(args: argparse.Namespace) -> None:
    """Run every missing point of the grid, appending rows to ``args.out``."""
    out = Path(args.out)
    done = set()
    if out.is_file():
        with out.open() as f:
            done = {_key(r) for r in csv.DictReader(f)}
    names = ["demand_veh_h", "green_share", "hv_sigma", "seed", "approach_m", "warmup_s",
             "measured_s", "step_s", "initial", "av_share"]
    todo = [(d, g, s, seed, args.approach, args.warmup, args.measured, args.step,
             not args.empty_start, args.av_share)
            for s in args.sigmas for seed in args.seeds for d in args.demands
            for g in args.greens]
    todo = [p for p in todo if _key(dict(zip(names, p, strict=True))) not in done]
    print(f"{len(todo)} runs to do", flush=True)
    new = not out.is_file()
    with out.open("a", newline="") as f, ProcessPoolExecutor(
            args.jobs, mp_context=mp.get_context("spawn"), max_tasks_per_child=1) as pool:
        w = csv.DictWriter(f, FIELDS)
        if new:
            w.writeheader()
        futs = [pool.submit(run_point, *p) for p in todo]
        for fut in as_completed(futs):
            row = fut.result()
            w.writerow({k: (f"{v:.5g}" if isinstance(v, float) else v)
                        for k, v in row.items()})
            f.flush()
            shown = FIELDS[:4] + FIELDS[FIELDS.index("wall_s"):]
            print(", ".join(f"{k}={row[k]:.4g}" if isinstance(row[k], float) else
                            f"{k}={row[k]}" for k in shown), flush=True)


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--out", default="docs/results/sumo_map/sumo_map.csv")
    p.add_argument("--demands", type=float, nargs="+", default=[4400, 4800, 5200, 5664, 6000])
    p.add_argument("--greens", type=float, nargs="+", default=[0.3, 0.5, 0.7, 0.9])
    p.add_argument("--sigmas", type=float, nargs="+", default=[0.5])
    p.add_argument("--seeds", type=int, nargs="+", default=[1])
    p.add_argument("--approach", type=float, default=1500.0, help="buffer length, m")
    p.add_argument("--empty-start", action="store_true",
                   help="start with an empty section (default: a congested one)")
    p.add_argument("--warmup", type=float, default=150.0)
    p.add_argument("--av-share", type=float, default=AV_SHARE,
                   help="AV share of the mainline demand (default: the default scenario's)")
    p.add_argument("--measured", type=float, default=450.0)
    p.add_argument("--step", type=float, default=0.1)
    p.add_argument("--jobs", type=int, default=1)
    p.add_argument("--plot", metavar="CSV", help="only draw the map of CSV (next to it)")
    args = p.parse_args(argv)
    if args.plot:
        from study_approach_plot import plot_map

        print(plot_map(Path(args.plot)))
        return 0
    sweep(args)
    return 0


if __name__ == "__main__":
    sys.exit(main())
